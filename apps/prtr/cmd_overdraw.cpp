// prtr overdraw MESH --probe PROBE: the overdraw benchmark (apps/prtr/overdraw_run.h), which
// reproduces the thesis's tables 5.2-5.17 (ch. 5) on our meshes. This file only turns flags
// into a plan and writes the report: Markdown or JSON on stdout, CSV and JSON in --out (the
// run itself writes the cluster and overdraw pictures there), draws the Pareto and timing
// plots (overdraw_plot.h), then has scripts/plot_overdraw.py draw the per-K plot from the CSV
// when python3-matplotlib is installed.
#include "bake_flags.h"
#include "commands.h"
#include "compress_flags.h"
#include "flag_checks.h"
#include "gl_flags.h"
#include "overdraw/plot.h"
#include "overdraw/run.h"
#include "pipeline/pipeline.h"
#include "progress_bar.h"
#include "subprocess.h"

#include "common/atomic_file.h"
#include "cpca/supercluster_strategy.h"
#include "meshes/load.h"
#include "render/false_colour.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace prtr_app {
// Named rather than anonymous: a unity build compiles every command in one unit.
namespace cmd_overdraw {

using overdraw::OverdrawPlan;
using overdraw::OverdrawReport;
using overdraw::PlanError;

namespace fs = std::filesystem;

struct Options {
  std::string mesh, probe, transfer, cache, out = "out/overdraw", pareto_plot, timing_plot;
  std::string clusters = "64,128,192,256",
              rows = "original,overdraw-reduction,coherence,both,patch-eps";
  std::string strategies = "order,greedy,greedy-refine,metis,ils", budgets = "default,thesis";
  int frames = 10, warmup = 2, rounds = 3, width = 1280, height = 948;
  double degrees_per_frame = 1.0;
  int image_rotations = 12;
  BakeFlags bake;
  CompressFlags compress;
  GlFlags gl;
  bool json = false, quiet = false, recompress = false, no_modes = false;
};

std::vector<std::string> split_list(const std::string& text, const char* flag) {
  std::vector<std::string> items;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (item.empty()) throw UsageError(std::string(flag) + ": empty item in '" + text + "'");
    if (std::find(items.begin(), items.end(), item) != items.end())
      throw UsageError(std::string(flag) + ": '" + item + "' is listed twice");
    items.push_back(item);
  }
  if (items.empty()) throw UsageError(std::string(flag) + " needs at least one item");
  return items;
}

std::vector<int> parse_clusters(const std::string& text) {
  std::vector<int> out;
  for (const std::string& item : split_list(text, "--clusters")) {
    std::size_t used = 0;
    int k = 0;
    try {
      k = std::stoi(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != item.size() || k < 1)
      throw UsageError("--clusters: '" + item + "' is not a positive integer");
    out.push_back(k);
  }
  return out;
}

void add_flags(CLI::App* cmd, Options& o) {
  cmd->add_option("MESH", o.mesh, std::string("Mesh file: ") + meshes::kMeshFormats)->required();
  cmd->add_option("--probe", o.probe, "Environment map lighting every render")->required();
  cmd->add_option("--transfer", o.transfer,
                  "Bake of MESH (.prtx); without it the mesh is baked with the bake flags and "
                  "cached in --cache");
  cmd->add_option("--cache", o.cache,
                  "Directory of cached bakes and compressions (default $PRTR_CACHE or "
                  "~/.cache/prtr, shared with prtr relight)");
  cmd->add_flag("--recompress", o.recompress, "Ignore cached compressions (still writes them)");
  cmd->add_option("--clusters", o.clusters, "Cluster counts K, comma separated")
      ->capture_default_str();
  cmd->add_option("--rows", o.rows, "Methods: " + overdraw::method_names())->capture_default_str();
  cmd->add_option("--strategies", o.strategies,
                  "Super-cluster strategies: " + cpca::supercluster_strategy_names())
      ->capture_default_str();
  cmd->add_option("--budgets", o.budgets,
                  "default: the GL context's register budget; thesis: 3 clusters per pass; or a "
                  "number of vec4 registers")
      ->capture_default_str();
  add_checked_option(cmd, "--frames", o.frames, "Timed frames per row in every round",
                     integer_in(1, 100000));
  add_checked_option(cmd, "--rounds", o.rounds,
                     "Timing rounds, each visiting every row in turn for --warmup + --frames "
                     "frames (FPS = median over all rounds, with the interquartile range)",
                     integer_in(1, 1000));
  add_checked_option(cmd, "--warmup", o.warmup, "Untimed frames first (every round)",
                     integer_in(0, 100000));
  add_checked_option(cmd, "--degrees-per-frame", o.degrees_per_frame,
                     "Environment rotation per frame about +Y while timing", angle_degrees());
  add_checked_option(cmd, "--image-rotations", o.image_rotations,
                     "Environment rotations about +Y (evenly spaced from 37 deg) the image RMSE "
                     "is pooled over",
                     integer_in(1, 360));
  add_checked_option(cmd, "--width", o.width, "Image width", integer_in(1, 16384));
  add_checked_option(cmd, "--height", o.height, "Image height", integer_in(1, 16384));
  cmd->add_option("--out", o.out, "Directory for CSV, JSON, plot and pictures")
      ->capture_default_str();
  cmd->add_option("--plot", o.pareto_plot,
                  "Pareto plot PNG: Average SE vs overdraw per K, every row, thesis's best "
                  "marked (default OUT/overdraw-pareto.png)");
  cmd->add_option("--timing-plot", o.timing_plot,
                  "GL ms and FPS vs overdraw PNG with the fitted lines (default "
                  "OUT/overdraw-timing.png)");
  cmd->add_flag("--no-modes", o.no_modes, "Skip the single-pass/decoupled/uncompressed timings");
  cmd->add_flag("--json", o.json, "Print the JSON report on stdout instead of the tables");
  cmd->add_flag("-q,--quiet", o.quiet, "No progress on stderr");
  // The rows set K, the method and the overdraw reduction; the coherence rows use --alpha.
  o.compress.compress.alpha = 0.05;
  add_compress_flags(cmd, o.compress, CompressFlagSet::kPerRow);
  cmd->get_option("--pcs")->check(integer_in(1, 64));
  add_bake_flags(cmd, o.bake);  // used only when there is no --transfer
  add_gl_flags(cmd, o.gl);
}

OverdrawPlan make_plan(const Options& o, const CLI::App* cmd) {
  OverdrawPlan plan;
  plan.clusters = parse_clusters(o.clusters);
  plan.methods = split_list(o.rows, "--rows");
  plan.strategies = split_list(o.strategies, "--strategies");
  plan.budgets = split_list(o.budgets, "--budgets");
  if (!o.transfer.empty()) {
    for (const char* flag : {"--kind", "--order", "--samples", "--bounces", "--material",
                             "--albedo", "--specular", "--exponent", "--roughness", "--f0"})
      if (cmd->count(flag))
        throw UsageError(std::string(flag) +
                         " is a bake flag; it does not apply with --transfer (drop one)");
  } else {
    plan.bake = resolve_bake_flags(o.bake);
  }
  plan.mesh = o.mesh;
  plan.probe = o.probe;
  plan.transfer = o.transfer;
  plan.cache = o.cache.empty() ? pipeline::default_cache_dir().string() : o.cache;
  plan.recompress = o.recompress;
  plan.compress = resolve_compress_flags(o.compress);
  plan.frames = o.frames;
  plan.warmup = o.warmup;
  plan.rounds = o.rounds;
  plan.width = o.width;
  plan.height = o.height;
  plan.degrees_per_frame = o.degrees_per_frame;
  plan.image_rotations = o.image_rotations;
  plan.modes = !o.no_modes;
  plan.reporter = stderr_reporter(o.quiet);
  plan.gl = gl_selection(o.gl);
  plan.pictures = o.out;
  return plan;
}

// Debian's own interpreter first: python3-matplotlib is installed for it, while a python3
// earlier on PATH (a virtualenv, pyenv) often lacks matplotlib.
std::string python_with_matplotlib() {
  for (const char* python : {"/usr/bin/python3", "python3"})
    if (run_program({python, "-c", "import matplotlib"}, true) == 0) return python;
  return "";
}

// The plot step: scripts/plot_overdraw.py draws overdraw-plot.png from the CSV. Returns what
// to tell the user: where the plot is, or why there is none and the command that makes it.
std::string plot(const fs::path& csv_path, const std::string& budget) {
  const std::string script = PRTR_PLOT_SCRIPT;
  const fs::path png = csv_path.parent_path() / "overdraw-plot.png";
  const std::string by_hand = script + " " + csv_path.string() + " --budget " + budget;
  if (!fs::is_regular_file(script))
    return "no plot: " + script + " is missing (prtr was moved from its source tree)";
  const std::string python = python_with_matplotlib();
  if (python.empty())
    return "no plot: python3 with matplotlib is not installed (apt-get install "
           "python3-matplotlib), then run: " +
           by_hand;
  if (run_program({python, script, csv_path.string(), "-o", png.string(), "--budget", budget},
                  true) != 0)
    return "no plot: " + script + " failed; run it by hand to see why: " + by_hand;
  return "plot " + png.string();
}

// The Pareto plot of the plot budget (the thesis's best marked on the thesis budget) and the
// timing plot; returns their paths for the closing line.
std::string write_plots(const OverdrawReport& report, const OverdrawPlan& plan, const Options& o) {
  const fs::path out = plan.pictures;
  const fs::path pareto =
      o.pareto_plot.empty() ? out / "overdraw-pareto.png" : fs::path(o.pareto_plot);
  const fs::path timing =
      o.timing_plot.empty() ? out / "overdraw-timing.png" : fs::path(o.timing_plot);
  const std::string budget = overdraw::plot_budget(plan.budgets);
  render::write_picture_png(
      pareto, overdraw::pareto_plot(
                  report, budget,
                  budget == "thesis" ? overdraw::thesis_best_overdraw() : std::map<int, double>{}));
  render::write_picture_png(timing, overdraw::timing_plot(report));
  return pareto.string() + " and " + timing.string();
}

void write_outputs(const OverdrawReport& report, const OverdrawPlan& plan, const Options& o) {
  const bool as_json = o.json;
  const fs::path out = plan.pictures;
  const std::string csv_text = overdraw::csv(report), json_text = overdraw::json(report),
                    fit_text = overdraw::fit_csv(report);
  common::write_file_atomically(out / "overdraw.csv", csv_text.data(), csv_text.size());
  common::write_file_atomically(out / "overdraw-fit.csv", fit_text.data(), fit_text.size());
  common::write_file_atomically(out / "overdraw.json", json_text.data(), json_text.size());
  const std::string plots = write_plots(report, plan, o);
  const std::string plotted = plot(out / "overdraw.csv", overdraw::plot_budget(plan.budgets));
  if (as_json) {
    std::fputs(json_text.c_str(), stdout);
    if (!o.quiet) std::fprintf(stderr, "overdraw: plots %s; %s\n", plots.c_str(), plotted.c_str());
    return;
  }
  std::fputs(overdraw::markdown(report).c_str(), stdout);
  std::printf(
      "\nWrote %s/overdraw.csv, overdraw-fit.csv, overdraw.json and the K=%d cluster and "
      "overdraw pictures; plots %s; %s\n",
      out.string().c_str(), *std::max_element(plan.clusters.begin(), plan.clusters.end()),
      plots.c_str(), plotted.c_str());
}

void run(const Options& o, CLI::App* cmd) {
  OverdrawPlan plan = make_plan(o, cmd);
  auto bar = std::make_shared<ProgressBar>(o.quiet);
  if (!o.quiet) {
    plan.note = [bar](const std::string& text) {
      bar->finish();
      std::fprintf(stderr, "overdraw: %s\n", text.c_str());
    };
    plan.progress = [bar](const std::string& label, std::uint64_t step, std::uint64_t steps) {
      bar->update(label, step, steps);
    };
  }
  OverdrawReport report;
  try {
    report = overdraw::run_overdraw(plan);
  } catch (const PlanError& e) {
    throw UsageError(e.what());
  }
  bar->finish();
  write_outputs(report, plan, o);
}

constexpr const char* kAbout =
    "Overdraw benchmark (thesis tables 5.2-5.17): methods x strategies x budgets -> clustering "
    "time, average overdraw, FPS, Average SE, image RMSE; Markdown, CSV, JSON, plot, pictures";

}  // namespace cmd_overdraw

Runner add_overdraw_command(CLI::App& app) {
  return add_command<cmd_overdraw::Options>(app, "overdraw", cmd_overdraw::kAbout,
                                            cmd_overdraw::add_flags, cmd_overdraw::run);
}

}  // namespace prtr_app
