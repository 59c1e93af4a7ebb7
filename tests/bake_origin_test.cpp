// Where the baker's rays start: pits, creases and enclosed vertices, against analytic
// visibility and an independent brute-force ray count (Moller-Trumbore over every triangle,
// from a point just outside the surface), plus the nearly-occluded vertex diagnostic.
#include "prt/bake.h"

#include "ray_oracle.h"

#include "meshes/frames.h"
#include "meshes/load.h"
#include "meshes/procedural.h"
#include "prt/sampling.h"
#include "prt/sh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <vector>

namespace {

using Vec3d = Eigen::Vector3d;
constexpr double kPi = std::numbers::pi;

// A diffuse bake of a white Lambert surface: under a white sky its DC term is the visibility.
prt::BakeOptions white_lambert_bake(int order, int samples, int bounces) {
  prt::BakeOptions o;
  o.kind = prt::TransferKind::kDiffuse;
  o.material.kind = prt::MaterialKind::kLambert;
  o.material.albedo = Eigen::Vector3f::Constant(1.f);
  o.material.specular = 0.f;
  o.order = order;
  o.samples = samples;
  o.bounces = bounces;
  return o;
}

// Diffuse exit radiance under a white sky of radiance 1, i.e. (rho / pi) int V cos.
double white_sky(const prt::TransferSet& t, std::size_t p) {
  return t.transfer(p, 0)(0, 0) * std::sqrt(4 * kPi);
}

// First hit along o + t d, t > 0, against every triangle; true when anything is hit.
bool brute_hits(const meshes::Mesh& m, const Vec3d& o, const Vec3d& d) {
  for (std::size_t t = 0; t < m.triangles.size(); ++t)
    if (test_support::ray_hits_triangle(m, t, o, d, 1e-12)) return true;
  return false;
}

// Cosine-weighted visible fraction (1/pi) int V cos seen from `o` about `n`, by counting rays.
double brute_visibility(const meshes::Mesh& m, const Vec3d& o, const Vec3d& n, int rays,
                        std::uint64_t seed) {
  const Vec3d a = std::abs(n.x()) < 0.9 ? Vec3d::UnitX() : Vec3d::UnitY();
  Eigen::Matrix3d b;
  b.col(0) = (a - a.dot(n) * n).normalized();
  b.col(1) = n.cross(b.col(0));
  b.col(2) = n;
  prt::Pcg32 rng(seed);
  int open = 0;
  for (int k = 0; k < rays; ++k) {
    const Vec3d d = b * prt::sample_cosine_hemisphere(rng.next_double(), rng.next_double());
    if (!brute_hits(m, o, d)) ++open;
  }
  return double(open) / rays;
}

// A closed prism, z in [-1, 1], whose cross-section has a V-shaped groove with its bottom
// on the z axis: walls 20 degrees either side of +Y, the left one 4 units long, the right one
// 1 unit, ending on a ledge. The vertex at the groove bottom (returned in *pit) has corner
// angles of 180 degrees on each wall, so its angle-weighted normal is +Y, straight up the
// groove; the area-weighted sum of its face normals leans 59 degrees toward the right wall,
// 39 degrees past the groove's 20-degree half-width, so an origin offset along that sum
// starts inside the solid. Everything it sees comes down the groove: a dihedral wedge of
// half-angle 20 degrees about its normal, whose cosine-weighted share is sin(20 degrees).
meshes::Mesh grooved_prism(std::uint32_t* pit) {
  const double b = 20.0 * kPi / 180.0;
  const std::vector<Eigen::Vector2f> outline = {
      {-3.f, -1.f},
      {3.f, -1.f},
      {3.f, float(std::cos(b))},
      {float(std::sin(b)), float(std::cos(b))},
      {0.f, 0.f},
      {float(-4 * std::sin(b)), float(4 * std::cos(b))},
      {-3.f, float(4 * std::cos(b))},
  };
  const std::uint32_t k = std::uint32_t(outline.size());
  const float zs[3] = {-1.f, 0.f, 1.f};
  meshes::Mesh m;
  for (float z : zs)
    for (const Eigen::Vector2f& q : outline) m.positions.emplace_back(q.x(), q.y(), z);
  auto at = [&](std::uint32_t i, std::uint32_t layer) { return layer * k + i % k; };
  // The outline runs counter-clockwise seen from +Z, so (a, b, c) below faces outward.
  for (std::uint32_t i = 0; i < k; ++i) {
    for (std::uint32_t layer = 0; layer < 2; ++layer) {
      const std::uint32_t a = at(i, layer), bb = at(i + 1, layer), c = at(i + 1, layer + 1),
                          d = at(i, layer + 1);
      m.triangles.push_back({a, bb, c});
      m.triangles.push_back({a, c, d});
    }
  }
  // Caps: a fan from the groove bottom (index 4), which sees the whole outline.
  for (std::uint32_t i : {5u, 6u, 0u, 1u, 2u}) {
    m.triangles.push_back({at(4, 2), at(i, 2), at(i + 1, 2)});
    m.triangles.push_back({at(4, 0), at(i + 1, 0), at(i, 0)});
  }
  meshes::compute_frames(m);
  *pit = at(4, 1);
  return m;
}

TEST(BakeOrigin, GroovePitSeesDownTheGroove) {
  std::uint32_t pit = 0;
  const meshes::Mesh m = grooved_prism(&pit);
  ASSERT_NO_THROW(meshes::validate(m, "grooved prism"));
  const Vec3d n = m.normals[pit].cast<double>();
  ASSERT_NEAR(n.y(), 1.0, 1e-5);  // the premise: the vertex normal points up the groove

  prt::BakeOptions o = white_lambert_bake(2, 4096, 0);
  prt::BakeStats stats;
  const prt::TransferSet t = prt::bake(m, o, &stats);

  const Vec3d origin = m.positions[pit].cast<double>() + 1e-5 * n;
  const double brute = brute_visibility(m, origin, n, 40000, 11);
  const double exact = std::sin(20.0 * kPi / 180.0);
  // The brute force is itself checked against the closed form: sigma ~ 0.0024 at 40000 rays.
  EXPECT_NEAR(brute, exact, 0.01);
  // 0.015: the brute force's sigma plus the lattice's error on a visibility edge.
  EXPECT_NEAR(white_sky(t, pit), brute, 0.015) << "vertex " << pit;
  EXPECT_TRUE(std::find(stats.occluded_vertices.begin(), stats.occluded_vertices.end(), pit) ==
              stats.occluded_vertices.end());
}

TEST(BakeOrigin, GroovePitBounceSeesTheWalls) {
  // The bounce pass starts from the same origins: a pit that sees its walls gets light back
  // from them, and no more than the energy bound allows.
  std::uint32_t pit = 0;
  const meshes::Mesh m = grooved_prism(&pit);
  prt::BakeOptions o = white_lambert_bake(2, 1024, 1);
  o.material.albedo = Eigen::Vector3f::Constant(0.5f);
  const prt::TransferSet t = prt::bake(m, o);
  o.bounces = 0;
  const prt::TransferSet direct = prt::bake(m, o);
  const double with_bounce = white_sky(t, pit), without = white_sky(direct, pit);
  const double open = std::sin(20.0 * kPi / 180.0);
  EXPECT_NEAR(without, 0.5 * open, 0.01);
  // The walls fill the other 1 - sin 20 degrees of its view and send back at most
  // 0.5 x 0.5 (albedo times their own direct light); they see a third or so of the sky, so
  // about 0.06 comes back (measured 0.057).
  EXPECT_GT(with_bounce - without, 0.03);
  EXPECT_LT(with_bounce - without, 0.25 * (1 - open));
}

TEST(BakeOrigin, ReportsEnclosedVertices) {
  // A plane with an open box turned upside down on it, sealing 5 x 5 of the plane's
  // vertices in. Those and every vertex of the lid see nothing; the plane outside sees at
  // least half its sky.
  meshes::Mesh lid = meshes::make_open_box(1.2f, 4);
  for (meshes::Vec3& p : lid.positions) p = meshes::Vec3(p.x(), 0.6f - p.y(), -p.z());
  const meshes::Mesh plane = meshes::make_plane(4.f, 16);
  const meshes::Mesh m = meshes::merge({plane, lid});
  prt::BakeOptions o = white_lambert_bake(2, 256, 0);
  prt::BakeStats stats;
  prt::bake(m, o, &stats);
  std::vector<std::uint32_t> expected;
  for (std::uint32_t v = 0; v < m.vertex_count(); ++v) {
    const meshes::Vec3& p = m.positions[v];
    const bool on_lid = v >= plane.vertex_count();
    if (on_lid || (std::abs(p.x()) < 0.6f && std::abs(p.z()) < 0.6f)) expected.push_back(v);
  }
  EXPECT_EQ(expected.size(), 25u + lid.vertex_count());
  EXPECT_EQ(stats.occluded_vertices, expected);
  // Name every vertex that differs: the comparison above prints only the first 32.
  for (std::uint32_t v : stats.occluded_vertices)
    if (std::find(expected.begin(), expected.end(), v) == expected.end())
      ADD_FAILURE() << "unexpected " << v << " at " << m.positions[v].transpose() << " n "
                    << m.normals[v].transpose();
  for (std::uint32_t v : expected)
    if (std::find(stats.occluded_vertices.begin(), stats.occluded_vertices.end(), v) ==
        stats.occluded_vertices.end())
      ADD_FAILURE() << "missing " << v << " at " << m.positions[v].transpose() << " n "
                    << m.normals[v].transpose();
}

TEST(BakeOrigin, BunnyPitsSeeTheSkyAndBlackVerticesAreReported) {
  const std::filesystem::path bunny = "/usr/share/glmark2/models/bunny.obj";
  if (!std::filesystem::exists(bunny)) GTEST_SKIP() << bunny << " missing (glmark2-data)";
  const meshes::Mesh m = meshes::load_mesh(bunny);
  prt::BakeOptions o = white_lambert_bake(1, 256, 0);
  prt::BakeStats stats;
  const prt::TransferSet t = prt::bake(m, o, &stats);
  // Two pits under the bunny whose summed face normals point into the body: a brute-force
  // count from a point just outside their faces gives 0.60 and 0.63 (2000 rays each, sigma 0.011).
  EXPECT_NEAR(white_sky(t, 115), 0.60, 0.05);
  EXPECT_NEAR(white_sky(t, 117), 0.63, 0.05);
  // A vertex is black only if it sees (almost) none of its rays, so the diagnostic names it.
  std::vector<std::uint32_t> black;
  for (std::uint32_t p = 0; p < m.vertex_count(); ++p)
    if (!(white_sky(t, p) > 1e-4)) black.push_back(p);
  for (std::uint32_t p : black) {
    EXPECT_TRUE(
        std::binary_search(stats.occluded_vertices.begin(), stats.occluded_vertices.end(), p))
        << "vertex " << p << " is black but not reported";
  }
  // Vertex 16322 is the one the mesh itself puts inside the body: triangle (16322, 16321,
  // 34834) folds back and takes it 1.8e-4 under the neighbouring face (16321, 20913, 34834).
  // The baker finds it just inside and starts its rays from just outside that face, so no
  // vertex is left nearly occluded, and it sees what a brute-force count from there sees.
  EXPECT_TRUE(stats.occluded_vertices.empty());
  EXPECT_TRUE(black.empty());
  EXPECT_TRUE(std::binary_search(stats.moved_origins.begin(), stats.moved_origins.end(), 16322u));
  const std::uint32_t v = 16322;
  const meshes::Triangle* over = nullptr;
  for (const meshes::Triangle& tri : m.triangles) {
    std::array<std::uint32_t, 3> sorted = tri;
    std::sort(sorted.begin(), sorted.end());
    if (sorted == std::array<std::uint32_t, 3>{16321, 20913, 34834}) over = &tri;
  }
  ASSERT_NE(over, nullptr);
  const Vec3d q0 = m.positions[(*over)[0]].cast<double>();
  const Vec3d n_over = (m.positions[(*over)[1]].cast<double>() - q0)
                           .cross(m.positions[(*over)[2]].cast<double>() - q0)
                           .normalized();
  const Vec3d p = m.positions[v].cast<double>();
  const double depth = n_over.dot(q0 - p);
  EXPECT_GT(depth, 1e-4);  // the premise: under the face, by about 1.8e-4
  const Vec3d outside = p + (depth + 1e-6) * n_over;
  const double brute = brute_visibility(m, outside, m.normals[v].cast<double>(), 2000, 5);
  EXPECT_GT(brute, 0.1);
  EXPECT_NEAR(white_sky(t, v), brute, 0.05);
}

// A closed box [-1, 1]^3 with a thin fin on its top, folded so that a vertex of the fin
// ends up just inside the box. Seen from above (x right, z down the page), the top is the
// square with an inner triangle a (0, -0.5), b (0, 0.5), w (-0.5, 0); face F = (a, e, b),
// e = (1, 0) on the right edge, lies across edge a-b from the triangle. The triangle is a
// fan about v. Then w rises to a fin tip 0.5 above the top, and v moves across a-b to
// `depth` under F at (0.2, 0): the fan's triangle on a-b folds back under F and its other
// two pierce F near v on their way up to w, so v and its immediate surroundings lie inside
// the box. *over is F.
meshes::Mesh folded_fin_box(float depth, std::uint32_t* v, std::uint32_t* over) {
  meshes::Mesh m;
  const float ring[5][2] = {{-1, -1}, {1, -1}, {1, 0}, {1, 1}, {-1, 1}};  // C0 C1 e C2 C3
  for (float y : {1.f, -1.f})
    for (const auto& q : ring) m.positions.emplace_back(q[0], y, q[1]);
  m.positions.emplace_back(0.f, 1.f, -0.5f);  // 10 a
  m.positions.emplace_back(0.f, 1.f, 0.5f);   // 11 b
  m.positions.emplace_back(-0.5f, 1.f, 0.f);  // 12 w
  m.positions.emplace_back(-0.2f, 1.f, 0.f);  // 13 v, inside a-b-w while flat
  const std::vector<meshes::Triangle> top = {{10, 13, 11}, {11, 13, 12}, {12, 13, 10},  // v's fan
                                             {10, 0, 1},   {10, 1, 2},   {10, 2, 11},
                                             {11, 2, 3},   {11, 3, 4},  // F = 5th
                                             {11, 4, 12},  {12, 4, 0},   {12, 0, 10}};
  std::vector<meshes::Triangle> tris = top;
  for (std::uint32_t i = 0; i < 5; ++i) {
    const std::uint32_t j = (i + 1) % 5;
    tris.push_back({i, j, j + 5});
    tris.push_back({i, j + 5, i + 5});
  }
  for (std::uint32_t i : {6u, 7u, 8u}) tris.push_back({5, i, i + 1});
  // Orient every face outward while the box is still convex.
  for (meshes::Triangle& t : tris) {
    const meshes::Vec3 p0 = m.positions[t[0]], p1 = m.positions[t[1]], p2 = m.positions[t[2]];
    if ((p1 - p0).cross(p2 - p0).dot(p0 + p1 + p2) < 0) std::swap(t[1], t[2]);
  }
  m.triangles = tris;
  m.positions[12].y() = 1.5f;
  m.positions[13] = meshes::Vec3(0.2f, 1.f - depth, 0.f);
  meshes::compute_frames(m);
  *v = 13;
  *over = 5;
  return m;
}

TEST(BakeOrigin, VertexFoldedJustInsideSeesFromOutsideItsFace) {
  // 2e-4 under the face: half the default ray offset (1e-4 of the diagonal, 3.77 here),
  // about as deep as the bunny's fold (0.6 offsets).
  std::uint32_t v = 0, over = 0;
  const meshes::Mesh m = folded_fin_box(2e-4f, &v, &over);
  const Vec3d p = m.positions[v].cast<double>(), n = m.normals[v].cast<double>();
  const meshes::Triangle& f = m.triangles[over];
  const Vec3d q0 = m.positions[f[0]].cast<double>();
  const Vec3d n_over = (m.positions[f[1]].cast<double>() - q0)
                           .cross(m.positions[f[2]].cast<double>() - q0)
                           .normalized();
  const double depth = n_over.dot(q0 - p);
  ASSERT_NEAR(depth, 2e-4, 1e-5);
  // The premise: from the vertex, nothing escapes, so an origin near it bakes black.
  EXPECT_EQ(brute_visibility(m, p + 1e-6 * n, n, 2000, 3), 0.0);

  prt::BakeOptions o = white_lambert_bake(2, 4096, 0);
  prt::BakeStats stats;
  const prt::TransferSet t = prt::bake(m, o, &stats);
  EXPECT_EQ(stats.moved_origins, std::vector<std::uint32_t>{v});
  EXPECT_TRUE(stats.occluded_vertices.empty());
  // Just outside the face it lies under, about its own normal.
  const double brute = brute_visibility(m, p + (depth + 1e-6) * n_over, n, 40000, 17);
  EXPECT_GT(brute, 0.2);
  // 0.015: the brute force's sigma (~0.0025) plus the lattice's error on a visibility edge.
  EXPECT_NEAR(white_sky(t, v), brute, 0.015) << "vertex " << v;
}

// A closed axis-aligned box, outward normals, 12 triangles on its 8 corners.
meshes::Mesh closed_box(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi) {
  meshes::Mesh m;
  for (int i = 0; i < 8; ++i)
    m.positions.emplace_back(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(),
                             i & 4 ? hi.z() : lo.z());
  // Each face as a quad, counter-clockwise seen from outside.
  const std::uint32_t quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                     {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& q : quads) {
    m.triangles.push_back({q[0], q[1], q[2]});
    m.triangles.push_back({q[0], q[2], q[3]});
  }
  meshes::compute_frames(m);
  return m;
}

TEST(BakeOrigin, BoxInsideABoxStaysBlackAndReported) {
  // The inner box's top is 0.02 under the outer box's: three times the inside test's reach
  // (10 ray offsets, 1e-3 of the diagonal 4 sqrt 3), so its vertices are enclosed, not just
  // inside, and nothing moves them out.
  const meshes::Mesh outer = closed_box({-2.f, -2.f, -2.f}, {2.f, 2.f, 2.f});
  const meshes::Mesh inner = closed_box({-0.5f, -0.5f, -0.5f}, {0.5f, 1.98f, 0.5f});
  const meshes::Mesh m = meshes::merge({outer, inner});
  prt::BakeOptions o = white_lambert_bake(2, 1024, 0);
  prt::BakeStats stats;
  const prt::TransferSet t = prt::bake(m, o, &stats);
  std::vector<std::uint32_t> expected;
  for (std::uint32_t v = outer.vertex_count(); v < m.vertex_count(); ++v) expected.push_back(v);
  EXPECT_EQ(stats.occluded_vertices, expected);
  EXPECT_TRUE(stats.moved_origins.empty());
  // Zero but for float cancellation in w Y Y^T - w Y_O Y_O^T.
  for (std::uint32_t v : expected) EXPECT_NEAR(white_sky(t, v), 0.0, 1e-6) << "vertex " << v;
  for (std::uint32_t v = 0; v < outer.vertex_count(); ++v) EXPECT_GT(white_sky(t, v), 0.5);
}

}  // namespace
