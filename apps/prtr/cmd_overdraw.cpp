// prtr overdraw MESH --probe PROBE: the overdraw benchmark, reproducing the
// thesis's tables 5.2-5.17 (ch. 5) on our meshes.
//
// For every cluster count K and method row (original CPCA, CPCA overdraw reduction, geometry
// coherence, both, ...) it compresses the bake (timing the clustering), then for every
// register budget (the GL context's, and the thesis's 3 clusters per pass) and super-cluster
// strategy it computes the exact average triangle overdraw (cpca::overdraw), renders the
// multipass path with that grouping, checks that the triangles the GL queries counted equal
// the prediction (a mismatch is a bug and stops the run), measures FPS with the same camera
// and frames for every row, and measures the image RMSE against the uncompressed render.
// Single-pass and decoupled FPS per K show what the overdraw costs.
//
// Caching (stated in the output): bakes and compressed sets go through the shared cache of
// apps/prtr/pipeline.h (keyed by content and every parameter), which also keeps each
// compression's clustering time and errors, so a cached row reports what was measured.
#include "bake_flags.h"
#include "commands.h"
#include "pipeline.h"

#include "common/atomic_file.h"
#include "cpca/compress.h"
#include "cpca/compressed_file.h"
#include "cpca/supercluster.h"
#include "cpca/supercluster_strategy.h"
#include "meshes/load.h"
#include "overdraw_report.h"
#include "probes/load.h"
#include "progress_bar.h"
#include "prt/bake.h"
#include "prt/projection.h"
#include "prt/sh_rotation.h"
#include "prt/transfer_file.h"
#include "render/camera.h"
#include "render/false_colour.h"
#include "render/gl_context.h"
#include "render/renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

namespace prtr_app {
namespace {

namespace fs = std::filesystem;

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

// The method rows: the thesis's four, and iterative CPCA with both (ours).
struct MethodPreset {
  const char* name;
  const char* summary;
  bool coherence, overdraw_reduction, iterative;
};
constexpr MethodPreset kMethods[] = {
    {"original", "LBG + PCA per cluster (thesis 'Original CPCA')", false, false, false},
    {"overdraw-reduction", "+ overdraw-aware reassignment (thesis 'CPCA overdraw red.')", false,
     true, false},
    {"coherence", "+ geometry coherence alpha (thesis 'Our method')", true, false, false},
    {"both", "coherence + overdraw reduction (thesis 'CPCA overdraw red. + Our method')", true,
     true, false},
    {"iterative", "iterative CPCA (Sloan et al. 2003) with coherence + overdraw reduction", true,
     true, true},
};

const MethodPreset& find_method(const std::string& name) {
  for (const MethodPreset& m : kMethods)
    if (name == m.name) return m;
  std::string names;
  for (const MethodPreset& m : kMethods) names += std::string(names.empty() ? "" : ", ") + m.name;
  throw UsageError("--rows: unknown method '" + name + "'; use one of " + names);
}

// RMSE over pixels both images cover (alpha > 0.5), averaged over R, G, B, and the
// reference's RMS over the same pixels.
struct ImageDifference {
  double rmse = 0, reference_rms = 0;
  double relative() const { return reference_rms > 0 ? rmse / reference_rms : 0; }
};
ImageDifference image_error(const render::Image& image, const render::Image& reference) {
  if (image.width != reference.width || image.height != reference.height)
    throw std::logic_error("image_error: image sizes differ");
  double se = 0, ref = 0;
  std::uint64_t n = 0;
  for (std::size_t i = 0; i < image.rgba.size(); i += 4) {
    if (reference.rgba[i + 3] <= 0.5f || image.rgba[i + 3] <= 0.5f) continue;
    for (int c = 0; c < 3; ++c) {
      const double d = double(image.rgba[i + c]) - reference.rgba[i + c];
      se += d * d;
      ref += double(reference.rgba[i + c]) * reference.rgba[i + c];
    }
    n += 3;
  }
  if (n == 0) return {};
  return {std::sqrt(se / double(n)), std::sqrt(ref / double(n))};
}

void write_text(const fs::path& path, const std::string& text) {
  common::write_file_atomically(path, text.data(), text.size());
}

}  // namespace

Runner add_overdraw_command(CLI::App& app) {
  struct Options {
    std::string mesh, probe, transfer, cache, out = "out/overdraw";
    std::string clusters = "64,128,192,256", rows = "original,overdraw-reduction,coherence,both";
    std::string strategies = "order,greedy,greedy-refine,metis,ils", budgets = "default,thesis";
    int pcs = 8, frames = 10, warmup = 2, width = 1280, height = 948;
    double alpha = 0.05, tolerance = 1.0, degrees_per_frame = 1.0, image_degrees = 37.0;
    BakeFlags flags;
    bool json = false, quiet = false, recompress = false, no_modes = false;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "overdraw",
      "Overdraw benchmark (thesis tables 5.2-5.17): methods x strategies x budgets -> clustering "
      "time, average overdraw, FPS, Average SE, image RMSE; Markdown, CSV, JSON, plot, pictures");
  cmd->add_option("MESH", opt->mesh, "Mesh file (OBJ, PLY, OFF, STL)")->required();
  cmd->add_option("--probe", opt->probe, "Environment map lighting every render")->required();
  cmd->add_option("--transfer", opt->transfer,
                  "Bake of MESH (.prtx); without it the mesh is baked with the bake flags and "
                  "cached in --cache");
  cmd->add_option("--cache", opt->cache,
                  "Directory of cached bakes and compressions (default $PRTR_CACHE or "
                  "~/.cache/prtr, shared with prtr relight)");
  cmd->add_flag("--recompress", opt->recompress, "Ignore cached compressions (still writes them)");
  cmd->add_option("--clusters", opt->clusters, "Cluster counts K, comma separated")
      ->capture_default_str();
  cmd->add_option("--pcs", opt->pcs, "Principal components per cluster N")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  cmd->add_option("--rows", opt->rows,
                  "Methods: original, overdraw-reduction, coherence, both, iterative")
      ->capture_default_str();
  cmd->add_option("--alpha", opt->alpha, "Geometry-coherence weight of the coherence rows")
      ->check(CLI::Range(0.0, 1e6))
      ->capture_default_str();
  cmd->add_option("--overdraw-tolerance", opt->tolerance,
                  "Overdraw reduction: largest error increase per move, in Average SE units")
      ->check(CLI::Range(0.0, 1e6))
      ->capture_default_str();
  cmd->add_option("--strategies", opt->strategies,
                  "Super-cluster strategies: " + cpca::supercluster_strategy_names())
      ->capture_default_str();
  cmd->add_option("--budgets", opt->budgets,
                  "default: the GL context's register budget; thesis: 3 clusters per pass; or a "
                  "number of vec4 registers")
      ->capture_default_str();
  cmd->add_option("--frames", opt->frames, "Timed frames per configuration (FPS = median)")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  cmd->add_option("--warmup", opt->warmup, "Untimed frames first")
      ->check(CLI::Range(0, 100000))
      ->capture_default_str();
  cmd->add_option("--degrees-per-frame", opt->degrees_per_frame,
                  "Environment rotation per frame about +Y while timing")
      ->capture_default_str();
  cmd->add_option("--width", opt->width, "Image width")
      ->check(CLI::Range(1, 16384))
      ->capture_default_str();
  cmd->add_option("--height", opt->height, "Image height")
      ->check(CLI::Range(1, 16384))
      ->capture_default_str();
  cmd->add_option("--out", opt->out, "Directory for CSV, JSON, plot and pictures")
      ->capture_default_str();
  cmd->add_flag("--no-modes", opt->no_modes, "Skip the single-pass/decoupled/uncompressed timings");
  cmd->add_flag("--json", opt->json, "Print the JSON report on stdout instead of the tables");
  cmd->add_flag("-q,--quiet", opt->quiet, "No progress on stderr");
  // Bake flags (used only when there is no --transfer), shared with prtr bake and relight.
  add_bake_flags(cmd, opt->flags);

  return [opt, cmd] {
    Options& o = *opt;
    // --- Parse and check everything before the slow work --------------------------------------
    const std::vector<int> ks = parse_clusters(o.clusters);
    std::vector<const MethodPreset*> methods;
    for (const std::string& name : split_list(o.rows, "--rows"))
      methods.push_back(&find_method(name));
    const std::vector<std::string> strategies = split_list(o.strategies, "--strategies");
    for (const std::string& s : strategies) {
      try {
        cpca::find_supercluster_strategy(s);
      } catch (const std::invalid_argument& e) {
        throw UsageError(std::string("--strategies: ") + e.what());
      }
    }
    const std::vector<std::string> budgets = split_list(o.budgets, "--budgets");
    for (const std::string& b : budgets)
      if (b != "default" && b != "thesis" && b.find_first_not_of("0123456789") != std::string::npos)
        throw UsageError("--budgets: '" + b + "' is not default, thesis or a register count");
    if (!o.transfer.empty()) {
      for (const char* flag : {"--kind", "--order", "--samples", "--bounces", "--material",
                               "--albedo", "--specular", "--exponent", "--roughness", "--f0"})
        if (cmd->count(flag))
          throw UsageError(std::string(flag) +
                           " is a bake flag; it does not apply with --transfer (drop one)");
    }

    if (o.cache.empty()) o.cache = default_cache_dir().string();
    ProgressBar bar(o.quiet);
    auto note = [&](const std::string& text) {
      if (o.quiet) return;
      bar.finish();
      std::fprintf(stderr, "overdraw: %s\n", text.c_str());
    };

    const meshes::Mesh mesh = meshes::load_mesh(o.mesh);
    const std::uint64_t mesh_hash = meshes::content_hash(mesh);
    const probes::Probe probe = probes::load_probe(o.probe);

    // --- The bake: given, cached, or made now ---------------------------------------------------
    OverdrawReport report;
    prt::TransferSet transfer;
    if (!o.transfer.empty()) {
      transfer = prt::read_transfer(o.transfer);
      if (transfer.mesh_hash != mesh_hash || transfer.vertex_count != mesh.vertex_count())
        throw std::runtime_error(o.transfer + " was not baked from " + o.mesh +
                                 " (mesh hash or vertex count differ); bake it again with "
                                 "prtr bake or drop --transfer");
      report.transfer = o.transfer;
      report.bake_cached = true;
    } else {
      const CacheResult cached =
          cached_bake(mesh, o.mesh, resolve_bake_flags(o.flags), o.cache, o.quiet);
      note(std::string(cached.hit ? "bake cached: " : "baked, cached as ") + cached.path.string());
      report.transfer = cached.path.string();
      report.bake_cached = cached.hit;
      transfer = prt::read_transfer(cached.path);
    }
    for (int k : ks)
      if (std::uint64_t(k) > transfer.vertex_count)
        throw UsageError("--clusters " + std::to_string(k) + " exceeds the " +
                         std::to_string(transfer.vertex_count) + " vertices of " + o.mesh);
    if (std::size_t(o.pcs) >= transfer.floats_per_vertex())
      throw UsageError("--pcs " + std::to_string(o.pcs) + " must be below the data dimension " +
                       std::to_string(transfer.floats_per_vertex()));
    {
      std::ostringstream b;
      b << prt::transfer_kind_name(transfer.kind) << " order " << transfer.order << ", "
        << transfer.channels << " channel(s), " << prt::material_name(transfer.material.kind)
        << " (albedo " << transfer.material.albedo.x() << ", specular "
        << transfer.material.specular;
      if (transfer.material.kind == prt::MaterialKind::kPhong)
        b << ", exponent " << transfer.material.exponent;
      if (transfer.material.kind == prt::MaterialKind::kCookTorrance)
        b << ", roughness " << transfer.material.roughness << ", f0 " << transfer.material.f0;
      b << "), " << transfer.samples << " samples, " << transfer.bounces << " bounce(s)";
      report.bake = b.str();
    }

    // --- GL, camera, lighting, the uncompressed reference -------------------------------------
    render::GlContext context(4, 5);
    const render::GlInfo info = context.info();
    report.gl_renderer = info.renderer;
    const int context_budget =
        std::min(info.max_vertex_uniform_vectors, info.max_uniform_block_size / 16);
    const meshes::Bounds box = meshes::bounds(mesh);
    const render::Camera camera = render::frame_sphere(
        box.center().cast<double>(), 0.5 * double(box.diagonal()), o.width, o.height);
    const prt::ShLighting lighting = prt::project(probe, transfer.order);
    const Eigen::Vector3d axis = Eigen::Vector3d::UnitY();
    const Eigen::Matrix3d image_rotation =
        prt::axis_angle(axis, o.image_degrees * std::numbers::pi / 180.0);
    const render::Background black{false, render::Rgb::Zero()};

    report.mesh = o.mesh;
    report.probe = o.probe;
    report.vertices = mesh.vertex_count();
    report.triangles = mesh.triangle_count();
    report.order = transfer.order;
    report.pcs = o.pcs;
    report.width = o.width;
    report.height = o.height;
    report.frames = o.frames;
    report.warmup = o.warmup;
    report.degrees_per_frame = o.degrees_per_frame;
    report.image_rotation_degrees = o.image_degrees;

    render::Image reference;
    {
      note("uncompressed reference render");
      render::RendererOptions ro;
      ro.mode = render::Mode::kUncompressed;
      render::Renderer r(mesh, nullptr, &transfer, &probe, ro);
      r.set_background(black);
      if (!o.no_modes) {
        const render::TimingSummary t =
            render::measure(r, camera, lighting, Eigen::Matrix3d::Identity(), axis,
                            o.degrees_per_frame, std::max(1, o.frames / 2), std::min(o.warmup, 1));
        report.modes.push_back({0, "uncompressed", t.fps, t.frame_ms_median, 0, 0});
      }
      r.render(camera, lighting, image_rotation);
      reference = r.read_image();
    }

    const cpca::Geometry geometry = geometry_of(mesh);
    fs::create_directories(o.out);
    fs::create_directories(o.cache);

    const std::uint64_t steps =
        std::uint64_t(ks.size() * methods.size() * (1 + budgets.size() * strategies.size()));
    std::uint64_t step = 0;
    const int largest_k = *std::max_element(ks.begin(), ks.end());

    for (int k : ks) {
      for (const MethodPreset* method : methods) {
        // --- Compress (or reuse a cached compression) ------------------------------------------
        cpca::CompressOptions co;
        co.layout = {transfer.order, transfer.channels, transfer.columns()};
        co.clusters = k;
        co.components = o.pcs;
        co.method = method->iterative ? cpca::ClusterMethod::kIterative : cpca::ClusterMethod::kLbg;
        co.alpha = method->coherence ? o.alpha : 0.0;
        co.overdraw_reduction = method->overdraw_reduction;
        co.overdraw.tolerance = o.tolerance;
        const std::string label = "K=" + std::to_string(k) + " " + method->name;
        bar.update(label + ": compression", step, steps);
        const CompressCacheResult compressed =
            cached_compress(report.transfer, mesh, o.mesh, co, o.cache, true, o.recompress);
        if (compressed.hit) report.compressions_cached = true;
        const cpca::CompressedSet set = cpca::read_compressed(compressed.path);
        const double clustering_seconds = compressed.summary.clustering_seconds;
        const double average_se = compressed.summary.average_se;
        const double relative_error = compressed.summary.relative_error;
        ++step;
        const cpca::TriangleSpan span = cpca::triangle_span(set.cluster_of, geometry.triangles);

        // Per K, the render modes without overdraw, on the original clustering.
        if (!o.no_modes && method == methods.front()) {
          for (render::Mode mode : {render::Mode::kSinglepass, render::Mode::kDecoupled}) {
            bar.update(label + ": " + render::mode_name(mode), step, steps);
            render::RendererOptions ro;
            ro.mode = mode;
            render::Renderer r(mesh, &set, nullptr, &probe, ro);
            r.set_background(black);
            const render::TimingSummary t =
                render::measure(r, camera, lighting, Eigen::Matrix3d::Identity(), axis,
                                o.degrees_per_frame, o.frames, o.warmup);
            r.render(camera, lighting, image_rotation);
            const ImageDifference e = image_error(r.read_image(), reference);
            report.modes.push_back(
                {k, render::mode_name(mode), t.fps, t.frame_ms_median, e.rmse, e.relative()});
          }
        }

        // --- Budgets x strategies ----------------------------------------------------------------
        const int cost = render::constant_layout(set).registers_per_cluster();
        report.registers_per_cluster = cost;
        double best_thesis_overdraw = 1e300;
        std::vector<std::uint8_t> best_counts;
        std::string best_strategy;
        for (const std::string& budget_name : budgets) {
          const int budget = budget_name == "default"  ? context_budget
                             : budget_name == "thesis" ? 3 * cost
                                                       : std::stoi(budget_name);
          if (budget < cost)
            throw UsageError("--budgets " + budget_name + ": " + std::to_string(budget) +
                             " registers hold no cluster of " + std::to_string(cost) +
                             "; use at least that many");
          const int per_pass = std::min(k, budget / cost);
          for (const std::string& strategy : strategies) {
            bar.update(label + ": " + budget_name + " budget, " + strategy, step, steps);
            cpca::SuperClusterInput input;
            input.cluster_of = set.cluster_of;
            input.triangles = geometry.triangles;
            input.cluster_count = k;
            input.per_pass = per_pass;
            const auto g0 = std::chrono::steady_clock::now();
            const cpca::SuperClusters groups = cpca::group_clusters(strategy, input);
            const double grouping_seconds =
                std::chrono::duration<double>(std::chrono::steady_clock::now() - g0).count();
            const cpca::OverdrawStats od =
                cpca::overdraw(set.cluster_of, geometry.triangles, groups);

            render::RendererOptions ro;
            ro.mode = render::Mode::kMultipass;
            ro.register_budget = budget;
            ro.clusters_per_pass = per_pass;
            ro.groups = groups;
            ro.count_primitives = true;  // same for every row: one query per pass
            render::Renderer r(mesh, &set, nullptr, &probe, ro);
            r.set_background(black);
            const render::TimingSummary t =
                render::measure(r, camera, lighting, Eigen::Matrix3d::Identity(), axis,
                                o.degrees_per_frame, o.frames, o.warmup);
            // The triangles GL counted are the cost model's prediction.
            const render::RenderStats& stats = r.stats();
            if (stats.measured_triangles != od.triangles_per_pass ||
                stats.triangles_per_pass != od.triangles_per_pass) {
              std::uint64_t measured = 0;
              for (std::uint64_t m : stats.measured_triangles) measured += m;
              throw std::logic_error(label + ", " + strategy + ", budget " +
                                     std::to_string(budget) + ": the renderer drew " +
                                     std::to_string(measured) + " triangles in " +
                                     std::to_string(stats.measured_triangles.size()) +
                                     " passes but cpca::overdraw "
                                     "predicts " +
                                     std::to_string(od.triangles_drawn) + " in " +
                                     std::to_string(od.triangles_per_pass.size()) +
                                     " passes; this is a bug in the renderer or the cost model");
            }
            r.render(camera, lighting, image_rotation);
            const ImageDifference e = image_error(r.read_image(), reference);

            OverdrawRow row;
            row.clusters = k;
            row.method = method->name;
            row.budget = budget_name;
            row.register_budget = budget;
            row.clusters_per_pass = per_pass;
            row.passes = int(groups.passes.size());
            row.strategy = strategy;
            row.clustering_seconds = clustering_seconds;
            row.grouping_seconds = grouping_seconds;
            row.average_overdraw = od.average_overdraw;
            row.triangles_drawn = od.triangles_drawn;
            row.fps = t.fps;
            row.frame_ms = t.frame_ms_median;
            row.cpu_ms = t.cpu_ms_median;
            row.gl_ms = t.gl_ms_median;
            row.average_se = average_se;
            row.relative_error = relative_error;
            row.image_rmse = e.rmse;
            row.image_rmse_relative = e.relative();
            row.multi_cluster_triangles =
                double(span.multi()) / double(std::max<std::size_t>(1, mesh.triangle_count()));
            report.rows.push_back(row);
            ++step;

            const bool picture_budget =
                budget_name == (std::find(budgets.begin(), budgets.end(), "thesis") != budgets.end()
                                    ? "thesis"
                                    : budgets.back());
            if (k == largest_k && picture_budget && od.average_overdraw < best_thesis_overdraw) {
              best_thesis_overdraw = od.average_overdraw;
              best_counts = cpca::triangle_pass_counts(set.cluster_of, geometry.triangles, groups);
              best_strategy = strategy + "-" + budget_name;
            }
          }
        }
        if (k == largest_k) {
          const std::string stem = "K" + std::to_string(k) + "-" + method->name;
          render::write_picture_png(fs::path(o.out) / ("clusters-" + stem + ".png"),
                                    render::cluster_picture(mesh, camera, set.cluster_of));
          if (!best_counts.empty())
            render::write_picture_png(
                fs::path(o.out) / ("overdraw-" + stem + "-" + best_strategy + ".png"),
                render::overdraw_picture(mesh, camera, best_counts));
        }
      }
    }
    bar.finish();

    // --- Outputs
    // ----------------------------------------------------------------------------------
    write_text(fs::path(o.out) / "overdraw.csv", csv(report));
    const std::string json_text = json(report);
    write_text(fs::path(o.out) / "overdraw.json", json_text);
    const std::string plot_budget =
        std::find(budgets.begin(), budgets.end(), "thesis") != budgets.end() ? "thesis"
                                                                             : budgets.front();
    render::write_picture_png(fs::path(o.out) / "overdraw-plot.png",
                              overdraw_plot(report, plot_budget));
    if (o.json) {
      std::fputs(json_text.c_str(), stdout);
    } else {
      std::fputs(markdown(report).c_str(), stdout);
      std::printf(
          "\nWrote %s/overdraw.csv, overdraw.json, overdraw-plot.png and the K=%d "
          "cluster and overdraw pictures.\n",
          o.out.c_str(), largest_k);
    }
  };
}

}  // namespace prtr_app
