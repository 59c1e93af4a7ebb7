// slf_noise_bench [--mesh M] [--probe P] [--rows R] [--spp S] [--truth-spp T] [--seeds N]
// [--light-samples L,...] [--bounces B] [--samples WxH] [--directions ZxW] [--roughness m]
// [--time-rows Q]: how noisy the surface light field's bake (prt/slf_bake.h) is for the time
// it takes, per estimator. R rows, in eight runs spread over the atlas, are baked once at T
// paths a cell (the truth, with the first light-sample setting) and N times (seeds 2..N+1)
// at S paths a cell with each setting; a row of the table gives the relative RMS difference
// from the truth over those entries (sqrt(sum (b - t)^2 / sum t^2)) with the truth's own
// noise taken out (its estimator's variance at T paths, from the S-path runs), the seconds a
// bake of 1,000 rows takes (timed on Q rows in one range, so the ray scene is built once as
// in a whole bake), and the efficiency 1 / (noise^2 x seconds), which compares estimators of
// different costs, over all entries and over the cells in front of their texel (their
// centre at least 0.25 above the shading plane in cosine), which make nearly every pixel of
// an image. The noise of the front, grazing and behind cells follows, each with its share
// of the squared noise. Defaults: the Stanford bunny, the forest probe, Cook-Torrance m 0.1
// (specular 0.5, albedo 0.3), 256 x 256 conformal atlas, 32 x 16 directions, 1 bounce, R 256,
// S 16, T 1024, N 2, Q 2048, light samples 0 (the paths' own) and 16.
#include "meshes/atlas.h"
#include "meshes/load.h"
#include "probes/load.h"
#include "prt/path_tracer.h"
#include "prt/slf_bake.h"

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace {

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct Args {
  std::string mesh = "/usr/share/glmark2/models/bunny.obj";
  std::string probe = "/usr/share/blender/datafiles/studiolights/world/forest.exr";
  int rows = 256, spp = 16, truth_spp = 1024, seeds = 2, bounces = 1, time_rows = 2048;
  int atlas_width = 256, atlas_height = 256, azimuth = 32, elevation = 16;
  float roughness = 0.1f;
  std::vector<int> light_samples{0, 16};
};

void parse_pair(const std::string& flag, const std::string& text, int& a, int& b) {
  if (std::sscanf(text.c_str(), "%dx%d", &a, &b) != 2 || a < 1 || b < 1)
    throw UsageError(flag + " wants WxH, got '" + text + "'");
}

Args parse(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string flag = argv[i];
    if (i + 1 >= argc) throw UsageError(flag + " needs a value (or is unknown)");
    const std::string value = argv[++i];
    const auto number = [&](int lo, int hi) {
      char* end = nullptr;
      const long v = std::strtol(value.c_str(), &end, 10);
      if (*end != '\0' || v < lo || v > hi)
        throw UsageError(flag + " must be an integer in [" + std::to_string(lo) + ", " +
                         std::to_string(hi) + "], got '" + value + "'");
      return int(v);
    };
    if (flag == "--mesh")
      a.mesh = value;
    else if (flag == "--probe")
      a.probe = value;
    else if (flag == "--rows")
      a.rows = number(8, 1 << 20);
    else if (flag == "--time-rows")
      a.time_rows = number(1, 1 << 24);
    else if (flag == "--spp")
      a.spp = number(1, 65536);
    else if (flag == "--truth-spp")
      a.truth_spp = number(1, 65536);
    else if (flag == "--seeds")
      a.seeds = number(1, 64);
    else if (flag == "--bounces")
      a.bounces = number(0, 16);
    else if (flag == "--samples")
      parse_pair(flag, value, a.atlas_width, a.atlas_height);
    else if (flag == "--directions")
      parse_pair(flag, value, a.azimuth, a.elevation);
    else if (flag == "--roughness") {
      a.roughness = std::strtof(value.c_str(), nullptr);
      if (!(a.roughness > 0.f && a.roughness <= 1.f)) throw UsageError("--roughness: (0, 1]");
    } else if (flag == "--light-samples") {
      a.light_samples.clear();
      std::stringstream list(value);
      for (std::string item; std::getline(list, item, ',');) {
        char* end = nullptr;
        const long v = std::strtol(item.c_str(), &end, 10);
        if (*end != '\0' || v < 0 || v > 4096)
          throw UsageError("--light-samples wants integers in [0, 4096], got '" + item + "'");
        a.light_samples.push_back(int(v));
      }
    } else {
      throw UsageError("unknown flag " + flag);
    }
  }
  return a;
}

struct Bake {
  std::vector<float> values;
  double seconds = 0;
};

// Where each entry's cell looks from its texel: 0 in front (the cell centre at least 0.25
// above the shading plane in cosine), 1 grazing, 2 behind (below -0.25).
constexpr int kViewClasses = 3;
constexpr const char* kViewClassNames[kViewClasses] = {"front", "grazing", "behind"};

// The rows measured: eight evenly spaced ranges [first, end) of rows / 8 each.
std::vector<std::pair<std::uint64_t, std::uint64_t>> bench_ranges(const meshes::Atlas& atlas,
                                                                  int rows) {
  const std::uint64_t total = atlas.used_texels(), run = std::uint64_t(rows / 8);
  std::vector<std::pair<std::uint64_t, std::uint64_t>> out;
  for (int r = 0; r < 8; ++r) {
    const std::uint64_t first = total * std::uint64_t(2 * r + 1) / 16;
    out.emplace_back(first, std::min(total, first + run));
  }
  return out;
}

std::vector<std::uint8_t> view_classes(const meshes::Mesh& mesh, const meshes::Atlas& atlas,
                                       const probes::Probe& probe, const prt::SlfBakeOptions& o,
                                       int rows) {
  const prt::PathTracer tracer(mesh, probe, o.material);
  const std::vector<std::uint32_t> texels = prt::slf_rows(atlas);
  std::vector<std::uint8_t> out;
  for (const auto& [first, end] : bench_ranges(atlas, rows))
    for (std::uint64_t row = first; row < end; ++row) {
      const std::uint32_t t = texels[row];
      const prt::SurfacePoint p = tracer.surface_point(
          atlas.texel_triangle[t], atlas.texel_barycentric[t].x(), atlas.texel_barycentric[t].y());
      for (int c = 0; c < o.grid.directions(); ++c) {
        const double z = p.frame.col(2).dot(prt::slf_grid_direction(o.grid, c));
        const std::uint8_t k = z >= 0.25 ? 0 : z >= -0.25 ? 1 : 2;
        out.insert(out.end(), 3, k);
      }
    }
  return out;
}

// Seconds per 1,000 rows: one range of `rows` rows from the middle of the atlas, so the
// tracer's scene is built once, as in a whole bake (the noise rows' eight ranges build it
// eight times, which on the bunny costs more than baking them).
double seconds_per_1000_rows(const meshes::Mesh& mesh, const meshes::Atlas& atlas,
                             const probes::Probe& probe, prt::SlfBakeOptions o, int rows) {
  const std::uint64_t total = atlas.used_texels();
  o.first_row = total / 2 - std::min<std::uint64_t>(total / 2, std::uint64_t(rows) / 2);
  o.end_row = std::min(total, o.first_row + std::uint64_t(rows));
  const auto start = std::chrono::steady_clock::now();
  prt::bake_slf(mesh, atlas, probe, o);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return 1000.0 * s / double(o.end_row - o.first_row);
}

// The bench_ranges rows, baked.
Bake bake_runs(const meshes::Mesh& mesh, const meshes::Atlas& atlas, const probes::Probe& probe,
               prt::SlfBakeOptions o, int rows) {
  Bake b;
  const auto start = std::chrono::steady_clock::now();
  for (const auto& [first, end] : bench_ranges(atlas, rows)) {
    o.first_row = first;
    o.end_row = end;
    const prt::SlfMatrix m = prt::bake_slf(mesh, atlas, probe, o);
    b.values.insert(b.values.end(), m.data.begin(), m.data.end());
  }
  b.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return b;
}

// Per view class, then the whole.
std::array<double, kViewClasses + 1> squared_difference(const std::vector<float>& a,
                                                        const std::vector<float>& b,
                                                        const std::vector<std::uint8_t>& cls) {
  std::array<double, kViewClasses + 1> s{};
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double d = (double(a[i]) - b[i]) * (double(a[i]) - b[i]);
    s[cls[i]] += d;
    s[kViewClasses] += d;
  }
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  Args args;
  try {
    args = parse(argc, argv);
  } catch (const UsageError& e) {
    std::fprintf(stderr, "slf_noise_bench: %s\n", e.what());
    return 2;
  }
  try {
    const meshes::Mesh mesh = meshes::load_mesh(args.mesh);
    const probes::Probe probe = probes::load_probe(args.probe);
    const meshes::Atlas atlas = meshes::make_atlas(mesh, args.atlas_width, args.atlas_height);
    prt::SlfBakeOptions o;
    o.grid.azimuth = args.azimuth;
    o.grid.elevation = args.elevation;
    o.bounces = args.bounces;
    o.material.kind = prt::MaterialKind::kCookTorrance;
    o.material.roughness = args.roughness;
    o.material.specular = 0.5f;
    o.material.albedo = Eigen::Vector3f::Constant(0.3f);
    std::printf(
        "%s, %s: %d rows of %llu, %d x %d directions, %d bounce(s), CT m %.2f; truth %d "
        "paths a cell, bakes %d, %d seed(s)\n",
        args.mesh.c_str(), args.probe.c_str(), args.rows / 8 * 8,
        static_cast<unsigned long long>(atlas.used_texels()), args.azimuth, args.elevation,
        args.bounces, double(args.roughness), args.truth_spp, args.spp, args.seeds);
    o.spp = args.truth_spp;
    o.seed = 1;
    o.light_samples = args.light_samples.front();
    const Bake truth = bake_runs(mesh, atlas, probe, o, args.rows);
    const std::vector<std::uint8_t> cls = view_classes(mesh, atlas, probe, o, args.rows);
    const std::vector<float> zeros(truth.values.size(), 0.f);
    const auto truth_energy = squared_difference(truth.values, zeros, cls);
    std::printf(
        "truth: %.1f s (light samples %d); its energy front %.2f, grazing %.2f, "
        "behind %.2f\n",
        truth.seconds, o.light_samples, truth_energy[0] / truth_energy[kViewClasses],
        truth_energy[1] / truth_energy[kViewClasses], truth_energy[2] / truth_energy[kViewClasses]);
    std::printf(
        "| light samples | relative RMS noise | seconds / 1000 rows | efficiency 1 / (noise^2 s) "
        "| front's efficiency |");
    for (const char* name : kViewClassNames) std::printf(" %s: noise, share |", name);
    std::printf("\n| ---: | ---: | ---: | ---: | ---: |");
    for (int c = 0; c < kViewClasses; ++c) std::printf(" ---: |");
    std::printf("\n");
    std::array<double, kViewClasses + 1> truth_variance{};  // the truth's, summed over entries
    for (std::size_t e = 0; e < args.light_samples.size(); ++e) {
      o.light_samples = args.light_samples[e];
      o.spp = args.spp;
      std::vector<Bake> bakes;
      for (int s = 0; s < args.seeds; ++s) {
        o.seed = std::uint64_t(2 + s);
        bakes.push_back(bake_runs(mesh, atlas, probe, o, args.rows));
      }
      std::array<double, kViewClasses + 1> against{};
      for (const Bake& b : bakes) {
        const auto d = squared_difference(b.values, truth.values, cls);
        for (int c = 0; c <= kViewClasses; ++c) against[c] += d[c] / args.seeds;
      }
      const double seconds = seconds_per_1000_rows(mesh, atlas, probe, o, args.time_rows);
      // The truth's estimator is the first setting: its S-path variance, scaled to T paths.
      if (e == 0) {
        int pairs = 0;
        std::array<double, kViewClasses + 1> between{};
        for (int a = 0; a < args.seeds; ++a)
          for (int b = a + 1; b < args.seeds; ++b, ++pairs) {
            const auto d = squared_difference(bakes[a].values, bakes[b].values, cls);
            for (int c = 0; c <= kViewClasses; ++c) between[c] += d[c] / 2;
          }
        for (int c = 0; c <= kViewClasses; ++c)
          truth_variance[c] =
              (pairs > 0 ? between[c] / pairs : against[c]) * args.spp / args.truth_spp;
      }
      std::array<double, kViewClasses + 1> noise2{};
      for (int c = 0; c <= kViewClasses; ++c)
        noise2[c] = std::max(0.0, against[c] - truth_variance[c]);
      const double noise = std::sqrt(noise2[kViewClasses] / truth_energy[kViewClasses]);
      const double front2 = noise2[0] / truth_energy[0];
      std::printf("| %d | %.2f %% | %.2f | %.3g | %.3g |", o.light_samples, 100 * noise, seconds,
                  1.0 / (noise * noise * seconds), 1.0 / (front2 * seconds));
      for (int c = 0; c < kViewClasses; ++c)
        std::printf(" %.1f %%, %.2f |", 100 * std::sqrt(noise2[c] / truth_energy[c]),
                    noise2[c] / noise2[kViewClasses]);
      std::printf("\n");
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "slf_noise_bench: %s\n", e.what());
    return 1;
  }
}
