// cpca/compress.h: the whole compression of a transfer set, in the order the thesis and
// Sloan et al. 2003 use: LBG clustering (optionally geometry-coherent), PCA per cluster,
// optionally iterative CPCA, optionally the overdraw-aware reassignment, then the metrics.
#pragma once

#include "cpca/compress_options.h"
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

// Original CPCA's PCA stage on a clustering already made (cluster_of, one entry per row,
// each < options.clusters): the clusters, means, bases and weights compress() returns for
// LBG when its LBG gave these clusters, without running LBG again. `vertex_error`, when given,
// receives each row's squared error.
CompressedSet fit_clustering(const Eigen::Ref<const DataMatrix>& data,
                             const CompressOptions& options, std::vector<std::uint32_t> cluster_of,
                             std::vector<double>* vertex_error = nullptr);

// Average SE, relative and max error of a set against its data, by reconstructing every row
// (a code path independent of the compressor's own bookkeeping).
ErrorMetrics error_metrics(const Eigen::Ref<const DataMatrix>& data, const CompressedSet& set);

}  // namespace cpca
