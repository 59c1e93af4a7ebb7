// meshes/mesh.cpp: bounds, triangle area, the structural invariants of meshes/mesh.h, and the
// content hash later stages use to tie a bake to the exact mesh it was made from.
#include "meshes/mesh.h"

#include "common/hash.h"

#include <cmath>
#include <sstream>

namespace meshes {

namespace {

// Frames are stored in float; 1e-3 is far above float rounding (~1e-7) and far below any
// real error (a frame built from a wrong normal is off by O(1)).
constexpr float kFrameTolerance = 1e-3f;

std::string describe(const Vec3& v) {
  std::ostringstream out;
  out << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
  return out.str();
}

[[noreturn]] void fail(const std::string& what, const std::string& problem) {
  throw MeshError(what + ": " + problem);
}

}  // namespace

Bounds bounds(const Mesh& mesh) {
  Bounds b;
  if (mesh.positions.empty()) return b;
  b.min = b.max = mesh.positions.front();
  for (const Vec3& p : mesh.positions) {
    b.min = b.min.cwiseMin(p);
    b.max = b.max.cwiseMax(p);
  }
  return b;
}

float double_area(const Mesh& mesh, const Triangle& t) {
  // In double: the cross product of two long, nearly parallel edges cancels badly in float,
  // and the degenerate-face test compares this against a tiny threshold.
  const Eigen::Vector3d p0 = mesh.positions[t[0]].cast<double>();
  const Eigen::Vector3d p1 = mesh.positions[t[1]].cast<double>();
  const Eigen::Vector3d p2 = mesh.positions[t[2]].cast<double>();
  return static_cast<float>((p1 - p0).cross(p2 - p0).norm());
}

void validate(const Mesh& mesh, const std::string& what) {
  const std::size_t n = mesh.positions.size();
  for (std::size_t v = 0; v < n; ++v) {
    if (!mesh.positions[v].allFinite()) {
      fail(what, "vertex " + std::to_string(v) + " has a non-finite position " +
                     describe(mesh.positions[v]));
    }
  }
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
    for (std::uint32_t i : mesh.triangles[f]) {
      if (i >= n) {
        fail(what, "triangle " + std::to_string(f) + " uses vertex " + std::to_string(i) +
                       " but the mesh has only " + std::to_string(n) + " vertices");
      }
    }
  }

  const bool any_frame =
      !mesh.normals.empty() || !mesh.tangents.empty() || !mesh.bitangents.empty();
  if (!any_frame) return;
  if (mesh.normals.size() != n || mesh.tangents.size() != n || mesh.bitangents.size() != n) {
    fail(what, "frames are partially filled (" + std::to_string(mesh.normals.size()) +
                   " normals, " + std::to_string(mesh.tangents.size()) + " tangents, " +
                   std::to_string(mesh.bitangents.size()) + " bitangents for " + std::to_string(n) +
                   " vertices); call compute_frames()");
  }
  for (std::size_t v = 0; v < n; ++v) {
    const Vec3& t = mesh.tangents[v];
    const Vec3& b = mesh.bitangents[v];
    const Vec3& nn = mesh.normals[v];
    const auto problem = [&](const std::string& text) {
      fail(what, "frame of vertex " + std::to_string(v) + " " + text + ": tangent " + describe(t) +
                     ", bitangent " + describe(b) + ", normal " + describe(nn) +
                     "; call compute_frames()");
    };
    if (!t.allFinite() || !b.allFinite() || !nn.allFinite()) problem("is not finite");
    if (std::abs(t.norm() - 1.f) > kFrameTolerance || std::abs(b.norm() - 1.f) > kFrameTolerance ||
        std::abs(nn.norm() - 1.f) > kFrameTolerance) {
      problem("has a column that is not unit length");
    }
    if (std::abs(t.dot(b)) > kFrameTolerance || std::abs(t.dot(nn)) > kFrameTolerance ||
        std::abs(b.dot(nn)) > kFrameTolerance) {
      problem("is not orthogonal");
    }
    if ((t.cross(b) - nn).norm() > kFrameTolerance) problem("is not right-handed (t x b != n)");
  }
}

std::uint64_t content_hash(const Mesh& mesh) {
  std::uint64_t hash = common::kFnvOffset;
  // Component by component, so the hash never depends on how Eigen lays out or pads Vec3.
  for (const Vec3& p : mesh.positions) {
    const float xyz[3] = {p.x(), p.y(), p.z()};
    hash = common::fnv1a(xyz, sizeof(xyz), hash);
  }
  for (const Triangle& t : mesh.triangles) {
    const std::uint32_t idx[3] = {t[0], t[1], t[2]};
    hash = common::fnv1a(idx, sizeof(idx), hash);
  }
  return hash;
}

}  // namespace meshes
