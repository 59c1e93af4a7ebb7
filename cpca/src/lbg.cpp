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

// Column-wise min and max block by block, chained over the ranks: exact, so the same as
// over all rows at once.
DataMatrix hyper_box_means(const RowBlocks& x, RowRange mine, Distribution& dist, int k,
                           std::uint64_t seed) {
  const Eigen::Index d = x.cols();
  std::vector<float> box(std::size_t(2 * d));
  Eigen::Map<Eigen::RowVectorXf> lo(box.data(), d), hi(box.data() + d, d);
  lo.setConstant(INFINITY);
  hi.setConstant(-INFINITY);
  chain(dist, box, [&](std::vector<float>&) {
    x.for_each_in(mine.begin, mine.end, [&](Eigen::Index, const auto& block) {
      lo = lo.cwiseMin(block.colwise().minCoeff());
      hi = hi.cwiseMax(block.colwise().maxCoeff());
    });
  });
  DataMatrix means(k, d);
  std::uint64_t state = seed;
  for (int j = 0; j < k; ++j)
    for (Eigen::Index c = 0; c < d; ++c)
      means(j, c) = lo[c] + float(next_uniform(state)) * (hi[c] - lo[c]);
  return means;
}

// Of this rank's rows only (the others stay 0): the assignment is the only user.
Eigen::VectorXf row_squared_norms(const RowBlocks& x, RowRange mine) {
  Eigen::VectorXf norms = Eigen::VectorXf::Zero(x.rows());
  x.for_each_in(mine.begin, mine.end, [&](Eigen::Index first, const auto& block) {
    norms.segment(first, block.rows()) = block.rowwise().squaredNorm();
  });
  return norms;
}

// Step 1 without coherence: the nearest mean of every row, one block's distances at a time
// (block x K instead of V x K); each rank assigns its rows, then all ranks get all ids.
std::vector<std::uint32_t> nearest_means(const RowBlocks& x, RowRange mine, Distribution& dist,
                                         const Eigen::VectorXf& norms, const DataMatrix& means) {
  std::vector<std::uint32_t> out(std::size_t(x.rows()));
  x.for_each_in(mine.begin, mine.end, [&](Eigen::Index first, const auto& block) {
    const Eigen::VectorXf block_norms = norms.segment(first, block.rows());
    const std::vector<std::uint32_t> nearest =
        argmin_rows(squared_distances(block, block_norms, means));
    std::copy(nearest.begin(), nearest.end(), out.begin() + first);
  });
  all_gather_rows(dist, out, mine);
  return out;
}

// Each cluster's sum runs over its members in ascending order, whatever the blocks and
// ranks: the block loop is in order, a cluster's rows within a block are added in order, and
// the ranks continue each other's sums (chain). The state is K rows of D sums and a count.
DataMatrix chained_means(const RowBlocks& x, RowRange mine, Distribution& dist,
                         const std::vector<std::uint32_t>& cluster_of, int cluster_count) {
  using RowMajorXd = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const Eigen::Index d = x.cols();
  std::vector<double> state(std::size_t(cluster_count) * std::size_t(d + 1), 0.0);
  Eigen::Map<RowMajorXd> sums(state.data(), cluster_count, d);
  double* count = state.data() + std::size_t(cluster_count) * std::size_t(d);
  chain(dist, state, [&](std::vector<double>&) {
    x.for_each_in(mine.begin, mine.end, [&](Eigen::Index first, const auto& block) {
      std::vector<std::vector<std::uint32_t>> members(static_cast<std::size_t>(cluster_count));
      for (Eigen::Index i = 0; i < block.rows(); ++i)
        members[cluster_of[std::size_t(first + i)]].push_back(std::uint32_t(i));
      tbb::parallel_for(0, cluster_count, [&](int j) {
        auto sum = sums.row(j);
        for (std::uint32_t i : members[std::size_t(j)]) sum += block.row(i).template cast<double>();
        count[j] += double(members[std::size_t(j)].size());
      });
    });
  });
  DataMatrix means = DataMatrix::Zero(cluster_count, d);
  for (int j = 0; j < cluster_count; ++j)
    if (count[j] != 0) means.row(j) = (sums.row(j) / count[j]).cast<float>();
  return means;
}

// Sums over fixed chunks of kChunk rows, then over the chunks in order: a fixed reduction
// order that depends neither on the blocks nor on the ranks (a chunk may straddle either; the
// chain carries the running total and the open chunk).
double chained_energy(const RowBlocks& x, RowRange mine, Distribution& dist,
                      const std::vector<std::uint32_t>& cluster_of, const DataMatrix& means) {
  constexpr Eigen::Index kChunk = 1024;
  // The terms before the chain, so that only the cheap running sum waits for rank r - 1.
  std::vector<double> term(std::size_t(mine.size()));
  x.for_each_in(mine.begin, mine.end, [&](Eigen::Index first, const auto& block) {
    tbb::parallel_for(Eigen::Index(0), block.rows(), [&](Eigen::Index i) {
      term[std::size_t(first - mine.begin + i)] =
          (block.row(i) - means.row(cluster_of[std::size_t(first + i)]))
              .template cast<double>()
              .squaredNorm();
    });
  });
  std::vector<double> state = {0.0, 0.0};  // total, open chunk
  chain(dist, state, [&](std::vector<double>&) {
    double& total = state[0];
    double& chunk = state[1];
    for (Eigen::Index p = mine.begin; p < mine.end; ++p) {
      chunk += term[std::size_t(p - mine.begin)];
      if ((p + 1) % kChunk == 0) {
        total += chunk;
        chunk = 0;
      }
    }
    if (dist.last() && x.rows() % kChunk != 0) total += chunk;
  });
  return state[0];
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
  SingleProcess one;
  return chained_means(x, {0, x.rows()}, one, cluster_of, cluster_count);
}

DataMatrix cluster_means(const Eigen::Ref<const DataMatrix>& x,
                         const std::vector<std::uint32_t>& cluster_of, int cluster_count) {
  return cluster_means(RowBlocks(x), cluster_of, cluster_count);
}

double clustering_energy(const RowBlocks& x, const std::vector<std::uint32_t>& cluster_of,
                         const DataMatrix& means) {
  SingleProcess one;
  return chained_energy(x, {0, x.rows()}, one, cluster_of, means);
}

DataMatrix cluster_means(const RowBlocks& x, const std::vector<std::uint32_t>& cluster_of,
                         int cluster_count, Distribution& dist) {
  return chained_means(x, rank_rows(x.rows(), dist.rank(), dist.size(), RowBlocks::kGranule), dist,
                       cluster_of, cluster_count);
}

double clustering_energy(const RowBlocks& x, const std::vector<std::uint32_t>& cluster_of,
                         const DataMatrix& means, Distribution& dist) {
  return chained_energy(x, rank_rows(x.rows(), dist.rank(), dist.size(), RowBlocks::kGranule), dist,
                        cluster_of, means);
}

double clustering_energy(const Eigen::Ref<const DataMatrix>& x,
                         const std::vector<std::uint32_t>& cluster_of, const DataMatrix& means) {
  return clustering_energy(RowBlocks(x), cluster_of, means);
}

namespace {

// The split needs a direction of large spread, not the exact principal axis: a strided
// sample of at most kSplitSample members finds it in cache, and one pass over all members
// then classifies them. Gathering the whole cluster and iterating over it cost a third of
// LBG's time on a 557 k-vertex bake, where the first splits halve clusters of 10^5 rows.
constexpr Eigen::Index kSplitSample = 2048;

// (x - mean) . dir in double, summed in column order: the same bits for a row wherever it
// lives (in memory or in a map at another alignment) and whichever thread computes it.
double offset_along(const float* x, const Eigen::VectorXd& mean, const Eigen::VectorXd& dir) {
  double s = 0.0;
  for (Eigen::Index c = 0; c < dir.size(); ++c) s += (double(x[c]) - mean[c]) * dir[c];
  return s;
}

// The members' rows come through gather(), a block at a time, so a split of an
// out-of-core cluster keeps neither the cluster nor its pages resident.
int split_clusters(const RowBlocks& x, std::vector<std::uint32_t>& cluster_of, int cluster_count) {
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
    const Eigen::Index s = std::min(m, kSplitSample);
    std::vector<std::uint32_t> picked(static_cast<std::size_t>(s));
    for (Eigen::Index i = 0; i < s; ++i) picked[std::size_t(i)] = members[std::size_t(i * m / s)];
    DataMatrix sample(s, x.cols());
    x.gather(picked.data(), s, sample.data());
    const Eigen::RowVectorXf mean = sample.colwise().mean();
    sample.rowwise() -= mean;
    // Principal direction by power iteration, started from the farthest point's offset
    // (deterministic, and already close to the direction of largest spread).
    Eigen::Index far = 0;
    sample.rowwise().squaredNorm().maxCoeff(&far);
    Eigen::VectorXf dir = sample.row(far).transpose();
    Eigen::VectorXf proj;
    for (int it = 0; it < 6 && dir.squaredNorm() > 0; ++it) {
      proj.noalias() = sample * dir;
      dir.noalias() = sample.transpose() * proj;
      const float norm = dir.norm();
      if (!(norm > 0)) break;
      dir /= norm;
    }
    const Eigen::VectorXd mean_d = mean.transpose().cast<double>(), dir_d = dir.cast<double>();
    std::vector<char> positive(members.size());
    constexpr Eigen::Index kRows = RowBlocks::kGranule;
    tbb::parallel_for(Eigen::Index(0), (m + kRows - 1) / kRows, [&](Eigen::Index b) {
      const Eigen::Index begin = b * kRows, rows = std::min(kRows, m - begin);
      DataMatrix block(rows, x.cols());
      x.gather(members.data() + begin, rows, block.data());
      for (Eigen::Index i = 0; i < rows; ++i)
        positive[std::size_t(begin + i)] = offset_along(&block(i, 0), mean_d, dir_d) > 0;
    });
    std::vector<std::uint32_t> moved;
    for (Eigen::Index i = 0; i < m; ++i)
      if (positive[std::size_t(i)]) moved.push_back(members[std::size_t(i)]);
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
  return split_clusters(RowBlocks(x), cluster_of, cluster_count);
}

int split_empty_clusters(const RowBlocks& x, std::vector<std::uint32_t>& cluster_of,
                         int cluster_count) {
  return split_clusters(x, cluster_of, cluster_count);
}

namespace {

// Every rank runs the same iterations on the same broadcast quantities, so all ranks take the
// same decisions (splits, convergence) and end with the same means and ids.
LbgResult run_lbg(const RowBlocks& x, const LbgOptions& options, const GeometryCoherence* coherence,
                  const LbgCallback& callback, Distribution& dist) {
  const int k = options.clusters;
  if (k < 1 || Eigen::Index(k) > x.rows())
    throw std::invalid_argument("LBG: cluster count must be in [1, points] = [1, " +
                                std::to_string(x.rows()) + "], got " + std::to_string(k));
  if (!(options.threshold >= 0) || options.max_iterations < 1)
    throw std::invalid_argument("LBG: threshold must be >= 0 and max_iterations >= 1");
  if (coherence && dist.size() > 1)
    throw std::invalid_argument("LBG: geometry coherence does not run distributed");
  const RowRange mine = rank_rows(x.rows(), dist.rank(), dist.size(), RowBlocks::kGranule);
  const Eigen::VectorXf norms = row_squared_norms(x, mine);
  LbgResult r;
  r.means = hyper_box_means(x, mine, dist, k, options.seed);
  double previous = 0.0;
  for (int it = 1; it <= options.max_iterations; ++it) {
    if (coherence && it > 1) {
      // Coherence weighs every cluster for every point against the previous membership:
      // it needs all rows' distances at once (V x K), so it does not stream.
      const DataMatrix d2 = squared_distances(x.all(), norms, r.means);
      x.release_all();
      r.cluster_of = coherence->assign(d2, r.cluster_of, std::sqrt(previous / double(x.rows())));
    } else {
      r.cluster_of = nearest_means(x, mine, dist, norms, r.means);
    }
    // The same ids on every rank, so every rank makes the same splits.
    r.splits += split_empty_clusters(x, r.cluster_of, k);
    r.means = chained_means(x, mine, dist, r.cluster_of, k);
    const double energy = chained_energy(x, mine, dist, r.cluster_of, r.means);
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

}  // namespace

LbgResult lbg(const RowBlocks& x, const LbgOptions& options, const GeometryCoherence* coherence,
              const LbgCallback& callback) {
  SingleProcess one;
  return run_lbg(x, options, coherence, callback, one);
}

LbgResult lbg(const RowBlocks& x, const LbgOptions& options, Distribution& distribution,
              const LbgCallback& callback) {
  return run_lbg(x, options, nullptr, callback, distribution);
}

LbgResult lbg(const Eigen::Ref<const DataMatrix>& x, const LbgOptions& options,
              const GeometryCoherence* coherence, const LbgCallback& callback) {
  return lbg(RowBlocks(x), options, coherence, callback);
}

}  // namespace cpca
