#include "cpca/row_blocks.h"

#include <algorithm>
#include <utility>

namespace cpca {

RowBlocks::RowBlocks(const Eigen::Ref<const DataMatrix>& rows, Eigen::Index block_rows,
                     Release release)
    : view_(rows.data(), rows.rows(), rows.cols(), Eigen::OuterStride<>(rows.outerStride())),
      release_(std::move(release)) {
  const Eigen::Index all = std::max<Eigen::Index>(rows.rows(), 1);
  const Eigen::Index wanted = block_rows <= 0 ? all : std::min(block_rows, all);
  block_rows_ = std::max<Eigen::Index>(
      1, block_rows <= 0 ? wanted : (wanted + kGranule - 1) / kGranule * kGranule);
}

Eigen::Index RowBlocks::block_size(Eigen::Index b) const {
  return std::min(block_rows_, rows() - block_begin(b));
}

}  // namespace cpca
