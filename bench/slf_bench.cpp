// slf_bench [--mesh M] [--frames F] [--width W] [--height H] [--map X] [--components k]
// [--clusters eta] [--azimuth Z] [--elevation W] [--gl osmesa|egl] [--gl-device N]: the
// one-pass surface light field renderer (render/slf_renderer.h) against the trivial-shader
// floor (render/floor_harness.h) on the same mesh, camera and framebuffer, in one run so the
// ratio is fair. Defaults: the Stanford bunny at 1280 x 948, k = 8, eta = 256, Z x W =
// 32 x 16 (the SLF paper's specular setting, with its direction grid), a 1024 x 1024 surface
// map. The model is synthetic (the bake's output is not needed to time the reconstruction):
// a chart per triangle, clusters in spatially coherent patches (the bunny's directions from
// its centre on a 16 x 16 lat-long grid, so most fragments see four texels of one cluster and
// the patch borders see several, as after CPCA), random weights and view maps. Rows: with
// the probe background (against the floor with the same background pass) and without; the
// shared-cluster fast path on and off; wall clock and process CPU per frame (the load of a
// shared machine inflates the first far more).
#include "bench_probe.h"
#include "meshes/load.h"
#include "render/camera.h"
#include "render/floor_harness.h"
#include "render/gl_context.h"
#include "render/slf_renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct Args {
  std::string mesh = "/usr/share/glmark2/models/bunny.obj";
  render::GlSelection gl;
  int frames = 15, width = 1280, height = 948, map = 1024;
  int components = 8, clusters = 256, azimuth = 32, elevation = 16;
};

int parse_int(const std::string& flag, const std::string& value, int lo, int hi) {
  char* end = nullptr;
  const long n = std::strtol(value.c_str(), &end, 10);
  if (value.empty() || *end || n < lo || n > hi)
    throw UsageError(flag + " " + value + ": expected an integer in " + std::to_string(lo) + ".." +
                     std::to_string(hi));
  return int(n);
}

Args parse_args(int argc, char** argv) {
  Args a;
  try {
    a.gl = render::gl_selection_from_environment();
  } catch (const render::GlError& e) {
    throw UsageError(e.what());
  }
  for (int i = 1; i < argc; i += 2) {
    const std::string flag = argv[i];
    if (i + 1 >= argc) throw UsageError(flag + " needs a value");
    const std::string value = argv[i + 1];
    if (flag == "--mesh") {
      a.mesh = value;
    } else if (flag == "--gl") {
      const auto backend = render::parse_gl_backend(value);
      if (!backend) throw UsageError("--gl " + value + ": use osmesa or egl");
      a.gl.backend = *backend;
    } else if (flag == "--gl-device") {
      a.gl.device = parse_int(flag, value, 0, 1000);
    } else if (flag == "--frames") {
      a.frames = parse_int(flag, value, 1, 10000);
    } else if (flag == "--width") {
      a.width = parse_int(flag, value, 1, 16384);
    } else if (flag == "--height") {
      a.height = parse_int(flag, value, 1, 16384);
    } else if (flag == "--map") {
      a.map = parse_int(flag, value, 16, 16384);
    } else if (flag == "--components") {
      a.components = parse_int(flag, value, 0, 256);
    } else if (flag == "--clusters") {
      a.clusters = parse_int(flag, value, 1, 65536);
    } else if (flag == "--azimuth") {
      a.azimuth = parse_int(flag, value, 1, 4096);
    } else if (flag == "--elevation") {
      a.elevation = parse_int(flag, value, 1, 4096);
    } else {
      throw UsageError("unknown flag " + flag);
    }
  }
  return a;
}

// A chart per triangle: an n x n cell of the map, the triangle's corners at texels (1, 1),
// (n - 1, 1) and (1, n - 1) of it, so a lookup inside reads only its own cell's texels.
// Each texel of a used cell takes the cluster of the surface point its position in the
// cell extrapolates to; unused cells are -1.
render::SlfModel synthetic_model(const meshes::Mesh& mesh, const Args& a) {
  const int triangles = int(mesh.triangle_count());
  const int n = std::max(3, int(std::floor(a.map / std::ceil(std::sqrt(double(triangles))))));
  const int per_row = a.map / n;
  if (per_row * per_row < triangles)
    throw UsageError("--map " + std::to_string(a.map) + " is too small for " +
                     std::to_string(triangles) + " triangles");
  render::SlfModel m;
  m.map_width = m.map_height = a.map;
  m.grid = {a.azimuth, a.elevation};
  m.components = a.components;
  m.clusters = a.clusters;
  m.texel_cluster.assign(std::size_t(a.map) * a.map, -1);
  m.texel_weights.assign(m.texel_cluster.size() * std::size_t(a.components), 0.f);
  const meshes::Bounds b = meshes::bounds(mesh);
  const Eigen::Vector3f centre = b.center();
  const int side = std::max(1, int(std::round(std::sqrt(double(a.clusters)))));
  auto cluster_of = [&](const Eigen::Vector3f& p) {
    const Eigen::Vector3f d = (p - centre).normalized();
    const double u = (std::atan2(d.x(), d.z()) / std::numbers::pi + 1.0) * 0.5;
    const double v = std::acos(std::clamp(double(d.y()), -1.0, 1.0)) / std::numbers::pi;
    const int i = std::min(side - 1, int(u * side)), j = std::min(side - 1, int(v * side));
    return (j * side + i) % a.clusters;
  };
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> weight(-0.5f, 0.5f);
  const float scale = 1.f / float(a.map);
  for (int t = 0; t < triangles; ++t) {
    const int cx = (t % per_row) * n, cy = (t / per_row) * n;
    const Eigen::Vector2f c0(float(cx + 1), float(cy + 1)), c1(float(cx + n - 1), float(cy + 1)),
        c2(float(cx + 1), float(cy + n - 1));
    const auto& tri = mesh.triangles[std::size_t(t)];
    const Eigen::Vector3f p0 = mesh.positions[tri[0]], p1 = mesh.positions[tri[1]],
                          p2 = mesh.positions[tri[2]];
    const Eigen::Vector3f normal = (p1 - p0).cross(p2 - p0).normalized();
    for (const Eigen::Vector2f& c : {c0, c1, c2}) m.uv.push_back(c * scale);
    for (const Eigen::Vector3f& p : {p0, p1, p2}) {
      m.positions.push_back(p);
      m.normals.push_back(normal);
    }
    for (int y = cy; y < cy + n; ++y)
      for (int x = cx; x < cx + n; ++x) {
        const float u = (float(x) + 0.5f - c0.x()) / float(n - 2);
        const float v = (float(y) + 0.5f - c0.y()) / float(n - 2);
        const std::size_t texel = std::size_t(y) * std::size_t(a.map) + std::size_t(x);
        m.texel_cluster[texel] = cluster_of((1 - u - v) * p0 + u * p1 + v * p2);
        for (int j = 0; j < a.components; ++j)
          m.texel_weights[texel * std::size_t(a.components) + std::size_t(j)] = weight(rng);
      }
  }
  std::uniform_real_distribution<float> view(0.f, 1.f);
  m.view_maps.resize(std::size_t(a.clusters) * std::size_t(a.components + 1) * m.slice_floats());
  for (float& value : m.view_maps) value = view(rng);
  m.validate();
  return m;
}

double process_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) * 1e3 + double(ts.tv_nsec) * 1e-6;
}

struct Row {
  double frame_ms = 0, cpu_ms = 0;
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

Row time_slf(render::SlfRenderer& renderer, const render::Camera& camera, int frames) {
  std::vector<double> wall, cpu;
  for (int f = -3; f < frames; ++f) {
    const double c0 = process_cpu_ms();
    const render::FrameTiming t = renderer.render(camera);
    if (f < 0) continue;
    wall.push_back(t.total_ms);
    cpu.push_back(process_cpu_ms() - c0);
  }
  return {median(wall), median(cpu)};
}

Row time_floor(const meshes::Mesh& mesh, const render::Camera& camera, int frames,
               const probes::Probe* background) {
  // floor_frame_ms reports the wall clock. Its process CPU includes its set-up (the
  // background's cube map is resampled on every call), so the CPU per frame is the
  // difference between a run of 2F frames and one of F, over F.
  render::FloorOptions o;
  o.warmup = 3;
  o.background = background;
  o.frames = frames;
  const double c0 = process_cpu_ms();
  const double wall = render::floor_frame_ms(mesh, camera, o);
  const double c1 = process_cpu_ms();
  o.frames = 2 * frames;
  render::floor_frame_ms(mesh, camera, o);
  const double c2 = process_cpu_ms();
  return {wall, ((c2 - c1) - (c1 - c0)) / frames};
}

}  // namespace

int main(int argc, char** argv) {
  Args a;
  try {
    a = parse_args(argc, argv);
  } catch (const UsageError& e) {
    std::fprintf(stderr, "slf_bench: %s\n", e.what());
    return 2;
  }
  try {
    render::GlContext context(a.gl);
    const meshes::Mesh mesh = meshes::load_mesh(a.mesh);
    const render::SlfModel model = synthetic_model(mesh, a);
    const probes::Probe probe = procedural_bench_probe();
    const meshes::Bounds b = meshes::bounds(mesh);
    const render::Camera camera =
        render::frame_sphere(b.center().cast<double>(), 0.5 * b.diagonal(), a.width, a.height);
    std::printf(
        "%s, %s: %zu triangles, %d x %d map, k = %d, eta = %d, %d x %d directions, "
        "%d x %d, median of %d frames\n",
        context.description().c_str(), context.info().renderer.c_str(), mesh.triangle_count(),
        a.map, a.map, a.components, a.clusters, a.azimuth, a.elevation, a.width, a.height,
        a.frames);

    render::SlfRenderer renderer(model, &probe);
    const Row floor_bg = time_floor(mesh, camera, a.frames, &probe);
    const Row floor = time_floor(mesh, camera, a.frames, nullptr);
    render::Background with_probe;
    render::Background solid;
    solid.use_probe = false;
    renderer.set_background(with_probe);
    const Row slf_bg = time_slf(renderer, camera, a.frames);
    renderer.set_background(solid);
    const Row slf = time_slf(renderer, camera, a.frames);
    renderer.set_options({true, false, false});
    const Row slf_four = time_slf(renderer, camera, a.frames);
    renderer.set_options({true, true, true});
    const Row slf_deferred = time_slf(renderer, camera, a.frames);
    renderer.set_background(with_probe);
    const Row slf_deferred_bg = time_slf(renderer, camera, a.frames);
    renderer.set_options({true, true, false});
    // The floor again at the end: a shared machine's load drifts during a run.
    const Row floor_bg_late = time_floor(mesh, camera, a.frames, &probe);

    auto print = [](const char* name, const Row& r, const Row& base) {
      std::printf("  %-44s %8.2f ms = %5.2f x floor   CPU %8.2f ms = %5.2f x floor\n", name,
                  r.frame_ms, r.frame_ms / base.frame_ms, r.cpu_ms, r.cpu_ms / base.cpu_ms);
    };
    std::printf("\nwith the probe background (floor: background pass + trivial mesh):\n");
    print("floor + background", floor_bg, floor_bg);
    print("floor + background (again, at the end)", floor_bg_late, floor_bg);
    print("SLF one pass + background", slf_bg, floor_bg);
    print("SLF deferred (uv pre-pass) + background", slf_deferred_bg, floor_bg);
    std::printf("\nsolid background (floor: clear + trivial mesh):\n");
    print("floor", floor, floor);
    print("SLF one pass", slf, floor);
    print("SLF one pass, four texels everywhere", slf_four, floor);
    print("SLF deferred (uv pre-pass)", slf_deferred, floor);
    std::printf(
        "\ntarget: SLF + background <= 2 x floor + background: one pass %.2f (%s), "
        "deferred %.2f (%s)\n",
        slf_bg.frame_ms / floor_bg.frame_ms,
        slf_bg.frame_ms <= 2 * floor_bg.frame_ms ? "met" : "not met",
        slf_deferred_bg.frame_ms / floor_bg.frame_ms,
        slf_deferred_bg.frame_ms <= 2 * floor_bg.frame_ms ? "met" : "not met");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "slf_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
