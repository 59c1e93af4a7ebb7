// render_bench COMPRESSED.prtc [--transfer T.prtx] [--probe P|procedural] [--mesh M]
// [--frames F] [--width W] [--height H] [--gl osmesa|egl] [--gl-device N]: the render benchmark
// (docs/ARCHITECTURE.md "Rendering", Measured), every configuration in one run so the ratios are
// fair.
//
// Bunny, 256 clusters x 8 PCs, order 6, 1280 x 948 (the thesis's setting): FPS and average
// overdraw for multipass at the context's register budget, multipass at 3 clusters per pass
// (the thesis's 256-register GPU), decoupled, single-pass, uncompressed (with --transfer) and
// CPU-shaded; plus the bare trivial-shader floor on the same mesh and each mode's frame time
// as a ratio to it; multipass both with feedback shading (the default) and in-draw shading,
// process CPU per frame over all threads beside the wall clock (the load of a shared
// machine inflates the wall clock far more), and the speed targets as ratios in the run. Plain
// main() rather than Google Benchmark: each row is a median over frames with glFinish, and lighting
// rotates every frame so constants are recomputed inside the timing.
#include "bench_probe.h"
#include "cpca/compressed_file.h"
#include "cpca/supercluster_strategy.h"
#include "meshes/load.h"
#include "prt/projection.h"
#include "prt/transfer_file.h"
#include "render/camera.h"
#include "render/floor_harness.h"
#include "render/gl_context.h"
#include "render/renderer.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace {

double process_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) * 1e3 + double(ts.tv_nsec) * 1e-6;
}

struct Sample {
  double overdraw = 0, frame_ms = 0, cpu_ms = 0;          // cpu: process CPU over all threads
  render::Constants constants = render::Constants::kCpu;  // where the row's were computed
};

// The speed targets as ratios within this run, by wall clock and by process CPU (the load of
// a shared machine inflates the first far more): the multipass cost of one unit of average
// overdraw (two groupings of the same 3-cluster passes differ only in overdraw) against the
// floor, and the thesis configuration's FPS.
void print_targets(const std::vector<Sample>& multipass_3, const Sample& thesis,
                   const Sample& floor, double floor_bg_ms) {
  std::printf("\ntargets (this run; wall clock, then process CPU):\n");
  if (multipass_3.size() == 2 && multipass_3[0].overdraw != multipass_3[1].overdraw) {
    const Sample& a = multipass_3[0];
    const Sample& b = multipass_3[1];
    const double d = a.overdraw - b.overdraw;
    const double wall = (a.frame_ms - b.frame_ms) / d, cpu = (a.cpu_ms - b.cpu_ms) / d;
    std::printf(
        "  multipass per unit overdraw (3/pass, order vs ILS): %.2f ms = %.2f x floor; "
        "CPU %.2f ms = %.2f x floor\n",
        wall, wall / floor.frame_ms, cpu, cpu / floor.cpu_ms);
    std::printf("  multipass ILS frame / overdraw: %.2f ms = %.2f x floor; CPU %.2f x floor\n",
                b.frame_ms / b.overdraw, b.frame_ms / b.overdraw / floor.frame_ms,
                b.cpu_ms / b.overdraw / floor.cpu_ms);
  }
  if (thesis.frame_ms > 0)
    std::printf(
        "  thesis config (3/pass, ILS): %.2f FPS (floor %.2f, floor + background %.2f FPS); "
        "CPU %.2f ms/frame = %.2f x floor\n",
        1000.0 / thesis.frame_ms, 1000.0 / floor.frame_ms, 1000.0 / floor_bg_ms, thesis.cpu_ms,
        thesis.cpu_ms / floor.cpu_ms);
}

// A flag the benchmark cannot use: exit 2.
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct Args {
  std::string compressed, transfer, mesh;
  std::string probe = "/usr/share/blender/datafiles/studiolights/world/forest.exr";
  render::GlSelection gl;
  int frames = 15, width = 1280, height = 948;
  render::Accumulation accumulation = render::Accumulation::kAuto;
  render::Constants constants = render::Constants::kAuto;
  bool sweep = false;  // --rows sweep
};

template <typename Table>
auto parse_named(const Table& table, const std::string& flag, const std::string& value) {
  try {
    return table.parse(value);
  } catch (const std::invalid_argument& e) {
    throw UsageError(flag + ": " + e.what());
  }
}

Args parse_args(int argc, char** argv) {
  if (argc < 2)
    throw UsageError(
        "usage: render_bench COMPRESSED.prtc [--transfer T.prtx] [--probe P|procedural] "
        "[--mesh M] [--frames F] [--width W] [--height H] [--gl osmesa|egl] "
        "[--gl-device N] [--accumulation auto|rgba32f|rgba16f] [--constants auto|cpu|gpu] "
        "[--rows main|sweep]");
  Args a;
  a.compressed = argv[1];
  try {
    a.gl = render::gl_selection_from_environment();  // PRTR_GL, PRTR_GL_DEVICE; flags beat it
  } catch (const render::GlError& e) {
    throw UsageError(e.what());
  }
  for (int i = 2; i + 1 < argc; i += 2) {
    const std::string flag = argv[i], value = argv[i + 1];
    if (flag == "--transfer") {
      a.transfer = value;
    } else if (flag == "--probe") {
      a.probe = value;
    } else if (flag == "--mesh") {  // the set's mesh elsewhere (the GPU bundle carries its own)
      a.mesh = value;
    } else if (flag == "--gl") {
      const auto backend = render::parse_gl_backend(value);
      if (!backend) throw UsageError("--gl " + value + ": use osmesa or egl");
      a.gl.backend = *backend;
    } else if (flag == "--gl-device") {
      char* end = nullptr;
      const long n = std::strtol(value.c_str(), &end, 10);
      if (*end || n < 0 || n > 1000)
        throw UsageError("--gl-device " + value + " is not a device index");
      a.gl.device = int(n);
    } else if (flag == "--accumulation") {
      a.accumulation = parse_named(render::kAccumulationNames, flag, value);
    } else if (flag == "--rows") {
      if (value != "main" && value != "sweep")
        throw UsageError("--rows " + value + ": use main or sweep");
      a.sweep = value == "sweep";
    } else if (flag == "--constants") {
      a.constants = parse_named(render::kConstantsNames, flag, value);
    } else if (flag == "--frames") {
      a.frames = std::atoi(value.c_str());
    } else if (flag == "--width") {
      a.width = std::atoi(value.c_str());
    } else if (flag == "--height") {
      a.height = std::atoi(value.c_str());
    } else {
      throw UsageError("unknown flag " + flag);
    }
  }
  return a;
}

// What every configuration renders: the set, its mesh, the probe and the framing camera.
struct Scene {
  cpca::CompressedSet set;
  meshes::Mesh mesh;
  std::optional<prt::TransferSet> transfer;
  probes::Probe probe;
  prt::ShLighting lighting;
  render::Camera camera;
};

Scene load_scene(const Args& a) {
  Scene s;
  s.set = cpca::read_compressed(a.compressed);
  s.mesh = meshes::load_mesh(a.mesh.empty() ? s.set.mesh_path : a.mesh);
  if (!a.transfer.empty()) s.transfer = prt::read_transfer(a.transfer);
  s.probe = load_bench_probe(a.probe);
  s.lighting = prt::project(s.probe, s.set.order);
  const meshes::Bounds b = meshes::bounds(s.mesh);
  double radius = 0;
  for (const auto& p : s.mesh.positions) radius = std::max(radius, double((p - b.center()).norm()));
  s.camera = render::frame_sphere(b.center().cast<double>(), radius, a.width, a.height);
  return s;
}

void print_work(const std::vector<render::PassWork>& work) {
  const render::WorkTotals w = render::work_totals(work);
  std::printf(" %9llu %9llu %6.3f %10llu\n", (unsigned long long)w.vs_invocations,
              (unsigned long long)w.referenced_vertices, w.vs_per_referenced_vertex,
              (unsigned long long)w.fs_invocations);
}

// The trivial-shader floors every row is a ratio to. They draw into the renderer's framebuffer
// format; "+ background" also runs the renderer's probe background pass, so a path's ratio to
// it compares like with like.
struct Floors {
  double ms = 0, background_ms = 0, cpu_ms = 0;
};

Floors measure_floors(const Scene& s, int frames) {
  std::vector<render::PassWork> floor_work, floor_bg_work;
  Floors f;
  f.ms = render::floor_frame_ms(s.mesh, s.camera, {true, true, frames, 3, nullptr, &floor_work});
  f.background_ms =
      render::floor_frame_ms(s.mesh, s.camera, {true, true, frames, 3, &s.probe, &floor_bg_work});
  const double plain = render::floor_frame_ms(s.mesh, s.camera, {false, false, frames, 3});
  // The floors' process CPU per frame: a run of 5F frames less a run of F, so the
  // harness's setup (index order, compile, probe upload) and any first-frame cost cancel.
  auto floor_cpu_ms = [&](const probes::Probe* bg) {
    auto run_cpu = [&](int n) {
      const double c0 = process_cpu_ms();
      render::floor_frame_ms(s.mesh, s.camera, {true, true, n, 1, bg});
      return process_cpu_ms() - c0;
    };
    const double few = run_cpu(frames);
    return (run_cpu(5 * frames) - few) / (4 * frames);
  };
  f.cpu_ms = floor_cpu_ms(nullptr);
  const double bg_cpu = floor_cpu_ms(&s.probe);
  std::printf("%-28s %6s %8s %7s %8s %7s %7s %6s %6s %8s %9s %9s %6s %10s\n", "configuration",
              "passes", "overdraw", "FPS", "frame ms", "cpu ms", "gl ms", "/floor", "/fl+bg",
              "proc cpu", "VS inv", "ref verts", "VS/ref", "FS inv");
  std::printf("%-28s %6d %8.3f %7.2f %8.2f %7s %7s %6.2f %6.2f %8.2f",
              "floor (trivial, cull+order)", 1, 1.0, 1000.0 / f.ms, f.ms, "-", "-", 1.0,
              f.ms / f.background_ms, f.cpu_ms);
  print_work(floor_work);
  std::printf("%-28s %6d %8.3f %7.2f %8.2f %7s %7s %6.2f %6.2f %8.2f", "floor + background", 1, 1.0,
              1000.0 / f.background_ms, f.background_ms, "-", "-", f.background_ms / f.ms, 1.0,
              bg_cpu);
  print_work(floor_bg_work);
  std::printf("%-28s %6d %8.3f %7.2f %8.2f %7s %7s %6.2f %6.2f\n", "floor (trivial, plain)", 1, 1.0,
              1000.0 / plain, plain, "-", "-", plain / f.ms, plain / f.background_ms);
  return f;
}

struct Row {
  std::string name;
  render::Mode mode;
  int clusters_per_pass;
  std::string_view strategy = {};  // cpca::group_clusters name; empty: cluster order
};

// The thesis configuration is the ILS row: 3 clusters per pass grouped by ILS.
const Row kRows[] = {{"multipass, context budget", render::Mode::kMultipass, 0},
                     {"multipass, 16 clusters/pass", render::Mode::kMultipass, 16},
                     {"multipass, 3 clusters/pass", render::Mode::kMultipass, 3},
                     {"multipass, 3/pass, ILS", render::Mode::kMultipass, 3, "ils"},
                     {"decoupled, 3 clusters/pass", render::Mode::kDecoupled, 3},
                     {"single-pass (SSBO)", render::Mode::kSinglepass, 0},
                     {"uncompressed", render::Mode::kUncompressed, 0},
                     {"cpu-shaded", render::Mode::kCpu, 0}};

// --rows sweep: multipass at 3 and 16 clusters a pass under every grouping strategy, the same
// passes with different overdraw, for FPS against overdraw (the thesis's Fig. 5.x question:
// does overdraw cost frames?).
std::vector<Row> sweep_rows() {
  std::vector<Row> rows;
  for (int per_pass : {3, 16})
    for (const cpca::NamedStrategy& strategy : cpca::supercluster_strategies())
      rows.push_back({"sweep " + std::to_string(per_pass) + "/pass, " + std::string(strategy.name),
                      render::Mode::kMultipass, per_pass, strategy.name});
  return rows;
}

using PassDetails = std::vector<std::pair<std::string, std::vector<render::PassWork>>>;

// One row (feedback: multipass shading by feedback, the default; else in the triangle draws),
// printed; nullopt when the context cannot run it. Its pass work goes to `details`.
std::optional<Sample> run_row(const Scene& s, const Args& a, const Floors& floors, const Row& row,
                              bool feedback, PassDetails& details) {
  const std::string name = row.name + (feedback ? "" : ", in-draw");
  render::RendererOptions o;
  o.accumulation = a.accumulation;
  o.constants = a.constants;
  o.multipass_feedback = feedback;
  o.mode = row.mode;
  o.clusters_per_pass = row.clusters_per_pass;
  if (!row.strategy.empty()) {
    std::vector<cpca::TriangleIndices> tris(s.mesh.triangles.begin(), s.mesh.triangles.end());
    o.groups = cpca::group_clusters(
        row.strategy, {s.set.cluster_of, tris, s.set.cluster_count, row.clusters_per_pass});
  }
  std::optional<render::Renderer> made;
  try {
    made.emplace(s.mesh, &s.set, s.transfer ? &*s.transfer : nullptr, &s.probe, o);
  } catch (const std::invalid_argument& e) {  // this context cannot run the row
    std::printf("%-28s (skipped: %s)\n", name.c_str(), e.what());
    return std::nullopt;
  }
  render::Renderer& r = *made;
  // Process CPU time over every thread (llvmpipe's included) per frame: the work, which
  // a shared machine's load inflates far less than the wall clock.
  r.render(s.camera, s.lighting, Eigen::Matrix3d::Identity());  // compiles outside the count
  const double cpu0 = process_cpu_ms();
  const render::TimingSummary t =
      render::measure(r, s.camera, s.lighting, Eigen::Matrix3d::Identity(),
                      Eigen::Vector3d::UnitY(), 1.0, a.frames, 3);
  const double proc_ms = (process_cpu_ms() - cpu0) / (a.frames + 3);
  r.set_count_work(true);
  r.render(s.camera, s.lighting, Eigen::Matrix3d::Identity());
  std::printf("%-28s %6d %8.3f %7.2f %8.2f %7.2f %7.2f %6.2f %6.2f %8.2f", name.c_str(),
              r.stats().passes, r.stats().average_overdraw, t.fps, t.frame_ms_median,
              t.cpu_ms_median, t.gl_ms_median, t.frame_ms_median / floors.ms,
              t.frame_ms_median / floors.background_ms, proc_ms);
  std::vector<render::PassWork> mesh_work = r.stats().pass_work;  // VS/ref without the quad
  std::erase_if(mesh_work, [](const render::PassWork& p) { return p.label == "background"; });
  print_work(mesh_work);
  details.emplace_back(name, r.stats().pass_work);
  std::fflush(stdout);
  return Sample{r.stats().average_overdraw, t.frame_ms_median, proc_ms, r.stats().constants};
}

// Per draw, so a path's waste can be traced to the draw that has it; multipass shading
// passes as one line (their sum, and the worst pass).
void print_details(const PassDetails& details) {
  std::printf("\nper draw: VS invocations / referenced vertices (primitives, FS invocations)\n");
  for (const auto& [name, work] : details) {
    std::printf("%s:\n", name.c_str());
    std::vector<render::PassWork> shade;
    double worst = 0;
    for (const render::PassWork& p : work) {
      const double ratio =
          p.referenced_vertices ? double(p.vs_invocations) / double(p.referenced_vertices) : 0.0;
      if (p.label.starts_with("shade ")) {
        shade.push_back(p);
        worst = std::max(worst, ratio);
        continue;
      }
      std::printf("  %-12s %8llu / %7llu = %6.3f  (%llu prims, %llu FS)\n", p.label.c_str(),
                  (unsigned long long)p.vs_invocations, (unsigned long long)p.referenced_vertices,
                  ratio, (unsigned long long)p.primitives, (unsigned long long)p.fs_invocations);
    }
    if (!shade.empty()) {
      const render::WorkTotals t = render::work_totals(shade);
      std::printf("  %zu passes   %8llu / %7llu = %6.3f  (%llu prims, %llu FS; worst pass %.3f)\n",
                  shade.size(), (unsigned long long)t.vs_invocations,
                  (unsigned long long)t.referenced_vertices, t.vs_per_referenced_vertex,
                  (unsigned long long)t.primitives, (unsigned long long)t.fs_invocations, worst);
    }
  }
}

void run(const Args& a) {
  const Scene s = load_scene(a);
  if (a.gl.backend == render::GlBackend::kEgl && a.gl.device >= 0 &&
      std::size_t(a.gl.device) >= render::list_egl_devices().size())
    throw UsageError("--gl-device " + std::to_string(a.gl.device) + ": EGL lists " +
                     std::to_string(render::list_egl_devices().size()) + " devices");
  render::GlContext context(a.gl);
  const render::GlInfo gl_info = context.info();
  std::printf("render_bench: %s, %s, %s, %s accumulation, constants %s\n",
              context.description().c_str(), gl_info.renderer.c_str(), gl_info.version.c_str(),
              render::kAccumulationNames.name(render::resolve_accumulation(a.accumulation)),
              render::kConstantsNames.name(a.constants));
  std::printf(
      "render_bench: %s, %zu vertices, %zu triangles, %d clusters x %d PCs, order %d, "
      "%d x %d, %d frames (median)\n",
      a.compressed.c_str(), s.mesh.vertex_count(), s.mesh.triangle_count(), s.set.cluster_count,
      s.set.component_count, s.set.order, a.width, a.height, a.frames);
  const Floors floors = measure_floors(s, a.frames);
  PassDetails details;
  std::vector<Sample> multipass_3;  // 3 clusters per pass: order, then ILS
  Sample thesis;
  std::set<std::string_view> used;  // where the GPU-shaded rows' constants were computed
  // Multipass twice: shading by feedback (the default) and in the triangle draws
  // (", in-draw"), so the effect is a ratio within this run.
  const std::vector<Row> rows =
      a.sweep ? sweep_rows() : std::vector<Row>(std::begin(kRows), std::end(kRows));
  for (const Row& row : rows)
    for (bool feedback : {false, true}) {
      if (!feedback && (a.sweep || row.mode != render::Mode::kMultipass)) continue;
      if (row.mode == render::Mode::kUncompressed && !s.transfer) {
        std::printf("%-28s (skipped: pass --transfer)\n", row.name.c_str());
        continue;
      }
      const std::optional<Sample> sample = run_row(s, a, floors, row, feedback, details);
      if (!sample) continue;
      if (feedback && row.mode == render::Mode::kMultipass && row.clusters_per_pass == 3)
        multipass_3.push_back(*sample);
      if (feedback && !row.strategy.empty()) thesis = *sample;
      if (row.mode != render::Mode::kCpu)
        used.insert(render::kConstantsNames.name(sample->constants));
    }
  std::string list;
  for (std::string_view u : used) list += (list.empty() ? "" : ", ") + std::string(u);
  std::printf("render_bench: the GPU-shaded rows' constants computed on the %s\n", list.c_str());
  if (a.sweep) return;
  print_targets(multipass_3, thesis, {1.0, floors.ms, floors.cpu_ms}, floors.background_ms);
  print_details(details);
}

}  // namespace

int main(int argc, char** argv) {
  try {
    run(parse_args(argc, argv));
  } catch (const UsageError& e) {
    std::fprintf(stderr, "render_bench: %s\n", e.what());
    return 2;
  } catch (const std::invalid_argument& e) {  // a flag's value the benchmark cannot use
    std::fprintf(stderr, "render_bench: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "render_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
