// prt/ray_scene.h: ray queries against a mesh, through Embree 3 (kept out of this header).
//
// Rays are given as structure-of-arrays lists of directions with either one shared origin or
// one origin per ray (the baker starts each ray on the face it leaves through). Queries are
// const and thread-safe; call them from many threads at once.
#pragma once

#include "meshes/mesh.h"

#include <Eigen/Core>

#include <cstdint>
#include <memory>
#include <stdexcept>

namespace prt {

class RayError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct RayHit {
  std::int32_t triangle = -1;  // index into mesh.triangles, -1 for a miss
  float u = 0.f, v = 0.f;      // barycentrics: point = (1-u-v) p0 + u p1 + v p2
  float t = 0.f;               // distance along the (unit) direction
};

class RayScene {
 public:
  // Builds a static, high-quality BVH of the mesh's triangles. Throws RayError with
  // Embree's message on failure.
  explicit RayScene(const meshes::Mesh& mesh);
  ~RayScene();
  RayScene(const RayScene&) = delete;
  RayScene& operator=(const RayScene&) = delete;

  // occluded[k] = 1 when the ray origin + t d_k hits any triangle for t in [tnear, inf),
  // else 0. `directions` is 3 x count (unit columns).
  void occluded(const Eigen::Vector3f& origin, const Eigen::Ref<const Eigen::Matrix3Xf>& directions,
                float tnear, std::uint8_t* occluded) const;

  // Closest hit along each ray in [tnear, inf).
  void intersect(const Eigen::Vector3f& origin,
                 const Eigen::Ref<const Eigen::Matrix3Xf>& directions, float tnear,
                 RayHit* hits) const;

  // The same with one origin per ray: `origins` is 3 x count, like `directions`.
  void occluded_from(const Eigen::Ref<const Eigen::Matrix3Xf>& origins,
                     const Eigen::Ref<const Eigen::Matrix3Xf>& directions, float tnear,
                     std::uint8_t* occluded) const;
  void intersect_from(const Eigen::Ref<const Eigen::Matrix3Xf>& origins,
                      const Eigen::Ref<const Eigen::Matrix3Xf>& directions, float tnear,
                      RayHit* hits) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace prt
