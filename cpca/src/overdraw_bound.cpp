#include "cpca/overdraw_bound.h"

#include <algorithm>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace cpca {

GroupingBound grouping_overdraw_bound(const ClusterIncidence& inc, int per_pass) {
  if (per_pass < 1)
    throw std::invalid_argument("grouping_overdraw_bound: clusters per pass must be >= 1, got " +
                                std::to_string(per_pass));
  GroupingBound b;
  std::uint64_t split4 = 0;  // 4 x the extra draws the bound guarantees
  std::vector<std::uint32_t> w;
  for (int c = 0; c < inc.cluster_count; ++c) {
    w.assign(inc.neighbor_weight.begin() + inc.neighbor_offset[std::size_t(c)],
             inc.neighbor_weight.begin() + inc.neighbor_offset[std::size_t(c) + 1]);
    std::uint64_t total = 0;
    for (std::uint32_t x : w) total += x;
    const std::size_t keep = std::min(w.size(), std::size_t(per_pass - 1));
    std::partial_sort(w.begin(), w.begin() + std::ptrdiff_t(keep), w.end(),
                      std::greater<std::uint32_t>());
    std::uint64_t top = 0;
    for (std::size_t i = 0; i < keep; ++i) top += w[i];
    split4 += total - top;
  }
  b.triangles_drawn = inc.triangle_count + (split4 + 3) / 4;
  b.average_overdraw =
      inc.triangle_count > 0 ? double(b.triangles_drawn) / double(inc.triangle_count) : 1.0;
  return b;
}

GroupingBound grouping_overdraw_bound(const SuperClusterInput& input) {
  validate(input);
  return grouping_overdraw_bound(cluster_incidence(input), input.per_pass);
}

}  // namespace cpca
