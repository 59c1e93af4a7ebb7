// meshes/creases.cpp: crease splitting by union-find over triangle corners.
//
// Each corner (triangle, vertex) starts in its own set; across every edge whose two faces
// are within the crease angle, the corners at each end of the edge are joined. The sets
// left at a vertex are its smooth fans. An edge shared by more than two faces (non-manifold)
// joins every pair within the angle, so a fin on a flat sheet stays hard against it.
#include "meshes/creases.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <vector>

namespace meshes {

namespace {

struct DisjointSets {
  std::vector<std::uint32_t> parent;

  explicit DisjointSets(std::size_t n) : parent(n) {
    std::iota(parent.begin(), parent.end(), std::uint32_t{0});
  }
  std::uint32_t find(std::uint32_t x) {
    while (parent[x] != x) {
      parent[x] = parent[parent[x]];
      x = parent[x];
    }
    return x;
  }
  // The lower root wins, so the result does not depend on the order of joins.
  void join(std::uint32_t a, std::uint32_t b) {
    a = find(a);
    b = find(b);
    if (a < b) parent[b] = a;
    if (b < a) parent[a] = b;
  }
};

struct EdgeUse {
  std::uint32_t lo, hi;  // vertex indices, lo < hi
  std::uint32_t triangle;
  bool operator<(const EdgeUse& o) const {
    return lo != o.lo ? lo < o.lo : hi != o.hi ? hi < o.hi : triangle < o.triangle;
  }
};

// The corner of triangle t at vertex v (v is one of its corners).
std::uint32_t corner_at(const Mesh& mesh, std::uint32_t t, std::uint32_t v) {
  const Triangle& tri = mesh.triangles[t];
  const std::uint32_t k = tri[0] == v ? 0u : tri[1] == v ? 1u : 2u;
  return 3 * t + k;
}

}  // namespace

std::size_t split_creases(Mesh& mesh, double angle_deg) {
  if (!(angle_deg < 180.0) || mesh.triangles.empty()) return 0;
  const std::size_t triangle_count = mesh.triangles.size();
  std::vector<Eigen::Vector3d> face_normals(triangle_count);
  for (std::size_t t = 0; t < triangle_count; ++t) {
    const Triangle& tri = mesh.triangles[t];
    const Eigen::Vector3d p0 = mesh.positions[tri[0]].cast<double>();
    const Eigen::Vector3d cross = (mesh.positions[tri[1]].cast<double>() - p0)
                                      .cross(mesh.positions[tri[2]].cast<double>() - p0);
    const double len = cross.norm();
    face_normals[t] = len > 0.0 ? Eigen::Vector3d(cross / len) : Eigen::Vector3d::Zero();
  }
  // A zero-area face (zero normal) has no angle to anyone: it joins its neighbours, as it
  // adds nothing to their normals either.
  const double min_cos = std::cos(std::max(0.0, angle_deg) * std::numbers::pi / 180.0);
  const auto smooth = [&](std::uint32_t a, std::uint32_t b) {
    if (face_normals[a].isZero() || face_normals[b].isZero()) return true;
    return face_normals[a].dot(face_normals[b]) >= min_cos;
  };

  std::vector<EdgeUse> edges;
  edges.reserve(3 * triangle_count);
  for (std::size_t t = 0; t < triangle_count; ++t) {
    const Triangle& tri = mesh.triangles[t];
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = tri[k], b = tri[(k + 1) % 3];
      edges.push_back({std::min(a, b), std::max(a, b), std::uint32_t(t)});
    }
  }
  std::sort(edges.begin(), edges.end());

  DisjointSets corners(3 * triangle_count);
  for (std::size_t begin = 0; begin < edges.size();) {
    std::size_t end = begin + 1;
    while (end < edges.size() && edges[end].lo == edges[begin].lo &&
           edges[end].hi == edges[begin].hi)
      ++end;
    for (std::size_t i = begin; i < end; ++i) {
      for (std::size_t j = i + 1; j < end; ++j) {
        const std::uint32_t a = edges[i].triangle, b = edges[j].triangle;
        if (!smooth(a, b)) continue;
        for (const std::uint32_t v : {edges[begin].lo, edges[begin].hi})
          corners.join(corner_at(mesh, a, v), corner_at(mesh, b, v));
      }
    }
    begin = end;
  }

  // The first fan met at each vertex keeps the vertex; every further one gets a copy.
  constexpr std::uint32_t kNone = 0xFFFFFFFFu;
  std::vector<std::uint32_t> owner(mesh.positions.size(), kNone);  // vertex -> its fan's root
  std::vector<std::uint32_t> vertex_of_root(3 * triangle_count, kNone);
  const std::size_t vertices_before = mesh.positions.size();
  for (std::size_t t = 0; t < triangle_count; ++t) {
    for (std::uint32_t k = 0; k < 3; ++k) {
      std::uint32_t& v = mesh.triangles[t][k];
      const std::uint32_t root = corners.find(std::uint32_t(3 * t + k));
      if (vertex_of_root[root] == kNone) {
        if (owner[v] == kNone) {
          owner[v] = root;
          vertex_of_root[root] = v;
        } else {
          vertex_of_root[root] = std::uint32_t(mesh.positions.size());
          const Vec3 p = mesh.positions[v];
          mesh.positions.push_back(p);
        }
      }
      v = vertex_of_root[root];
    }
  }
  return mesh.positions.size() - vertices_before;
}

}  // namespace meshes
