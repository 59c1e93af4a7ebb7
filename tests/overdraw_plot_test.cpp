// The overdraw benchmark's statistics and plots: quartiles and the least-squares line against
// hand-computed answers, and the plots decoded from their PNG files with every marker found
// where the layout documented in overdraw_plot.h puts the data (the mapping recomputed here).
#include "overdraw/plot.h"
#include "overdraw/stats.h"

#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <vector>

namespace {

using overdraw::fit_line;
using overdraw::LineFit;
using overdraw::OverdrawReport;
using overdraw::OverdrawRow;

TEST(OverdrawStats, QuartilesInterpolateBetweenOrderStatistics) {
  const overdraw::Spread s = overdraw::spread({4, 1, 3, 2});  // unsorted on purpose
  EXPECT_DOUBLE_EQ(s.median, 2.5);
  EXPECT_DOUBLE_EQ(s.q1, 1.75);  // h = 3 / 4: 1 + 0.75 (2 - 1)
  EXPECT_DOUBLE_EQ(s.q3, 3.25);
  EXPECT_DOUBLE_EQ(s.iqr(), 1.5);
  const overdraw::Spread one = overdraw::spread({7});
  EXPECT_EQ(one.median, 7);
  EXPECT_EQ(one.iqr(), 0);
  EXPECT_EQ(overdraw::spread({}).median, 0);
}

TEST(OverdrawStats, AnExactLineIsRecoveredWithRSquaredOne) {
  // GL ms = 45 ms per unit of overdraw + 3 ms, at overdraws like the benchmark's.
  const std::vector<double> x{1.174, 1.237, 1.28, 1.315, 1.5, 2.0};
  std::vector<double> y;
  for (double v : x) y.push_back(45 * v + 3);
  const LineFit f = fit_line(x, y);
  EXPECT_NEAR(f.slope, 45, 1e-9);
  EXPECT_NEAR(f.intercept, 3, 1e-9);
  EXPECT_NEAR(f.r2, 1, 1e-12);
  EXPECT_EQ(f.points, x.size());
}

TEST(OverdrawStats, ResidualsGiveTheHandComputedRSquared) {
  // (0,1), (1,3), (2,2): slope 1/2, intercept 3/2, SS_res 1.5, SS_tot 2, R^2 1/4.
  const LineFit f = fit_line({0, 1, 2}, {1, 3, 2});
  EXPECT_NEAR(f.slope, 0.5, 1e-12);
  EXPECT_NEAR(f.intercept, 1.5, 1e-12);
  EXPECT_NEAR(f.r2, 0.25, 1e-12);
  // No correlation at all: slope 0, R^2 0.
  const LineFit flat = fit_line({0, 1, 2}, {0, 1, 0});
  EXPECT_NEAR(flat.slope, 0, 1e-12);
  EXPECT_NEAR(flat.r2, 0, 1e-12);
  // One distinct x determines no line.
  const LineFit none = fit_line({1.2, 1.2}, {3, 5});
  EXPECT_EQ(none.slope, 0);
  EXPECT_EQ(none.intercept, 4);
  EXPECT_EQ(none.r2, 0);
  EXPECT_THROW(fit_line({1}, {}), std::logic_error);
}

struct Decoded {
  int width = 0, height = 0;
  std::vector<unsigned char> rgb;
  std::array<int, 3> at(int x, int y) const {
    const std::size_t i = (std::size_t(y) * width + x) * 3;
    return {rgb[i], rgb[i + 1], rgb[i + 2]};
  }
};

// Written to disk and read back through OpenImageIO: what a reader of the file sees.
Decoded write_and_decode(const render::Picture& picture, const std::string& name) {
  const std::filesystem::path dir = PRTR_TEST_TMPDIR;
  std::filesystem::create_directories(dir);
  const std::filesystem::path path = dir / name;
  render::write_picture_png(path, picture);
  auto in = OIIO::ImageInput::open(path.string());
  EXPECT_TRUE(in) << path;
  Decoded d;
  if (!in) return d;
  d.width = in->spec().width;
  d.height = in->spec().height;
  EXPECT_EQ(in->spec().nchannels, 3);
  d.rgb.resize(std::size_t(d.width) * d.height * 3);
  EXPECT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, d.rgb.data()));
  return d;
}

OverdrawRow row(int k, const char* method, double overdraw, double se, double gl_ms) {
  OverdrawRow r;
  r.clusters = k;
  r.method = method;
  r.budget = "thesis";
  r.clusters_per_pass = 3;
  r.strategy = "ils";
  r.average_overdraw = overdraw;
  r.average_se = se;
  r.gl_ms = gl_ms;
  r.gl_ms_spread = {gl_ms, gl_ms - 1, gl_ms + 1};
  r.fps = 1000 / gl_ms;
  r.fps_spread = {r.fps, r.fps - 0.5, r.fps + 0.5};
  r.process_cpu_ms = 2 * gl_ms;
  r.process_cpu_spread = {2 * gl_ms, 2 * gl_ms - 2, 2 * gl_ms + 2};
  return r;
}

// The layout rule of overdraw_plot.h, written out again: panel i of a 2-column grid below a
// 34-pixel title, 560 x 420 panels, margins 84 / 16 / 30 / 56, ranges padded by 8 %.
struct Mapping {
  double xlo, xhi, ylo, yhi;
  int panel;
  int left() const { return (panel % 2) * 560 + 84; }
  int top() const { return 34 + (panel / 2) * 420 + 30; }
  int px(double x) const { return left() + int(std::lround((x - xlo) / (xhi - xlo) * 459)); }
  int py(double y) const { return top() + 333 - int(std::lround((y - ylo) / (yhi - ylo) * 333)); }
};
Mapping mapping(int panel, double xmin, double xmax, double ymin, double ymax) {
  const double sx = xmax - xmin, sy = ymax - ymin;
  return {xmin - 0.08 * sx, xmax + 0.08 * sx, ymin - 0.08 * sy, ymax + 0.08 * sy, panel};
}

constexpr std::array<int, 3> kFirstMethod{31, 119, 180}, kSecondMethod{255, 127, 14};

TEST(OverdrawPlot, ParetoMarkersAndTheThesisLineLandWhereTheDataSays) {
  OverdrawReport report;
  report.rows = {row(64, "original", 1.25, 3.4e-3, 40), row(64, "both", 1.17, 3.2e-3, 36),
                 row(64, "both", 1.30, 3.2e-3, 41), row(128, "original", 1.33, 1.7e-3, 44),
                 row(128, "both", 1.24, 1.5e-3, 40)};
  report.rows.push_back(row(64, "original", 1.40, 3.4e-3, 47));
  report.rows.back().budget = "default";  // another budget: not in this plot
  const Decoded d = write_and_decode(
      overdraw::pareto_plot(report, "thesis", overdraw::thesis_best_overdraw()), "pareto.png");
  ASSERT_EQ(d.width, 1120);  // two panels side by side
  ASSERT_EQ(d.height, 34 + 420);

  // K = 64: x spans the rows and the thesis's 1.208; y the rows' SE.
  const Mapping k64 = mapping(0, 1.17, 1.30, 3.2e-3, 3.4e-3);
  EXPECT_EQ(d.at(k64.px(1.25), k64.py(3.4e-3)), kFirstMethod);
  EXPECT_EQ(d.at(k64.px(1.17), k64.py(3.2e-3)), kSecondMethod);
  EXPECT_EQ(d.at(k64.px(1.30) + 4, k64.py(3.2e-3) - 4), kSecondMethod);  // marker corner
  // (The default-budget row at 1.40 would have widened the x range and moved every marker.)
  EXPECT_EQ(d.at(k64.px(1.208), k64.top() + 1), (std::array<int, 3>{120, 120, 120}));
  // Mirrored y would put the first marker where there is none.
  EXPECT_NE(d.at(k64.px(1.25), k64.py(3.2e-3)), kFirstMethod);

  // K = 128: the thesis's 1.286 lies between the rows.
  const Mapping k128 = mapping(1, 1.24, 1.33, 1.5e-3, 1.7e-3);
  EXPECT_EQ(d.at(k128.px(1.33), k128.py(1.7e-3)), kFirstMethod);
  EXPECT_EQ(d.at(k128.px(1.24), k128.py(1.5e-3)), kSecondMethod);
  EXPECT_EQ(d.at(k128.px(1.286), k128.top() + 2), (std::array<int, 3>{120, 120, 120}));
  EXPECT_THROW(overdraw::pareto_plot(report, "none", {}), std::invalid_argument);
}

TEST(OverdrawPlot, TimingMarkersSitOnTheirMediansBesideTheFittedLine) {
  OverdrawReport report;
  report.rows = {row(64, "original", 1.0, 1e-3, 40), row(64, "both", 1.5, 1e-3, 60),
                 row(64, "both", 2.0, 1e-3, 80)};
  overdraw::fit_timings(report);
  EXPECT_NEAR(report.gl_fit.slope, 40, 1e-9);
  EXPECT_NEAR(report.gl_fit.r2, 1, 1e-12);
  EXPECT_NEAR(report.process_cpu_fit.slope, 80, 1e-9);
  const Decoded d = write_and_decode(overdraw::timing_plot(report), "timing.png");
  ASSERT_EQ(d.width, 1120);
  ASSERT_EQ(d.height, 34 + 2 * 420);  // three panels: two rows of the 2-column grid
  // GL panel: y spans the medians and their quartiles (39 .. 81).
  const Mapping gl = mapping(0, 1.0, 2.0, 39, 81);
  EXPECT_EQ(d.at(gl.px(1.0), gl.py(40)), kFirstMethod);
  EXPECT_EQ(d.at(gl.px(2.0), gl.py(80)), kSecondMethod);
  // The fitted line passes halfway between the markers, at x = 1.25 (GL ms 50).
  EXPECT_EQ(d.at(gl.px(1.25), gl.py(50)), (std::array<int, 3>{120, 120, 120}));
  // FPS panel: 1000 / GL ms with quartiles of +-0.5.
  const Mapping fps = mapping(1, 1.0, 2.0, 12.0, 25.5);
  EXPECT_EQ(d.at(fps.px(1.0), fps.py(25)), kFirstMethod);
  EXPECT_EQ(d.at(fps.px(2.0), fps.py(12.5)), kSecondMethod);
  // Process CPU panel, below the GL panel: 2 x GL ms, quartiles +-2 (78 .. 162).
  const Mapping cpu = mapping(2, 1.0, 2.0, 78, 162);
  EXPECT_EQ(d.at(cpu.px(1.0), cpu.py(80)), kFirstMethod);
  EXPECT_EQ(d.at(cpu.px(1.5), cpu.py(120)), kSecondMethod);
}

}  // namespace
