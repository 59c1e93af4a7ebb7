#include "overdraw/run.h"

#include "pipeline/pipeline.h"

#include "cpca/compressed_file.h"
#include "cpca/overdraw_bound.h"
#include "cpca/patch_first.h"
#include "cpca/supercluster.h"
#include "cpca/supercluster_strategy.h"
#include "meshes/load.h"
#include "probes/load.h"
#include "prt/projection.h"
#include "prt/sh_rotation.h"
#include "prt/transfer_file.h"
#include "render/camera.h"
#include "render/false_colour.h"
#include "render/gl_context.h"
#include "render/pass_capacity.h"
#include "render/renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <deque>
#include <filesystem>
#include <map>
#include <memory>
#include <numbers>
#include <sstream>
#include <stdexcept>

namespace overdraw {
namespace {

namespace fs = std::filesystem;

constexpr MethodPreset kMethods[] = {
    {"original", "LBG + PCA per cluster (thesis 'Original CPCA')", false, false, false},
    {"overdraw-reduction", "+ overdraw-aware reassignment (thesis 'CPCA overdraw red.')", false,
     true, false},
    {"coherence", "+ geometry coherence alpha (thesis 'Our method')", true, false, false},
    {"both", "coherence + overdraw reduction (thesis 'CPCA overdraw red. + Our method')", true,
     true, false},
    {"iterative", "iterative CPCA (Sloan et al. 2003) with coherence + overdraw reduction", true,
     true, true},
    {"patch-first", "METIS patches, one per pass, CPCA inside each (designs the passes)", false,
     false, false, cpca::ClusterMethod::kPatchFirst},
    {"patch-joint",
     "patch-first, then the joint search of error + 0.5 x overdraw, overdraw capped at 1.14", false,
     false, false, cpca::ClusterMethod::kPatchJoint, 0.5, 1.14},
    {"patch-eps",
     "patch-first, then the least overdraw with Average SE <= (1 + --epsilon) x original's "
     "(epsilon constraint; recommended)",
     false, false, false, cpca::ClusterMethod::kPatchEpsilon},
};

bool has(const std::vector<std::string>& list, const char* item) {
  return std::find(list.begin(), list.end(), item) != list.end();
}

// RMSE over pixels both images cover (alpha > 0.5), averaged over R, G, B and pooled over
// the environment rotations, and the reference's RMS over the same pixels.
struct ImageDifference {
  double se = 0, reference_se = 0;
  std::uint64_t n = 0;
  void add(const render::Image& image, const render::Image& reference);
  double rmse() const { return n ? std::sqrt(se / double(n)) : 0; }
  double relative() const { return reference_se > 0 ? std::sqrt(se / reference_se) : 0; }
};
void ImageDifference::add(const render::Image& image, const render::Image& reference) {
  if (image.width != reference.width || image.height != reference.height)
    throw std::logic_error("image_error: image sizes differ");
  for (std::size_t i = 0; i < image.rgba.size(); i += 4) {
    if (reference.rgba[i + 3] <= 0.5f || image.rgba[i + 3] <= 0.5f) continue;
    for (int c = 0; c < 3; ++c) {
      const double d = double(image.rgba[i + c]) - reference.rgba[i + c];
      se += d * d;
      reference_se += double(reference.rgba[i + c]) * reference.rgba[i + c];
    }
    n += 3;
  }
}

std::string describe_bake(const prt::TransferSet& t) {
  std::ostringstream b;
  b << prt::kTransferKindNames.name(t.kind) << " order " << t.order << ", " << t.channels
    << " channel(s), " << prt::kMaterialNames.name(t.material.kind) << " (albedo "
    << t.material.albedo.x() << ", specular " << t.material.specular;
  if (t.material.kind == prt::MaterialKind::kPhong) b << ", exponent " << t.material.exponent;
  if (t.material.kind == prt::MaterialKind::kCookTorrance)
    b << ", roughness " << t.material.roughness << ", f0 " << t.material.f0 << ", "
      << prt::kMaskingNames.name(t.material.masking) << " masking";
  b << "), " << t.samples << " samples, " << t.bounces << " bounce(s)";
  return b.str();
}

// What every row shares: inputs, the GL context, camera, lighting and the reference image.
struct Scene {
  explicit Scene(const OverdrawPlan& p)
      : plan(p), mesh(meshes::load_mesh(p.mesh)), probe(probes::load_probe(p.probe)) {}
  const OverdrawPlan& plan;
  meshes::Mesh mesh;
  probes::Probe probe;
  prt::TransferSet transfer;
  cpca::Geometry geometry;
  render::Camera camera;
  prt::ShLighting lighting;
  Eigen::Vector3d axis = Eigen::Vector3d::UnitY();
  std::vector<Eigen::Matrix3d> image_rotations;  // where image errors are measured
  std::vector<render::Image> references;         // the uncompressed render at each
  int context_budget = 0;
  // cpca::equal_patches_overdraw per number of passes, computed once (rows run one by one).
  mutable std::map<int, double> equal_patches;
  double equal_patches_overdraw(int passes) const {
    const auto [at, added] = equal_patches.try_emplace(passes, 1.0);
    if (added && passes <= int(geometry.positions.size()))
      at->second = cpca::equal_patches_overdraw(geometry, passes, plan.compress.seed);
    return at->second;
  }
};

void note(const OverdrawPlan& plan, const std::string& text) {
  if (plan.note) plan.note(text);
}

// The bake: given, cached, or made now; checked against the mesh and the plan's sizes.
void load_bake(Scene& s, OverdrawReport& report) {
  const OverdrawPlan& plan = s.plan;
  if (!plan.transfer.empty()) {
    s.transfer = prt::read_transfer(plan.transfer);
    if (s.transfer.mesh_hash != meshes::content_hash(s.mesh) ||
        s.transfer.vertex_count != s.mesh.vertex_count())
      throw std::runtime_error(plan.transfer + " was not baked from " + plan.mesh +
                               " (mesh hash or vertex count differ); bake it again with "
                               "prtr bake or drop --transfer");
    report.transfer = plan.transfer;
    report.bake_cached = true;
  } else {
    const pipeline::CacheResult cached =
        pipeline::cached_bake(s.mesh, plan.mesh, plan.bake, plan.cache, plan.reporter);
    note(plan,
         std::string(cached.hit ? "bake cached: " : "baked, cached as ") + cached.path.string());
    report.transfer = cached.path.string();
    report.bake_cached = cached.hit;
    s.transfer = prt::read_transfer(cached.path);
  }
  for (int k : plan.clusters)
    if (std::uint64_t(k) > s.transfer.vertex_count)
      throw PlanError("--clusters " + std::to_string(k) + " exceeds the " +
                      std::to_string(s.transfer.vertex_count) + " vertices of " + plan.mesh);
  if (std::size_t(plan.compress.components) >= s.transfer.floats_per_vertex())
    throw PlanError("--pcs " + std::to_string(plan.compress.components) +
                    " must be below the data dimension " +
                    std::to_string(s.transfer.floats_per_vertex()));
  report.bake = describe_bake(s.transfer);
}

void describe_plan(const Scene& s, OverdrawReport& report) {
  const OverdrawPlan& plan = s.plan;
  report.mesh = plan.mesh;
  report.probe = plan.probe;
  report.vertices = s.mesh.vertex_count();
  report.triangles = s.mesh.triangle_count();
  report.order = s.transfer.order;
  report.pcs = plan.compress.components;
  report.width = plan.width;
  report.height = plan.height;
  report.frames = plan.frames;
  report.warmup = plan.warmup;
  report.degrees_per_frame = plan.degrees_per_frame;
  report.image_rotation_degrees = plan.image_degrees;
  report.image_rotations = plan.image_rotations;
}

render::TimingSummary time_frames(render::Renderer& r, const Scene& s, int frames, int warmup) {
  return render::measure(r, s.camera, s.lighting, Eigen::Matrix3d::Identity(), s.axis,
                         s.plan.degrees_per_frame, frames, warmup);
}

// One rotation of the environment is one sample of the lighting a relit mesh sees: on the
// asteroid the same two compressions' error ratio ranged 0.88-1.16 over 13 rotations
// (docs/BENCHMARKS.md), so errors are pooled over evenly spaced rotations.
ImageDifference image_error(render::Renderer& r, const Scene& s) {
  ImageDifference e;
  for (std::size_t i = 0; i < s.image_rotations.size(); ++i) {
    r.render(s.camera, s.lighting, s.image_rotations[i]);
    e.add(r.read_image(), s.references[i]);
  }
  return e;
}

const render::Background kBlack{false, render::Rgb::Zero()};

// The uncompressed render every image error is measured against (and its timing).
void render_reference(Scene& s, OverdrawReport& report) {
  note(s.plan, "uncompressed reference render");
  render::RendererOptions ro;
  ro.mode = render::Mode::kUncompressed;
  render::Renderer r(s.mesh, nullptr, &s.transfer, &s.probe, ro);
  r.set_background(kBlack);
  if (s.plan.modes) {
    const render::TimingSummary t =
        time_frames(r, s, std::max(1, s.plan.frames / 2), std::min(s.plan.warmup, 1));
    report.modes.push_back({0, "uncompressed", t.fps, t.frame_ms_median, 0, 0});
  }
  for (const Eigen::Matrix3d& rotation : s.image_rotations) {
    r.render(s.camera, s.lighting, rotation);
    s.references.push_back(r.read_image());
  }
}

// A render path without overdraw, on one compressed set.
ModeTiming measure_mode(const Scene& s, const cpca::CompressedSet& set, int k, render::Mode mode) {
  render::RendererOptions ro;
  ro.mode = mode;
  render::Renderer r(s.mesh, &set, nullptr, &s.probe, ro);
  r.set_background(kBlack);
  const render::TimingSummary t = time_frames(r, s, s.plan.frames, s.plan.warmup);
  const ImageDifference e = image_error(r, s);
  return {k, render::kModeNames.name(mode), t.fps, t.frame_ms_median, e.rmse(), e.relative()};
}

// One compression (K x method) as every row of it sees it.
struct Compression {
  int k = 0;
  const MethodPreset* method = nullptr;
  cpca::CompressedSet set;
  pipeline::CompressionSummary summary;
  double multi_cluster_triangles = 0;
  // A pass-designing method's compression belongs to one budget and its clusters per pass.
  std::string designed_budget;
  int designed_per_pass = 0;
  std::string label() const {
    return "K=" + std::to_string(k) + " " + method->name +
           (designed_budget.empty() ? "" : " (" + designed_budget + " budget)");
  }
};

// `per_pass` is the clusters per pass a pass-designing method designs for (0 otherwise).
Compression compress_row(const Scene& s, const std::string& transfer_path, int k,
                         const MethodPreset& method, int per_pass, bool* cached) {
  const OverdrawPlan& plan = s.plan;
  cpca::CompressOptions co = plan.compress;
  co.layout = {s.transfer.order, s.transfer.channels, s.transfer.columns()};
  co.clusters = k;
  co.method = method.iterative ? cpca::ClusterMethod::kIterative : cpca::ClusterMethod::kLbg;
  co.alpha = method.coherence ? plan.compress.alpha : 0.0;
  co.overdraw_reduction = method.overdraw_reduction;
  if (method.designs_passes()) {
    co.method = method.designed;
    co.clusters_per_pass = per_pass;
    co.lambda = method.lambda;
    co.overdraw_cap = method.overdraw_cap;
  }
  if (method.designed == cpca::ClusterMethod::kPatchEpsilon) {
    // The constraint's reference is the original row at this K (the cached compression when
    // that row ran): its Average SE and its clusters, which weigh the patches. The row
    // reports only its own clustering time.
    bool original_cached = false;
    Compression original =
        compress_row(s, transfer_path, k, find_method("original"), 0, &original_cached);
    co.error_target = original.summary.average_se;
    co.reference_clusters = std::move(original.set.cluster_of);
  }
  // Compressions run without a progress bar (the run has its own), but cache repairs are told.
  pipeline::Reporter warnings_only;
  warnings_only.warning = plan.reporter.warning;
  const pipeline::CompressCacheResult compressed = pipeline::cached_compress(
      transfer_path, s.mesh, plan.mesh, co, plan.cache, warnings_only, plan.recompress);
  *cached = compressed.hit;
  Compression c;
  c.k = k;
  c.method = &method;
  c.designed_per_pass = method.designs_passes() ? per_pass : 0;
  c.set = cpca::read_compressed(compressed.path);
  c.summary = compressed.summary;
  const cpca::TriangleSpan span = cpca::triangle_span(c.set.cluster_of, s.geometry.triangles);
  c.multi_cluster_triangles =
      double(span.multi()) / double(std::max<std::size_t>(1, s.mesh.triangle_count()));
  return c;
}

int budget_registers(const Scene& s, const std::string& name, int cost) {
  const int budget = name == "default"  ? s.context_budget
                     : name == "thesis" ? 3 * cost
                                        : std::stoi(name);
  if (budget < cost)
    throw PlanError("--budgets " + name + ": " + std::to_string(budget) +
                    " registers hold no cluster of " + std::to_string(cost) +
                    "; use at least that many");
  return budget;
}

// The renderer's GL triangle counts must be the cost model's; anything else is a bug.
void check_counts(const render::RenderStats& stats, const cpca::OverdrawStats& od,
                  const std::string& where) {
  if (stats.measured_triangles == od.triangles_per_pass &&
      stats.triangles_per_pass == od.triangles_per_pass)
    return;
  std::uint64_t measured = 0;
  for (std::uint64_t m : stats.measured_triangles) measured += m;
  throw std::logic_error(
      where + ": the renderer drew " + std::to_string(measured) + " triangles in " +
      std::to_string(stats.measured_triangles.size()) + " passes but cpca::overdraw predicts " +
      std::to_string(od.triangles_drawn) + " in " + std::to_string(od.triangles_per_pass.size()) +
      " passes; this is a bug in the renderer or the cost model");
}

// A row's multipass renderer; every timing round builds it anew, so no row keeps GL memory
// (or a warm cache) between its turns.
std::unique_ptr<render::Renderer> multipass_renderer(const Scene& s, const Compression& c,
                                                     int budget, int per_pass,
                                                     const cpca::SuperClusters& groups) {
  render::RendererOptions ro;
  ro.mode = render::Mode::kMultipass;
  ro.register_budget = budget;
  ro.clusters_per_pass = per_pass;
  ro.groups = groups;
  auto r = std::make_unique<render::Renderer>(s.mesh, &c.set, nullptr, &s.probe, ro);
  r->set_background(kBlack);
  return r;
}

// What the timing rounds need to rebuild a measured row's renderer.
struct TimedRow {
  const Compression* compression = nullptr;
  cpca::SuperClusters groups;
  int budget = 0, per_pass = 0;
  std::size_t row = 0;  // index into OverdrawReport::rows
  std::vector<double> frame_ms, cpu_ms, gl_ms, process_cpu_ms;
};

double process_cpu_ms_now() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
}

// One table row without its timing: a compression grouped by one strategy under one budget,
// rendered multipass once for the GL counts, the work counters and the image.
OverdrawRow measure_row(const Scene& s, const Compression& c, const std::string& budget_name,
                        int budget, int per_pass, const std::string& strategy,
                        cpca::SuperClusters* groups_out) {
  const cpca::SuperClusterInput input{c.set.cluster_of, s.geometry.triangles, c.k, per_pass};
  const auto g0 = std::chrono::steady_clock::now();
  const cpca::SuperClusters groups = cpca::group_clusters(strategy, input);
  const double grouping_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - g0).count();
  const cpca::OverdrawStats od = cpca::overdraw(c.set.cluster_of, s.geometry.triangles, groups);
  const cpca::GroupingBound bound = cpca::grouping_overdraw_bound(input);

  const auto r = multipass_renderer(s, c, budget, per_pass, groups);
  r->set_count_primitives(true);  // one query per pass; timed frames draw without them
  r->render(s.camera, s.lighting, Eigen::Matrix3d::Identity());
  r->set_count_primitives(false);
  check_counts(r->stats(), od, c.label() + ", " + strategy + ", budget " + std::to_string(budget));
  r->set_count_work(true);
  r->render(s.camera, s.lighting, Eigen::Matrix3d::Identity());
  const render::WorkTotals work = render::work_totals(r->stats().pass_work);
  r->set_count_work(false);
  const ImageDifference e = image_error(*r, s);

  OverdrawRow row;
  row.clusters = c.k;
  row.method = c.method->name;
  row.budget = budget_name;
  row.register_budget = budget;
  row.clusters_per_pass = per_pass;
  row.passes = int(groups.passes.size());
  row.strategy = strategy;
  row.clustering_seconds = c.summary.clustering_seconds;
  row.grouping_seconds = grouping_seconds;
  row.average_overdraw = od.average_overdraw;
  row.overdraw_bound = bound.average_overdraw;
  row.equal_patches_overdraw = s.equal_patches_overdraw((c.k + per_pass - 1) / per_pass);
  row.triangles_drawn = od.triangles_drawn;
  row.average_se = c.summary.average_se;
  row.relative_error = c.summary.relative_error;
  row.image_rmse = e.rmse();
  row.image_rmse_relative = e.relative();
  row.multi_cluster_triangles = c.multi_cluster_triangles;
  row.vs_invocations = work.vs_invocations;
  row.primitives = work.primitives;
  row.vs_per_referenced_vertex = work.vs_per_referenced_vertex;
  *groups_out = groups;
  return row;
}

// One turn of one row: warm-up + frames frames, the environment rotating from the same start
// in every turn, so every row and round renders the same frames.
void time_turn(const Scene& s, TimedRow& t) {
  const auto r = multipass_renderer(s, *t.compression, t.budget, t.per_pass, t.groups);
  for (int f = 0; f < s.plan.warmup + s.plan.frames; ++f) {
    const double radians = s.plan.degrees_per_frame * f * std::numbers::pi / 180.0;
    const double cpu0 = process_cpu_ms_now();
    const render::FrameTiming timing =
        r->render(s.camera, s.lighting, prt::axis_angle(s.axis, radians));
    const double cpu = process_cpu_ms_now() - cpu0;
    if (f < s.plan.warmup) continue;
    t.process_cpu_ms.push_back(cpu);
    t.frame_ms.push_back(timing.total_ms);
    t.cpu_ms.push_back(timing.cpu_ms);
    t.gl_ms.push_back(timing.gl_ms);
  }
}

// The interleaved timing rounds, then each row's medians and quartiles and the run's fits.
void time_rows(const Scene& s, std::vector<TimedRow>& timed, OverdrawReport& report) {
  for (int round = 0; round < s.plan.rounds; ++round) {
    note(s.plan, "timing round " + std::to_string(round + 1) + " of " +
                     std::to_string(s.plan.rounds) + " over " + std::to_string(timed.size()) +
                     " rows");
    for (TimedRow& t : timed) time_turn(s, t);
  }
  for (const TimedRow& t : timed) {
    OverdrawRow& row = report.rows[t.row];
    std::vector<double> fps;
    for (double ms : t.frame_ms) fps.push_back(ms > 0 ? 1000.0 / ms : 0.0);
    row.fps_spread = spread(fps);
    row.fps = row.fps_spread.median;
    row.frame_ms = spread(t.frame_ms).median;
    row.cpu_ms = spread(t.cpu_ms).median;
    row.gl_ms_spread = spread(t.gl_ms);
    row.gl_ms = row.gl_ms_spread.median;
    row.process_cpu_spread = spread(t.process_cpu_ms);
    row.process_cpu_ms = row.process_cpu_spread.median;
  }
  report.rounds = s.plan.rounds;
  fit_timings(report);
}

// Counts steps for the progress callback.
struct Progress {
  const OverdrawPlan& plan;
  std::uint64_t step = 0, steps = 0;
  void show(const std::string& label) const {
    if (plan.progress) plan.progress(label, step, steps);
  }
};

// Every budget x strategy row of one compression; at the largest K also its pictures.
void measure_compression(const Scene& s, const Compression& c, OverdrawReport& report,
                         std::vector<TimedRow>& timed, Progress& progress) {
  const OverdrawPlan& plan = s.plan;
  const int cost = render::constant_layout(c.set).registers_per_cluster();
  report.registers_per_cluster = cost;
  const std::string picture_budget = has(plan.budgets, "thesis") ? "thesis" : plan.budgets.back();
  const bool pictures = !plan.pictures.empty() &&
                        c.k == *std::max_element(plan.clusters.begin(), plan.clusters.end());
  double best_overdraw = 1e300;
  cpca::SuperClusters best_groups;
  std::string best_strategy;
  static const std::vector<std::string> kDesignedOrder{"order"};
  const bool designed = c.designed_per_pass > 0;
  for (const std::string& budget_name : plan.budgets) {
    if (designed && budget_name != c.designed_budget) continue;
    const int budget = budget_registers(s, budget_name, cost);
    const int per_pass =
        std::min(c.k, render::pass_capacity(c.set, budget, s.context_budget).clusters_per_pass);
    if (designed && per_pass != c.designed_per_pass)
      throw std::logic_error(c.label() + ": designed for " + std::to_string(c.designed_per_pass) +
                             " clusters per pass, the budget holds " + std::to_string(per_pass));
    for (const std::string& strategy : designed ? kDesignedOrder : plan.strategies) {
      progress.show(c.label() + ": " + budget_name + " budget, " + strategy);
      cpca::SuperClusters groups;
      report.rows.push_back(measure_row(s, c, budget_name, budget, per_pass, strategy, &groups));
      TimedRow& t = timed.emplace_back();
      t.compression = &c;
      t.groups = groups;
      t.budget = budget;
      t.per_pass = per_pass;
      t.row = report.rows.size() - 1;
      ++progress.step;
      const double od = report.rows.back().average_overdraw;
      if (pictures && budget_name == picture_budget && od < best_overdraw) {
        best_overdraw = od;
        best_groups = groups;
        best_strategy = strategy + "-" + budget_name;
      }
    }
  }
  if (!pictures) return;
  const std::string stem = "K" + std::to_string(c.k) + "-" + c.method->name;
  const fs::path dir = plan.pictures;
  render::write_picture_png(dir / ("clusters-" + stem + ".png"),
                            render::cluster_picture(s.mesh, s.camera, c.set.cluster_of));
  if (!best_strategy.empty())
    render::write_picture_png(
        dir / ("overdraw-" + stem + "-" + best_strategy + ".png"),
        render::overdraw_picture(
            s.mesh, s.camera,
            cpca::triangle_pass_counts(c.set.cluster_of, s.geometry.triangles, best_groups)));
}

// What one run's compressions and rows accumulate into.
struct Rows {
  const Scene& s;
  OverdrawReport& report;
  std::deque<Compression> compressions;  // deque: the timed rows point into it
  std::vector<TimedRow> timed;
  Progress progress;
};

// The layout (and so the registers) one cluster of this bake will cost the renderer, known
// before compressing: a pass-designing method needs its clusters per pass up front.
render::ConstantLayout expected_layout(const Scene& s) {
  return render::constant_layout(s.transfer.order, s.transfer.columns() > 1,
                                 s.plan.compress.components);
}

int expected_cost(const Scene& s) {
  return expected_layout(s).registers_per_cluster();
}

// One compression (K x method, and the budget a pass-designing method designs for) and its
// rows; `modes` also times the single-pass and decoupled paths on it.
void measure_method(Rows& rows, int k, const MethodPreset& method, int per_pass,
                    const std::string& budget, bool modes) {
  const Scene& s = rows.s;
  rows.progress.show("K=" + std::to_string(k) + " " + method.name + ": compression");
  bool cached = false;
  Compression& c = rows.compressions.emplace_back(
      compress_row(s, rows.report.transfer, k, method, per_pass, &cached));
  c.designed_budget = budget;
  if (cached) rows.report.compressions_cached = true;
  ++rows.progress.step;
  const int cost = render::constant_layout(c.set).registers_per_cluster();
  if (cost != expected_cost(s))
    throw std::logic_error(c.label() + ": a cluster costs " + std::to_string(cost) +
                           " registers, not the " + std::to_string(expected_cost(s)) +
                           " its clusters per pass were designed for");
  if (s.plan.modes && modes)
    for (render::Mode mode : {render::Mode::kSinglepass, render::Mode::kDecoupled}) {
      rows.progress.show(c.label() + ": " + render::kModeNames.name(mode));
      rows.report.modes.push_back(measure_mode(s, c.set, k, mode));
    }
  measure_compression(s, c, rows.report, rows.timed, rows.progress);
}

}  // namespace

const MethodPreset& find_method(const std::string& name) {
  for (const MethodPreset& m : kMethods)
    if (name == m.name) return m;
  throw PlanError("--rows: unknown method '" + name + "'; use one of " + method_names());
}

std::string method_names() {
  std::string names;
  for (const MethodPreset& m : kMethods) names += std::string(names.empty() ? "" : ", ") + m.name;
  return names;
}

std::string plot_budget(const std::vector<std::string>& budgets) {
  return has(budgets, "thesis") ? "thesis" : budgets.front();
}

void validate(const OverdrawPlan& plan) {
  if (plan.rounds < 1 || plan.frames < 1)
    throw PlanError("--rounds and --frames must be at least 1");
  if (plan.clusters.empty() || plan.methods.empty() || plan.strategies.empty() ||
      plan.budgets.empty())
    throw PlanError("the plan needs clusters, methods, strategies and budgets");
  for (int k : plan.clusters)
    if (k < 1) throw PlanError("--clusters: " + std::to_string(k) + " is below 1");
  for (const std::string& name : plan.methods) find_method(name);
  for (const std::string& name : plan.strategies) {
    try {
      cpca::find_supercluster_strategy(name);
    } catch (const std::invalid_argument& e) {
      throw PlanError(std::string("--strategies: ") + e.what());
    }
  }
  for (const std::string& b : plan.budgets)
    if (b != "default" && b != "thesis" &&
        (b.empty() || b.find_first_not_of("0123456789") != std::string::npos))
      throw PlanError("--budgets: '" + b + "' is not default, thesis or a register count");
}

OverdrawReport run_overdraw(const OverdrawPlan& plan) {
  validate(plan);
  Scene s(plan);
  OverdrawReport report;
  load_bake(s, report);

  render::GlContext context(plan.gl, 4, 5);
  const render::GlInfo info = context.info();
  report.gl_renderer = info.renderer;
  s.context_budget = info.default_register_budget();
  const meshes::Bounds box = meshes::bounds(s.mesh);
  s.camera = render::frame_sphere(box.center().cast<double>(), 0.5 * double(box.diagonal()),
                                  plan.width, plan.height);
  s.lighting = prt::project(s.probe, s.transfer.order);
  for (int i = 0; i < plan.image_rotations; ++i)
    s.image_rotations.push_back(prt::axis_angle(
        s.axis,
        (plan.image_degrees + 360.0 * i / plan.image_rotations) * std::numbers::pi / 180.0));
  describe_plan(s, report);
  render_reference(s, report);
  s.geometry = pipeline::geometry_of(s.mesh);
  if (!plan.pictures.empty()) fs::create_directories(plan.pictures);
  fs::create_directories(plan.cache);

  std::uint64_t steps = 0;
  for (const std::string& name : plan.methods)
    steps += find_method(name).designs_passes() ? 2 * plan.budgets.size()
                                                : 1 + plan.budgets.size() * plan.strategies.size();
  Rows rows{s, report, {}, {}, Progress{plan, 0, steps * plan.clusters.size()}};
  for (int k : plan.clusters)
    for (const std::string& method_name : plan.methods) {
      const MethodPreset& method = find_method(method_name);
      if (!method.designs_passes()) {
        measure_method(rows, k, method, 0, "", method_name == plan.methods.front());
        continue;
      }
      const int cost = expected_cost(s);
      for (const std::string& budget : plan.budgets) {
        const int per_pass = std::min(
            k, render::pass_capacity(expected_layout(s), s.transfer.order, plan.compress.components,
                                     budget_registers(s, budget, cost), s.context_budget)
                   .clusters_per_pass);
        measure_method(rows, k, method, per_pass, budget,
                       method_name == plan.methods.front() && budget == plan.budgets.front());
      }
    }
  time_rows(s, rows.timed, report);
  return report;
}

}  // namespace overdraw
