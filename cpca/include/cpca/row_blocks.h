// cpca/row_blocks.h: the V x D data rows of a compression, visited in blocks of whole rows,
// so that compression can run out of core (docs/ARCHITECTURE.md "Scale"). The rows are one
// view, in memory or a Map over a memory-mapped .prtx payload (no copy either way); after a
// pass has used a block, `release` lets an out-of-core source drop that block's pages, so a
// pass holds one block of the data, not all of it. Random access (a cluster's PCA and a
// split gather their members) goes through gather(), which an out-of-core source serves
// with reads rather than the map: on large-folio page caches a fault maps up to megabytes,
// so rows scattered over the file would make most of it resident.
#pragma once

#include "cpca/metrics.h"

#include <Eigen/Core>

#include <algorithm>
#include <cstdint>
#include <functional>

namespace cpca {

class RowBlocks {
 public:
  using View = Eigen::Map<const DataMatrix, 0, Eigen::OuterStride<>>;
  using Release = std::function<void(Eigen::Index first_row, Eigen::Index rows)>;
  // Copies rows[0..count) to out, count x cols() floats, row-major.
  using Gather = std::function<void(const std::uint32_t* rows, Eigen::Index count, float* out)>;
  // Block boundaries fall on multiples of this, the row block of the distance products
  // (assignment.cpp, cluster_pca.cpp), so every product sees the same rows whatever the
  // block size: the results are bit-identical for every block size.
  static constexpr Eigen::Index kGranule = 256;

  // `block_rows` <= 0 means one block of all rows; otherwise it is rounded up to a multiple
  // of kGranule. `release` (optional) is called with each block's range after it is used;
  // `gather` (optional) replaces copying from the view for random access.
  explicit RowBlocks(const Eigen::Ref<const DataMatrix>& rows, Eigen::Index block_rows = 0,
                     Release release = {}, Gather gather = {});

  Eigen::Index rows() const { return view_.rows(); }
  Eigen::Index cols() const { return view_.cols(); }
  Eigen::Index block_rows() const { return block_rows_; }
  Eigen::Index block_count() const { return (rows() + block_rows_ - 1) / block_rows_; }
  Eigen::Index block_begin(Eigen::Index b) const { return b * block_rows_; }
  Eigen::Index block_size(Eigen::Index b) const;
  auto block(Eigen::Index b) const { return view_.middleRows(block_begin(b), block_size(b)); }
  const View& all() const { return view_; }

  void release(Eigen::Index first_row, Eigen::Index count) const {
    if (release_) release_(first_row, count);
  }
  void release_all() const { release(0, rows()); }
  // Rows rows[0..count) into out (count x cols() floats, row-major), exact copies.
  void gather(const std::uint32_t* rows, Eigen::Index count, float* out) const;

  // f(first_row, block) for every block in order, each released after f returns.
  template <class F>
  void for_each(F&& f) const {
    for (Eigen::Index b = 0; b < block_count(); ++b) {
      f(block_begin(b), block(b));
      release(block_begin(b), block_size(b));
    }
  }
  // The same over rows [begin, end) only (one rank's rows, distribution.h), in blocks of
  // block_rows() from `begin`: with `begin` on a multiple of kGranule every block boundary
  // still falls on one.
  template <class F>
  void for_each_in(Eigen::Index begin, Eigen::Index end, F&& f) const {
    for (Eigen::Index first = begin; first < end; first += block_rows_) {
      const Eigen::Index n = std::min(block_rows_, end - first);
      f(first, view_.middleRows(first, n));
      release(first, n);
    }
  }

 private:
  View view_;
  Eigen::Index block_rows_ = 1;
  Release release_;
  Gather gather_;
};

}  // namespace cpca
