// cpca/supercluster.h: grouping clusters into super-clusters, one per render pass, and the
// triangle overdraw that a grouping causes (thesis ch. 4.1, eq. 8; docs/ARCHITECTURE.md
// "Rendering", multipass).
//
// A pass holds the constants of its clusters within a register budget (vec4 count). A
// triangle is drawn in every pass that holds the cluster of at least one of its vertices,
// so its draw count is the number of distinct passes among its vertices' clusters (1..3).
// Average triangle overdraw = sum over triangles of that count / triangle count.
#pragma once

#include "cpca/geometry.h"

#include <cstdint>
#include <vector>

namespace cpca {

struct SuperClusters {
  std::vector<std::vector<std::uint32_t>> passes;  // cluster ids of each pass
  // pass_of[k]: the pass holding cluster k. Filled by the strategies; see pass_of_clusters().
  std::vector<std::uint32_t> pass_of;
};

// pass_of from passes; throws std::invalid_argument unless every cluster < cluster_count
// is in exactly one pass.
std::vector<std::uint32_t> pass_of_clusters(const SuperClusters& groups, int cluster_count);

// Baseline strategy: fill passes in cluster order, `per_pass` clusters each.
SuperClusters group_in_order(int cluster_count, int per_pass);

struct OverdrawStats {
  std::vector<std::uint64_t> triangles_per_pass;  // triangles each pass draws
  std::uint64_t triangles_drawn = 0;              // sum over passes
  std::uint64_t triangle_count = 0;
  double average_overdraw = 0.0;  // triangles_drawn / triangle_count (1 when nothing is drawn)
};

// Exact overdraw of a grouping: cluster_of per vertex, the mesh's triangles.
OverdrawStats overdraw(const std::vector<std::uint32_t>& cluster_of,
                       const std::vector<TriangleIndices>& triangles, const SuperClusters& groups);

// Per pass, the triangles it draws (indices into `triangles`, ascending): the index buffers
// a multi-pass renderer builds once.
std::vector<std::vector<std::uint32_t>> triangles_per_pass(
    const std::vector<std::uint32_t>& cluster_of, const std::vector<TriangleIndices>& triangles,
    const SuperClusters& groups);

// Per triangle, how many passes draw it (1..3): the overdraw picture's colour index. Its sum
// is overdraw(...).triangles_drawn.
std::vector<std::uint8_t> triangle_pass_counts(const std::vector<std::uint32_t>& cluster_of,
                                               const std::vector<TriangleIndices>& triangles,
                                               const SuperClusters& groups);

}  // namespace cpca
