#include "cpca/cluster_pca.h"

#include "cpca/assignment.h"
#include "cpca/lbg.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cstring>
#include <functional>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

namespace cpca {
namespace {

// Rows `m` of x, kGranule at a time through RowBlocks::gather: f(i, row) for member i.
template <class F>
void for_each_member_row(const RowBlocks& x, const std::vector<std::uint32_t>& m, F&& f) {
  constexpr Eigen::Index kRows = RowBlocks::kGranule;
  const Eigen::Index rows = Eigen::Index(m.size());
  DataMatrix block(std::min(kRows, rows), x.cols());
  for (Eigen::Index begin = 0; begin < rows; begin += kRows) {
    const Eigen::Index n = std::min(kRows, rows - begin);
    x.gather(m.data() + begin, n, block.data());
    for (Eigen::Index i = 0; i < n; ++i) f(begin + i, block.row(i));
  }
}

// A cluster's rows come through RowBlocks::gather, so an out-of-core source keeps no pages
// of them resident.
std::vector<double> fit_clusters(const RowBlocks& x, CompressedSet& set, PcaSolver solver,
                                 const PowerIterationOptions& power, ClusterPcaStats* stats,
                                 const std::function<bool(int)>& fits = {},
                                 const std::vector<float>* warm = nullptr,
                                 const std::vector<const Eigen::MatrixXd*>* grams = nullptr,
                                 bool keep_others = false) {
  const int k = set.cluster_count, n = set.component_count;
  const Eigen::Index d = x.cols();
  set.vertex_count = std::uint64_t(x.rows());
  set.solver = solver;
  // keep_others: the clusters `fits` skips keep their numbers (the arrays are full size).
  if (!keep_others) {
    set.means.assign(std::size_t(k) * std::size_t(d), 0.f);
    set.bases.assign(std::size_t(k) * std::size_t(n) * std::size_t(d), 0.f);
    set.weights.assign(std::size_t(x.rows()) * std::size_t(n), 0.f);
  }
  std::vector<double> error(std::size_t(x.rows()), 0.0);
  const auto members = cluster_members(set.cluster_of, k);
  // Largest clusters first, so one big cluster does not finish alone at the end.
  std::vector<int> order(static_cast<std::size_t>(k));
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return members[std::size_t(a)].size() > members[std::size_t(b)].size();
  });
  std::atomic<int> iterations{0};
  tbb::parallel_for(0, k, [&](int o) {
    const int c = order[std::size_t(o)];
    const auto& m = members[std::size_t(c)];
    if (m.empty() || (fits && !fits(c))) return;
    const Eigen::Index rows = Eigen::Index(m.size());
    Eigen::MatrixXd f(rows, d);
    for_each_member_row(
        x, m, [&](Eigen::Index i, const auto& row) { f.row(i) = row.template cast<double>(); });
    const Eigen::RowVectorXd mean = f.colwise().mean();
    f.rowwise() -= mean;
    Eigen::Map<Eigen::RowVectorXf>(set.means.data() + std::size_t(c) * std::size_t(d), d) =
        mean.cast<float>();
    Eigen::MatrixXd basis = Eigen::MatrixXd::Zero(n, d);
    const int rank_limit = int(std::min<Eigen::Index>({Eigen::Index(n), rows, d}));
    if (rank_limit >= 1) {
      PowerIterationOptions po = power;
      Eigen::MatrixXd start;
      if (warm) {
        start =
            Eigen::Map<const Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
                warm->data() + std::size_t(c) * std::size_t(n) * std::size_t(d), n, d)
                .cast<double>();
        po.start = &start;
      }
      const Eigen::MatrixXd* gram = grams ? (*grams)[std::size_t(c)] : nullptr;
      PcaResult pca;
      if (solver == PcaSolver::kEigen) {
        pca = eigen_pca(f, rank_limit);
      } else if (gram && rows < d) {
        // Centred from the caller's uncentred x_i . x_j: (x_i - mu) . (x_j - mu) =
        // G_ij - r_i - r_j + s with r_i = x_i . mu (the mean of row i of G), s = mu . mu.
        const Eigen::VectorXd r = gram->rowwise().mean();
        Eigen::MatrixXd centred = *gram;
        centred.colwise() -= r;
        centred.rowwise() -= r.transpose();
        centred.array() += r.mean();
        pca = power_iteration_pca_gram(f, std::move(centred), rank_limit, po);
      } else {
        pca = power_iteration_pca(f, rank_limit, po);
      }
      basis.topRows(rank_limit) = pca.basis;
      iterations += pca.iterations;
    }
    // Store the float basis and project onto it, so weights match what the renderer
    // reconstructs from the stored numbers.
    Eigen::Map<Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> stored(
        set.bases.data() + std::size_t(c) * std::size_t(n) * std::size_t(d), n, d);
    stored = basis.cast<float>();
    const Eigen::MatrixXd b = stored.cast<double>();
    // The weights as stored (float), and each member's squared residual against the stored
    // mean and basis, r = f + delta - w b with delta = mean - mean_f (x - mean_f = f + delta),
    // expanded so that no d-wide residual is formed:
    //   |r|^2 = |f|^2 + 2 f.delta + |delta|^2 - 2 w.(c + delta b^T) + w (b b^T) w^T,
    // with c = f b^T the projections before rounding. The terms cancel in double to about
    // 1e-16 |f|^2, below the float weights' own rounding; forming r cost a second
    // rows x n x d product and a pass over f.
    const Eigen::MatrixXd projections = f * b.transpose();  // rows x n
    const Eigen::MatrixXd w = projections.cast<float>().cast<double>();
    const Eigen::RowVectorXd delta = mean - mean.cast<float>().cast<double>();
    // Column by column: a row of f is strided, and its squared norm one serial chain of d
    // multiply-adds (a third of a small cluster's refit on the horse).
    Eigen::VectorXd squared = Eigen::VectorXd::Zero(rows);
    for (Eigen::Index j = 0; j < d; ++j) squared += f.col(j).cwiseAbs2();
    squared += 2 * (f * delta.transpose());
    squared.array() += delta.squaredNorm();
    const Eigen::MatrixXd shifted = projections.rowwise() + delta * b.transpose();
    squared -= 2 * w.cwiseProduct(shifted).rowwise().sum();
    squared += (w * (b * b.transpose())).cwiseProduct(w).rowwise().sum();
    for (Eigen::Index i = 0; i < rows; ++i) {
      const std::uint32_t p = m[std::size_t(i)];
      for (int j = 0; j < n; ++j)
        set.weights[std::size_t(p) * std::size_t(n) + std::size_t(j)] = float(w(i, j));
      error[p] = std::max(0.0, squared[i]);
    }
  });
  if (stats) stats->power_iterations = iterations;
  return error;
}

}  // namespace

std::vector<double> fit_cluster_pca(const Eigen::Ref<const DataMatrix>& x, CompressedSet& set,
                                    PcaSolver solver, const PowerIterationOptions& power,
                                    ClusterPcaStats* stats) {
  return fit_clusters(RowBlocks(x), set, solver, power, stats);
}

std::vector<double> fit_cluster_pca(const RowBlocks& x, CompressedSet& set, PcaSolver solver,
                                    const PowerIterationOptions& power, ClusterPcaStats* stats) {
  return fit_clusters(x, set, solver, power, stats);
}

std::vector<double> fit_cluster_pca_warm(const Eigen::Ref<const DataMatrix>& x, CompressedSet& set,
                                         const std::vector<float>& previous_bases,
                                         const PowerIterationOptions& power,
                                         const std::vector<const Eigen::MatrixXd*>& grams,
                                         const std::vector<char>& only) {
  if (!grams.empty() && grams.size() != std::size_t(set.cluster_count))
    throw std::invalid_argument("fit_cluster_pca_warm: " + std::to_string(grams.size()) +
                                " Gram matrices for " + std::to_string(set.cluster_count) +
                                " clusters");
  const std::size_t d = std::size_t(x.cols()), n = std::size_t(set.component_count);
  if (!only.empty() && (only.size() != std::size_t(set.cluster_count) ||
                        set.means.size() != std::size_t(set.cluster_count) * d ||
                        set.bases.size() != std::size_t(set.cluster_count) * n * d ||
                        set.weights.size() != std::size_t(x.rows()) * n))
    throw std::invalid_argument(
        "fit_cluster_pca_warm: refitting some clusters needs one flag per cluster and the "
        "set's means, bases and weights at full size");
  if (previous_bases.size() !=
      std::size_t(set.cluster_count) * std::size_t(set.component_count) * std::size_t(x.cols()))
    throw std::invalid_argument("fit_cluster_pca_warm: the previous bases hold " +
                                std::to_string(previous_bases.size()) +
                                " floats, not clusters x components x dimension");
  std::function<bool(int)> fits;
  if (!only.empty()) fits = [&only](int c) { return only[std::size_t(c)] != 0; };
  return fit_clusters(RowBlocks(x), set, PcaSolver::kPowerIteration, power, nullptr, fits,
                      &previous_bases, grams.empty() ? nullptr : &grams, !only.empty());
}

namespace {

// What rank `rank` of `ranks` fitted, in the order both sides walk it: for each of its
// clusters (c = rank, rank + ranks, ...) the mean, the basis and its members' weights as
// floats, and its members' errors as doubles.
struct ClusterShare {
  std::vector<float> floats;
  std::vector<double> errors;
};

template <class F>
void walk_share(const CompressedSet& set, const std::vector<std::vector<std::uint32_t>>& members,
                int rank, int ranks, F&& visit) {
  const std::size_t n = std::size_t(set.component_count), d = set.dimension();
  for (int c = rank; c < set.cluster_count; c += ranks) {
    if (members[std::size_t(c)].empty()) continue;
    visit(std::size_t(c) * d, d, std::size_t(c) * n * d, n * d, members[std::size_t(c)]);
  }
}

ClusterShare pack_share(const CompressedSet& set, const std::vector<double>& error,
                        const std::vector<std::vector<std::uint32_t>>& members, int rank,
                        int ranks) {
  ClusterShare out;
  const std::size_t n = std::size_t(set.component_count);
  walk_share(set, members, rank, ranks,
             [&](std::size_t mean, std::size_t d, std::size_t basis, std::size_t nd,
                 const std::vector<std::uint32_t>& m) {
               auto add = [&](const float* p, std::size_t count) {
                 out.floats.insert(out.floats.end(), p, p + count);
               };
               add(set.means.data() + mean, d);
               add(set.bases.data() + basis, nd);
               for (std::uint32_t p : m) {
                 add(set.weights.data() + std::size_t(p) * n, n);
                 out.errors.push_back(error[p]);
               }
             });
  return out;
}

// The inverse of pack_share; advances `floats` and `errors` past what it read.
void unpack_share(CompressedSet& set, std::vector<double>& error, const float*& floats,
                  const double*& errors, const std::vector<std::vector<std::uint32_t>>& members,
                  int rank, int ranks) {
  const std::size_t n = std::size_t(set.component_count);
  walk_share(set, members, rank, ranks,
             [&](std::size_t mean, std::size_t d, std::size_t basis, std::size_t nd,
                 const std::vector<std::uint32_t>& m) {
               auto take = [&](float* to, std::size_t count) {
                 std::copy(floats, floats + count, to);
                 floats += count;
               };
               take(set.means.data() + mean, d);
               take(set.bases.data() + basis, nd);
               for (std::uint32_t p : m) {
                 take(set.weights.data() + std::size_t(p) * n, n);
                 error[p] = *errors++;
               }
             });
}

}  // namespace

std::vector<double> fit_cluster_pca(const RowBlocks& x, CompressedSet& set, PcaSolver solver,
                                    const PowerIterationOptions& power, ClusterPcaStats* stats,
                                    Distribution& dist) {
  const int rank = dist.rank(), ranks = dist.size();
  ClusterPcaStats own;
  std::vector<double> error =
      fit_clusters(x, set, solver, power, &own, [&](int c) { return c % ranks == rank; });
  if (ranks > 1) {
    // Every rank holds the same ids, so rank 0 knows the layout of every share.
    const auto members = cluster_members(set.cluster_of, set.cluster_count);
    ClusterShare share = pack_share(set, error, members, rank, ranks);
    share.errors.push_back(double(own.power_iterations));
    const auto floats = dist.gather(share.floats.data(), share.floats.size() * sizeof(float), 0);
    const auto errors = dist.gather(share.errors.data(), share.errors.size() * sizeof(double), 0);
    if (dist.first()) {
      std::vector<float> f(floats.size() / sizeof(float));
      std::vector<double> e(errors.size() / sizeof(double));
      std::memcpy(f.data(), floats.data(), floats.size());
      std::memcpy(e.data(), errors.data(), errors.size());
      const float* fp = f.data();
      const double* ep = e.data();
      own.power_iterations = 0;
      for (int r = 0; r < ranks; ++r) {
        unpack_share(set, error, fp, ep, members, r, ranks);
        own.power_iterations += int(*ep++);
      }
    }
  }
  if (stats) *stats = own;
  return error;
}

DataMatrix subspace_distances(const Eigen::Ref<const DataMatrix>& x,
                              const Eigen::VectorXf& x_squared_norms, const CompressedSet& set) {
  const int k = set.cluster_count, n = set.component_count;
  const Eigen::Index v = x.rows(), d = x.cols();
  const Eigen::Map<const DataMatrix> means(set.means.data(), k, d);
  const Eigen::Map<const DataMatrix> bases(set.bases.data(), Eigen::Index(k) * n, d);
  // Per cluster: ||m_k||^2 and c_k = B_k m_k, so that B_k (x - m_k) = B_k x - c_k.
  const Eigen::RowVectorXf mean_norms = means.rowwise().squaredNorm().transpose();
  Eigen::RowVectorXf c(Eigen::Index(k) * n);
  for (int j = 0; j < k; ++j)
    c.segment(Eigen::Index(j) * n, n) =
        (bases.middleRows(Eigen::Index(j) * n, n) * means.row(j).transpose()).transpose();
  DataMatrix out(v, k);
  constexpr Eigen::Index kBlock = 256;
  tbb::parallel_for(Eigen::Index(0), (v + kBlock - 1) / kBlock, [&](Eigen::Index b) {
    const Eigen::Index begin = b * kBlock, rows = std::min(kBlock, v - begin);
    const auto xb = x.middleRows(begin, rows);
    DataMatrix proj(rows, Eigen::Index(k) * n);
    if (n > 0) proj.noalias() = xb * bases.transpose();
    auto block = out.middleRows(begin, rows);
    block.noalias() = -2.f * xb * means.transpose();
    block.rowwise() += mean_norms;
    block.colwise() += x_squared_norms.segment(begin, rows);
    if (n > 0) {
      proj.rowwise() -= c;
      for (int j = 0; j < k; ++j)
        block.col(j) -= proj.middleCols(Eigen::Index(j) * n, n).rowwise().squaredNorm();
    }
    block = block.cwiseMax(0.f);
  });
  return out;
}

namespace {

// The `count` ids in [0, k) of least distance(id), ties to the lower id, then `own` when it
// is not among them.
template <class Distance>
std::vector<std::uint32_t> nearest_ids(int k, int count, std::uint32_t own, Distance distance) {
  std::vector<std::uint32_t> order(static_cast<std::size_t>(k));
  std::iota(order.begin(), order.end(), 0u);
  std::nth_element(order.begin(), order.begin() + (count - 1), order.end(),
                   [&](std::uint32_t a, std::uint32_t b) {
                     const float da = distance(a), db = distance(b);
                     return da < db || (da == db && a < b);
                   });
  order.resize(std::size_t(count));
  if (std::find(order.begin(), order.end(), own) == order.end()) order.push_back(own);
  return order;
}

// V x K, +infinity but for the points listed per cluster: column c holds points[c]'s squared
// distances to cluster c's affine subspace.
DataMatrix listed_distances(const Eigen::Ref<const DataMatrix>& x, const CompressedSet& set,
                            const std::vector<std::vector<std::uint32_t>>& points) {
  DataMatrix out =
      DataMatrix::Constant(x.rows(), set.cluster_count, std::numeric_limits<float>::infinity());
  tbb::parallel_for(0, set.cluster_count, [&](int c) {
    const std::vector<std::uint32_t>& members = points[std::size_t(c)];
    const std::vector<float> residual = subspace_residuals(x, set, c, members);
    // Columns of `out` are written by one task each: no two tasks touch the same entry.
    for (std::size_t i = 0; i < members.size(); ++i) out(members[i], c) = residual[i];
  });
  return out;
}

}  // namespace

DataMatrix subspace_distances(const Eigen::Ref<const DataMatrix>& x,
                              const Eigen::VectorXf& x_squared_norms, const CompressedSet& set,
                              int candidates) {
  const int k = set.cluster_count;
  if (candidates <= 0 || candidates >= k) return subspace_distances(x, x_squared_norms, set);
  const Eigen::Index v = x.rows(), d = x.cols();
  const Eigen::Map<const DataMatrix> means(set.means.data(), k, d);
  const DataMatrix to_means = squared_distances(x, x_squared_norms, means);
  std::vector<std::vector<std::uint32_t>> chosen(static_cast<std::size_t>(v));
  tbb::parallel_for(Eigen::Index(0), v, [&](Eigen::Index p) {
    chosen[std::size_t(p)] = nearest_ids(k, candidates, set.cluster_of[std::size_t(p)],
                                         [&](std::uint32_t c) { return to_means(p, c); });
  });
  std::vector<std::vector<std::uint32_t>> points(static_cast<std::size_t>(k));
  for (Eigen::Index p = 0; p < v; ++p)
    for (std::uint32_t j : chosen[std::size_t(p)]) points[j].push_back(std::uint32_t(p));
  return listed_distances(x, set, points);
}

std::vector<std::vector<std::uint32_t>> cluster_closures(const CompressedSet& set, int candidates) {
  const int k = set.cluster_count;
  const Eigen::Map<const DataMatrix> means(set.means.data(), k, Eigen::Index(set.dimension()));
  const DataMatrix between = squared_distances(means, means.rowwise().squaredNorm(), means);
  std::vector<std::vector<std::uint32_t>> closure(static_cast<std::size_t>(k));
  tbb::parallel_for(0, k, [&](int c) {
    closure[std::size_t(c)] = nearest_ids(k, std::clamp(candidates, 1, k), std::uint32_t(c),
                                          [&](std::uint32_t b) { return between(c, b); });
  });
  return closure;
}

DataMatrix subspace_distances_near_clusters(const Eigen::Ref<const DataMatrix>& x,
                                            const CompressedSet& set, int candidates) {
  const int k = set.cluster_count;
  const std::vector<std::vector<std::uint32_t>> closure = cluster_closures(set, candidates);
  std::vector<std::vector<std::uint32_t>> points(static_cast<std::size_t>(k));
  for (std::uint32_t p = 0; p < set.cluster_of.size(); ++p)
    for (std::uint32_t c : closure[set.cluster_of[p]]) points[c].push_back(p);
  return listed_distances(x, set, points);
}

std::vector<float> subspace_residuals(const Eigen::Ref<const DataMatrix>& x,
                                      const CompressedSet& set, int cluster,
                                      const std::vector<std::uint32_t>& points) {
  // In chunks whose centred rows stay in cache for the product that reads them again: one
  // centred copy of every point cost more in memory traffic than the product itself.
  constexpr std::size_t kChunk = 64;
  const Eigen::Index d = x.cols();
  const auto mean = set.mean(cluster);
  std::vector<float> out(points.size());
  DataMatrix centred(Eigen::Index(std::min(kChunk, points.size())), d);
  for (std::size_t begin = 0; begin < points.size(); begin += kChunk) {
    const Eigen::Index rows = Eigen::Index(std::min(kChunk, points.size() - begin));
    auto block = centred.topRows(rows);
    for (Eigen::Index i = 0; i < rows; ++i)
      block.row(i) = x.row(points[begin + std::size_t(i)]) - mean;
    Eigen::VectorXf residual = block.rowwise().squaredNorm();
    if (set.component_count > 0)
      residual -= (block * set.basis(cluster).transpose()).rowwise().squaredNorm();
    for (Eigen::Index i = 0; i < rows; ++i)
      out[begin + std::size_t(i)] = std::max(0.f, residual[i]);
  }
  return out;
}

double subspace_distance(const Eigen::Ref<const Eigen::RowVectorXf>& x, const CompressedSet& set,
                         int cluster) {
  const Eigen::RowVectorXd centred = (x - set.mean(cluster)).cast<double>();
  if (set.component_count == 0) return centred.squaredNorm();
  const Eigen::MatrixXd b = set.basis(cluster).cast<double>();
  const Eigen::VectorXd w = b * centred.transpose();
  return std::max(0.0, centred.squaredNorm() - w.squaredNorm());
}

}  // namespace cpca
