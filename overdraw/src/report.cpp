// overdraw/report.cpp: tables, CSV and JSON of the overdraw benchmark.
#include "overdraw/report.h"

#include "common/json.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <utility>

namespace overdraw {
using common::dump_json;
using common::Json;
namespace {

std::string format(const char* fmt, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, fmt, value);
  return buffer;
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
         std::to_string(r.width) + " x " + std::to_string(r.height) +
         ", FPS and GL ms = median (interquartile range) of " + std::to_string(r.frames) +
         " frames after " + std::to_string(r.warmup) + " warm-up in each of " +
         std::to_string(r.rounds) +
         " rounds taken round-robin over the rows, environment rotating " +
         format("%g", r.degrees_per_frame) + " deg/frame about +Y; " + r.gl_renderer + ".\n";
  out += "Image RMSE: multipass render vs the uncompressed render, pooled over covered pixels " +
         (r.image_rotations > 1
              ? "and " + std::to_string(r.image_rotations) + " environment rotations " +
                    format("%g", r.image_rotation_degrees) + " + k x " +
                    format("%g", 360.0 / r.image_rotations) + " deg"
              : "with the environment rotated " + format("%g", r.image_rotation_degrees) + " deg") +
         "; in brackets relative to the reference's RMS.\n";
  if (r.compressions_cached)
    out +=
        "Some compressions came from the cache; their clustering times are those measured "
        "when they were made.\n";
  return out;
}

std::string with_iqr(double median, const Spread& s, const char* fmt) {
  return format(fmt, median) + " (" + format(fmt, s.iqr()) + ")";
}

std::string table_row(const OverdrawRow& row) {
  return "| " + row.method + " | " + row.strategy + " | " +
         format_duration(row.clustering_seconds) + " | " + format("%.6f", row.average_overdraw) +
         " | " + format("%.4f", row.overdraw_bound) + " | " +
         with_iqr(row.fps, row.fps_spread, "%.2f") + " | " +
         with_iqr(row.gl_ms, row.gl_ms_spread, "%.1f") + " | " +
         with_iqr(row.process_cpu_ms, row.process_cpu_spread, "%.1f") + " | " +
         format("%.6f", row.average_se) + " | " + format("%.4g", row.image_rmse) + " (" +
         format("%.2f%%", 100.0 * row.image_rmse_relative) + ") | " +
         std::to_string(row.vs_invocations) + " | " + std::to_string(row.primitives) + " | " +
         format("%.3f", row.vs_per_referenced_vertex) + " |\n";
}

std::string describe_fit(const char* what, const LineFit& f) {
  return std::string(what) + " = " + format("%.4g", f.slope) + " x overdraw " +
         (f.intercept < 0 ? "- " : "+ ") + format("%.4g", std::abs(f.intercept)) +
         ", R^2 = " + format("%.3f", f.r2);
}

// The least-squares lines of GL time and FPS against overdraw over every row.
std::string markdown_fits(const OverdrawReport& r) {
  if (r.gl_fit.points == 0) return "";
  return "\nAcross all " + std::to_string(r.gl_fit.points) +
         " rows (least squares on the medians): " + describe_fit("GL ms", r.gl_fit) + "; " +
         describe_fit("FPS", r.fps_fit) + "; " + describe_fit("CPU ms", r.process_cpu_fit) + ".\n";
}

// The row a user would pick from one table: the lowest overdraw among the rows whose Average SE
// and image RMSE are at most 1.05 x the original's, with its gap to the overdraw bound.
std::string best_row_line(const std::vector<OverdrawRow>& rows) {
  const OverdrawRow* original = nullptr;
  for (const OverdrawRow& row : rows)
    if (row.method == "original") original = &row;
  const OverdrawRow* best = nullptr;
  double lowest_bound = 1e300;
  for (const OverdrawRow& row : rows) {
    lowest_bound = std::min(lowest_bound, row.overdraw_bound);
    const bool within = !original || (row.average_se <= 1.05 * original->average_se &&
                                      row.image_rmse <= 1.05 * original->image_rmse);
    if (within && (!best || row.average_overdraw < best->average_overdraw)) best = &row;
  }
  if (!best) return "";
  std::string out = "\nBest row with Average SE and image RMSE <= 1.05 x original's: ";
  out += best->method;
  out += " / ";
  out += best->strategy;
  out += ", overdraw " + format("%.4f", best->average_overdraw);
  if (original)
    out += " (SE " + format("%.3f", best->average_se / original->average_se) + " x, RMSE " +
           format("%.3f", best->image_rmse / std::max(original->image_rmse, 1e-300)) + " x)";
  out += "; its bound " + format("%.4f", best->overdraw_bound) + ", gap " +
         format("%.4f", best->average_overdraw - best->overdraw_bound) +
         "; lowest bound of the table " + format("%.4f", lowest_bound) +
         "; equal compact passes of the mesh alone (METIS, error ignored) draw " +
         format("%.4f", best->equal_patches_overdraw) + ".\n";
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
          "| method | strategy | clustering time | average overdraw | overdraw bound | FPS (IQR) | "
          "GL ms (IQR) | CPU ms (IQR) | Average SE | image RMSE (rel.) | VS invocations | "
          "primitives | VS per vertex |\n";
      out +=
          "| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | "
          "---: |\n";
      OverdrawReport table;  // this table's rows, for their own fits
      for (const OverdrawRow& row : r.rows)
        if (row.budget == budget && std::to_string(row.clusters) == k) {
          out += table_row(row);
          table.rows.push_back(row);
        }
      out += best_row_line(table.rows);
      fit_timings(table);
      if (table.rows.size() > 2)
        out += "\nThis table's rows: " + describe_fit("CPU ms", table.process_cpu_fit) + "; " +
               describe_fit("GL ms", table.gl_fit) + ".\n";
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
  return markdown_preamble(r) + markdown_tables(r) + markdown_fits(r) + markdown_modes(r);
}

void fit_timings(OverdrawReport& r) {
  std::vector<double> overdraw, gl, fps, cpu;
  for (const OverdrawRow& row : r.rows) {
    overdraw.push_back(row.average_overdraw);
    gl.push_back(row.gl_ms);
    fps.push_back(row.fps);
    cpu.push_back(row.process_cpu_ms);
  }
  r.gl_fit = fit_line(overdraw, gl);
  r.fps_fit = fit_line(overdraw, fps);
  r.process_cpu_fit = fit_line(overdraw, cpu);
}

std::string fit_csv(const OverdrawReport& r) {
  std::string out = "quantity,slope,intercept,r2,points\n";
  for (const auto& [name, f] : {std::pair{"gl_ms", r.gl_fit}, std::pair{"fps", r.fps_fit},
                                std::pair{"process_cpu_ms", r.process_cpu_fit}})
    out += std::string(name) + "," + format("%.9g", f.slope) + "," + format("%.9g", f.intercept) +
           "," + format("%.9g", f.r2) + "," + std::to_string(f.points) + "\n";
  return out;
}

std::string csv(const OverdrawReport& r) {
  std::string out =
      "clusters,method,budget,register_budget,clusters_per_pass,passes,strategy,"
      "clustering_seconds,grouping_seconds,average_overdraw,overdraw_bound,triangles_drawn,"
      "triangles,fps,"
      "frame_ms,cpu_ms,gl_ms,average_se,relative_error,image_rmse,image_rmse_relative,"
      "multi_cluster_triangles,vs_invocations,primitives,vs_per_referenced_vertex,fps_q1,fps_q3,"
      "gl_ms_q1,gl_ms_q3,process_cpu_ms,process_cpu_ms_q1,process_cpu_ms_q3,"
      "equal_patches_overdraw\n";
  for (const OverdrawRow& x : r.rows) {
    out += std::to_string(x.clusters) + "," + csv_field(x.method) + "," + csv_field(x.budget) +
           "," + std::to_string(x.register_budget) + "," + std::to_string(x.clusters_per_pass) +
           "," + std::to_string(x.passes) + "," + csv_field(x.strategy) + "," +
           format("%.4f", x.clustering_seconds) + "," + format("%.4f", x.grouping_seconds) + "," +
           format("%.9g", x.average_overdraw) + "," + format("%.9g", x.overdraw_bound) + "," +
           std::to_string(x.triangles_drawn) + "," + std::to_string(r.triangles) + "," +
           format("%.4f", x.fps) + "," + format("%.4f", x.frame_ms) + "," +
           format("%.4f", x.cpu_ms) + "," + format("%.4f", x.gl_ms) + "," +
           format("%.9g", x.average_se) + "," + format("%.9g", x.relative_error) + "," +
           format("%.9g", x.image_rmse) + "," + format("%.9g", x.image_rmse_relative) + "," +
           format("%.9g", x.multi_cluster_triangles) + "," + std::to_string(x.vs_invocations) +
           "," + std::to_string(x.primitives) + "," + format("%.6f", x.vs_per_referenced_vertex) +
           "," + format("%.4f", x.fps_spread.q1) + "," + format("%.4f", x.fps_spread.q3) + "," +
           format("%.4f", x.gl_ms_spread.q1) + "," + format("%.4f", x.gl_ms_spread.q3) + "," +
           format("%.4f", x.process_cpu_ms) + "," + format("%.4f", x.process_cpu_spread.q1) + "," +
           format("%.4f", x.process_cpu_spread.q3) + "," +
           format("%.9g", x.equal_patches_overdraw) + "\n";
  }
  return out;
}

namespace {
Json fit_json(const OverdrawReport& r) {
  Json fits = Json::object();
  for (const auto& [name, f] : {std::pair{"gl_ms", r.gl_fit}, std::pair{"fps", r.fps_fit},
                                std::pair{"process_cpu_ms", r.process_cpu_fit}})
    fits[name] = {
        {"slope", f.slope}, {"intercept", f.intercept}, {"r2", f.r2}, {"points", f.points}};
  return fits;
}
}  // namespace

std::string json(const OverdrawReport& r) {
  Json rows = Json::array();
  for (const OverdrawRow& x : r.rows)
    rows.push_back({{"clusters", x.clusters},
                    {"method", x.method},
                    {"budget", x.budget},
                    {"register_budget", x.register_budget},
                    {"clusters_per_pass", x.clusters_per_pass},
                    {"passes", x.passes},
                    {"strategy", x.strategy},
                    {"clustering_seconds", x.clustering_seconds},
                    {"grouping_seconds", x.grouping_seconds},
                    {"average_overdraw", x.average_overdraw},
                    {"overdraw_bound", x.overdraw_bound},
                    {"equal_patches_overdraw", x.equal_patches_overdraw},
                    {"triangles_drawn", x.triangles_drawn},
                    {"fps", x.fps},
                    {"frame_ms", x.frame_ms},
                    {"cpu_ms", x.cpu_ms},
                    {"gl_ms", x.gl_ms},
                    {"average_se", x.average_se},
                    {"relative_error", x.relative_error},
                    {"image_rmse", x.image_rmse},
                    {"image_rmse_relative", x.image_rmse_relative},
                    {"multi_cluster_triangles", x.multi_cluster_triangles},
                    {"vs_invocations", x.vs_invocations},
                    {"primitives", x.primitives},
                    {"vs_per_referenced_vertex", x.vs_per_referenced_vertex},
                    {"fps_q1", x.fps_spread.q1},
                    {"fps_q3", x.fps_spread.q3},
                    {"gl_ms_q1", x.gl_ms_spread.q1},
                    {"gl_ms_q3", x.gl_ms_spread.q3},
                    {"process_cpu_ms", x.process_cpu_ms},
                    {"process_cpu_ms_q1", x.process_cpu_spread.q1},
                    {"process_cpu_ms_q3", x.process_cpu_spread.q3}});
  Json modes = Json::array();
  for (const ModeTiming& m : r.modes)
    modes.push_back({{"clusters", m.clusters},
                     {"mode", m.mode},
                     {"fps", m.fps},
                     {"frame_ms", m.frame_ms},
                     {"image_rmse", m.image_rmse},
                     {"image_rmse_relative", m.image_rmse_relative}});
  const Json report = {{"mesh", r.mesh},
                       {"probe", r.probe},
                       {"transfer", r.transfer},
                       {"bake", r.bake},
                       {"bake_cached", r.bake_cached},
                       {"compressions_cached", r.compressions_cached},
                       {"vertices", r.vertices},
                       {"triangles", r.triangles},
                       {"order", r.order},
                       {"pcs", r.pcs},
                       {"registers_per_cluster", r.registers_per_cluster},
                       {"width", r.width},
                       {"height", r.height},
                       {"frames", r.frames},
                       {"warmup", r.warmup},
                       {"rounds", r.rounds},
                       {"fits", fit_json(r)},
                       {"degrees_per_frame", r.degrees_per_frame},
                       {"image_rotation_degrees", r.image_rotation_degrees},
                       {"image_rotations", r.image_rotations},
                       {"gl_renderer", r.gl_renderer},
                       {"rows", std::move(rows)},
                       {"modes", std::move(modes)}};
  return dump_json(report) + "\n";
}

}  // namespace overdraw
