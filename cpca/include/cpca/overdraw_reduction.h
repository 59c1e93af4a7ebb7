// cpca/overdraw_reduction.h: overdraw-aware reassignment, our definition of the thesis's
// "CPCA overdraw reduction" row (the thesis names it but does not define it).
//
// Triangle overdraw comes from triangles whose vertices lie in different clusters (only they
// can be drawn in several passes). Passes are not known when compressing, so the proxy is the
// number of distinct clusters on a vertex's triangles:
//   span(p, c) = sum over triangles t containing p of |{c} U {clusters of t's other vertices}|.
// A sweep visits the vertices in order; vertex p moves from cluster a to a cluster c of one of
// its neighbours when
//   span(p, c) < span(p, a)   and   err(p, c) - err(p, a) <= tolerance * AverageSE,
// where err(p, k) is the squared distance from x_p to cluster k's affine subspace (its
// reconstruction error there) and AverageSE is the set's current average squared error. Among
// admissible clusters it takes the largest span reduction, then the smallest error increase.
// A move never empties a cluster. Sweeps repeat until none moves or max_sweeps. The caller
// then refits the PCA (which can only lower the error of the new clustering).
#pragma once

#include "cpca/compressed.h"
#include "cpca/geometry.h"
#include "cpca/metrics.h"

#include <vector>

namespace cpca {

struct OverdrawReductionOptions {
  double tolerance = 1.0;  // per move, in units of the current Average SE
  int max_sweeps = 8;
};

struct OverdrawReductionResult {
  std::uint64_t moves = 0;
  int sweeps = 0;
  double error_increase = 0.0;  // sum of the accepted moves' err(p, c) - err(p, a)
};

// Changes set.cluster_of only (means, bases and weights become stale: refit afterwards).
// `vertex_error` holds err(p, cluster_of[p]) for the current fit.
OverdrawReductionResult reduce_overdraw(const Eigen::Ref<const DataMatrix>& x,
                                        const Geometry& geometry, CompressedSet& set,
                                        const std::vector<double>& vertex_error,
                                        const OverdrawReductionOptions& options = {});

}  // namespace cpca
