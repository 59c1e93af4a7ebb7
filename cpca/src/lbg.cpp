#include "cpca/lbg.h"

#include "splitmix.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace cpca {
namespace {

using detail::next_uniform;

DataMatrix hyper_box_means(const Eigen::Ref<const DataMatrix>& x, int k, std::uint64_t seed) {
  const Eigen::RowVectorXf lo = x.colwise().minCoeff(), hi = x.colwise().maxCoeff();
  DataMatrix means(k, x.cols());
  std::uint64_t state = seed;
  for (int j = 0; j < k; ++j)
    for (Eigen::Index d = 0; d < x.cols(); ++d)
      means(j, d) = lo[d] + float(next_uniform(state)) * (hi[d] - lo[d]);
  return means;
}

}  // namespace

std::vector<std::vector<std::uint32_t>> cluster_members(
    const std::vector<std::uint32_t>& cluster_of, int cluster_count) {
  std::vector<std::vector<std::uint32_t>> members(static_cast<std::size_t>(cluster_count));
  for (std::size_t p = 0; p < cluster_of.size(); ++p)
    members[cluster_of[p]].push_back(std::uint32_t(p));
  return members;
}

DataMatrix cluster_means(const Eigen::Ref<const DataMatrix>& x,
                         const std::vector<std::uint32_t>& cluster_of, int cluster_count) {
  const auto members = cluster_members(cluster_of, cluster_count);
  DataMatrix means = DataMatrix::Zero(cluster_count, x.cols());
  tbb::parallel_for(0, cluster_count, [&](int j) {
    const auto& m = members[std::size_t(j)];
    if (m.empty()) return;
    Eigen::RowVectorXd sum = Eigen::RowVectorXd::Zero(x.cols());
    for (std::uint32_t p : m) sum += x.row(p).cast<double>();
    means.row(j) = (sum / double(m.size())).cast<float>();
  });
  return means;
}

double clustering_energy(const Eigen::Ref<const DataMatrix>& x,
                         const std::vector<std::uint32_t>& cluster_of, const DataMatrix& means) {
  constexpr Eigen::Index kBlock = 1024;
  const Eigen::Index rows = x.rows(), blocks = (rows + kBlock - 1) / kBlock;
  std::vector<double> partial(std::size_t(blocks), 0.0);
  tbb::parallel_for(Eigen::Index(0), blocks, [&](Eigen::Index b) {
    double sum = 0;
    for (Eigen::Index p = b * kBlock; p < std::min(rows, (b + 1) * kBlock); ++p)
      sum += (x.row(p) - means.row(cluster_of[std::size_t(p)])).cast<double>().squaredNorm();
    partial[std::size_t(b)] = sum;
  });
  double total = 0;
  for (double s : partial) total += s;
  return total;
}

int split_empty_clusters(const Eigen::Ref<const DataMatrix>& x,
                         std::vector<std::uint32_t>& cluster_of, int cluster_count) {
  if (Eigen::Index(cluster_count) > x.rows())
    throw std::invalid_argument("cannot form " + std::to_string(cluster_count) + " clusters from " +
                                std::to_string(x.rows()) +
                                " points: use at most as many clusters as vertices");
  std::vector<std::size_t> count(std::size_t(cluster_count), 0);
  for (std::uint32_t c : cluster_of) ++count[c];
  int splits = 0;
  for (int empty = 0; empty < cluster_count; ++empty) {
    if (count[std::size_t(empty)] != 0) continue;
    const std::size_t largest =
        std::size_t(std::max_element(count.begin(), count.end()) - count.begin());
    std::vector<std::uint32_t> members;
    members.reserve(count[largest]);
    for (std::size_t p = 0; p < cluster_of.size(); ++p)
      if (cluster_of[p] == largest) members.push_back(std::uint32_t(p));
    const Eigen::Index m = Eigen::Index(members.size());
    Eigen::MatrixXf centred(m, x.cols());
    for (Eigen::Index i = 0; i < m; ++i) centred.row(i) = x.row(members[std::size_t(i)]);
    const Eigen::RowVectorXf mean = centred.colwise().mean();
    centred.rowwise() -= mean;
    // Principal direction by power iteration, started from the farthest point's offset
    // (deterministic, and already close to the direction of largest spread).
    Eigen::Index far = 0;
    centred.rowwise().squaredNorm().maxCoeff(&far);
    Eigen::VectorXf dir = centred.row(far).transpose();
    Eigen::VectorXf proj;
    for (int it = 0; it < 6 && dir.squaredNorm() > 0; ++it) {
      proj.noalias() = centred * dir;
      dir.noalias() = centred.transpose() * proj;
      const float norm = dir.norm();
      if (!(norm > 0)) break;
      dir /= norm;
    }
    proj.noalias() = centred * dir;
    std::vector<std::uint32_t> moved;
    for (Eigen::Index i = 0; i < m; ++i)
      if (proj[i] > 0) moved.push_back(members[std::size_t(i)]);
    if (moved.empty() || moved.size() == members.size()) {
      // No spread along any direction (identical points): move half of them.
      moved.assign(members.begin() + m / 2, members.end());
    }
    for (std::uint32_t p : moved) cluster_of[p] = std::uint32_t(empty);
    count[largest] -= moved.size();
    count[std::size_t(empty)] += moved.size();
    ++splits;
  }
  return splits;
}

LbgResult lbg(const Eigen::Ref<const DataMatrix>& x, const LbgOptions& options,
              const GeometryCoherence* coherence, const LbgCallback& callback) {
  const int k = options.clusters;
  if (k < 1 || Eigen::Index(k) > x.rows())
    throw std::invalid_argument("LBG: cluster count must be in [1, points] = [1, " +
                                std::to_string(x.rows()) + "], got " + std::to_string(k));
  if (!(options.threshold >= 0) || options.max_iterations < 1)
    throw std::invalid_argument("LBG: threshold must be >= 0 and max_iterations >= 1");
  const Eigen::VectorXf norms = x.rowwise().squaredNorm();
  LbgResult r;
  r.means = hyper_box_means(x, k, options.seed);
  double previous = 0.0;
  for (int it = 1; it <= options.max_iterations; ++it) {
    const DataMatrix d2 = squared_distances(x, norms, r.means);
    if (coherence && it > 1)
      r.cluster_of = coherence->assign(d2, r.cluster_of, std::sqrt(previous / double(x.rows())));
    else
      r.cluster_of = argmin_rows(d2);
    r.splits += split_empty_clusters(x, r.cluster_of, k);
    r.means = cluster_means(x, r.cluster_of, k);
    const double energy = clustering_energy(x, r.cluster_of, r.means);
    r.energy.push_back(energy);
    r.iterations = it;
    const double ratio = it == 1 ? 1.0 : (previous - energy) / previous;
    if (callback) callback(it, energy, ratio);
    // |ratio|: with geometry coherence the data energy may rise while the total cost falls;
    // that is progress, not convergence.
    if (energy == 0.0 || (it > 1 && std::abs(ratio) < options.threshold)) break;
    previous = energy;
  }
  return r;
}

}  // namespace cpca
