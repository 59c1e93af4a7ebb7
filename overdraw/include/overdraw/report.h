// overdraw/report.h: the results of `prtr overdraw` and their three
// renderings: Markdown tables in the thesis's column order (tables 5.2-5.17: method,
// clustering time, average triangle overdraw, FPS, Average SE, then our image RMSE), CSV and
// JSON. The plots are drawn by overdraw/plot.h.
#pragma once

#include "overdraw/stats.h"

#include <cstdint>
#include <string>
#include <vector>

namespace overdraw {

// One measured configuration: a compression (K x method) grouped by one strategy under one
// register budget, rendered multipass.
struct OverdrawRow {
  int clusters = 0;
  std::string method;  // "original", "overdraw-reduction", "coherence", "both", ...
  std::string budget;  // "default" or "thesis"
  int register_budget = 0;
  int clusters_per_pass = 0;
  int passes = 0;
  std::string strategy;
  double clustering_seconds = 0;
  double grouping_seconds = 0;
  double average_overdraw = 0;  // exact, cpca::overdraw
  // cpca::grouping_overdraw_bound: no grouping of this row's clustering into passes of
  // clusters_per_pass can draw less (a bound on the strategy's gap, not on other clusterings).
  double overdraw_bound = 1;
  // cpca::equal_patches_overdraw for this row's least number of passes (ceil(K / per pass)):
  // what equal compact passes of the mesh alone draw, the error ignored. A reference, not a
  // bound.
  double equal_patches_overdraw = 1;
  std::uint64_t triangles_drawn = 0;  // = the renderer's GL count (checked)
  // Medians over every timed frame of every interleaved round, with their quartiles (FPS per
  // frame is 1000 / frame ms, so its quartiles are the frame time's, inverted).
  double fps = 0, frame_ms = 0, cpu_ms = 0, gl_ms = 0;
  Spread fps_spread, gl_ms_spread;
  // The process's CPU time per frame, all threads (llvmpipe rasterises on its own threads):
  // the work a frame costs, which time slices lost to other processes on a shared machine do
  // not inflate the way they inflate wall-clock GL ms.
  double process_cpu_ms = 0;
  Spread process_cpu_spread;
  double average_se = 0, relative_error = 0;
  double image_rmse = 0, image_rmse_relative = 0;  // against the uncompressed render
  double multi_cluster_triangles = 0;              // share of triangles spanning clusters
  // One counted frame's pipeline statistics (render::WorkTotals): deterministic work beside
  // the noisy FPS; vs_per_referenced_vertex is 1 when the driver shades each vertex once.
  std::uint64_t vs_invocations = 0, primitives = 0;
  double vs_per_referenced_vertex = 0;
};

// FPS of the other render modes per K (the original CPCA set), for "what the overdraw costs".
struct ModeTiming {
  int clusters = 0;  // 0 for the uncompressed render
  std::string mode;
  double fps = 0, frame_ms = 0;
  double image_rmse = 0, image_rmse_relative = 0;
};

struct OverdrawReport {
  std::string mesh, probe, transfer, bake;  // bake: one-line description of its parameters
  bool bake_cached = false;                 // the transfer came from the cache
  bool compressions_cached = false;         // some compressed sets came from the cache
  std::uint64_t vertices = 0, triangles = 0;
  int order = 0, pcs = 0, width = 0, height = 0, frames = 0, warmup = 0;
  int rounds = 0;  // interleaved timing rounds: frames x rounds timed frames per row
  int registers_per_cluster = 0;
  double degrees_per_frame = 0, image_rotation_degrees = 0;
  int image_rotations = 1;
  std::string gl_renderer;
  std::vector<OverdrawRow> rows;
  std::vector<ModeTiming> modes;
  // GL ms and FPS against average overdraw, least squares over every row of the run.
  LineFit gl_fit, fps_fit, process_cpu_fit;
};

// Fills gl_fit, fps_fit and process_cpu_fit from the rows.
void fit_timings(OverdrawReport& report);

// Per budget and K, one table in the thesis's column order (with each row's overdraw bound),
// and under it the lowest-overdraw row whose Average SE and image RMSE are at most 1.05 x the
// original's, its gap to its bound and the lowest bound of the table; then per K the FPS of
// multipass (best strategy of the original method) against single-pass and decoupled.
std::string markdown(const OverdrawReport& report);
std::string csv(const OverdrawReport& report);
// The fits as CSV: quantity (gl_ms, fps, process_cpu_ms), slope, intercept, r2, points.
std::string fit_csv(const OverdrawReport& report);
std::string json(const OverdrawReport& report);

// "3 m 53 s" / "12.4 s", the thesis's style for clustering times.
std::string format_duration(double seconds);

}  // namespace overdraw
