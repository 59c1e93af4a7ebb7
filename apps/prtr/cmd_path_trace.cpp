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

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

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
  const Eigen::Index subpixels = Eigen::Index(n) * n, row_rays = Eigen::Index(w) * subpixels;
  const std::uint64_t total = std::uint64_t(row_rays) * std::uint64_t(h);

  // The rows are traced in bands of about 2^20 rays (some 40 MB of rays and radiance),
  // so memory does not grow with the image or the paths a pixel. Each ray's paths keep its
  // index in the whole image as their key, so the bands do not change a bit of the result.
  constexpr Eigen::Index kBandRays = Eigen::Index(1) << 20;
  const int band_rows = int(std::clamp<Eigen::Index>(kBandRays / row_rays, 1, h));
  render::Image image;
  image.width = w;
  image.height = h;
  image.rgba.resize(std::size_t(w) * h * 4);
  ProgressBar bar(o.quiet);
  const auto start = std::chrono::steady_clock::now();
  for (int y0 = 0; y0 < h; y0 += band_rows) {
    const int rows = std::min(band_rows, h - y0);
    const Eigen::Index rays = row_rays * rows;
    const std::uint64_t first = std::uint64_t(row_rays) * std::uint64_t(y0);
    Eigen::Matrix3Xf origins(3, rays), directions(3, rays);
    origins.colwise() = camera.eye.cast<float>();
    for (int y = y0; y < y0 + rows; ++y)
      for (int x = 0; x < w; ++x)
        for (int j = 0; j < n; ++j)
          for (int i = 0; i < n; ++i) {
            const Eigen::Index r = ((Eigen::Index(y - y0) * w + x) * n + j) * n + i;
            directions.col(r) = camera.subpixel_direction(x, y, i, j, n).cast<float>();
          }
    std::vector<std::uint8_t> hit(static_cast<std::size_t>(rays));
    const Eigen::Matrix3Xf radiance = prt::path_trace_image(
        tracer, origins, directions, per_subpixel,
        [&bar, first, total](std::uint64_t done, std::uint64_t) {
          bar.update("path trace", first + done, total);
        },
        first, hit.data());
    for (int y = y0; y < y0 + rows; ++y) {
      for (int x = 0; x < w; ++x) {
        const Eigen::Index begin = (Eigen::Index(y - y0) * w + x) * subpixels;
        const Eigen::Vector3f mean = radiance.middleCols(begin, subpixels).rowwise().mean();
        int covered = 0;
        for (Eigen::Index r = begin; r < begin + subpixels; ++r) covered += hit[std::size_t(r)];
        float* p = image.pixel(x, y);
        for (int c = 0; c < 3; ++c) p[c] = mean[c];
        p[3] = float(covered) / float(subpixels);
      }
    }
  }
  bar.finish();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

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
