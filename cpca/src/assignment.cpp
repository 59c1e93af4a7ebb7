#include "cpca/assignment.h"

#include "cpca/kd_tree.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace cpca {

DataMatrix squared_distances(const Eigen::Ref<const DataMatrix>& x,
                             const Eigen::VectorXf& x_squared_norms,
                             const Eigen::Ref<const DataMatrix>& centroids) {
  const Eigen::Index v = x.rows(), k = centroids.rows();
  DataMatrix out(v, k);
  const Eigen::RowVectorXf c_norms = centroids.rowwise().squaredNorm().transpose();
  // A block of rows per task keeps each product large enough for Eigen's blocked GEMM while
  // the tasks spread over the cores (Eigen itself is single-threaded here).
  constexpr Eigen::Index kBlock = 256;
  tbb::parallel_for(Eigen::Index(0), (v + kBlock - 1) / kBlock, [&](Eigen::Index b) {
    const Eigen::Index begin = b * kBlock, rows = std::min(kBlock, v - begin);
    auto block = out.middleRows(begin, rows);
    block.noalias() = -2.f * x.middleRows(begin, rows) * centroids.transpose();
    block.rowwise() += c_norms;
    block.colwise() += x_squared_norms.segment(begin, rows);
    block = block.cwiseMax(0.f);
  });
  return out;
}

std::vector<std::uint32_t> argmin_rows(const DataMatrix& cost) {
  std::vector<std::uint32_t> out(std::size_t(cost.rows()));
  tbb::parallel_for(Eigen::Index(0), cost.rows(), [&](Eigen::Index i) {
    Eigen::Index j = 0;
    cost.row(i).minCoeff(&j);  // first minimum: lowest index on ties
    out[std::size_t(i)] = std::uint32_t(j);
  });
  return out;
}

GeometryCoherence::GeometryCoherence(const Geometry& geometry, std::size_t vertex_count,
                                     double alpha)
    : alpha_(alpha) {
  if (geometry.positions.size() != vertex_count)
    throw std::invalid_argument("geometry coherence: " + std::to_string(geometry.positions.size()) +
                                " positions for " + std::to_string(vertex_count) +
                                " data rows; the mesh does not match the transfer");
  if (!(alpha >= 0.0) || !std::isfinite(alpha))
    throw std::invalid_argument("geometry coherence: alpha must be finite and >= 0, got " +
                                std::to_string(alpha));
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(INFINITY), hi = -lo;
  for (const Eigen::Vector3f& p : geometry.positions) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const float diagonal = vertex_count ? (hi - lo).norm() : 1.f;
  const float inv = diagonal > 0 ? 1.f / diagonal : 1.f;
  positions_.reserve(vertex_count);
  for (const Eigen::Vector3f& p : geometry.positions) positions_.push_back(p * inv);
}

std::vector<std::uint32_t> GeometryCoherence::assign(const DataMatrix& squared_distance,
                                                     const std::vector<std::uint32_t>& previous,
                                                     double data_scale) const {
  const std::size_t v = std::size_t(squared_distance.rows());
  const int k = int(squared_distance.cols());
  if (previous.size() != v || positions_.size() != v)
    throw std::invalid_argument("geometry coherence: assignment sizes do not match");
  if (!(data_scale > 0.0)) return argmin_rows(squared_distance);

  // One tree per cluster over its previous members.
  std::vector<std::vector<Eigen::Vector3f>> points(static_cast<std::size_t>(k));
  std::vector<std::vector<std::uint32_t>> ids(static_cast<std::size_t>(k));
  for (std::size_t i = 0; i < v; ++i) {
    points[previous[i]].push_back(positions_[i]);
    ids[previous[i]].push_back(std::uint32_t(i));
  }
  std::vector<KdTree> trees(static_cast<std::size_t>(k));
  tbb::parallel_for(0, k, [&](int j) {
    trees[std::size_t(j)] =
        KdTree(std::move(points[std::size_t(j)]), std::move(ids[std::size_t(j)]));
  });

  const double inv_scale = 1.0 / data_scale;
  std::vector<std::uint32_t> out(v);
  tbb::parallel_for(std::size_t(0), v, [&](std::size_t i) {
    const auto row = squared_distance.row(Eigen::Index(i));
    const Eigen::Vector3f& p = positions_[i];
    // Geometric term of cluster j, or +inf when it cannot beat `limit` on the total.
    auto geo = [&](int j, double limit_geo) -> double {
      const KdTree& tree = trees[std::size_t(j)];
      if (tree.size() == 0) return 0.0;  // an emptied cluster: no geometry to be far from
      if (tree.size() == 1 && previous[i] == std::uint32_t(j)) return 0.0;
      const float radius =
          std::isfinite(limit_geo) ? float(limit_geo) * 1.0001f + 1e-12f : INFINITY;
      const KdTree::Hit hit = tree.nearest(p, radius, std::uint32_t(i));
      return hit.id == KdTree::kNone ? INFINITY : double(hit.distance);
    };
    // Start from the nearest cluster in data space, then visit only clusters whose data term
    // alone is below the best total so far.
    Eigen::Index j0 = 0;
    row.minCoeff(&j0);
    int best = int(j0);
    double best_d2 = row[j0];
    double best_total =
        std::sqrt(best_d2) * inv_scale + (alpha_ > 0 ? alpha_ * geo(best, INFINITY) : 0.0);
    for (int j = 0; j < k; ++j) {
      if (j == best) continue;
      const double d2 = row[j];
      const double data = std::sqrt(d2) * inv_scale;
      if (data > best_total) continue;
      const double g = geo(j, alpha_ > 0 ? (best_total - data) / alpha_ : INFINITY);
      if (!std::isfinite(g)) continue;
      const double total = data + alpha_ * g;
      // Ties: smaller total, then smaller data distance, then lower index.
      if (total < best_total ||
          (total == best_total && (d2 < best_d2 || (d2 == best_d2 && j < best)))) {
        best = j;
        best_d2 = d2;
        best_total = total;
      }
    }
    out[i] = std::uint32_t(best);
  });
  return out;
}

}  // namespace cpca
