// Ray start points of the shadow pass: the candidate faces of every position group, the
// choice per ray, and the escape from a fold (prt/bake.h, "Ray origins"; docs/ARCHITECTURE.md,
// "Baking (prt/)").
#include "bake_origins.h"

#include "bake_context.h"
#include "meshes/weld.h"

#include <algorithm>

namespace prt::detail {

OriginFaces origin_faces(const meshes::Mesh& mesh, float offset) {
  OriginFaces f;
  meshes::PositionGroups groups = meshes::group_equal_positions(mesh.positions);
  f.group = std::move(groups.group);
  const std::size_t group_count = groups.count();
  // Zero-area faces have no plane to start above; they are left out.
  auto unit_normal = [&](const meshes::Triangle& t) {
    return (mesh.positions[t[1]] - mesh.positions[t[0]])
        .cross(mesh.positions[t[2]] - mesh.positions[t[0]])
        .normalized()
        .eval();
  };
  f.first.assign(group_count + 1, 0);
  for (const meshes::Triangle& t : mesh.triangles) {
    if (!unit_normal(t).allFinite()) continue;
    for (int c = 0; c < 3; ++c) ++f.first[f.group[t[c]] + 1];
  }
  for (std::size_t g = 0; g < group_count; ++g) f.first[g + 1] += f.first[g];
  std::vector<std::uint32_t> fill(f.first.begin(), f.first.end() - 1);
  f.normals.resize(3, f.first.back());
  f.steps.resize(3, f.first.back());
  for (const meshes::Triangle& t : mesh.triangles) {
    const meshes::Vec3 n = unit_normal(t);
    if (!n.allFinite()) continue;
    const meshes::Vec3 centroid =
        (mesh.positions[t[0]] + mesh.positions[t[1]] + mesh.positions[t[2]]) / 3.f;
    for (int c = 0; c < 3; ++c) {
      const meshes::Vec3 inward = centroid - mesh.positions[t[c]];
      // Half the way to the centroid at most, so the start point stays on a small face.
      const float step = std::min(kStep * offset, 0.5f * inward.norm());
      const std::uint32_t e = fill[f.group[t[c]]]++;
      f.normals.col(e) = n;
      f.steps.col(e) = step * (inward.normalized() + kLift * n);
    }
  }
  return f;
}

void ray_origins(const BakeContext& ctx, std::uint64_t p, const Eigen::Matrix3Xf& world,
                 Eigen::Matrix3Xf& origins) {
  const OriginFaces& f = ctx.faces;
  const std::uint32_t g = f.group[p], begin = f.first[g], end = f.first[g + 1];
  const meshes::Vec3& at = ctx.mesh.positions[p];
  if (begin == end) {
    origins.colwise() = at + ctx.offset * ctx.mesh.normals[p];
    return;
  }
  for (Eigen::Index k = 0; k < world.cols(); ++k) {
    const Eigen::Vector3f d = world.col(k);
    std::uint32_t best = begin;
    float best_rise = f.normals.col(begin).dot(d);
    for (std::uint32_t e = begin + 1; e < end; ++e) {
      const float rise = f.normals.col(e).dot(d);
      if (rise > best_rise) best_rise = rise, best = e;
    }
    origins.col(k) = at + f.steps.col(best);
  }
}

std::optional<Eigen::Vector3f> escape_origin(const BakeContext& ctx, std::uint64_t p) {
  const OriginFaces& f = ctx.faces;
  const std::uint32_t g = f.group[p], begin = f.first[g], end = f.first[g + 1];
  const meshes::Mesh& mesh = ctx.mesh;
  const meshes::Vec3& at = mesh.positions[p];
  const float bound = kEscape * ctx.offset, lift = kLift * kStep * ctx.offset;
  std::optional<Eigen::Vector3f> best;
  float best_t = bound;
  Eigen::Matrix3Xf probes(3, 2);
  RayHit hits[2];
  for (std::uint32_t e = begin; e < end; ++e) {
    const Eigen::Vector3f start = at + f.steps.col(e);
    probes.col(0) = mesh.normals[p];
    probes.col(1) = f.normals.col(e);
    ctx.scene->intersect(start, probes, 0.f, hits);
    for (int j = 0; j < 2; ++j) {
      const RayHit& h = hits[j];
      if (h.triangle < 0 || !(h.t < best_t)) continue;
      const meshes::Triangle& tri = mesh.triangles[h.triangle];
      const Eigen::Vector3f n = (mesh.positions[tri[1]] - mesh.positions[tri[0]])
                                    .cross(mesh.positions[tri[2]] - mesh.positions[tri[0]])
                                    .normalized();
      if (!(n.dot(probes.col(j)) > 0.f)) continue;
      best_t = h.t;
      best = (start + h.t * probes.col(j) + lift * n).eval();
    }
  }
  return best;
}

}  // namespace prt::detail
