// Bake throughput against the machine's limit: the bare Embree occlusion queries for
// exactly the rays the shadow pass traces (same mesh, frames, direction set, offsets), in
// the same run. Usage: bake_bench [MESH] [SAMPLES] [THREADS]
#include "meshes/load.h"
#include "prt/bake.h"
#include "prt/ray_scene.h"
#include "prt/sampling.h"

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

namespace {

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Bare occlusion: the bake's shadow rays and nothing else; the seconds taken, and the
// occluded ray count in `occluded`.
double bare_occlusion_seconds(const meshes::Mesh& mesh, int samples, std::uint64_t& occluded) {
  const prt::RayScene scene(mesh);
  const prt::DirectionSet set = prt::hemisphere_directions(samples, 1);
  const Eigen::Matrix3Xf local = set.directions.cast<float>();
  const float offset = float(1e-4 * meshes::bounds(mesh).diagonal());
  std::atomic<std::uint64_t> occluded_total{0};
  const double t0 = now_seconds();
  tbb::parallel_for(std::size_t(0), mesh.vertex_count(), [&](std::size_t p) {
    thread_local Eigen::Matrix3Xf world;
    thread_local std::vector<std::uint8_t> occ;
    world.resize(3, samples);
    occ.resize(samples);
    Eigen::Matrix3f f;
    f << mesh.tangents[p], mesh.bitangents[p], mesh.normals[p];
    world.noalias() = f * local;
    scene.occluded(mesh.positions[p] + offset * mesh.normals[p], world, 0.f, occ.data());
    std::uint64_t k = 0;
    for (std::uint8_t o : occ) k += o;
    occluded_total += k;
  });
  occluded = occluded_total;
  return now_seconds() - t0;
}

// The GEMM rate on this machine: w Y Y^T for one vertex's samples, as the textbook
// projection would do it for its visible samples (n = 36, one thread), against the baker's
// shadow-pass work besides the rays, per visible sample.
void print_gemm_comparison(const meshes::Mesh& mesh, int samples, double bare, double rays,
                           double occluded_fraction) {
  const Eigen::MatrixXf y = Eigen::MatrixXf::Random(36, samples);
  Eigen::MatrixXf t(36, 36);
  const int reps = 2000;
  const double g0 = now_seconds();
  for (int r = 0; r < reps; ++r) t.noalias() = y * y.transpose();
  const double gemm = (now_seconds() - g0) / reps;
  const double per_sample_gemm = gemm / samples;
  const double flops = 2.0 * 36 * 36 * samples / gemm;
  prt::BakeOptions o;
  o.samples = samples;
  o.bounces = 0;
  prt::BakeStats stats;
  prt::bake(mesh, o, &stats);
  const double non_ray = std::max(0.0, stats.seconds_shadow - bare);
  const double visible = rays * (1.0 - occluded_fraction);
  std::printf("GEMM Y Y^T (36 x %d): %.1f GFLOP/s, %.1f ns per sample\n", samples, flops / 1e9,
              per_sample_gemm * 1e9);
  std::printf(
      "shadow pass besides rays: %.2f s, %.1f ns per visible sample "
      "(%.2fx the GEMM cost per sample)\n",
      non_ray, non_ray / visible * 1e9, (non_ray / visible) / per_sample_gemm);
}

}  // namespace

int main(int argc, char** argv) {
  const std::string path = argc > 1 ? argv[1] : "/usr/share/glmark2/models/bunny.obj";
  const int samples = argc > 2 ? std::atoi(argv[2]) : 1024;
  const int threads = argc > 3 ? std::atoi(argv[3]) : 0;  // 0: all cores
  std::unique_ptr<tbb::global_control> limit;
  if (threads > 0) {
    limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                  threads);
  }
  const meshes::Mesh mesh = meshes::load_mesh(path);
  std::uint64_t occluded = 0;
  const double bare = bare_occlusion_seconds(mesh, samples, occluded);
  const double rays = double(mesh.vertex_count()) * samples;

  for (int bounces : {0, 1}) {
    prt::BakeOptions o;
    o.samples = samples;
    o.bounces = bounces;
    prt::BakeStats stats;
    prt::bake(mesh, o, &stats);
    std::printf("glossy order 6, %d bounce(s): total %.2f s (shadow %.2f s, bounces %.2f s)\n",
                bounces, stats.seconds_total, stats.seconds_shadow, stats.seconds_bounces);
    if (bounces == 0) {
      std::printf(
          "bare occlusion: %.2f s, %.1f M rays/s; shadow pass: %.1f M rays/s; "
          "ratio %.2f\n",
          bare, rays / bare / 1e6, rays / stats.seconds_shadow / 1e6, bare / stats.seconds_shadow);
    }
  }
  const double occluded_fraction = double(occluded) / rays;
  std::printf("occluded fraction %.3f\n", occluded_fraction);
  print_gemm_comparison(mesh, samples, bare, rays, occluded_fraction);
  return 0;
}
