// render/src/median.h (private): the median every frame-time summary reports (an even
// count averages the middle two), so the renderer's timing and the floor harness agree.
#pragma once

#include <algorithm>
#include <vector>

namespace render {

inline double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

}  // namespace render
