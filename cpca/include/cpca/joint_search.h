// cpca/joint_search.h: a local search over vertex -> cluster and cluster -> pass together,
// minimising  J = Average SE + lambda * E0 * average overdraw  (docs/ARCHITECTURE.md
// "Compression"). E0 is the start's Average SE, so lambda is unitless: lambda = 0.1 trades
// 10% of the start's error for one unit of overdraw. Overdraw is the renderer's count
// (cpca/supercluster.h): triangles drawn over all passes / triangles.
//
// It extends Sloan et al. 2003's iterative CPCA, whose step is "reassign every vertex to the
// affine subspace that reconstructs it best, then refit", with the pass structure the
// thesis adds afterwards (super-clusters, ch. 4). One step:
//  1. Vertex moves, Gauss-Seidel in vertex order, with the bases of the step's start fixed:
//     vertex p goes to the cluster c minimising err(p, c) / V + lambda E0 * draws(p, c) / T
//     over its current cluster, the clusters with the nearest means (as iterative CPCA) and
//     its neighbours' clusters, where draws counts the passes its triangles are drawn in.
//     Each accepted move lowers J exactly (no cluster is ever emptied).
//  2. PCA refit of every cluster for the new membership.
//  3. Pass swaps: two clusters of different passes trade passes when that lowers the
//     triangles drawn (supercluster_refine.h), so the pass sizes never change.
//  The step is kept only when the refitted J is lower than before it; the search stops when
//  J falls by less than the threshold (relative) or after max_steps.
// With lambda = 0 steps 1 and 3 reduce to iterative CPCA's argmin and nothing, so the search
// is exactly CompressOptions::method = kIterative (tested).
#pragma once

#include "cpca/compress_options.h"
#include "cpca/supercluster.h"

#include <cstdint>
#include <vector>

namespace cpca {

struct JointSearchOptions {
  double lambda = 0.0;  // >= 0, in units of the start's Average SE per unit overdraw
  int per_pass = 16;    // clusters per pass
  int max_steps = 20;
  double threshold = 1e-3;  // stop when J falls by less than this fraction
  int candidates = 16;      // nearest-mean candidates per vertex (cluster_pca.h)
  PcaSolver solver = PcaSolver::kPowerIteration;
  std::uint64_t seed = 1;
  // 0, or an average overdraw no vertex move may take the search above (a start above it
  // may only come down). A constraint, not a weight: with a small lambda the search spends
  // the overdraw budget on error, and J still never rises.
  double overdraw_cap = 0.0;
  // > 0: the epsilon-constraint search (Haimes, Lasdon & Wismer 1971) instead: minimise the
  // triangles drawn subject to Average SE <= error_target. lambda and overdraw_cap are then
  // unused: the price of a drawn triangle is a multiplier the search adapts (halved while the
  // error is above the target or the moves the target refused would overspend it by more
  // than 1%, quadrupled while more than 1% of the allowance is unspent). Its moves are
  // bounded (a vertex considers the clusters of its pass and of its 1-ring, and the nearest
  // means only while the error is above the target); after the vertex moves, every border
  // between two passes is relabelled at once by a minimum cut (border_cut.h); its refits
  // start from the previous bases (refit_tolerance). Stops after max_steps or 3 steps in a
  // row that move neither the extra draws nor the error by `threshold`.
  double error_target = 0.0;
  double refit_tolerance = 1e-6;  // the bases are stored as floats
  // A candidate's distance to a cluster whose fit no kept step has changed since is taken
  // from the step that computed it; false computes every distance in every step (the
  // reference the tests hold the reuse to).
  bool reuse_distances = true;
};

struct JointSearchResult {
  std::vector<double> objective;  // J after the start and after every accepted stage
  std::vector<std::uint32_t> pass_of;
  std::uint64_t triangles_drawn = 0;  // tracked incrementally by the search
  double error_scale = 0.0;           // E0
  std::uint64_t vertex_moves = 0, pass_swaps = 0;
  int steps = 0;  // accepted steps
  int tried = 0;  // steps tried (a last one may be undone), as iterative CPCA counts them
  // The epsilon search stopped above the cap because its excess, falling at its last rate,
  // would not have reached zero in the steps left.
  bool gave_up = false;
};

// Pass sizes that group_in_order(K, per_pass) has: per_pass for all but the last pass. From
// any grouping into the minimum number of passes, moves clusters out of the pass with the
// most room into the other short passes (cheapest move first) and puts that pass last.
std::vector<std::uint32_t> order_profile(const std::vector<std::uint32_t>& cluster_of,
                                         const std::vector<TriangleIndices>& triangles,
                                         const SuperClusters& groups, int cluster_count,
                                         int per_pass);

// Searches from a fitted set (vertex_error[p] = err(p, cluster_of[p])) and a pass_of with
// order_profile's sizes. Updates set and vertex_error to the result.
JointSearchResult joint_search(const Eigen::Ref<const DataMatrix>& data, const Geometry& geometry,
                               CompressedSet& set, std::vector<double>& vertex_error,
                               std::vector<std::uint32_t> pass_of,
                               const JointSearchOptions& options);

// The whole method (CompressOptions::method kJoint or kPatchJoint; compress() dispatches
// here). kJoint starts from LBG and PCA as compress() does, with the METIS super-cluster
// strategy brought to order_profile; kPatchJoint from patch-first's clusters and passes. Then
// the search, then clusters renumbered so that pass p holds [p * per_pass, (p + 1) *
// per_pass) (designed_passes() in patch_first.h). Needs the geometry; alpha must be 0. The
// report's pca_seconds holds the start's fit, refit and grouping, cpca_seconds the search.
// CompressOptions::overdraw_cap is JointSearchOptions::overdraw_cap (the epsilon-constraint
// form of the trade-off, Haimes et al. 1971).
CompressedSet compress_joint(const Eigen::Ref<const DataMatrix>& data,
                             const CompressOptions& options, const Geometry& geometry,
                             CompressReport* report = nullptr, JointSearchResult* search = nullptr);

}  // namespace cpca
