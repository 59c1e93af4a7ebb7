// meshes/spatial_order.h: vertices ordered along a space-filling curve, so that neighbours
// on the surface are mostly neighbours in memory. The bake with bounces visits and stores
// vertices in this order (docs/ARCHITECTURE.md, "Scale").
#pragma once

#include "meshes/mesh.h"

#include <cstdint>
#include <vector>

namespace meshes {

// The vertices sorted along a Morton (Z-order) curve over the mesh's bounding box, 21 bits
// an axis, ties in index order. Neighbours on the surface are mostly near in this order, so
// consecutive vertices' bounce rays hit the same places, and the three corners of a hit
// triangle are stored near each other: a bounce reads the previous pass at random hit
// corners, and in an index order with no locality (Loop subdivision numbers new vertices
// after old ones) every read misses the caches and the TLB.
std::vector<std::uint32_t> spatial_order(const Mesh& mesh);

// The Morton code of cell (x, y, z), each < 2^21: their bits interleaved, x lowest.
std::uint64_t morton_code(std::uint32_t x, std::uint32_t y, std::uint32_t z);

// inverse[order[i]] = i.
std::vector<std::uint32_t> inverse_permutation(const std::vector<std::uint32_t>& order);

}  // namespace meshes
