// cpca/cluster_gram.h: each cluster's Gram matrix G = X X^T of its member rows, kept up to
// date while a search moves points between clusters.
//
// A refit after a search step fits every cluster whose membership changed. On the Gram path
// (fewer members m than dimensions d, power_iteration.h) forming F F^T costs O(m^2 d), about
// ten times the rest of a warm refit, although a late step moves a handful of a cluster's
// hundreds of points. Here a cluster's G changes only by the rows and columns of the points
// that joined (O(joined x m x d)); the centring needs only G (cluster_pca.cpp).
#pragma once

#include "cpca/metrics.h"

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace cpca {

class ClusterGrams {
 public:
  // Clusters with at least `data.cols()` members (the covariance path) keep no matrix; nor do
  // clusters past `max_bytes` of matrices in all, which are then fitted from scratch.
  explicit ClusterGrams(std::size_t max_bytes = std::size_t(512) << 20) : max_bytes_(max_bytes) {}

  // Brings every cluster's matrix to the membership `cluster_of` (ids < clusters): the rows
  // and columns of points that left are dropped, those of points that joined are computed,
  // the rest are kept. Members stay in ascending order, as cluster_pca.h fits them.
  void sync(const Eigen::Ref<const DataMatrix>& data, const std::vector<std::uint32_t>& cluster_of,
            int clusters);

  // x_i . x_j in double of cluster c's members in ascending order, or null when not kept.
  const Eigen::MatrixXd* gram(std::uint32_t c) const;
  const std::vector<std::uint32_t>& members(std::uint32_t c) const { return members_[c]; }
  std::uint64_t rows_computed() const { return rows_computed_; }  // joined rows so far

 private:
  std::size_t max_bytes_;
  std::vector<std::vector<std::uint32_t>> members_;
  std::vector<Eigen::MatrixXd> grams_;
  std::vector<char> kept_;
  std::uint64_t rows_computed_ = 0;
};

}  // namespace cpca
