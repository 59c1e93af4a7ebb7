// cpca/compress.h: the whole compression of a transfer set, in the order the thesis and
// Sloan et al. 2003 use: LBG clustering (optionally geometry-coherent), PCA per cluster,
// optionally iterative CPCA, optionally the overdraw-aware reassignment, then the metrics.
#pragma once

#include "cpca/compressed.h"
#include "cpca/distribution.h"
#include "cpca/geometry.h"
#include "cpca/lbg.h"
#include "cpca/metrics.h"
#include "cpca/overdraw_reduction.h"
#include "cpca/row_blocks.h"

#include <functional>
#include <string>
#include <vector>

namespace cpca {

// The layout of a data row (compressed.h). Order 0 means "infer from the dimension": the one
// of diffuse grey (n), glossy grey (n^2), diffuse RGB (3n), glossy RGB (3n^2), order 1..10,
// whose size matches. Sizes two layouts share (1, 3, 16, 48, 81, 243) are refused
// (std::invalid_argument): callers that know the layout should always pass it.
struct DataLayout {
  int order = 0;
  int channels = 1;
  int columns = 1;
};

struct CompressOptions {
  DataLayout layout;
  int clusters = 256;
  int components = 8;
  ClusterMethod method = ClusterMethod::kLbg;
  PcaSolver solver = PcaSolver::kPowerIteration;
  double alpha = 0.0;               // geometry coherence (assignment.h); needs geometry when > 0
  bool overdraw_reduction = false;  // needs geometry
  OverdrawReductionOptions overdraw;
  std::uint64_t seed = 1;
  double lbg_threshold = 1e-3;  // converged ratio (thesis eq. 5)
  int lbg_max_iterations = 200;
  double cpca_threshold = 1e-3;  // iterative CPCA stops when the error falls less than this
  int cpca_max_iterations = 20;
  // Iterative CPCA compares each point against its current cluster and this many clusters
  // with the nearest means (0: all clusters, exact but ~K/candidates times slower).
  int cpca_candidates = 16;
  // Methods that design the passes (patch_first.h, joint_search.h): the clusters one render
  // pass holds, the joint search's overdraw weight in units of its start's Average SE, and
  // its overdraw cap (JointSearchOptions::overdraw_cap; 0 = none).
  int clusters_per_pass = 16;
  double lambda = 0.0;
  double overdraw_cap = 0.0;
};

// Triangles whose three vertices lie in 1, 2 or 3 distinct clusters.
struct TriangleSpan {
  std::uint64_t one = 0, two = 0, three = 0;
  std::uint64_t multi() const { return two + three; }
};
TriangleSpan triangle_span(const std::vector<std::uint32_t>& cluster_of,
                           const std::vector<TriangleIndices>& triangles);

struct CompressReport {
  double lbg_seconds = 0, pca_seconds = 0, cpca_seconds = 0, overdraw_seconds = 0,
         total_seconds = 0;
  double clustering_seconds() const { return lbg_seconds + cpca_seconds + overdraw_seconds; }
  int lbg_iterations = 0;
  int cpca_iterations = 0;
  int splits = 0;  // null clusters filled
  int power_iterations = 0;
  std::vector<double> lbg_energy;  // per LBG iteration
  std::vector<double> cpca_error;  // total squared error after each iterative CPCA step
  OverdrawReductionResult overdraw;
  ErrorMetrics error;
  SizeMetrics size;
  bool has_geometry = false;
  TriangleSpan span;  // of the final clustering, when geometry was given
};

// `stage` is "lbg", "pca", "cpca" or "overdraw"; `fraction` in [0, 1] is an estimate.
using CompressProgress = std::function<void(const std::string& stage, double fraction)>;

// Compresses V x D data (one row per vertex). Geometry is required for alpha > 0 and the
// overdraw reduction, optional otherwise (it adds the triangle span to the report). The
// returned set has the layout, sizes, clustering, fit and method fields filled; the hashes
// and mesh path are the caller's. Throws std::invalid_argument
// naming the bad parameter.
CompressedSet compress(const Eigen::Ref<const DataMatrix>& data, const CompressOptions& options,
                       const Geometry* geometry = nullptr, CompressReport* report = nullptr,
                       const CompressProgress& progress = {});

// The same, out of core (docs/ARCHITECTURE.md "Scale"): LBG and the PCA stream over the
// blocks (lbg.h, cluster_pca.h), so with LBG and alpha 0 memory holds one block, the
// centroids and the clusters being fitted; geometry coherence, iterative CPCA and the
// overdraw reduction still need V x K matrices. Bit-identical to the call above.
// With a `distribution` of several ranks (LBG, alpha 0, no overdraw reduction; else
// std::invalid_argument) every rank calls this; LBG and the PCA are spread over them
// (lbg.h, cluster_pca.h) and rank 0 returns the whole set and report, bit-identical to one
// process; the other ranks return an incomplete set to be discarded.
CompressedSet compress(const RowBlocks& data, const CompressOptions& options,
                       const Geometry* geometry = nullptr, CompressReport* report = nullptr,
                       const CompressProgress& progress = {}, Distribution* distribution = nullptr);

// Average SE, relative and max error of a set against its data, by reconstructing every row
// (a code path independent of the compressor's own bookkeeping).
ErrorMetrics error_metrics(const Eigen::Ref<const DataMatrix>& data, const CompressedSet& set);

}  // namespace cpca
