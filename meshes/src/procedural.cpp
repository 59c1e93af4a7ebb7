// meshes/procedural.cpp: analytic test meshes whose areas, normals and occlusion have closed
// forms (sphere 4 pi r^2, torus 4 pi^2 R r, plane, open box), for the tests of every stage.
//
// Winding: every triangle is counter-clockwise seen from the side its normal points to,
// (p1 - p0) x (p2 - p0) (meshes/mesh.h). Grids are emitted by one helper, emit_grid(), whose
// triangles have normal U x V for the two spanning directions U, V.
#include "meshes/procedural.h"

#include "meshes/frames.h"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace meshes {

namespace {

constexpr double kPi = std::numbers::pi;

void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument(message);
}

std::uint32_t index_of(const Mesh& mesh) {
  return static_cast<std::uint32_t>(mesh.positions.size());
}

// Appends the parallelogram a, b, c, d = b + c - a as the triangles (a, b, c), (b, d, c),
// both with the normal (b - a) x (c - a).
void add_quad(Mesh& mesh, std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d) {
  mesh.triangles.push_back({a, b, c});
  mesh.triangles.push_back({b, d, c});
}

// A flat (n+1) x (n+1) grid origin + U i/n + V j/n whose triangles have normal U x V.
void emit_grid(Mesh& mesh, const Vec3& origin, const Vec3& u, const Vec3& v, int n) {
  const std::uint32_t base = index_of(mesh);
  const auto at = [&](int i, int j) { return base + static_cast<std::uint32_t>(i * (n + 1) + j); };
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; j <= n; ++j) {
      mesh.positions.push_back(origin + u * (static_cast<float>(i) / static_cast<float>(n)) +
                               v * (static_cast<float>(j) / static_cast<float>(n)));
    }
  }
  // Triangle (a, a + U, a + V) has normal U x V.
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      add_quad(mesh, at(i, j), at(i + 1, j), at(i, j + 1), at(i + 1, j + 1));
    }
  }
}

}  // namespace

Mesh make_sphere(float radius, int segments, int rings, const Vec3& center) {
  require(radius > 0.f && std::isfinite(radius), "make_sphere: radius must be positive");
  require(segments >= 3, "make_sphere: need at least 3 segments");
  require(rings >= 2, "make_sphere: need at least 2 rings");
  require(center.allFinite(), "make_sphere: centre must be finite");

  // Point at polar angle theta from +Y and azimuth phi: (sin t cos p, cos t, sin t sin p).
  // Its outward normal is d/dphi x d/dtheta, so a quad corner a with b one step in phi and c
  // one step in theta gives the outward triangle (a, b, c).
  Mesh mesh;
  const auto point = [&](double theta, double phi) {
    const double s = std::sin(theta);
    const Eigen::Vector3d dir(s * std::cos(phi), std::cos(theta), s * std::sin(phi));
    return Vec3(center + (static_cast<double>(radius) * dir).cast<float>());
  };
  mesh.positions.push_back(center + Vec3(0.f, radius, 0.f));  // north pole, index 0
  for (int i = 1; i < rings; ++i) {
    const double theta = kPi * i / rings;
    for (int j = 0; j < segments; ++j)
      mesh.positions.push_back(point(theta, 2.0 * kPi * j / segments));
  }
  mesh.positions.push_back(center - Vec3(0.f, radius, 0.f));  // south pole
  const std::uint32_t south = index_of(mesh) - 1;

  const auto ring = [&](int i, int j) {  // ring i in [1, rings - 1], j wraps around
    return static_cast<std::uint32_t>(1 + (i - 1) * segments + (j % segments));
  };
  for (int j = 0; j < segments; ++j) {
    mesh.triangles.push_back({0, ring(1, j + 1), ring(1, j)});
  }
  for (int i = 1; i < rings - 1; ++i) {
    for (int j = 0; j < segments; ++j) {
      add_quad(mesh, ring(i, j), ring(i, j + 1), ring(i + 1, j), ring(i + 1, j + 1));
    }
  }
  for (int j = 0; j < segments; ++j) {
    mesh.triangles.push_back({ring(rings - 1, j), ring(rings - 1, j + 1), south});
  }
  compute_frames(mesh);
  return mesh;
}

Mesh make_torus(float major_radius, float minor_radius, int segments, int sides) {
  require(minor_radius > 0.f && major_radius > minor_radius,
          "make_torus: need 0 < minor_radius < major_radius");
  require(segments >= 3 && sides >= 3, "make_torus: need at least 3 segments and 3 sides");

  // Point at angle u about +Y and v about the tube: ((R + r cos v) cos u, r sin v,
  // (R + r cos v) sin u). Outward normal is d/dv x d/du, so with b one step in v and c one
  // step in u, (a, b, c) faces out.
  Mesh mesh;
  for (int i = 0; i < segments; ++i) {
    const double u = 2.0 * kPi * i / segments;
    for (int j = 0; j < sides; ++j) {
      const double v = 2.0 * kPi * j / sides;
      const double ring = major_radius + minor_radius * std::cos(v);
      mesh.positions.push_back(
          Eigen::Vector3d(ring * std::cos(u), minor_radius * std::sin(v), ring * std::sin(u))
              .cast<float>());
    }
  }
  const auto at = [&](int i, int j) {
    return static_cast<std::uint32_t>((i % segments) * sides + (j % sides));
  };
  for (int i = 0; i < segments; ++i) {
    for (int j = 0; j < sides; ++j) {
      add_quad(mesh, at(i, j), at(i, j + 1), at(i + 1, j), at(i + 1, j + 1));
    }
  }
  compute_frames(mesh);
  return mesh;
}

Mesh make_plane(float size, int subdivisions, float y) {
  require(size > 0.f && std::isfinite(size), "make_plane: size must be positive");
  require(subdivisions >= 1, "make_plane: need at least 1 subdivision");
  Mesh mesh;
  const float h = 0.5f * size;
  // Z x X = +Y.
  emit_grid(mesh, Vec3(-h, y, -h), Vec3(0.f, 0.f, size), Vec3(size, 0.f, 0.f), subdivisions);
  compute_frames(mesh);
  return mesh;
}

Mesh make_plane_and_sphere(float plane_size, int plane_subdivisions, float radius, float height,
                           int segments, int rings) {
  require(height > radius,
          "make_plane_and_sphere: the sphere must float above the plane "
          "(height > radius)");
  return merge({make_plane(plane_size, plane_subdivisions, 0.f),
                make_sphere(radius, segments, rings, Vec3(0.f, height, 0.f))});
}

Mesh make_open_box(float size, int subdivisions) {
  require(size > 0.f && std::isfinite(size), "make_open_box: size must be positive");
  require(subdivisions >= 1, "make_open_box: need at least 1 subdivision");
  // Each face is its own grid (edges not shared) so its normal stays exactly the face's.
  // U x V is the inward normal.
  Mesh mesh;
  const float h = 0.5f * size;
  const Vec3 x(size, 0.f, 0.f), y(0.f, size, 0.f), z(0.f, 0.f, size);
  emit_grid(mesh, Vec3(-h, -h, -h), z, x, subdivisions);  // floor y = -h, normal +Y
  emit_grid(mesh, Vec3(-h, -h, -h), y, z, subdivisions);  // wall x = -h, normal +X
  emit_grid(mesh, Vec3(h, -h, -h), z, y, subdivisions);   // wall x = +h, normal -X
  emit_grid(mesh, Vec3(-h, -h, -h), x, y, subdivisions);  // wall z = -h, normal +Z
  emit_grid(mesh, Vec3(-h, -h, h), y, x, subdivisions);   // wall z = +h, normal -Z
  compute_frames(mesh);
  return mesh;
}

Mesh merge(const std::vector<Mesh>& parts) {
  Mesh mesh;
  for (const Mesh& part : parts) {
    const std::uint32_t offset = index_of(mesh);
    mesh.positions.insert(mesh.positions.end(), part.positions.begin(), part.positions.end());
    for (const Triangle& t : part.triangles) {
      mesh.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
    }
  }
  compute_frames(mesh);
  return mesh;
}

}  // namespace meshes
