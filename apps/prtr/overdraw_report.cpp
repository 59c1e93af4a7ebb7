// apps/prtr/overdraw_report.cpp: tables, CSV, JSON and the plot of the overdraw benchmark.
#include "overdraw_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>

namespace prtr_app {
namespace {

std::string format(const char* fmt, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, fmt, value);
  return buffer;
}

std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    if (static_cast<unsigned char>(c) < 0x20) {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\u%04x", unsigned(static_cast<unsigned char>(c)));
      out += escaped;
      continue;
    }
    out += c;
  }
  return out + "\"";
}

std::string json_number(double v) {
  if (!std::isfinite(v)) return "null";
  return format("%.9g", v);
}

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

// Budgets, K values and methods in first-seen order, so tables follow the command line.
template <class F>
std::vector<std::string> distinct(const std::vector<OverdrawRow>& rows, F key) {
  std::vector<std::string> out;
  for (const OverdrawRow& r : rows)
    if (std::find(out.begin(), out.end(), key(r)) == out.end()) out.push_back(key(r));
  return out;
}

}  // namespace

std::string format_duration(double seconds) {
  if (seconds < 60) return format("%.1f s", seconds);
  const int whole = int(std::lround(seconds));
  return std::to_string(whole / 60) + " m " + std::to_string(whole % 60) + " s";
}

namespace {

// The run's inputs and settings, one paragraph.
std::string markdown_preamble(const OverdrawReport& r) {
  std::string out;
  out += "Mesh " + r.mesh + " (" + std::to_string(r.vertices) + " vertices, " +
         std::to_string(r.triangles) + " triangles), probe " + r.probe + "\n";
  out += "Bake " + r.bake + (r.bake_cached ? " (cached: " : " (baked now, cached as ") +
         r.transfer + ")\n";
  out += "Order " + std::to_string(r.order) + ", " + std::to_string(r.pcs) +
         " PCs: " + std::to_string(r.registers_per_cluster) + " vec4 registers per cluster. " +
         std::to_string(r.width) + " x " + std::to_string(r.height) + ", FPS = median of " +
         std::to_string(r.frames) + " frames after " + std::to_string(r.warmup) +
         " warm-up, environment rotating " + format("%g", r.degrees_per_frame) +
         " deg/frame about +Y; " + r.gl_renderer + ".\n";
  out += "Image RMSE: multipass render vs the uncompressed render, environment rotated " +
         format("%g", r.image_rotation_degrees) +
         " deg, over covered pixels; in brackets relative to the reference's RMS.\n";
  if (r.compressions_cached)
    out +=
        "Some compressions came from the cache; their clustering times are those measured "
        "when they were made.\n";
  return out;
}

// Per budget and K, one table in the thesis's column order.
std::string markdown_tables(const OverdrawReport& r) {
  std::string out;
  for (const std::string& budget :
       distinct(r.rows, [](const OverdrawRow& x) { return x.budget; })) {
    for (const std::string& k :
         distinct(r.rows, [](const OverdrawRow& x) { return std::to_string(x.clusters); })) {
      const OverdrawRow* first = nullptr;
      for (const OverdrawRow& row : r.rows)
        if (row.budget == budget && std::to_string(row.clusters) == k) {
          first = &row;
          break;
        }
      if (!first) continue;
      out += "\n### " + k + " clusters, " + budget + " budget (" +
             std::to_string(first->register_budget) + " registers, " +
             std::to_string(first->clusters_per_pass) + " clusters per pass, " +
             std::to_string(first->passes) + " passes)\n\n";
      out +=
          "| method | strategy | clustering time | average overdraw | FPS | Average SE | "
          "image RMSE (rel.) |\n";
      out += "| --- | --- | ---: | ---: | ---: | ---: | ---: |\n";
      for (const OverdrawRow& row : r.rows) {
        if (row.budget != budget || std::to_string(row.clusters) != k) continue;
        out += "| " + row.method + " | " + row.strategy + " | " +
               format_duration(row.clustering_seconds) + " | " +
               format("%.6f", row.average_overdraw) + " | " + format("%.2f", row.fps) + " | " +
               format("%.6f", row.average_se) + " | " + format("%.4g", row.image_rmse) + " (" +
               format("%.2f%%", 100.0 * row.image_rmse_relative) + ") |\n";
      }
    }
  }
  return out;
}

// Per K, multipass (best strategy of the original method) against the other modes.
std::string markdown_modes(const OverdrawReport& r) {
  std::string out;
  if (!r.modes.empty()) {
    out += "\n### What the overdraw costs: FPS by render mode\n\n";
    out += "Multipass: the original CPCA clustering with its lowest-overdraw strategy.\n\n";
    const std::vector<std::string> budgets =
        distinct(r.rows, [](const OverdrawRow& x) { return x.budget; });
    out += "| clusters | single-pass FPS | decoupled FPS |";
    for (const std::string& b : budgets) out += " multipass FPS, " + b + " (overdraw) |";
    out += "\n| ---: | ---: | ---: |";
    for (std::size_t i = 0; i < budgets.size(); ++i) out += " ---: |";
    out += "\n";
    std::set<int> ks;
    for (const ModeTiming& m : r.modes)
      if (m.clusters > 0) ks.insert(m.clusters);
    for (int k : ks) {
      auto mode_fps = [&](const std::string& mode) {
        for (const ModeTiming& m : r.modes)
          if (m.clusters == k && m.mode == mode) return format("%.2f", m.fps);
        return std::string("-");
      };
      out += "| " + std::to_string(k) + " | " + mode_fps("singlepass") + " | " +
             mode_fps("decoupled") + " |";
      for (const std::string& b : budgets) {
        const OverdrawRow* best = nullptr;
        for (const OverdrawRow& row : r.rows)
          if (row.clusters == k && row.budget == b && row.method == "original" &&
              (!best || row.average_overdraw < best->average_overdraw))
            best = &row;
        // Appended piece by piece: GCC 12 misreads a " " + std::string chain here as an
        // overlapping memcpy (-Wrestrict false positive).
        if (!best) {
          out += " - |";
          continue;
        }
        out += ' ';
        out += format("%.2f", best->fps);
        out += " (";
        out += format("%.3f", best->average_overdraw);
        out += ") |";
      }
      out += "\n";
    }
    for (const ModeTiming& m : r.modes)
      if (m.clusters == 0)
        out += "\nUncompressed transfer (no CPCA): " + format("%.2f", m.fps) + " FPS.\n";
  }
  return out;
}

}  // namespace

std::string markdown(const OverdrawReport& r) {
  return markdown_preamble(r) + markdown_tables(r) + markdown_modes(r);
}

std::string csv(const OverdrawReport& r) {
  std::string out =
      "clusters,method,budget,register_budget,clusters_per_pass,passes,strategy,"
      "clustering_seconds,grouping_seconds,average_overdraw,triangles_drawn,triangles,fps,"
      "frame_ms,cpu_ms,gl_ms,average_se,relative_error,image_rmse,image_rmse_relative,"
      "multi_cluster_triangles\n";
  for (const OverdrawRow& x : r.rows) {
    out += std::to_string(x.clusters) + "," + csv_field(x.method) + "," + csv_field(x.budget) +
           "," + std::to_string(x.register_budget) + "," + std::to_string(x.clusters_per_pass) +
           "," + std::to_string(x.passes) + "," + csv_field(x.strategy) + "," +
           format("%.4f", x.clustering_seconds) + "," + format("%.4f", x.grouping_seconds) + "," +
           format("%.9g", x.average_overdraw) + "," + std::to_string(x.triangles_drawn) + "," +
           std::to_string(r.triangles) + "," + format("%.4f", x.fps) + "," +
           format("%.4f", x.frame_ms) + "," + format("%.4f", x.cpu_ms) + "," +
           format("%.4f", x.gl_ms) + "," + format("%.9g", x.average_se) + "," +
           format("%.9g", x.relative_error) + "," + format("%.9g", x.image_rmse) + "," +
           format("%.9g", x.image_rmse_relative) + "," + format("%.9g", x.multi_cluster_triangles) +
           "\n";
  }
  return out;
}

std::string json(const OverdrawReport& r) {
  std::string out = "{";
  out += "\"mesh\":" + json_string(r.mesh) + ",\"probe\":" + json_string(r.probe) +
         ",\"transfer\":" + json_string(r.transfer) + ",\"bake\":" + json_string(r.bake) +
         ",\"bake_cached\":" + (r.bake_cached ? "true" : "false") +
         ",\"compressions_cached\":" + (r.compressions_cached ? "true" : "false") +
         ",\"vertices\":" + std::to_string(r.vertices) +
         ",\"triangles\":" + std::to_string(r.triangles) + ",\"order\":" + std::to_string(r.order) +
         ",\"pcs\":" + std::to_string(r.pcs) +
         ",\"registers_per_cluster\":" + std::to_string(r.registers_per_cluster) +
         ",\"width\":" + std::to_string(r.width) + ",\"height\":" + std::to_string(r.height) +
         ",\"frames\":" + std::to_string(r.frames) + ",\"warmup\":" + std::to_string(r.warmup) +
         ",\"degrees_per_frame\":" + json_number(r.degrees_per_frame) +
         ",\"image_rotation_degrees\":" + json_number(r.image_rotation_degrees) +
         ",\"gl_renderer\":" + json_string(r.gl_renderer) + ",\"rows\":[";
  for (std::size_t i = 0; i < r.rows.size(); ++i) {
    const OverdrawRow& x = r.rows[i];
    out += std::string(i ? "," : "") + "{\"clusters\":" + std::to_string(x.clusters) +
           ",\"method\":" + json_string(x.method) + ",\"budget\":" + json_string(x.budget) +
           ",\"register_budget\":" + std::to_string(x.register_budget) +
           ",\"clusters_per_pass\":" + std::to_string(x.clusters_per_pass) +
           ",\"passes\":" + std::to_string(x.passes) + ",\"strategy\":" + json_string(x.strategy) +
           ",\"clustering_seconds\":" + json_number(x.clustering_seconds) +
           ",\"grouping_seconds\":" + json_number(x.grouping_seconds) +
           ",\"average_overdraw\":" + json_number(x.average_overdraw) +
           ",\"triangles_drawn\":" + std::to_string(x.triangles_drawn) +
           ",\"fps\":" + json_number(x.fps) + ",\"frame_ms\":" + json_number(x.frame_ms) +
           ",\"cpu_ms\":" + json_number(x.cpu_ms) + ",\"gl_ms\":" + json_number(x.gl_ms) +
           ",\"average_se\":" + json_number(x.average_se) +
           ",\"relative_error\":" + json_number(x.relative_error) +
           ",\"image_rmse\":" + json_number(x.image_rmse) +
           ",\"image_rmse_relative\":" + json_number(x.image_rmse_relative) +
           ",\"multi_cluster_triangles\":" + json_number(x.multi_cluster_triangles) + "}";
  }
  out += "],\"modes\":[";
  for (std::size_t i = 0; i < r.modes.size(); ++i) {
    const ModeTiming& m = r.modes[i];
    out += std::string(i ? "," : "") + "{\"clusters\":" + std::to_string(m.clusters) +
           ",\"mode\":" + json_string(m.mode) + ",\"fps\":" + json_number(m.fps) +
           ",\"frame_ms\":" + json_number(m.frame_ms) +
           ",\"image_rmse\":" + json_number(m.image_rmse) +
           ",\"image_rmse_relative\":" + json_number(m.image_rmse_relative) + "}";
  }
  out += "]}\n";
  return out;
}

render::Picture overdraw_plot(const OverdrawReport& r, const std::string& budget, int width,
                              int height) {
  // method -> K -> (lowest overdraw, its strategy)
  std::map<std::string, std::map<int, std::pair<double, std::string>>> best;
  for (const OverdrawRow& row : r.rows) {
    if (row.budget != budget) continue;
    auto [it, fresh] =
        best[row.method].try_emplace(row.clusters, row.average_overdraw, row.strategy);
    if (!fresh && row.average_overdraw < it->second.first)
      it->second = {row.average_overdraw, row.strategy};
  }
  if (best.empty())
    throw std::invalid_argument("overdraw_plot: no rows for budget '" + budget +
                                "'; include it in --budgets");
  const std::vector<std::string> methods =
      distinct(r.rows, [](const OverdrawRow& x) { return x.method; });

  double kmin = std::numeric_limits<double>::max(), kmax = 0, omin = 1e9, omax = 0;
  for (const auto& [method, by_k] : best)
    for (const auto& [k, v] : by_k) {
      kmin = std::min(kmin, double(k));
      kmax = std::max(kmax, double(k));
      omin = std::min(omin, v.first);
      omax = std::max(omax, v.first);
    }
  if (kmax == kmin) kmin -= 1, kmax += 1;
  // Overdraw axis from a round value at or below the data to one above, with margin.
  omin = std::floor((omin - 0.02) * 20) / 20;
  omax = std::ceil((omax + 0.02) * 20) / 20;
  if (omax <= omin) omax = omin + 0.05;

  render::Picture p(width, height, {255, 255, 255});
  const int left = 90, right = width - 230, top = 50, bottom = height - 70;
  auto px = [&](double k) { return left + (k - kmin) / (kmax - kmin) * (right - left); };
  auto py = [&](double o) { return bottom - (o - omin) / (omax - omin) * (bottom - top); };
  const render::Colour8 black{0, 0, 0}, grid{220, 220, 220};

  // Grid and ticks: every distinct K on x, steps of 0.05 (or 0.1) in overdraw on y.
  std::set<int> ks;
  for (const auto& [method, by_k] : best)
    for (const auto& [k, v] : by_k) ks.insert(k);
  for (int k : ks) {
    render::draw_line(p, px(k), top, px(k), bottom, grid);
    render::draw_text(p, int(px(k)) - 12, bottom + 24, std::to_string(k), 16, black);
  }
  const double step = (omax - omin) > 0.6 ? 0.1 : 0.05;
  for (double o = omin; o <= omax + 1e-9; o += step) {
    render::draw_line(p, left, py(o), right, py(o), grid);
    render::draw_text(p, left - 60, int(py(o)) + 6, format("%.2f", o), 16, black);
  }
  render::draw_line(p, left, bottom, right, bottom, black, 2);
  render::draw_line(p, left, top, left, bottom, black, 2);
  render::draw_text(p, (left + right) / 2 - 40, bottom + 55, "clusters K", 18, black);
  render::draw_text(p, left, top - 18,
                    "average triangle overdraw (" + budget + " budget, best strategy)", 18, black);

  int legend_y = top + 10;
  for (std::size_t m = 0; m < methods.size(); ++m) {
    const auto found = best.find(methods[m]);
    if (found == best.end()) continue;
    const render::Colour8 colour = render::cluster_colour(std::uint32_t(m));
    bool first = true;
    double x0 = 0, y0 = 0;
    for (const auto& [k, v] : found->second) {
      const double x = px(k), y = py(v.first);
      if (!first) render::draw_line(p, x0, y0, x, y, colour, 3);
      render::fill_rect(p, {int(x) - 4, int(y) - 4, int(x) + 5, int(y) + 5}, colour);
      x0 = x, y0 = y, first = false;
    }
    render::fill_rect(p, {right + 20, legend_y - 6, right + 50, legend_y + 2}, colour);
    render::draw_text(p, right + 58, legend_y + 2, methods[m], 16, black);
    legend_y += 26;
  }
  return p;
}

}  // namespace prtr_app
