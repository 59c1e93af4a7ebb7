#include "meshes/spatial_order.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace meshes {
namespace {

// The low 21 bits of x, spread to every third bit.
std::uint64_t spread3(std::uint64_t x) {
  x &= 0x1fffff;
  x = (x | x << 32) & 0x001f00000000ffffULL;
  x = (x | x << 16) & 0x001f0000ff0000ffULL;
  x = (x | x << 8) & 0x100f00f00f00f00fULL;
  x = (x | x << 4) & 0x10c30c30c30c30c3ULL;
  x = (x | x << 2) & 0x1249249249249249ULL;
  return x;
}

}  // namespace

std::uint64_t morton_code(std::uint32_t x, std::uint32_t y, std::uint32_t z) {
  return spread3(x) | spread3(y) << 1 | spread3(z) << 2;
}

std::vector<std::uint32_t> spatial_order(const Mesh& mesh) {
  const std::size_t v = mesh.vertex_count();
  const Bounds b = bounds(mesh);
  const Eigen::Vector3f extent = b.max - b.min;
  constexpr float kCells = float((1 << 21) - 1);
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed(v);
  for (std::size_t i = 0; i < v; ++i) {
    std::uint32_t cell[3];
    for (int a = 0; a < 3; ++a) {
      const float t = extent[a] > 0.f ? (mesh.positions[i][a] - b.min[a]) / extent[a] : 0.f;
      cell[a] = std::uint32_t(std::clamp(t, 0.f, 1.f) * kCells);
    }
    keyed[i] = {morton_code(cell[0], cell[1], cell[2]), std::uint32_t(i)};
  }
  std::sort(keyed.begin(), keyed.end());
  std::vector<std::uint32_t> order(v);
  for (std::size_t i = 0; i < v; ++i) order[i] = keyed[i].second;
  return order;
}

std::vector<std::uint32_t> inverse_permutation(const std::vector<std::uint32_t>& order) {
  std::vector<std::uint32_t> inverse(order.size());
  for (std::size_t i = 0; i < order.size(); ++i) inverse[order[i]] = std::uint32_t(i);
  return inverse;
}

}  // namespace meshes
