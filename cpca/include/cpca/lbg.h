// cpca/lbg.h: LBG (k-means) clustering of the per-vertex transfer data, as in thesis
// Fig. 3.2, and the null-cluster avoidance that iterative CPCA shares.
//
//  0. Initial means: uniform random points in the data's hyper-box (per-dimension min/max).
//  1. Assign every point to its nearest mean (distances as matrix products, assignment.h), or
//     with geometry coherence when one is given.
//  -  Null-cluster avoidance: while a cluster is empty, split the most populated cluster in two
//     along its principal direction (a few power iterations on a strided sample of at most
//     2048 of its points) and give the half on one side to the empty one.
//  2. Update every mean to the average of its points.
//  3. Energy E_i = sum_p ||x_p - mean||^2 (eq. 4); stop when E_i = 0 or the converged ratio
//     (E_{i-1} - E_i) / E_{i-1} (eq. 5) falls below the threshold in magnitude (with geometry
//     coherence E may rise while the total cost falls), or after max_iterations.
#pragma once

#include "cpca/assignment.h"
#include "cpca/distribution.h"
#include "cpca/metrics.h"
#include "cpca/row_blocks.h"

#include <cstdint>
#include <functional>
#include <vector>

namespace cpca {

struct LbgOptions {
  int clusters = 256;
  double threshold = 1e-3;  // on the converged ratio (eq. 5): energy falls < 0.1%
  int max_iterations = 200;
  std::uint64_t seed = 1;  // of the hyper-box initialisation
};

struct LbgResult {
  std::vector<std::uint32_t> cluster_of;
  DataMatrix means;  // K x D
  int iterations = 0;
  int splits = 0;              // null clusters filled by splitting
  std::vector<double> energy;  // E_i after each iteration
};

// Called after each iteration with its number (1-based), energy and converged ratio.
using LbgCallback = std::function<void(int iteration, double energy, double ratio)>;

// Requires 1 <= clusters <= rows (std::invalid_argument otherwise). Deterministic for a seed.
LbgResult lbg(const Eigen::Ref<const DataMatrix>& x, const LbgOptions& options,
              const GeometryCoherence* coherence = nullptr, const LbgCallback& callback = {});

// The same, out of core: every pass streams over the blocks (distances block x K, centroid
// sums K x D), except that geometry coherence needs V x K distances at once. Bit-identical
// to the in-memory call on the same rows for every block size.
LbgResult lbg(const RowBlocks& x, const LbgOptions& options,
              const GeometryCoherence* coherence = nullptr, const LbgCallback& callback = {});

// The same spread over the ranks of `distribution` (no geometry coherence): each rank
// assigns its rank_rows; the centroid sums, energy and hyper box are chained
// (distribution.h), so every rank returns the result of the one-process call bit for bit.
LbgResult lbg(const RowBlocks& x, const LbgOptions& options, Distribution& distribution,
              const LbgCallback& callback = {});

// Fills every empty cluster (ids < cluster_count) by splitting the most populated one along
// its principal direction (estimated from a strided sample of at most 2048 members; every
// member is then classified by its side). Returns the number of splits. Throws
// std::invalid_argument when there are more clusters than points.
int split_empty_clusters(const Eigen::Ref<const DataMatrix>& x,
                         std::vector<std::uint32_t>& cluster_of, int cluster_count);
// The same, reading the largest cluster's rows through RowBlocks::gather.
int split_empty_clusters(const RowBlocks& x, std::vector<std::uint32_t>& cluster_of,
                         int cluster_count);

// Mean of each cluster's rows (K x D), accumulated in double. Empty clusters get zero rows.
DataMatrix cluster_means(const Eigen::Ref<const DataMatrix>& x,
                         const std::vector<std::uint32_t>& cluster_of, int cluster_count);
DataMatrix cluster_means(const RowBlocks& x, const std::vector<std::uint32_t>& cluster_of,
                         int cluster_count);

// sum_p ||x_p - means[cluster_of[p]]||^2 in double, with a fixed reduction order.
double clustering_energy(const Eigen::Ref<const DataMatrix>& x,
                         const std::vector<std::uint32_t>& cluster_of, const DataMatrix& means);
double clustering_energy(const RowBlocks& x, const std::vector<std::uint32_t>& cluster_of,
                         const DataMatrix& means);

// The same two spread over ranks (each its rank_rows, chained), equal to the calls above bit
// for bit on every rank. `cluster_of` holds every row's id on every rank.
DataMatrix cluster_means(const RowBlocks& x, const std::vector<std::uint32_t>& cluster_of,
                         int cluster_count, Distribution& distribution);
double clustering_energy(const RowBlocks& x, const std::vector<std::uint32_t>& cluster_of,
                         const DataMatrix& means, Distribution& distribution);

// Members of each cluster, ascending.
std::vector<std::vector<std::uint32_t>> cluster_members(
    const std::vector<std::uint32_t>& cluster_of, int cluster_count);

}  // namespace cpca
