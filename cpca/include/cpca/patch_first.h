// cpca/patch_first.h: patch-first CPCA, a clustering designed for multipass rendering from the
// start (docs/ARCHITECTURE.md "Compression").
//
// The thesis clusters by signal and groups clusters into passes afterwards, so a pass's
// triangles are scattered and every triangle between two passes is drawn twice. Here the
// mesh is first cut into P = ceil(K / per_pass) spatially compact patches, one per pass, by
// a METIS k-way partition (Karypis & Kumar 1998) of the vertex graph whose edge weights grow
// with transfer similarity, so cuts run where the signal changes; then CPCA (Sloan et al.
// 2003, iterative) runs inside each patch with that pass's cluster count. Only triangles
// crossing a patch border are drawn more than once. Clusters are numbered so that pass p
// holds [p * per_pass, (p + 1) * per_pass): the grouping is group_in_order(K, per_pass).
#pragma once

#include "cpca/compress_options.h"
#include "cpca/supercluster.h"

#include <cstdint>
#include <vector>

namespace cpca {

// Clusters of each patch: per_pass for all but the last, which takes the rest.
std::vector<int> patch_cluster_counts(int cluster_count, int per_pass);

// The patch (0..counts.size()-1) of every vertex: METIS on the mesh's vertex graph, each
// patch's share of the vertices' weight (`vertex_weight`, one per vertex; empty: 1 each)
// proportional to its cluster count, then repaired so that every patch holds at least as
// many vertices as clusters. Edge weight 1 + round(100 exp(-d/d̄)), d = ||x_i - x_j||^2 and
// d̄ its mean over the edges. Throws std::invalid_argument when the mesh has fewer
// vertices than clusters or the weights are not one per vertex.
std::vector<std::uint32_t> partition_patches(const Eigen::Ref<const DataMatrix>& data,
                                             const Geometry& geometry,
                                             const std::vector<int>& counts, std::uint64_t seed,
                                             const std::vector<std::uint32_t>& vertex_weight = {});

// Vertex weights that measure how much of a clustering's budget a vertex takes: 1 / |c| for a
// vertex of cluster c (scaled to integers whose sum fits METIS's 32 bits), so each cluster
// weighs the same. Patches balanced by them hold equal shares of the clusters that clustering
// spent on their area: where the signal is complex (many small clusters) they are small,
// where it is smooth they are large. patch-eps weighs by original CPCA's clusters.
std::vector<std::uint32_t> cluster_density_weights(const std::vector<std::uint32_t>& cluster_of,
                                                   int cluster_count);

// A reference for what pass layouts can reach, not a bound: the average overdraw of the
// mesh cut into `passes` equal patches by METIS on its plain vertex graph (unit edge
// weights: the shortest borders it finds, the signal and the error ignored), each patch one
// pass. Equal compact passes draw about this much however their clusters are chosen; a
// pass-designing method goes below it only with unequal passes.
double equal_patches_overdraw(const Geometry& geometry, int passes, std::uint64_t seed);

// The whole method (CompressOptions::method == kPatchFirst; compress() dispatches here).
// Inside each patch: options' components, solver, alpha (on the patch's own triangles) and
// CPCA settings, iterative CPCA. Needs the geometry. The report's lbg_seconds holds the
// partition and the per-patch clustering (which includes their PCA fits).
CompressedSet compress_patch_first(const Eigen::Ref<const DataMatrix>& data,
                                   const CompressOptions& options, const Geometry& geometry,
                                   CompressReport* report = nullptr);

// The passes a set from compress_patch_first or compress_joint was designed for.
inline SuperClusters designed_passes(const CompressedSet& set, int per_pass) {
  return group_in_order(set.cluster_count, per_pass);
}

}  // namespace cpca
