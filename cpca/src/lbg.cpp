#include "cpca/lbg.h"

#include "splitmix.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>

namespace cpca {
namespace {

using detail::next_uniform;

// Column-wise min and max block by block: exact, so the same as over all rows at once.
DataMatrix hyper_box_means(const RowBlocks& x, int k, std::uint64_t seed) {
  Eigen::RowVectorXf lo = Eigen::RowVectorXf::Constant(x.cols(), INFINITY), hi = -lo;
  x.for_each([&](Eigen::Index, const auto& block) {
    lo = lo.cwiseMin(block.colwise().minCoeff());
    hi = hi.cwiseMax(block.colwise().maxCoeff());
  });
  DataMatrix means(k, x.cols());
  std::uint64_t state = seed;
  for (int j = 0; j < k; ++j)
    for (Eigen::Index d = 0; d < x.cols(); ++d)
      means(j, d) = lo[d] + float(next_uniform(state)) * (hi[d] - lo[d]);
  return means;
}

Eigen::VectorXf row_squared_norms(const RowBlocks& x) {
  Eigen::VectorXf norms(x.rows());
  x.for_each([&](Eigen::Index first, const auto& block) {
    norms.segment(first, block.rows()) = block.rowwise().squaredNorm();
  });
  return norms;
}

// Step 1 without coherence: the nearest mean of every row, one block's distances at a time
// (block x K instead of V x K).
std::vector<std::uint32_t> nearest_means(const RowBlocks& x, const Eigen::VectorXf& norms,
                                         const DataMatrix& means) {
  std::vector<std::uint32_t> out(std::size_t(x.rows()));
  x.for_each([&](Eigen::Index first, const auto& block) {
    const Eigen::VectorXf block_norms = norms.segment(first, block.rows());
    const std::vector<std::uint32_t> nearest =
        argmin_rows(squared_distances(block, block_norms, means));
    std::copy(nearest.begin(), nearest.end(), out.begin() + first);
  });
  return out;
}

}  // namespace

std::vector<std::vector<std::uint32_t>> cluster_members(
    const std::vector<std::uint32_t>& cluster_of, int cluster_count) {
  std::vector<std::vector<std::uint32_t>> members(static_cast<std::size_t>(cluster_count));
  for (std::size_t p = 0; p < cluster_of.size(); ++p)
    members[cluster_of[p]].push_back(std::uint32_t(p));
  return members;
}

DataMatrix cluster_means(const RowBlocks& x, const std::vector<std::uint32_t>& cluster_of,
                         int cluster_count) {
  // Each cluster's sum runs over its members in ascending order, whatever the blocks: the
  // block loop is in order and a cluster's rows within a block are added in order.
  using RowMajorXd = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  RowMajorXd sums = RowMajorXd::Zero(cluster_count, x.cols());
  std::vector<std::size_t> count(std::size_t(cluster_count), 0);
  x.for_each([&](Eigen::Index first, const auto& block) {
    std::vector<std::vector<std::uint32_t>> members(static_cast<std::size_t>(cluster_count));
    for (Eigen::Index i = 0; i < block.rows(); ++i)
      members[cluster_of[std::size_t(first + i)]].push_back(std::uint32_t(i));
    tbb::parallel_for(0, cluster_count, [&](int j) {
      auto sum = sums.row(j);
      for (std::uint32_t i : members[std::size_t(j)]) sum += block.row(i).template cast<double>();
      count[std::size_t(j)] += members[std::size_t(j)].size();
    });
  });
  DataMatrix means = DataMatrix::Zero(cluster_count, x.cols());
  for (int j = 0; j < cluster_count; ++j)
    if (count[std::size_t(j)] != 0)
      means.row(j) = (sums.row(j) / double(count[std::size_t(j)])).cast<float>();
  return means;
}

DataMatrix cluster_means(const Eigen::Ref<const DataMatrix>& x,
                         const std::vector<std::uint32_t>& cluster_of, int cluster_count) {
  return cluster_means(RowBlocks(x), cluster_of, cluster_count);
}

double clustering_energy(const RowBlocks& x, const std::vector<std::uint32_t>& cluster_of,
                         const DataMatrix& means) {
  // Sums over fixed chunks of kChunk rows, then over the chunks in order: a fixed reduction
  // order that does not depend on the blocks (a chunk may straddle two).
  constexpr Eigen::Index kChunk = 1024;
  double total = 0, chunk = 0;
  std::vector<double> term;
  x.for_each([&](Eigen::Index first, const auto& block) {
    term.resize(std::size_t(block.rows()));
    tbb::parallel_for(Eigen::Index(0), block.rows(), [&](Eigen::Index i) {
      term[std::size_t(i)] = (block.row(i) - means.row(cluster_of[std::size_t(first + i)]))
                                 .template cast<double>()
                                 .squaredNorm();
    });
    for (Eigen::Index i = 0; i < block.rows(); ++i) {
      chunk += term[std::size_t(i)];
      if ((first + i + 1) % kChunk == 0) {
        total += chunk;
        chunk = 0;
      }
    }
  });
  if (x.rows() % kChunk != 0) total += chunk;
  return total;
}

double clustering_energy(const Eigen::Ref<const DataMatrix>& x,
                         const std::vector<std::uint32_t>& cluster_of, const DataMatrix& means) {
  return clustering_energy(RowBlocks(x), cluster_of, means);
}

namespace {

// `after_gather` runs once the largest cluster's rows are copied, so an out-of-core source
// can drop the pages the gather touched before the next split gathers again.
int split_clusters(const Eigen::Ref<const DataMatrix>& x, std::vector<std::uint32_t>& cluster_of,
                   int cluster_count, const std::function<void()>& after_gather) {
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
    if (after_gather) after_gather();
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

}  // namespace

int split_empty_clusters(const Eigen::Ref<const DataMatrix>& x,
                         std::vector<std::uint32_t>& cluster_of, int cluster_count) {
  return split_clusters(x, cluster_of, cluster_count, {});
}

int split_empty_clusters(const RowBlocks& x, std::vector<std::uint32_t>& cluster_of,
                         int cluster_count) {
  return split_clusters(x.all(), cluster_of, cluster_count, [&x] { x.release_all(); });
}

LbgResult lbg(const RowBlocks& x, const LbgOptions& options, const GeometryCoherence* coherence,
              const LbgCallback& callback) {
  const int k = options.clusters;
  if (k < 1 || Eigen::Index(k) > x.rows())
    throw std::invalid_argument("LBG: cluster count must be in [1, points] = [1, " +
                                std::to_string(x.rows()) + "], got " + std::to_string(k));
  if (!(options.threshold >= 0) || options.max_iterations < 1)
    throw std::invalid_argument("LBG: threshold must be >= 0 and max_iterations >= 1");
  const Eigen::VectorXf norms = row_squared_norms(x);
  LbgResult r;
  r.means = hyper_box_means(x, k, options.seed);
  double previous = 0.0;
  for (int it = 1; it <= options.max_iterations; ++it) {
    if (coherence && it > 1) {
      // Coherence weighs every cluster for every point against the previous membership:
      // it needs all rows' distances at once (V x K), so it does not stream.
      const DataMatrix d2 = squared_distances(x.all(), norms, r.means);
      x.release_all();
      r.cluster_of = coherence->assign(d2, r.cluster_of, std::sqrt(previous / double(x.rows())));
    } else {
      r.cluster_of = nearest_means(x, norms, r.means);
    }
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

LbgResult lbg(const Eigen::Ref<const DataMatrix>& x, const LbgOptions& options,
              const GeometryCoherence* coherence, const LbgCallback& callback) {
  return lbg(RowBlocks(x), options, coherence, callback);
}

}  // namespace cpca
