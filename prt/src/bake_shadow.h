// prt/src/bake_shadow.h (private to prt): the shadow pass (thesis ch. 3.1.1, eq. 1-2;
// Sloan, Kautz & Snyder 2002, section 5): per vertex, the transfer of the directions its rays
// escape along, and the front hits of the occluded ones for the bounces.
#pragma once

#include "bake_context.h"
#include "bake_engine.h"
#include "prt/sh_rotation.h"

#include <tbb/enumerable_thread_specific.h>

#include <cstdint>
#include <vector>

namespace prt::detail {

// Per-thread scratch of the shadow pass, allocated once per thread and reused for every vertex.
struct ShadowScratch {
  ShadowScratch(int order, int n, int samples) : rotation(order, Eigen::Matrix3d::Identity()) {
    world.resize(3, samples);
    occluded.resize(samples);
    occluded_index.resize(samples);
    y_occluded.resize(n, samples);
    transfer.resize(n, n);
    scratch.resize(n, n);
    diffuse_local.resize(n);
    diffuse_world.resize(n);
    for (int l = 0; l < order; ++l) bands.emplace_back(2 * l + 1, 2 * l + 1);
    occluded_world.resize(3, samples);
    origins.resize(3, samples);
    occluded_origins.resize(3, samples);
    hits.resize(samples);
  }
  Eigen::Matrix3Xf world;
  std::vector<std::uint8_t> occluded;
  std::vector<int> occluded_index;
  MatF y_occluded, transfer, scratch;
  Eigen::VectorXf diffuse_local;
  Eigen::VectorXd diffuse_world;
  ShRotation rotation;  // D of the current vertex's frame, rebuilt in place
  std::vector<MatF> bands;
  Eigen::Matrix3Xf occluded_world;
  Eigen::Matrix3Xf origins, occluded_origins;  // per ray, for world and occluded_world
  std::vector<RayHit> hits;
  std::uint64_t rays_shadow = 0, rays_bounce = 0, occluded_count = 0;
};
using ShadowPool = tbb::enumerable_thread_specific<ShadowScratch>;

// Per-vertex outcome of the shadow pass.
enum VertexFlag : std::uint8_t { kNearly = 1, kMoved = 2 };

// Direct light: the shadow-pass transfer of `vertices` into dst (row i for vertices[i]),
// and (with bounces) the front hits each vertex's occluded rays find, per kChunk of them. flags[p]
// has kNearly where p sees less than kNearlyOccluded of its rays escape, and kMoved where its
// origin was moved out of the body.
void shadow_range(const BakeContext& ctx, ShadowPool& pool, VertexList vertices, float* dst,
                  std::vector<HitBlock>* hit_blocks, std::vector<std::uint8_t>& flags,
                  ProgressReporter& progress);

}  // namespace prt::detail
