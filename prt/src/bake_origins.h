// prt/src/bake_origins.h (private to prt): where each vertex's shadow rays start, so that
// a ray leaving a pit or a crease starts outside the surface (prt/bake.h, "Ray origins";
// docs/ARCHITECTURE.md, "Baking (prt/)"; the start points replace the single offset origin
// of Sloan, Kautz & Snyder 2002, section 5).
#pragma once

#include "meshes/mesh.h"

#include <Eigen/Core>

#include <cstdint>
#include <optional>
#include <vector>

namespace prt::detail {

struct BakeContext;

// Where each vertex's rays start (prt/bake.h, "Ray origins"; docs/ARCHITECTURE.md, "Baking
// (prt/)"). Every triangle at a vertex's position, split vertices included, offers a start
// point: a step from the corner into the triangle, toward its centroid, lifted a tenth of
// that step along its normal. A ray starts from the face whose plane it rises most steeply
// above. One shared origin cannot be outside everywhere: at a pit or a crease the outside
// near the vertex is a narrow wedge, and a fixed direction can miss it.
struct OriginFaces {
  std::vector<std::uint32_t> group;  // vertex -> position group
  std::vector<std::uint32_t> first;  // group g's entries are [first[g], first[g + 1])
  Eigen::Matrix3Xf normals;          // unit face normal of each entry
  Eigen::Matrix3Xf steps;            // corner to start point, in world units
};

// Start points sit kStep x offset into their face and kLift of that above it. The lift keeps
// them ~50 float ulps off their own face's plane at the default offset (1e-4 of the
// diagonal), so Embree cannot report the face itself, yet small against the step, so a
// start point stays inside wedges down to ~10 degrees between faces. The step is a tenth of
// the offset because the bunny's pits fold at that scale: their visibility converges to a
// brute-force count from a point just outside as the step shrinks (docs/ARCHITECTURE.md).
inline constexpr float kStep = 0.1f;
inline constexpr float kLift = 0.1f;

// A nearly occluded vertex whose start points lie just inside a closed surface (a fold can
// take a vertex under its neighbouring face) starts its rays again from just past the exit.
// "Just": the first hit along a probe is a back face within kEscape x offset. The folds
// measured so far are 0.6 and 1.5 offsets deep (bunny, horse); the nearest exit from
// genuinely enclosed parts (glmark2's cat) is 28 offsets away, so those stay black and
// flagged (docs/ARCHITECTURE.md).
inline constexpr float kEscape = 10.f;

// The start faces of every position group; `offset` is the ray offset in world units.
OriginFaces origin_faces(const meshes::Mesh& mesh, float offset);

// Start points of p's rays (the directions `world`, one per column) into `origins`: each on
// the face at p's position whose plane the ray rises most steeply above. A vertex on no face
// starts above itself.
void ray_origins(const BakeContext& ctx, std::uint64_t p, const Eigen::Matrix3Xf& world,
                 Eigen::Matrix3Xf& origins);

// Where p's rays should start instead when its start points are just inside a closed
// surface: probes from each start point, along p's normal and the start face's normal, look
// for a first hit on a back face (the ray leaves the body) closer than kEscape x offset. The
// nearest such exit wins, and the new origin sits that exit's lift above it, on its outer
// side. None when every probe first meets a front face, nothing, or a distant back face.
std::optional<Eigen::Vector3f> escape_origin(const BakeContext& ctx, std::uint64_t p);

}  // namespace prt::detail
