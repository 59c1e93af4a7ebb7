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
  const prt::RayScene scene(mesh);
  const prt::DirectionSet set = prt::hemisphere_directions(samples, 1);
  const Eigen::Matrix3Xf local = set.directions.cast<float>();
  const float offset = float(1e-4 * meshes::bounds(mesh).diagonal());

  // Bare occlusion: the same rays, nothing else.
  std::atomic<std::uint64_t> occluded_total{0};
  double t0 = now_seconds();
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
  const double bare = now_seconds() - t0;
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
  std::printf("occluded fraction %.3f\n", double(occluded_total) / rays);
  return 0;
}
