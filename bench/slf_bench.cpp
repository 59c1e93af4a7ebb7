// slf_bench [--mesh M] [--frames F] [--rounds R] [--width W] [--height H] [--charts
// conformal|per-triangle]
// [--map X] [--components k] [--clusters eta] [--azimuth Z] [--elevation W]
// [--gl osmesa|egl] [--gl-device N]: the surface light field renderer
// (render/slf_renderer.h) against the trivial-shader floor (render/floor_harness.h) on the
// same mesh, camera and framebuffer, in one run so the ratio is fair. Defaults: the Stanford
// bunny at 1280 x 948, k = 8, eta = 256, Z x W = 32 x 16 (the SLF paper's specular setting,
// with its direction grid), the 256 x 256 conformal atlas `prtr slf` makes by default. The
// model is synthetic (the bake's output is not needed to time the reconstruction): clusters
// in spatially coherent patches (the bunny's directions from its centre on a 16 x 16
// lat-long grid, so most fragments see four texels of one cluster and the patch borders see
// several, as after CPCA), random weights and view maps. `--charts per-triangle` makes a
// chart per triangle instead (`--map 1024` holds the bunny's). Rows: each shading
// (one pass, deferred, texture space, and the automatic choice) with the probe background
// (against the floor with the same background pass) and without; the shared-cluster fast
// path on and off; wall clock and process CPU per frame (the load of a shared machine
// inflates the first far more). Every row is timed once a round, between the floors of
// that round, over R rounds (default 5); a ratio is the median over rounds of the row's
// time over its round's floor, so a drift of the machine's speed does not enter it.
#include "bench_probe.h"
#include "meshes/atlas.h"
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
  meshes::AtlasCharts charts = meshes::AtlasCharts::kConformal;
  int frames = 10, rounds = 5, width = 1280, height = 948, map = 256;
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
    } else if (flag == "--rounds") {
      a.rounds = parse_int(flag, value, 1, 1000);
    } else if (flag == "--width") {
      a.width = parse_int(flag, value, 1, 16384);
    } else if (flag == "--height") {
      a.height = parse_int(flag, value, 1, 16384);
    } else if (flag == "--charts") {
      try {
        a.charts = meshes::kAtlasChartsNames.parse(value);
      } catch (const std::invalid_argument& e) {
        throw UsageError("--charts: " + std::string(e.what()));
      }
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

// Clusters in patches by direction from the mesh's centre; random weights and view maps.
struct Synthetic {
  const Args& a;
  Eigen::Vector3f centre;
  int side;
  std::mt19937 rng{1};
  std::uniform_real_distribution<float> weight{-0.5f, 0.5f};

  Synthetic(const meshes::Mesh& mesh, const Args& args)
      : a(args),
        centre(meshes::bounds(mesh).center()),
        side(std::max(1, int(std::round(std::sqrt(double(args.clusters)))))) {}

  int cluster_of(const Eigen::Vector3f& p) const {
    const Eigen::Vector3f d = (p - centre).normalized();
    const double u = (std::atan2(d.x(), d.z()) / std::numbers::pi + 1.0) * 0.5;
    const double v = std::acos(std::clamp(double(d.y()), -1.0, 1.0)) / std::numbers::pi;
    const int i = std::min(side - 1, int(u * side)), j = std::min(side - 1, int(v * side));
    return (j * side + i) % a.clusters;
  }
  // Texel `texel` samples point p.
  void use_texel(render::SlfModel& m, std::size_t texel, const Eigen::Vector3f& p) {
    m.texel_cluster[texel] = cluster_of(p);
    m.texel_positions[texel] = p;
    for (int j = 0; j < a.components; ++j)
      m.texel_weights[texel * std::size_t(a.components) + std::size_t(j)] = weight(rng);
  }
};

render::SlfModel empty_model(const meshes::Mesh& mesh, const Args& a) {
  render::SlfModel m;
  m.map_width = m.map_height = a.map;
  m.grid = {a.azimuth, a.elevation};
  m.components = a.components;
  m.clusters = a.clusters;
  const std::size_t texels = std::size_t(a.map) * std::size_t(a.map);
  m.texel_cluster.assign(texels, -1);
  m.texel_weights.assign(texels * std::size_t(a.components), 0.f);
  m.texel_positions.assign(texels, Eigen::Vector3f::Zero());
  for (const auto& tri : mesh.triangles) {
    const Eigen::Vector3f p0 = mesh.positions[tri[0]], p1 = mesh.positions[tri[1]],
                          p2 = mesh.positions[tri[2]];
    const Eigen::Vector3f normal = (p1 - p0).cross(p2 - p0).normalized();
    for (const Eigen::Vector3f& p : {p0, p1, p2}) {
      m.positions.push_back(p);
      m.normals.push_back(normal);
    }
  }
  return m;
}

// A chart per triangle: an n x n cell of the map, the triangle's corners at texels (1, 1),
// (n - 1, 1) and (1, n - 1) of it, so a lookup inside reads only its own cell's texels.
// Each texel of a used cell samples the surface point its position in the cell
// extrapolates to; unused cells are -1.
void per_triangle_charts(render::SlfModel& m, const meshes::Mesh& mesh, Synthetic& synthetic) {
  const Args& a = synthetic.a;
  const int triangles = int(mesh.triangle_count());
  const int n = std::max(3, int(std::floor(a.map / std::ceil(std::sqrt(double(triangles))))));
  const int per_row = a.map / n;
  if (per_row * per_row < triangles)
    throw UsageError("--map " + std::to_string(a.map) + " is too small for " +
                     std::to_string(triangles) + " triangles");
  const float scale = 1.f / float(a.map);
  for (int t = 0; t < triangles; ++t) {
    const int cx = (t % per_row) * n, cy = (t / per_row) * n;
    const Eigen::Vector2f c0(float(cx + 1), float(cy + 1)), c1(float(cx + n - 1), float(cy + 1)),
        c2(float(cx + 1), float(cy + n - 1));
    for (const Eigen::Vector2f& c : {c0, c1, c2}) m.uv.push_back(c * scale);
    const Eigen::Vector3f p0 = m.positions[3 * std::size_t(t)],
                          p1 = m.positions[3 * std::size_t(t) + 1],
                          p2 = m.positions[3 * std::size_t(t) + 2];
    for (int y = cy; y < cy + n; ++y)
      for (int x = cx; x < cx + n; ++x) {
        const float u = (float(x) + 0.5f - c0.x()) / float(n - 2);
        const float v = (float(y) + 0.5f - c0.y()) / float(n - 2);
        synthetic.use_texel(m, std::size_t(y) * std::size_t(a.map) + std::size_t(x),
                            (1 - u - v) * p0 + u * p1 + v * p2);
      }
  }
}

render::SlfModel synthetic_model(const meshes::Mesh& mesh, const Args& a) {
  render::SlfModel m = empty_model(mesh, a);
  Synthetic synthetic(mesh, a);
  if (a.charts == meshes::AtlasCharts::kPerTriangle) {
    per_triangle_charts(m, mesh, synthetic);
  } else {
    const meshes::Atlas atlas = meshes::make_atlas(mesh, a.map, a.map, {a.charts});
    m.uv = atlas.uv;
    const std::vector<Eigen::Vector3f> points = meshes::texel_points(mesh, atlas);
    for (std::size_t texel = 0; texel < points.size(); ++texel)
      if (atlas.texel_triangle[texel] >= 0) synthetic.use_texel(m, texel, points[texel]);
  }
  std::uniform_real_distribution<float> view(0.f, 1.f);
  m.view_maps.resize(std::size_t(a.clusters) * std::size_t(a.components + 1) * m.slice_floats());
  for (float& value : m.view_maps) value = view(synthetic.rng);
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
        "%d x %d, median of %d frames, %d rounds\n",
        context.description().c_str(), context.info().renderer.c_str(), mesh.triangle_count(),
        a.map, a.map, a.components, a.clusters, a.azimuth, a.elevation, a.width, a.height, a.frames,
        a.rounds);

    render::SlfRenderer renderer(model, &probe);
    render::Background with_probe;
    render::Background solid;
    solid.use_probe = false;
    using render::SlfShading;
    struct Timed {
      std::string name;
      SlfShading shading;
      bool shared;
      bool background;
      std::vector<Row> rounds{};
    };
    std::vector<Timed> rows;
    for (bool background : {true, false}) {
      rows.push_back({"one pass", SlfShading::kOnePass, true, background});
      rows.push_back({"deferred (uv pre-pass)", SlfShading::kDeferred, true, background});
      rows.push_back({"texture space", SlfShading::kTextureSpace, true, background});
      rows.push_back({"automatic", SlfShading::kAutomatic, true, background});
    }
    rows.push_back({"one pass, four texels everywhere", SlfShading::kOnePass, false, false});
    std::vector<Row> floors_bg, floors;
    SlfShading chosen = SlfShading::kAutomatic;
    long long texels_shaded = 0;
    for (int round = 0; round < a.rounds; ++round) {
      floors_bg.push_back(time_floor(mesh, camera, a.frames, &probe));
      floors.push_back(time_floor(mesh, camera, a.frames, nullptr));
      for (Timed& row : rows) {
        renderer.set_options({true, row.shared, row.shading});
        renderer.set_background(row.background ? with_probe : solid);
        row.rounds.push_back(time_slf(renderer, camera, a.frames));
        if (row.shading == SlfShading::kAutomatic) chosen = renderer.shading();
        if (row.shading == SlfShading::kTextureSpace) texels_shaded = renderer.texels_shaded();
      }
    }

    // Medians over rounds: of the times, and of each round's ratio to its own floor.
    auto print = [&](const std::string& name, const std::vector<Row>& r,
                     const std::vector<Row>& base) {
      std::vector<double> wall, cpu, wall_ratio, cpu_ratio;
      for (std::size_t i = 0; i < r.size(); ++i) {
        wall.push_back(r[i].frame_ms);
        cpu.push_back(r[i].cpu_ms);
        wall_ratio.push_back(r[i].frame_ms / base[i].frame_ms);
        cpu_ratio.push_back(r[i].cpu_ms / base[i].cpu_ms);
      }
      std::printf("  %-44s %8.2f ms = %5.2f x floor   CPU %8.2f ms = %5.2f x floor\n", name.c_str(),
                  median(wall), median(wall_ratio), median(cpu), median(cpu_ratio));
      return median(wall_ratio);
    };
    std::printf("\nwith the probe background (floor: background pass + trivial mesh):\n");
    print("floor + background", floors_bg, floors_bg);
    double automatic = 0;
    for (const Timed& row : rows)
      if (row.background) {
        const double ratio = print("SLF " + row.name + " + background", row.rounds, floors_bg);
        if (row.shading == SlfShading::kAutomatic) automatic = ratio;
      }
    std::printf("\nsolid background (floor: clear + trivial mesh):\n");
    print("floor", floors, floors);
    for (const Timed& row : rows)
      if (!row.background) print("SLF " + row.name, row.rounds, floors);
    std::printf(
        "\ntexture space shades %lld texels a frame (%.0f%% of the %lld in blocks that "
        "triangles read)\n",
        texels_shaded, 100.0 * double(texels_shaded) / double(renderer.texels_in_blocks()),
        renderer.texels_in_blocks());
    std::printf("\ntarget: SLF + background <= 2 x floor + background: automatic (%s) %.2f (%s)\n",
                render::kSlfShadingNames.name(chosen), automatic,
                automatic <= 2 ? "met" : "not met");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "slf_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
