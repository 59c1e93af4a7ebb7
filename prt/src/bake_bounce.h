// prt/src/bake_bounce.h (private to prt): the interreflection passes (thesis ch. 3.1.1,
// eq. 3; Sloan, Kautz & Snyder 2002, section 5): bounce b's transfer of a vertex is the light
// its shadow pass's front hits send back, interpolated from bounce b - 1's transfer at the hit
// triangles' corners.
#pragma once

#include "bake_context.h"
#include "bake_engine.h"
#include "prt/sh.h"

#include <tbb/enumerable_thread_specific.h>

#include <cstdint>
#include <vector>

namespace prt::detail {

// Per-thread scratch of the interreflection passes.
struct BounceScratch {
  BounceScratch(int n, int samples) {
    corner_dirs.resize(3, 3 * samples);
    y_hit.resize(n, samples);
    rows.resize(samples, n);
    transfer.resize(n, n);
  }
  Eigen::Matrix3Xf corner_dirs;
  ShBatchF corner_batch;
  MatF corner_y;
  MatF y_hit, transfer;
  RowMatF rows;  // row h is updated per hit: keep it contiguous
};
using BouncePool = tbb::enumerable_thread_specific<BounceScratch>;

// A vertex's frame, stored with its row of the previous pass: a hit's corners are read
// together with their transfer.
struct CornerFrame {
  Eigen::Vector3f tangent, bitangent, normal;
};

// The previous bounce's transfer of the vertices a bounce reads, with its layout.
struct BounceSource {
  const float* previous;        // M^{b-1}: the whole pass, or the rows gathered (slot_of)
  const std::uint32_t* row_of;  // vertex q is row row_of[q] of the pass; null: row q
  const CornerFrame* frames;    // by row of the pass
  std::size_t per_vertex, per_channel;
  const std::uint32_t* slot_of = nullptr;  // vertex q is row slot_of[q] of previous
  std::size_t row_index(std::uint32_t q) const { return row_of ? row_of[q] : q; }
  const float* row(std::uint32_t q) const {
    return previous + (slot_of ? slot_of[q] : row_index(q)) * per_vertex;
  }
};

// One interreflection pass over the vertices [first, last) of `vertices`: their bounce-b
// transfer, into dst (row i for vertices[i]), from bounce b - 1's of the vertices their hits
// reach (src). Work is split at chunk boundaries.
void bounce_range(const BakeContext& ctx, BouncePool& pool, const std::vector<HitBlock>& hit_blocks,
                  const BounceSource& src, VertexList vertices, std::uint64_t first,
                  std::uint64_t last, float* dst, ProgressReporter& progress);

}  // namespace prt::detail
