#include "cpca/row_blocks.h"

#include <algorithm>
#include <utility>

namespace cpca {

RowBlocks::RowBlocks(const Eigen::Ref<const DataMatrix>& rows, Eigen::Index block_rows,
                     Release release, Gather gather)
    : view_(rows.data(), rows.rows(), rows.cols(), Eigen::OuterStride<>(rows.outerStride())),
      release_(std::move(release)),
      gather_(std::move(gather)) {
  const Eigen::Index all = std::max<Eigen::Index>(rows.rows(), 1);
  const Eigen::Index wanted = block_rows <= 0 ? all : std::min(block_rows, all);
  block_rows_ = std::max<Eigen::Index>(
      1, block_rows <= 0 ? wanted : (wanted + kGranule - 1) / kGranule * kGranule);
}

Eigen::Index RowBlocks::block_size(Eigen::Index b) const {
  return std::min(block_rows_, rows() - block_begin(b));
}

void RowBlocks::gather(const std::uint32_t* rows, Eigen::Index count, float* out) const {
  if (gather_) {
    gather_(rows, count, out);
    return;
  }
  Eigen::Map<DataMatrix> to(out, count, cols());
  for (Eigen::Index i = 0; i < count; ++i) to.row(i) = view_.row(rows[i]);
}

}  // namespace cpca
