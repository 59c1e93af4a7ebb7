#include "overdraw/plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace overdraw {
namespace {

using render::Colour8;
using render::Picture;

constexpr Colour8 kInk{40, 40, 40}, kGrid{225, 225, 225}, kGrey{120, 120, 120};
constexpr int kText = 14;

std::string number(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.4g", v);
  return buffer;
}

// Every pixel of the segment (DDA), inside `clip` only; `dash` > 0 draws dash-long pieces
// with dash-long gaps.
void draw_line(Picture& p, double x0, double y0, double x1, double y1, const Colour8& c,
               const render::Rect& clip, int dash = 0) {
  const int steps = std::max(1, int(std::ceil(std::max(std::abs(x1 - x0), std::abs(y1 - y0)))));
  for (int i = 0; i <= steps; ++i) {
    if (dash > 0 && (i / dash) % 2 == 1) continue;
    const double t = double(i) / steps;
    const int x = int(std::lround(x0 + t * (x1 - x0))), y = int(std::lround(y0 + t * (y1 - y0)));
    if (x >= clip.x0 && x < clip.x1 && y >= clip.y0 && y < clip.y1) p.set(x, y, c);
  }
}

render::Rect area(const PanelAxes& a) {
  return {a.left, a.top, a.left + a.width, a.top + a.height};
}

void marker(Picture& p, const PanelAxes& a, double x, double y, const Colour8& c) {
  const int cx = a.px(x), cy = a.py(y);
  render::fill_rect(
      p, {cx - kMarkerHalf, cy - kMarkerHalf, cx + kMarkerHalf + 1, cy + kMarkerHalf + 1}, c);
}

// Border, five grid lines and tick labels per axis, the panel title and the x axis's name.
void draw_frame(Picture& p, const PanelAxes& a, const std::string& title,
                const std::string& x_name) {
  const render::Rect whole{0, 0, p.width, p.height};
  for (int i = 0; i <= 4; ++i) {
    const double xv = a.x.lo + (a.x.hi - a.x.lo) * i / 4, yv = a.y.lo + (a.y.hi - a.y.lo) * i / 4;
    draw_line(p, a.px(xv), a.top, a.px(xv), a.top + a.height - 1, kGrid, whole);
    draw_line(p, a.left, a.py(yv), a.left + a.width - 1, a.py(yv), kGrid, whole);
    render::draw_text(p, a.px(xv) - 18, a.top + a.height + 18, number(xv), kText - 2, kInk);
    render::draw_text(p, a.left - kMarginLeft + 4, a.py(yv) + 5, number(yv), kText - 2, kInk);
  }
  const int r = a.left + a.width - 1, b = a.top + a.height - 1;
  draw_line(p, a.left, a.top, r, a.top, kInk, whole);
  draw_line(p, a.left, b, r, b, kInk, whole);
  draw_line(p, a.left, a.top, a.left, b, kInk, whole);
  draw_line(p, r, a.top, r, b, kInk, whole);
  render::draw_text(p, a.left, a.top - 10, title, kText, kInk);
  render::draw_text(p, a.left + a.width / 2 - 50, a.top + a.height + 40, x_name, kText, kInk);
}

Picture canvas(int panels) {
  const int columns = std::min(panels, kPanelColumns);
  const int rows = (panels + kPanelColumns - 1) / kPanelColumns;
  return Picture(columns * kPanelWidth, kTitleHeight + rows * kPanelHeight,
                 render::kPictureBackground);
}

std::vector<std::string> methods_of(const std::vector<OverdrawRow>& rows) {
  std::vector<std::string> out;
  for (const OverdrawRow& r : rows)
    if (std::find(out.begin(), out.end(), r.method) == out.end()) out.push_back(r.method);
  return out;
}

int index_of(const std::vector<std::string>& list, const std::string& item) {
  return int(std::find(list.begin(), list.end(), item) - list.begin());
}

// Title and one swatch per method across the title strip.
void legend(Picture& p, const std::string& title, const std::vector<std::string>& methods) {
  render::draw_text(p, 8, 22, title, kText + 1, kInk);
  int x = std::max(8 + int(title.size()) * 8 + 16, p.width / 2);
  for (std::size_t m = 0; m < methods.size(); ++m) {
    render::fill_rect(p, {x, 12, x + 10, 22}, method_colour(int(m)));
    render::draw_text(p, x + 14, 22, methods[m], kText - 2, kInk);
    x += 22 + int(methods[m].size()) * 7;
  }
}

Range range_of(const std::vector<double>& v) {
  const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
  return padded_range(*lo, *hi);
}

// The rows no other row beats on both overdraw and SE, by increasing overdraw.
std::vector<const OverdrawRow*> pareto_front(std::vector<const OverdrawRow*> rows) {
  std::sort(rows.begin(), rows.end(), [](const OverdrawRow* a, const OverdrawRow* b) {
    return a->average_overdraw != b->average_overdraw ? a->average_overdraw < b->average_overdraw
                                                      : a->average_se < b->average_se;
  });
  std::vector<const OverdrawRow*> front;
  for (const OverdrawRow* r : rows)
    if (front.empty() || r->average_se < front.back()->average_se) front.push_back(r);
  return front;
}

void pareto_panel(Picture& p, int index, const std::vector<const OverdrawRow*>& rows,
                  const std::vector<std::string>& methods, const std::map<int, double>& thesis) {
  const int k = rows.front()->clusters;
  std::vector<double> xs, ys;
  for (const OverdrawRow* r : rows) {
    xs.push_back(r->average_overdraw);
    ys.push_back(r->average_se);
  }
  const auto mark = thesis.find(k);
  if (mark != thesis.end()) xs.push_back(mark->second);
  const PanelAxes a = panel_axes(index, range_of(xs), range_of(ys));
  draw_frame(p, a,
             "K = " + std::to_string(k) + ", " + std::to_string(rows.front()->clusters_per_pass) +
                 " per pass: Average SE",
             "average overdraw");
  if (mark != thesis.end()) {
    draw_line(p, a.px(mark->second), a.top, a.px(mark->second), a.top + a.height - 1, kGrey,
              area(a), 4);
    render::draw_text(p, a.px(mark->second) + 4, a.top + 16, "thesis best", kText - 2, kGrey);
  }
  const std::vector<const OverdrawRow*> front = pareto_front(rows);
  for (std::size_t i = 1; i < front.size(); ++i)
    draw_line(p, a.px(front[i - 1]->average_overdraw), a.py(front[i - 1]->average_se),
              a.px(front[i]->average_overdraw), a.py(front[i]->average_se), kInk, area(a));
  for (const OverdrawRow* r : rows)
    marker(p, a, r->average_overdraw, r->average_se, method_colour(index_of(methods, r->method)));
}

// One timing panel: medians with their IQR whiskers and the fitted line.
enum class Timing { kGl, kFps, kProcessCpu };

const Spread& spread_of(const OverdrawRow& r, Timing t) {
  return t == Timing::kGl    ? r.gl_ms_spread
         : t == Timing::kFps ? r.fps_spread
                             : r.process_cpu_spread;
}

void timing_panel(Picture& p, int index, const OverdrawReport& report, Timing which,
                  const std::vector<std::string>& methods) {
  std::vector<double> xs, ys;
  for (const OverdrawRow& r : report.rows) {
    const Spread& s = spread_of(r, which);
    xs.push_back(r.average_overdraw);
    ys.insert(ys.end(), {s.median, s.q1, s.q3});
  }
  const PanelAxes a = panel_axes(index, range_of(xs), range_of(ys));
  const LineFit& f = which == Timing::kGl    ? report.gl_fit
                     : which == Timing::kFps ? report.fps_fit
                                             : report.process_cpu_fit;
  const char* name = which == Timing::kGl    ? "GL ms"
                     : which == Timing::kFps ? "FPS"
                                             : "process CPU ms";
  draw_frame(p, a,
             std::string(name) + " = " + number(f.slope) + " x " + (f.intercept < 0 ? "- " : "+ ") +
                 number(std::abs(f.intercept)) + ", R^2 = " + number(f.r2),
             "average overdraw");
  draw_line(p, a.px(a.x.lo), a.py(f.at(a.x.lo)), a.px(a.x.hi), a.py(f.at(a.x.hi)), kGrey, area(a));
  for (const OverdrawRow& r : report.rows) {
    const Spread& s = spread_of(r, which);
    const Colour8 c = method_colour(index_of(methods, r.method));
    draw_line(p, a.px(r.average_overdraw), a.py(s.q1), a.px(r.average_overdraw), a.py(s.q3), c,
              area(a));
    marker(p, a, r.average_overdraw, s.median, c);
  }
}

}  // namespace

Range padded_range(double lo, double hi) {
  double span = hi - lo;
  if (!(span > 0)) {
    const double half = lo != 0 ? 0.1 * std::abs(lo) : 1.0;
    return {lo - half, hi + half};
  }
  return {lo - 0.08 * span, hi + 0.08 * span};
}

int PanelAxes::px(double v) const {
  return left + int(std::lround((v - x.lo) / (x.hi - x.lo) * (width - 1)));
}
int PanelAxes::py(double v) const {
  return top + height - 1 - int(std::lround((v - y.lo) / (y.hi - y.lo) * (height - 1)));
}

PanelAxes panel_axes(int index, Range x, Range y) {
  PanelAxes a;
  a.left = (index % kPanelColumns) * kPanelWidth + kMarginLeft;
  a.top = kTitleHeight + (index / kPanelColumns) * kPanelHeight + kMarginTop;
  a.width = kPanelWidth - kMarginLeft - kMarginRight;
  a.height = kPanelHeight - kMarginTop - kMarginBottom;
  a.x = x;
  a.y = y;
  return a;
}

render::Colour8 method_colour(int method_index) {
  static constexpr Colour8 kColours[] = {{31, 119, 180},  {255, 127, 14},  {44, 160, 44},
                                         {214, 39, 40},   {148, 103, 189}, {140, 86, 75},
                                         {227, 119, 194}, {188, 189, 34},  {23, 190, 207}};
  return kColours[std::size_t(method_index) % std::size(kColours)];
}

const std::map<int, double>& thesis_best_overdraw() {
  static const std::map<int, double> best{{64, 1.208}, {128, 1.286}, {192, 1.338}, {256, 1.379}};
  return best;
}

render::Picture pareto_plot(const OverdrawReport& report, const std::string& budget,
                            const std::map<int, double>& thesis) {
  std::vector<int> ks;
  for (const OverdrawRow& r : report.rows)
    if (r.budget == budget && std::find(ks.begin(), ks.end(), r.clusters) == ks.end())
      ks.push_back(r.clusters);
  if (ks.empty()) throw std::invalid_argument("pareto_plot: no rows for budget " + budget);
  const std::vector<std::string> methods = methods_of(report.rows);
  Picture p = canvas(int(ks.size()));
  legend(p, "Average SE vs overdraw, " + budget + " budget", methods);
  for (std::size_t i = 0; i < ks.size(); ++i) {
    std::vector<const OverdrawRow*> rows;
    for (const OverdrawRow& r : report.rows)
      if (r.budget == budget && r.clusters == ks[i]) rows.push_back(&r);
    pareto_panel(p, int(i), rows, methods, thesis);
  }
  return p;
}

render::Picture timing_plot(const OverdrawReport& report) {
  if (report.rows.empty()) throw std::invalid_argument("timing_plot: the report has no rows");
  const std::vector<std::string> methods = methods_of(report.rows);
  Picture p = canvas(3);
  legend(p, "Multipass time vs overdraw, all rows (median, IQR)", methods);
  timing_panel(p, 0, report, Timing::kGl, methods);
  timing_panel(p, 1, report, Timing::kFps, methods);
  timing_panel(p, 2, report, Timing::kProcessCpu, methods);
  return p;
}

}  // namespace overdraw
