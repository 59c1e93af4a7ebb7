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
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace {

double process_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) * 1e3 + double(ts.tv_nsec) * 1e-6;
}

struct Sample {
  double overdraw = 0, frame_ms = 0, cpu_ms = 0;  // cpu: process CPU over all threads
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

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr,
                 "usage: render_bench COMPRESSED.prtc [--transfer T.prtx] [--probe P|procedural] "
                 "[--mesh M] [--frames F] [--width W] [--height H] [--gl osmesa|egl] "
                 "[--gl-device N] [--accumulation auto|rgba32f|rgba16f]\n");
    return 2;
  }
  std::string compressed = argv[1], transfer_path, mesh_path,
              probe_path = "/usr/share/blender/datafiles/studiolights/world/forest.exr";
  render::GlSelection gl;
  try {
    gl = render::gl_selection_from_environment();  // PRTR_GL, PRTR_GL_DEVICE; flags beat it
  } catch (const render::GlError& e) {
    std::fprintf(stderr, "render_bench: %s\n", e.what());
    return 2;
  }
  int frames = 15, width = 1280, height = 948;
  render::Accumulation accumulation = render::Accumulation::kAuto;
  for (int i = 2; i + 1 < argc; i += 2) {
    const std::string flag = argv[i], value = argv[i + 1];
    if (flag == "--transfer")
      transfer_path = value;
    else if (flag == "--probe")
      probe_path = value;
    else if (flag == "--mesh")  // the set's mesh elsewhere (the GPU bundle carries its own)
      mesh_path = value;
    else if (flag == "--gl") {
      const auto backend = render::parse_gl_backend(value);
      if (!backend) {
        std::fprintf(stderr, "render_bench: --gl %s: use osmesa or egl\n", value.c_str());
        return 2;
      }
      gl.backend = *backend;
    } else if (flag == "--gl-device") {
      char* end = nullptr;
      const long n = std::strtol(value.c_str(), &end, 10);
      if (*end || n < 0 || n > 1000) {
        std::fprintf(stderr, "render_bench: --gl-device %s is not a device index\n", value.c_str());
        return 2;
      }
      gl.device = int(n);
    } else if (flag == "--accumulation") {
      try {
        accumulation = render::parse_accumulation(value);
      } catch (const std::invalid_argument& e) {
        std::fprintf(stderr, "render_bench: --accumulation: %s\n", e.what());
        return 2;
      }
    } else if (flag == "--frames")
      frames = std::atoi(value.c_str());
    else if (flag == "--width")
      width = std::atoi(value.c_str());
    else if (flag == "--height")
      height = std::atoi(value.c_str());
    else {
      std::fprintf(stderr, "render_bench: unknown flag %s\n", flag.c_str());
      return 2;
    }
  }
  try {
    const cpca::CompressedSet set = cpca::read_compressed(compressed);
    const meshes::Mesh mesh = meshes::load_mesh(mesh_path.empty() ? set.mesh_path : mesh_path);
    std::optional<prt::TransferSet> transfer;
    if (!transfer_path.empty()) transfer = prt::read_transfer(transfer_path);
    const probes::Probe probe = load_bench_probe(probe_path);
    const prt::ShLighting lighting = prt::project(probe, set.order);
    const meshes::Bounds b = meshes::bounds(mesh);
    double radius = 0;
    for (const auto& p : mesh.positions) radius = std::max(radius, double((p - b.center()).norm()));
    const render::Camera camera =
        render::frame_sphere(b.center().cast<double>(), radius, width, height);
    if (gl.backend == render::GlBackend::kEgl && gl.device >= 0 &&
        std::size_t(gl.device) >= render::list_egl_devices().size()) {
      std::fprintf(stderr, "render_bench: --gl-device %d: EGL lists %zu devices\n", gl.device,
                   render::list_egl_devices().size());
      return 2;
    }
    render::GlContext context(gl);
    const render::GlInfo gl_info = context.info();
    std::printf("render_bench: %s, %s, %s, %s accumulation\n", context.description().c_str(),
                gl_info.renderer.c_str(), gl_info.version.c_str(),
                render::accumulation_name(render::resolve_accumulation(accumulation)));
    std::printf(
        "render_bench: %s, %zu vertices, %zu triangles, %d clusters x %d PCs, order %d, "
        "%d x %d, %d frames (median)\n",
        compressed.c_str(), mesh.vertex_count(), mesh.triangle_count(), set.cluster_count,
        set.component_count, set.order, width, height, frames);
    // Every floor draws into the renderer's framebuffer format; "+ background" also runs the
    // renderer's probe background pass, so a path's ratio to it compares like with like.
    std::vector<render::PassWork> floor_work, floor_bg_work;
    const double floor_ms =
        render::floor_frame_ms(mesh, camera, {true, true, frames, 3, nullptr, &floor_work});
    const double floor_bg =
        render::floor_frame_ms(mesh, camera, {true, true, frames, 3, &probe, &floor_bg_work});
    const double floor_plain = render::floor_frame_ms(mesh, camera, {false, false, frames, 3});
    // The floors' process CPU per frame: a run of 5F frames less a run of F, so the
    // harness's setup (index order, compile, probe upload) and any first-frame cost cancel.
    auto floor_cpu_ms = [&](const probes::Probe* bg) {
      auto run_cpu = [&](int n) {
        const double c0 = process_cpu_ms();
        render::floor_frame_ms(mesh, camera, {true, true, n, 1, bg});
        return process_cpu_ms() - c0;
      };
      const double few = run_cpu(frames);
      return (run_cpu(5 * frames) - few) / (4 * frames);
    };
    const double floor_cpu = floor_cpu_ms(nullptr), floor_bg_cpu = floor_cpu_ms(&probe);
    std::printf("%-28s %6s %8s %7s %8s %7s %7s %6s %6s %8s %9s %9s %6s %10s\n", "configuration",
                "passes", "overdraw", "FPS", "frame ms", "cpu ms", "gl ms", "/floor", "/fl+bg",
                "proc cpu", "VS inv", "ref verts", "VS/ref", "FS inv");
    auto print_work = [](const std::vector<render::PassWork>& work) {
      const render::WorkTotals w = render::work_totals(work);
      std::printf(" %9llu %9llu %6.3f %10llu\n", (unsigned long long)w.vs_invocations,
                  (unsigned long long)w.referenced_vertices, w.vs_per_referenced_vertex,
                  (unsigned long long)w.fs_invocations);
    };
    auto mesh_only = [](std::vector<render::PassWork> work) {  // VS/ref without the quad
      std::erase_if(work, [](const render::PassWork& p) { return p.label == "background"; });
      return work;
    };
    std::printf("%-28s %6d %8.3f %7.2f %8.2f %7s %7s %6.2f %6.2f %8.2f",
                "floor (trivial, cull+order)", 1, 1.0, 1000.0 / floor_ms, floor_ms, "-", "-", 1.0,
                floor_ms / floor_bg, floor_cpu);
    print_work(floor_work);
    std::printf("%-28s %6d %8.3f %7.2f %8.2f %7s %7s %6.2f %6.2f %8.2f", "floor + background", 1,
                1.0, 1000.0 / floor_bg, floor_bg, "-", "-", floor_bg / floor_ms, 1.0, floor_bg_cpu);
    print_work(floor_bg_work);
    std::printf("%-28s %6d %8.3f %7.2f %8.2f %7s %7s %6.2f %6.2f\n", "floor (trivial, plain)", 1,
                1.0, 1000.0 / floor_plain, floor_plain, "-", "-", floor_plain / floor_ms,
                floor_plain / floor_bg);
    struct Row {
      const char* name;
      render::Mode mode;
      int clusters_per_pass;
      const char* strategy = nullptr;  // cpca::group_clusters name; null: cluster order
    };
    // The thesis configuration is the ILS row: 3 clusters per pass grouped by ILS.
    const Row rows[] = {{"multipass, context budget", render::Mode::kMultipass, 0},
                        {"multipass, 16 clusters/pass", render::Mode::kMultipass, 16},
                        {"multipass, 3 clusters/pass", render::Mode::kMultipass, 3},
                        {"multipass, 3/pass, ILS", render::Mode::kMultipass, 3, "ils"},
                        {"decoupled, 3 clusters/pass", render::Mode::kDecoupled, 3},
                        {"single-pass (SSBO)", render::Mode::kSinglepass, 0},
                        {"uncompressed", render::Mode::kUncompressed, 0},
                        {"cpu-shaded", render::Mode::kCpu, 0}};
    std::vector<std::pair<std::string, std::vector<render::PassWork>>> details;
    std::vector<Sample> multipass_3;  // 3 clusters per pass: order, then ILS
    Sample thesis, floor{1.0, floor_ms, floor_cpu};
    // Multipass twice: shading by feedback (the default) and in the triangle draws
    // (", in-draw"), so the effect is a ratio within this run.
    for (const Row& row : rows)
      for (bool feedback : {false, true}) {
        if (!feedback && row.mode != render::Mode::kMultipass) continue;
        if (row.mode == render::Mode::kUncompressed && !transfer) {
          std::printf("%-28s (skipped: pass --transfer)\n", row.name);
          continue;
        }
        const std::string name = std::string(row.name) + (feedback ? "" : ", in-draw");
        render::RendererOptions o;
        o.accumulation = accumulation;
        o.multipass_feedback = feedback;
        o.mode = row.mode;
        o.clusters_per_pass = row.clusters_per_pass;
        if (row.strategy) {
          std::vector<cpca::TriangleIndices> tris(mesh.triangles.begin(), mesh.triangles.end());
          o.groups = cpca::group_clusters(
              row.strategy, {set.cluster_of, tris, set.cluster_count, row.clusters_per_pass});
        }
        std::optional<render::Renderer> made;
        try {
          made.emplace(mesh, &set, transfer ? &*transfer : nullptr, &probe, o);
        } catch (const std::invalid_argument& e) {  // this context cannot run the row
          std::printf("%-28s (skipped: %s)\n", name.c_str(), e.what());
          continue;
        }
        render::Renderer& r = *made;
        // Process CPU time over every thread (llvmpipe's included) per frame: the work, which
        // a shared machine's load inflates far less than the wall clock.
        r.render(camera, lighting, Eigen::Matrix3d::Identity());  // compiles outside the count
        const double cpu0 = process_cpu_ms();
        const render::TimingSummary t =
            render::measure(r, camera, lighting, Eigen::Matrix3d::Identity(),
                            Eigen::Vector3d::UnitY(), 1.0, frames, 3);
        const double proc_ms = (process_cpu_ms() - cpu0) / (frames + 3);
        r.set_count_work(true);
        r.render(camera, lighting, Eigen::Matrix3d::Identity());
        std::printf("%-28s %6d %8.3f %7.2f %8.2f %7.2f %7.2f %6.2f %6.2f %8.2f", name.c_str(),
                    r.stats().passes, r.stats().average_overdraw, t.fps, t.frame_ms_median,
                    t.cpu_ms_median, t.gl_ms_median, t.frame_ms_median / floor_ms,
                    t.frame_ms_median / floor_bg, proc_ms);
        print_work(mesh_only(r.stats().pass_work));
        details.emplace_back(name, r.stats().pass_work);
        if (feedback && row.mode == render::Mode::kMultipass && row.clusters_per_pass == 3)
          multipass_3.push_back({r.stats().average_overdraw, t.frame_ms_median, proc_ms});
        if (feedback && row.strategy)
          thesis = {r.stats().average_overdraw, t.frame_ms_median, proc_ms};
        std::fflush(stdout);
      }
    print_targets(multipass_3, thesis, floor, floor_bg);
    // Per draw, so a path's waste can be traced to the draw that has it; multipass shading
    // passes as one line (their sum, and the worst pass).
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
        std::printf(
            "  %zu passes   %8llu / %7llu = %6.3f  (%llu prims, %llu FS; worst pass %.3f)\n",
            shade.size(), (unsigned long long)t.vs_invocations,
            (unsigned long long)t.referenced_vertices, t.vs_per_referenced_vertex,
            (unsigned long long)t.primitives, (unsigned long long)t.fs_invocations, worst);
      }
    }
  } catch (const std::invalid_argument& e) {  // a flag's value the benchmark cannot use
    std::fprintf(stderr, "render_bench: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "render_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
