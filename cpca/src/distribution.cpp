#include "cpca/distribution.h"

#include <algorithm>

namespace cpca {

std::vector<unsigned char> SingleProcess::gather(const void* data, std::size_t bytes, int) {
  const auto* p = static_cast<const unsigned char*>(data);
  return std::vector<unsigned char>(p, p + bytes);
}

RowRange rank_rows(Eigen::Index rows, int rank, int size, Eigen::Index granule) {
  const Eigen::Index granules = (rows + granule - 1) / granule;
  auto boundary = [&](int r) {
    return std::min(rows, granules * Eigen::Index(r) / Eigen::Index(size) * granule);
  };
  return {boundary(rank), rank + 1 == size ? rows : boundary(rank + 1)};
}

}  // namespace cpca
