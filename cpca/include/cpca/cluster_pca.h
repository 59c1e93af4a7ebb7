// cpca/cluster_pca.h: the PCA half of CPCA. Given a clustering, fit every cluster's mean and
// N principal components (power iteration or Eigen's solver, cpca/power_iteration.h) and
// project each vertex onto its cluster's basis; and the squared reconstruction error of every
// point under every cluster's affine subspace, which iterative CPCA and the overdraw-aware
// reassignment compare.
#pragma once

#include "cpca/compressed.h"
#include "cpca/distribution.h"
#include "cpca/metrics.h"
#include "cpca/power_iteration.h"
#include "cpca/row_blocks.h"

#include <vector>

namespace cpca {

struct ClusterPcaStats {
  int power_iterations = 0;  // total over clusters (0 for the Eigen solver)
};

// Uses set.cluster_of, set.cluster_count, set.component_count; fills set.vertex_count, means,
// bases and weights. A cluster with fewer than N + 1 points gets zero rows past its rank.
// Returns each vertex's squared reconstruction error (double). Clusters run in parallel.
std::vector<double> fit_cluster_pca(const Eigen::Ref<const DataMatrix>& x, CompressedSet& set,
                                    PcaSolver solver, const PowerIterationOptions& power = {},
                                    ClusterPcaStats* stats = nullptr);

// The same, each cluster's power iteration started from `previous_bases` (K x N x D floats, as
// CompressedSet::bases) of the same cluster id, with power.tolerance as given: a refit after a
// search moved some points. Power-iteration solver only. `grams`, when not empty, holds per
// cluster either null or x_i . x_j (double) of its member rows in ascending order, which a
// cluster with fewer members than dimensions then uses instead of forming F F^T
// (cluster_gram.h keeps them up to date across a search). `only`, when not empty, holds one
// flag per cluster: only those are fitted, every other cluster keeps the mean, basis and
// weights the set holds (full size), and their rows' errors are returned as 0.
std::vector<double> fit_cluster_pca_warm(const Eigen::Ref<const DataMatrix>& x, CompressedSet& set,
                                         const std::vector<float>& previous_bases,
                                         const PowerIterationOptions& power,
                                         const std::vector<const Eigen::MatrixXd*>& grams = {},
                                         const std::vector<char>& only = {});

// The same, out of core: each cluster gathers only its own rows (random access through
// x.all()) and the source's pages are released after every cluster, so memory holds the
// clusters being fitted (one per thread), not the data. Bit-identical to the call above.
std::vector<double> fit_cluster_pca(const RowBlocks& x, CompressedSet& set, PcaSolver solver,
                                    const PowerIterationOptions& power = {},
                                    ClusterPcaStats* stats = nullptr);

// The same spread over ranks: rank r fits clusters r, r + R, ... (every rank holds all ids
// and maps all rows, so each gathers its clusters itself), then rank 0 gathers the means,
// bases, weights and errors of the others. The set and errors are complete on rank 0 only.
// Bit-identical to the calls above: each cluster is fitted by the same code on the same rows.
std::vector<double> fit_cluster_pca(const RowBlocks& x, CompressedSet& set, PcaSolver solver,
                                    const PowerIterationOptions& power, ClusterPcaStats* stats,
                                    Distribution& distribution);

// V x K: ||x_p - m_k||^2 - ||B_k (x_p - m_k)||^2 for every point and cluster, i.e. the squared
// distance from x_p to cluster k's affine subspace (bases orthonormal). Computed as two matrix
// products per row block; clamped at 0. `x_squared_norms` holds ||x_p||^2.
DataMatrix subspace_distances(const Eigen::Ref<const DataMatrix>& x,
                              const Eigen::VectorXf& x_squared_norms, const CompressedSet& set);

// The same restricted to candidates: for each point, its current cluster and the
// `candidates` clusters with the nearest means; every other entry is +infinity. The nearest
// affine subspace is almost always among the nearest means, and this costs ~K / candidates
// times less than the full matrix (one V x K distance product plus small per-cluster ones).
DataMatrix subspace_distances(const Eigen::Ref<const DataMatrix>& x,
                              const Eigen::VectorXf& x_squared_norms, const CompressedSet& set,
                              int candidates);

// The same restricted to each point's own cluster and the `candidates` clusters whose means
// are nearest its own cluster's mean (a cluster closure, after Wang et al. 2012, "Fast
// approximate k-means via cluster closures"): one K x K distance product in place of the
// V x K one above. A point's better cluster is nearly always one close to its own, and the
// epsilon search takes these in every step that must lower the error.
DataMatrix subspace_distances_near_clusters(const Eigen::Ref<const DataMatrix>& x,
                                            const CompressedSet& set, int candidates);

// Each cluster's closure as used above: itself and the `candidates` clusters whose means are
// nearest its mean, nearest first (ties to the lower id), the cluster itself appended when
// tied out. For callers that keep distances of their own (the epsilon search's, from step to
// step).
std::vector<std::vector<std::uint32_t>> cluster_closures(const CompressedSet& set, int candidates);

// The same for rows `points` of x and one cluster, in float, clamped at 0: result[i] is
// points[i]'s distance.
std::vector<float> subspace_residuals(const Eigen::Ref<const DataMatrix>& x,
                                      const CompressedSet& set, int cluster,
                                      const std::vector<std::uint32_t>& points);

// The same for one point and one cluster, in double.
double subspace_distance(const Eigen::Ref<const Eigen::RowVectorXf>& x, const CompressedSet& set,
                         int cluster);

}  // namespace cpca
