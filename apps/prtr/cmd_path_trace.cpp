// prtr path-trace MESH --probe P -o ref.exr: the reference image a surface light field (or
// a PRT relighting) is judged against: every pixel path traced under the probe with the
// engine's material (prt/path_tracer.h), through the camera prtr render places.
#include "bake_flags.h"
#include "commands.h"
#include "flag_checks.h"
#include "mesh_flags.h"
#include "progress_bar.h"
#include "view_flags.h"

#include "meshes/load.h"
#include "probes/load.h"
#include "prt/path_tracer.h"
#include "render/camera.h"
#include "render/image.h"

#include <chrono>
#include <cstdio>
#include <string>

namespace prtr_app {
// Named rather than anonymous: a unity build compiles every command in one unit.
namespace cmd_path_trace {

struct Options {
  std::string mesh, probe, output, png;
  MaterialFlags material;
  MeshFlags mesh_flags;
  ViewFlags view;
  int spp = 64, bounces = 1;
  std::uint64_t seed = 1;
  bool quiet = false;
};

void add_flags(CLI::App* cmd, Options& o) {
  cmd->add_option("MESH", o.mesh, std::string("Mesh file: ") + meshes::kMeshFormats)->required();
  cmd->add_option("--probe", o.probe, "Light probe (lat-long or angular EXR/HDR)")->required();
  cmd->add_option("-o,--output", o.output, "EXR to write (linear RGB, alpha = coverage)")
      ->required();
  cmd->add_option("--png", o.png, "Also write a tone-mapped PNG");
  add_checked_option(cmd, "--spp", o.spp, "Paths per pixel", integer_in(1, 1 << 20));
  add_checked_option(cmd, "--bounces", o.bounces, "Interreflections (0: direct light, shadows)",
                     integer_in(0, 16));
  add_checked_option(cmd, "--seed", o.seed, "Seed of the random numbers", unsigned_integer());
  add_material_flags(cmd, o.material);
  add_view_flags(cmd, o.view);
  add_mesh_flags(cmd, o.mesh_flags);
  cmd->add_flag("-q,--quiet", o.quiet, "No progress bar");
}

void run(const Options& o, CLI::App* cmd) {
  check_outputs({{"-o", o.output}, {"--png", o.png}}, {{"MESH", o.mesh}, {"--probe", o.probe}});
  if (cmd->count("--background") || cmd->count("--axis"))
    throw UsageError(
        "prtr path-trace shows the probe itself behind the mesh, unrotated: "
        "--background and --axis do not apply");
  const prt::Material material = resolve_material_flags(o.material);
  const meshes::Mesh mesh = meshes::load_mesh(o.mesh, load_options(o.mesh_flags));
  const probes::Probe probe = probes::load_probe(o.probe);
  const render::Camera camera = resolve_camera(o.view, mesh);
  prt::PathTracerOptions options;
  options.bounces = o.bounces;
  options.seed = o.seed;
  const prt::PathTracer tracer(mesh, probe, material, options);

  // Each pixel is integrated over its area, as prtr render's supersampled frames are
  // box-filtered: the paths are spread over an n x n grid of sub-pixels (n the largest with
  // n^2 <= spp, at most 8), spp / n^2 paths through each sub-pixel's centre, and the coverage
  // is the fraction of sub-pixels whose ray meets the mesh.
  const int w = camera.width, h = camera.height;
  int n = 1;
  while (n < 8 && (n + 1) * (n + 1) <= o.spp) ++n;
  const int per_subpixel = o.spp / (n * n), spp = per_subpixel * n * n;
  const Eigen::Index rays = Eigen::Index(w) * h * n * n;
  Eigen::Matrix3Xf origins(3, rays), directions(3, rays);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
          const Eigen::Index r = ((Eigen::Index(y) * w + x) * n + j) * n + i;
          origins.col(r) = camera.eye.cast<float>();
          directions.col(r) = camera.subpixel_direction(x, y, i, j, n).cast<float>();
        }
  ProgressBar bar(o.quiet);
  const auto start = std::chrono::steady_clock::now();
  const Eigen::Matrix3Xf radiance = prt::path_trace_image(
      tracer, origins, directions, per_subpixel,
      [&bar](std::uint64_t done, std::uint64_t total) { bar.update("path trace", done, total); });
  bar.finish();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  std::vector<prt::RayHit> hits(static_cast<std::size_t>(rays));
  tracer.scene().intersect_from(origins, directions, 0.f, hits.data());
  render::Image image;
  image.width = w;
  image.height = h;
  image.rgba.resize(std::size_t(w) * h * 4);
  const Eigen::Index subpixels = Eigen::Index(n) * n;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const Eigen::Index first = (Eigen::Index(y) * w + x) * subpixels;
      const Eigen::Vector3f mean = radiance.middleCols(first, subpixels).rowwise().mean();
      int covered = 0;
      for (Eigen::Index r = first; r < first + subpixels; ++r)
        covered += hits[std::size_t(r)].triangle >= 0 ? 1 : 0;
      float* p = image.pixel(x, y);
      for (int c = 0; c < 3; ++c) p[c] = mean[c];
      p[3] = float(covered) / float(subpixels);
    }
  }
  render::write_exr(o.output, image);
  if (!o.png.empty()) render::write_png(o.png, image, o.view.exposure);
  std::printf(
      "wrote %s: %d x %d, %d paths per pixel over %d x %d sub-pixels, %d bounce(s), %.1f s\n",
      o.output.c_str(), w, h, spp, n, n, o.bounces, seconds);
}

}  // namespace cmd_path_trace

Runner add_path_trace_command(CLI::App& app) {
  return add_command(app, "path-trace",
                     "Path trace a reference image of a mesh under a probe (the image SLF and "
                     "PRT renderings are judged against)",
                     cmd_path_trace::add_flags, cmd_path_trace::run);
}

}  // namespace prtr_app
