// tests/cpca_test_support.h: geometry shared by the cpca suites.
#pragma once

#include "cpca/geometry.h"

namespace cpca_test {

// A regular n x n vertex grid on the unit square (z = 0), two triangles per cell.
inline cpca::Geometry grid(int n) {
  cpca::Geometry g;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x)
      g.positions.emplace_back(float(x) / float(n - 1), float(y) / float(n - 1), 0.f);
  for (int y = 0; y + 1 < n; ++y)
    for (int x = 0; x + 1 < n; ++x) {
      const std::uint32_t a = std::uint32_t(y * n + x), b = a + 1, c = a + std::uint32_t(n),
                          d = c + 1;
      g.triangles.push_back({a, b, d});
      g.triangles.push_back({a, d, c});
    }
  return g;
}

}  // namespace cpca_test
