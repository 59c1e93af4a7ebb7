// meshes/mesh.h: the triangle mesh that crosses module borders.
//
// Conventions (fixed here, used everywhere):
//  - Right-handed world, +Y up. Units are whatever the file used.
//  - Triangles are counter-clockwise seen from the front (outside); the face normal is
//    (p1 - p0) x (p2 - p0).
//  - Per-vertex frame F = [tangent bitangent normal]: columns orthonormal and right-handed,
//    bitangent = normal x tangent. Filled by compute_frames() (meshes/frames.h).
//  - Indices are 32-bit; every index is < positions.size().
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>  // Vec3::cross, used by every user of the winding convention

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace meshes {

using Vec3 = Eigen::Vector3f;
using Triangle = std::array<std::uint32_t, 3>;

struct Mesh {
  std::vector<Vec3> positions;
  std::vector<Triangle> triangles;
  // Per-vertex frame; empty until compute_frames() runs, then one entry per position.
  std::vector<Vec3> normals;
  std::vector<Vec3> tangents;
  std::vector<Vec3> bitangents;

  std::size_t vertex_count() const { return positions.size(); }
  std::size_t triangle_count() const { return triangles.size(); }
  bool has_frames() const { return normals.size() == positions.size() && !positions.empty(); }
};

struct Bounds {
  Vec3 min = Vec3::Constant(0.f);
  Vec3 max = Vec3::Constant(0.f);
  Vec3 center() const { return 0.5f * (min + max); }
  float diagonal() const { return (max - min).norm(); }
};

// Axis-aligned bounds of the positions; zero bounds for an empty mesh.
Bounds bounds(const Mesh& mesh);

// Twice the area of triangle t (the length of the unnormalised face normal).
float double_area(const Mesh& mesh, const Triangle& t);

// Thrown for any input that cannot become a valid mesh. what() names the input and the fix.
class MeshError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Checks the structural invariants above (indices in range, finite positions, frames sized
// and orthonormal when present). Throws MeshError naming `what` on the first violation.
void validate(const Mesh& mesh, const std::string& what);

// A stable 64-bit content hash of positions and triangles (FNV-1a over the raw bytes), used
// by later stages to detect a bake made from a different mesh.
std::uint64_t content_hash(const Mesh& mesh);

}  // namespace meshes
