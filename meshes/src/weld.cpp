// meshes/weld.cpp: position grouping and tolerance welding.
//
// Welding uses a uniform hash grid with cells as large as the weld distance: two points
// within that distance lie in the same or in neighbouring cells, so each vertex checks the
// 27 cells around it. Vertices are visited in index order and each merges into the lowest
// index within reach, so the result does not depend on hash-table order.
#include "meshes/weld.h"

#include <bit>
#include <cmath>
#include <unordered_map>

namespace meshes {

namespace {

// Below this relative tolerance the weld distance is under float resolution for coordinates
// of the size of the mesh, and grid cell coordinates could overflow; weld exact matches only.
constexpr double kSmallestGridTolerance = 1e-15;

struct CellKey {
  std::int64_t x, y, z;
  bool operator==(const CellKey&) const = default;
};

struct CellHash {
  std::size_t operator()(const CellKey& k) const {
    // splitmix64 finaliser over a combination of the three coordinates.
    std::uint64_t h = static_cast<std::uint64_t>(k.x) * 0x9E3779B97F4A7C15ull;
    h ^= static_cast<std::uint64_t>(k.y) + 0x632BE59BD9B4E019ull + (h << 6) + (h >> 2);
    h ^= static_cast<std::uint64_t>(k.z) + 0x8CB92BA72F3D8DD7ull + (h << 6) + (h >> 2);
    h ^= h >> 30;
    h *= 0xBF58476D1CE4E5B9ull;
    h ^= h >> 27;
    h *= 0x94D049BB133111EBull;
    h ^= h >> 31;
    return static_cast<std::size_t>(h);
  }
};

// Adding +0 turns -0 into +0, so equal floats have equal bits.
std::int64_t cell_bits(float x) {
  return std::bit_cast<std::int32_t>(x + 0.f);
}

}  // namespace

PositionGroups group_equal_positions(const std::vector<Vec3>& positions) {
  PositionGroups out;
  out.group.resize(positions.size());
  std::unordered_map<CellKey, std::uint32_t, CellHash> group_of;
  group_of.reserve(positions.size());
  for (std::size_t v = 0; v < positions.size(); ++v) {
    const Vec3& p = positions[v];
    const CellKey key{cell_bits(p.x()), cell_bits(p.y()), cell_bits(p.z())};
    const auto [it, fresh] = group_of.try_emplace(key, std::uint32_t(out.first.size()));
    if (fresh) out.first.push_back(std::uint32_t(v));
    out.group[v] = it->second;
  }
  return out;
}

std::vector<std::uint32_t> weld_map(const std::vector<Vec3>& positions, double tolerance,
                                    const Bounds& box) {
  const std::size_t n = positions.size();
  std::vector<std::uint32_t> remap(n);
  for (std::size_t v = 0; v < n; ++v) remap[v] = static_cast<std::uint32_t>(v);
  if (tolerance < 0.0 || n == 0) return remap;

  // In double: the float difference max - min overflows for coordinates near the float limit.
  const double diagonal = (box.max.cast<double>() - box.min.cast<double>()).norm();
  const double eps = tolerance * diagonal;
  if (!(tolerance >= kSmallestGridTolerance) || !(eps > 0.0)) {
    const PositionGroups groups = group_equal_positions(positions);
    for (std::size_t v = 0; v < n; ++v) remap[v] = groups.first[groups.group[v]];
    return remap;
  }

  const Eigen::Vector3d origin = box.min.cast<double>();
  const double eps2 = eps * eps;
  std::unordered_map<CellKey, std::vector<std::uint32_t>, CellHash> grid;
  grid.reserve(n);
  for (std::size_t v = 0; v < n; ++v) {
    const Eigen::Vector3d p = positions[v].cast<double>();
    const Eigen::Vector3d c = ((p - origin) / eps).array().floor();
    const CellKey cell{static_cast<std::int64_t>(c.x()), static_cast<std::int64_t>(c.y()),
                       static_cast<std::int64_t>(c.z())};
    std::uint32_t best = static_cast<std::uint32_t>(v);
    for (std::int64_t dx = -1; dx <= 1; ++dx) {
      for (std::int64_t dy = -1; dy <= 1; ++dy) {
        for (std::int64_t dz = -1; dz <= 1; ++dz) {
          const auto it = grid.find({cell.x + dx, cell.y + dy, cell.z + dz});
          if (it == grid.end()) continue;
          for (std::uint32_t r : it->second) {
            if (r < best && (positions[r].cast<double>() - p).squaredNorm() <= eps2) best = r;
          }
        }
      }
    }
    if (best == v) {
      grid[cell].push_back(best);
    } else {
      remap[v] = best;
    }
  }
  return remap;
}

}  // namespace meshes
