#include "cpca/compress.h"

#include "cpca/cluster_pca.h"
#include "cpca/joint_search.h"
#include "cpca/patch_first.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <numeric>
#include <stdexcept>
#include <string>

namespace cpca {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

double sum(const std::vector<double>& v) {
  return std::accumulate(v.begin(), v.end(), 0.0);
}

DataLayout resolve_layout(const DataLayout& given, Eigen::Index d);

void check(const RowBlocks& data, const CompressOptions& o, const Geometry* geometry) {
  auto bad = [](const std::string& what) { throw std::invalid_argument(what); };
  if (data.rows() < 1 || data.cols() < 1) bad("compress: the data is empty");
  if (o.clusters < 1 || Eigen::Index(o.clusters) > data.rows())
    bad("clusters must be in [1, vertices] = [1, " + std::to_string(data.rows()) + "], got " +
        std::to_string(o.clusters));
  if (o.components < 0 || Eigen::Index(o.components) >= data.cols())
    bad("PCs must be in [0, dimension - 1] = [0, " + std::to_string(data.cols() - 1) + "], got " +
        std::to_string(o.components));
  if (!(o.alpha >= 0) || !std::isfinite(o.alpha))
    bad("alpha must be finite and >= 0, got " + std::to_string(o.alpha));
  if ((o.alpha > 0 || o.overdraw_reduction) && !geometry)
    bad("geometry coherence and overdraw reduction need the mesh");
  if (geometry && geometry->positions.size() != std::size_t(data.rows()))
    bad("the mesh has " + std::to_string(geometry->positions.size()) +
        " vertices but the transfer has " + std::to_string(data.rows()) +
        ": bake the transfer from this mesh again");
  resolve_layout(o.layout, data.cols());
  bool finite = true;
  data.for_each([&](Eigen::Index, const auto& block) { finite = finite && block.allFinite(); });
  if (!finite) bad("the transfer data holds NaN or infinite values: bake it again");
}

DataLayout resolve_layout(const DataLayout& given, Eigen::Index d) {
  auto size = [](const DataLayout& l) {
    return Eigen::Index(l.channels) * l.order * l.order * l.columns;
  };
  if (given.order != 0) {
    if (size(given) != d)
      throw std::invalid_argument("compress: layout (order " + std::to_string(given.order) + ", " +
                                  std::to_string(given.channels) + " channels, " +
                                  std::to_string(given.columns) + " columns) does not match " +
                                  "the data dimension " + std::to_string(d));
    return given;
  }
  // A size two layouts share (16: diffuse order 4 or glossy order 2) is refused rather than
  // guessed: a wrong guess compresses without complaint and renders nonsense.
  std::vector<DataLayout> matches;
  std::string names;
  for (int channels : {1, 3})
    for (bool glossy : {false, true})
      for (int order = 1; order <= 10; ++order) {
        const DataLayout l{order, channels, glossy ? order * order : 1};
        if (size(l) != d) continue;
        matches.push_back(l);
        names += std::string(names.empty() ? "" : " or ") + (glossy ? "glossy" : "diffuse") +
                 " order " + std::to_string(order) + (channels == 3 ? " RGB" : " grey");
      }
  if (matches.size() == 1) return matches.front();
  if (matches.empty())
    throw std::invalid_argument("compress: data dimension " + std::to_string(d) +
                                " is not the size of an SH transfer vector or matrix");
  throw std::invalid_argument("compress: data dimension " + std::to_string(d) + " fits " + names +
                              "; set CompressOptions::layout to say which");
}

}  // namespace

TriangleSpan triangle_span(const std::vector<std::uint32_t>& cluster_of,
                           const std::vector<TriangleIndices>& triangles) {
  TriangleSpan s;
  for (const TriangleIndices& t : triangles) {
    const std::uint32_t a = cluster_of[t[0]], b = cluster_of[t[1]], c = cluster_of[t[2]];
    const int distinct = 1 + (b != a) + (c != a && c != b);
    (distinct == 1 ? s.one : distinct == 2 ? s.two : s.three)++;
  }
  return s;
}

ErrorMetrics error_metrics(const Eigen::Ref<const DataMatrix>& data, const CompressedSet& set) {
  validate(set);
  if (set.vertex_count != std::uint64_t(data.rows()) || set.dimension() != std::size_t(data.cols()))
    throw std::invalid_argument("error_metrics: the set does not match the data's shape");
  return error_metrics_by_row(
      data, [&](Eigen::Index p, float* out) { reconstruct_vertex(set, std::uint64_t(p), out); });
}

namespace {

using Notify = std::function<void(const char*, double)>;

// Stage 1, LBG. Progress: log of the converged ratio against log of the threshold.
LbgResult run_lbg(const RowBlocks& data, const CompressOptions& options,
                  GeometryCoherence* coherence, Distribution& dist, const Notify& notify) {
  LbgOptions lbg_options;
  lbg_options.clusters = options.clusters;
  lbg_options.threshold = options.lbg_threshold;
  lbg_options.max_iterations = options.lbg_max_iterations;
  lbg_options.seed = options.seed;
  notify("lbg", 0);
  const LbgCallback progress = [&](int it, double, double ratio) {
    const double by_ratio = ratio > 0 && options.lbg_threshold > 0
                                ? std::log(ratio) / std::log(options.lbg_threshold)
                                : 1.0;
    notify("lbg", std::max(by_ratio, double(it) / options.lbg_max_iterations));
  };
  return dist.size() > 1 ? lbg(data, lbg_options, dist, progress)
                         : lbg(data, lbg_options, coherence, progress);
}

// Distributed, only the streaming stages run: iterative CPCA, coherence and the overdraw
// reduction compare every point with many clusters (V x K) and have no chained form.
void check_distributed(const CompressOptions& o, const Distribution& dist) {
  if (dist.size() > 1 && (o.method != ClusterMethod::kLbg || o.alpha > 0 || o.overdraw_reduction))
    throw std::invalid_argument(
        "a distributed compression runs LBG only (no iterative CPCA, alpha or overdraw "
        "reduction): run those in one process");
}

CompressedSet new_set(const CompressOptions& options, const DataLayout& layout,
                      std::vector<std::uint32_t> cluster_of) {
  return {.order = layout.order,
          .channels = layout.channels,
          .columns = layout.columns,
          .cluster_count = options.clusters,
          .component_count = options.components,
          .method = options.method,
          .alpha = options.alpha,
          .overdraw_reduction = options.overdraw_reduction,
          .seed = options.seed,
          .cluster_of = std::move(cluster_of)};
}

// Stage 3, iterative CPCA: reassign to the best-reconstructing cluster, refit, until the
// error stops falling; a step that raises it (possible with coherence) is undone. It compares
// every point with many clusters' subspaces (V x K), so it takes the whole view, not blocks.
void iterate_cpca(const Eigen::Ref<const DataMatrix>& data, const CompressOptions& options,
                  GeometryCoherence* coherence, const PowerIterationOptions& power,
                  CompressedSet& set, std::vector<double>& vertex_error, CompressReport& r,
                  const Notify& notify) {
  ClusterPcaStats stats;
  const Eigen::VectorXf norms = data.rowwise().squaredNorm();
  double error = sum(vertex_error);
  r.cpca_error.push_back(error);
  for (int it = 1; it <= options.cpca_max_iterations && error > 0; ++it) {
    notify("cpca", double(it - 1) / options.cpca_max_iterations);
    const DataMatrix d2 = subspace_distances(data, norms, set, options.cpca_candidates);
    CompressedSet next = set;
    next.cluster_of =
        coherence ? coherence->assign(d2, set.cluster_of, std::sqrt(error / double(data.rows())))
                  : argmin_rows(d2);
    r.splits += split_empty_clusters(data, next.cluster_of, set.cluster_count);
    std::vector<double> next_error = fit_cluster_pca(data, next, options.solver, power, &stats);
    r.power_iterations += stats.power_iterations;
    const double e = sum(next_error);
    r.cpca_iterations = it;
    if (!(e < error)) break;
    const bool converged = (error - e) / error < options.cpca_threshold;
    set = std::move(next);
    vertex_error = std::move(next_error);
    error = e;
    r.cpca_error.push_back(error);
    if (converged) break;
  }
}

// The errors, size and triangle span of the final set.
void measure(const RowBlocks& data, const CompressOptions& options, const Geometry* geometry,
             const CompressedSet& set, const std::vector<double>& vertex_error, CompressReport& r) {
  const double total = sum(vertex_error);
  Eigen::VectorXd row_norms(data.rows());
  data.for_each([&](Eigen::Index first, const auto& block) {
    row_norms.segment(first, block.rows()) = block.rowwise().squaredNorm().template cast<double>();
  });
  const double norm = row_norms.sum();
  r.error.average_squared_error = total / double(data.rows());
  r.error.relative_error = norm > 0 ? total / norm : 0.0;
  r.error.max_squared_error = *std::max_element(vertex_error.begin(), vertex_error.end());
  r.size = size_metrics(std::uint64_t(data.rows()), std::uint64_t(data.cols()),
                        std::uint64_t(options.clusters), std::uint64_t(options.components));
  if (geometry) {
    r.has_geometry = true;
    r.span = triangle_span(set.cluster_of, geometry->triangles);
  }
}

}  // namespace

CompressedSet fit_clustering(const Eigen::Ref<const DataMatrix>& data,
                             const CompressOptions& options, std::vector<std::uint32_t> cluster_of,
                             std::vector<double>* vertex_error) {
  if (cluster_of.size() != std::size_t(data.rows()))
    throw std::invalid_argument("fit_clustering: " + std::to_string(cluster_of.size()) +
                                " cluster labels for " + std::to_string(data.rows()) + " rows");
  for (std::uint32_t c : cluster_of)
    if (c >= std::uint32_t(options.clusters))
      throw std::invalid_argument("fit_clustering: cluster " + std::to_string(c) +
                                  " is out of range for " + std::to_string(options.clusters) +
                                  " clusters");
  CompressOptions lbg = options;
  lbg.method = ClusterMethod::kLbg;
  CompressedSet set =
      new_set(lbg, resolve_layout(options.layout, data.cols()), std::move(cluster_of));
  PowerIterationOptions power;
  power.seed = options.seed;
  std::vector<double> error = fit_cluster_pca(data, set, options.solver, power);
  if (vertex_error) *vertex_error = std::move(error);
  return set;
}

CompressedSet compress(const Eigen::Ref<const DataMatrix>& data, const CompressOptions& options,
                       const Geometry* geometry, CompressReport* report,
                       const CompressProgress& progress) {
  return compress(RowBlocks(data), options, geometry, report, progress);
}

CompressedSet compress(const RowBlocks& data, const CompressOptions& options,
                       const Geometry* geometry, CompressReport* report,
                       const CompressProgress& progress, Distribution* distribution) {
  SingleProcess one;
  Distribution& dist = distribution ? *distribution : one;
  check_distributed(options, dist);
  check(data, options, geometry);
  if (options.method == ClusterMethod::kPatchFirst || options.method == ClusterMethod::kJoint ||
      options.method == ClusterMethod::kPatchJoint ||
      options.method == ClusterMethod::kPatchEpsilon) {
    if (!geometry) throw std::invalid_argument("the patch-first and joint methods need the mesh");
    return options.method == ClusterMethod::kPatchFirst
               ? compress_patch_first(data.all(), options, *geometry, report)
               : compress_joint(data.all(), options, *geometry, report);
  }
  CompressReport local;
  CompressReport& r = report ? *report : local;
  r = CompressReport{};
  const auto start = Clock::now();
  const Notify notify = [&](const char* stage, double fraction) {
    if (progress) progress(stage, std::clamp(fraction, 0.0, 1.0));
  };

  // 1. LBG clustering, geometry-coherent when alpha > 0.
  auto t = Clock::now();
  std::unique_ptr<GeometryCoherence> coherence;
  if (options.alpha > 0)
    coherence =
        std::make_unique<GeometryCoherence>(*geometry, std::size_t(data.rows()), options.alpha);
  LbgResult clustering = run_lbg(data, options, coherence.get(), dist, notify);
  r.lbg_seconds = seconds_since(t);
  r.lbg_iterations = clustering.iterations;
  r.splits = clustering.splits;
  r.lbg_energy = clustering.energy;
  CompressedSet set = new_set(options, resolve_layout(options.layout, data.cols()),
                              std::move(clustering.cluster_of));

  // 2. PCA per cluster.
  t = Clock::now();
  notify("pca", 0);
  PowerIterationOptions power;
  power.seed = options.seed;
  ClusterPcaStats stats;
  std::vector<double> vertex_error =
      dist.size() > 1 ? fit_cluster_pca(data, set, options.solver, power, &stats, dist)
                      : fit_cluster_pca(data, set, options.solver, power, &stats);
  r.power_iterations += stats.power_iterations;
  r.pca_seconds = seconds_since(t);
  notify("pca", 1);
  if (!dist.first()) return set;  // rank 0 holds the whole set

  // 3. Iterative CPCA (Sloan et al. 2003), when asked for.
  int iterations = clustering.iterations;
  if (options.method == ClusterMethod::kIterative) {
    t = Clock::now();
    iterate_cpca(data.all(), options, coherence.get(), power, set, vertex_error, r, notify);
    iterations += r.cpca_iterations;
    r.cpca_seconds = seconds_since(t);
    notify("cpca", 1);
  }

  // 4. Overdraw-aware reassignment, then a refit for the new membership.
  if (options.overdraw_reduction) {
    t = Clock::now();
    notify("overdraw", 0);
    r.overdraw = reduce_overdraw(data.all(), *geometry, set, vertex_error, options.overdraw);
    vertex_error = fit_cluster_pca(data, set, options.solver, power, &stats);
    r.power_iterations += stats.power_iterations;
    r.overdraw_seconds = seconds_since(t);
    notify("overdraw", 1);
  }
  // 5. The metrics of the final set.
  set.iterations = iterations;
  measure(data, options, geometry, set, vertex_error, r);
  r.total_seconds = seconds_since(start);
  return set;
}

}  // namespace cpca
