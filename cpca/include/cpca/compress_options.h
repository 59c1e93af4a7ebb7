// cpca/compress_options.h: what a compression is asked to do (CompressOptions) and what it
// reports (CompressReport). Its own header so that the methods compress() dispatches to
// (patch_first.h, joint_search.h) take the same options without including compress.h, which
// calls them.
#pragma once

#include "cpca/compressed.h"
#include "cpca/geometry.h"
#include "cpca/metrics.h"
#include "cpca/overdraw_reduction.h"

#include <cstdint>
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
  OverdrawReductionOptions overdraw{};
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
  // patch-eps (joint_search.h): the least overdraw with Average SE <= (1 + error_slack) x a
  // reference, the Average SE of original CPCA (LBG + PCA, same K and seed). error_target > 0
  // gives that reference's Average SE and reference_clusters its cluster of every vertex (a
  // caller that has already compressed the original; both or neither); 0 makes the method
  // compress the original itself, inside its clustering time. The clusters weigh the patches
  // (cpca::cluster_density_weights).
  double error_slack = 0.0;
  double error_target = 0.0;
  std::vector<std::uint32_t> reference_clusters{};
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

}  // namespace cpca
