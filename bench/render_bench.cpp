// render_bench COMPRESSED.prtc [--transfer T.prtx] [--probe P] [--frames F] [--width W]
// [--height H]: the render benchmark (docs/ARCHITECTURE.md "Rendering", Measured), every
// configuration in one run so the ratios are fair.
//
// Bunny, 256 clusters x 8 PCs, order 6, 1280 x 948 (the thesis's setting): FPS and average
// overdraw for multipass at the context's register budget, multipass at 3 clusters per pass
// (the thesis's 256-register GPU), decoupled, single-pass, uncompressed (with --transfer) and
// CPU-shaded; plus the bare trivial-shader floor on the same mesh and each mode's frame time
// as a ratio to it. Plain main() rather than Google Benchmark: each row is a median over
// frames with glFinish, and lighting rotates every frame so constants are recomputed inside
// the timing.
#include "cpca/compressed_file.h"
#include "meshes/load.h"
#include "probes/load.h"
#include "prt/projection.h"
#include "prt/transfer_file.h"
#include "render/camera.h"
#include "render/floor_harness.h"
#include "render/gl_context.h"
#include "render/renderer.h"

#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr,
                 "usage: render_bench COMPRESSED.prtc [--transfer T.prtx] [--probe P] "
                 "[--frames F] [--width W] [--height H]\n");
    return 2;
  }
  std::string compressed = argv[1], transfer_path,
              probe_path = "/usr/share/blender/datafiles/studiolights/world/forest.exr";
  int frames = 15, width = 1280, height = 948;
  for (int i = 2; i + 1 < argc; i += 2) {
    const std::string flag = argv[i], value = argv[i + 1];
    if (flag == "--transfer")
      transfer_path = value;
    else if (flag == "--probe")
      probe_path = value;
    else if (flag == "--frames")
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
    const meshes::Mesh mesh = meshes::load_mesh(set.mesh_path);
    std::optional<prt::TransferSet> transfer;
    if (!transfer_path.empty()) transfer = prt::read_transfer(transfer_path);
    const probes::Probe probe = probes::load_probe(probe_path);
    const prt::ShLighting lighting = prt::project(probe, set.order);
    const meshes::Bounds b = meshes::bounds(mesh);
    double radius = 0;
    for (const auto& p : mesh.positions) radius = std::max(radius, double((p - b.center()).norm()));
    const render::Camera camera =
        render::frame_sphere(b.center().cast<double>(), radius, width, height);
    render::GlContext context;
    std::printf(
        "render_bench: %s, %zu vertices, %zu triangles, %d clusters x %d PCs, order %d, "
        "%d x %d, %d frames (median)\n",
        compressed.c_str(), mesh.vertex_count(), mesh.triangle_count(), set.cluster_count,
        set.component_count, set.order, width, height, frames);
    const double floor_ms = render::floor_frame_ms(mesh, camera, {true, true, frames, 3});
    const double floor_plain = render::floor_frame_ms(mesh, camera, {false, false, frames, 3});
    std::printf("%-28s %7s %9s %8s %9s %8s %8s %7s\n", "configuration", "passes", "overdraw", "FPS",
                "frame ms", "cpu ms", "gl ms", "/floor");
    std::printf("%-28s %7d %9.3f %8.2f %9.2f %8s %8s %7.2f\n", "floor (trivial, cull+order)", 1,
                1.0, 1000.0 / floor_ms, floor_ms, "-", "-", 1.0);
    std::printf("%-28s %7d %9.3f %8.2f %9.2f %8s %8s %7.2f\n", "floor (trivial, plain)", 1, 1.0,
                1000.0 / floor_plain, floor_plain, "-", "-", floor_plain / floor_ms);
    struct Row {
      const char* name;
      render::Mode mode;
      int clusters_per_pass;
    };
    const Row rows[] = {{"multipass, context budget", render::Mode::kMultipass, 0},
                        {"multipass, 3 clusters/pass", render::Mode::kMultipass, 3},
                        {"decoupled, 3 clusters/pass", render::Mode::kDecoupled, 3},
                        {"single-pass (SSBO)", render::Mode::kSinglepass, 0},
                        {"uncompressed", render::Mode::kUncompressed, 0},
                        {"cpu-shaded", render::Mode::kCpu, 0}};
    for (const Row& row : rows) {
      if (row.mode == render::Mode::kUncompressed && !transfer) {
        std::printf("%-28s (skipped: pass --transfer)\n", row.name);
        continue;
      }
      render::RendererOptions o;
      o.mode = row.mode;
      o.clusters_per_pass = row.clusters_per_pass;
      render::Renderer r(mesh, &set, transfer ? &*transfer : nullptr, &probe, o);
      const render::TimingSummary t =
          render::measure(r, camera, lighting, Eigen::Matrix3d::Identity(),
                          Eigen::Vector3d::UnitY(), 1.0, frames, 3);
      std::printf("%-28s %7d %9.3f %8.2f %9.2f %8.2f %8.2f %7.2f\n", row.name, r.stats().passes,
                  r.stats().average_overdraw, t.fps, t.frame_ms_median, t.cpu_ms_median,
                  t.gl_ms_median, t.frame_ms_median / floor_ms);
      std::fflush(stdout);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "render_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
