// Loop subdivision (meshes/subdivide.h): exact counts on a closed mesh, the convex
// hull bound on a sphere, and the PLY it writes read back by the mesh loader.
#include "meshes/subdivide.h"
#include "meshes/load.h"
#include "meshes/mesh.h"
#include "meshes/write_ply.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <utility>

namespace {

// Regular icosahedron on the unit sphere, counter-clockwise from outside: V 12, E 30, F 20.
meshes::Mesh icosahedron() {
  const float t = (1.f + std::sqrt(5.f)) / 2.f;
  meshes::Mesh m;
  m.positions = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                 {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  for (meshes::Vec3& p : m.positions) p.normalize();
  m.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                 {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                 {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                 {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  return m;
}

// Splits every edge at its midpoint pushed onto the unit sphere, `levels` times.
meshes::Mesh icosphere(int levels) {
  meshes::Mesh m = icosahedron();
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> mid;
    auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
      const auto key = std::minmax(a, b);
      auto [it, fresh] = mid.emplace(key, std::uint32_t(m.positions.size()));
      if (fresh) m.positions.push_back((m.positions[a] + m.positions[b]).normalized());
      return it->second;
    };
    std::vector<meshes::Triangle> next;
    for (const meshes::Triangle& t : m.triangles) {
      const std::uint32_t a = midpoint(t[0], t[1]), b = midpoint(t[1], t[2]),
                          c = midpoint(t[2], t[0]);
      next.insert(next.end(), {{t[0], a, c}, {t[1], b, a}, {t[2], c, b}, {a, b, c}});
    }
    m.triangles = next;
  }
  return m;
}

std::size_t edge_count(const meshes::Mesh& m) {
  std::set<std::pair<std::uint32_t, std::uint32_t>> edges;
  for (const meshes::Triangle& t : m.triangles) {
    for (int c = 0; c < 3; ++c) edges.insert(std::minmax(t[c], t[(c + 1) % 3]));
  }
  return edges.size();
}

TEST(LoopSubdivision, ClosedMeshCountsFollowTheExactFormulas) {
  const meshes::Mesh base = icosahedron();
  meshes::Mesh expected = base;
  for (int steps = 1; steps <= 2; ++steps) {
    // One round: a new vertex per edge (V' = V + E), four triangles per triangle (F' = 4F).
    const std::size_t v = expected.vertex_count() + edge_count(expected);
    const std::size_t f = 4 * expected.triangle_count();
    const meshes::Mesh refined = meshes::loop_subdivide(base, steps);
    EXPECT_EQ(refined.vertex_count(), v) << steps << " step(s)";
    EXPECT_EQ(refined.triangle_count(), f) << steps << " step(s)";
    // Still closed: Euler characteristic 2 and every edge in exactly two triangles (E = 3F/2).
    EXPECT_EQ(edge_count(refined) * 2, 3 * refined.triangle_count());
    EXPECT_EQ(std::int64_t(v) - std::int64_t(edge_count(refined)) + std::int64_t(f), 2);
    expected = refined;
  }
  EXPECT_EQ(expected.vertex_count(), 162u);
  EXPECT_EQ(expected.triangle_count(), 320u);
}

TEST(LoopSubdivision, SphereVerticesStayBetweenTheHullBoundAndTheSphere) {
  const meshes::Mesh sphere = icosphere(3);
  // Every Loop vertex is a convex combination of a vertex's one-ring (even) or of an edge's
  // two ends and two opposite corners (odd): unit vectors within the largest edge angle a of
  // one of them, so its length is in [cos a, 1].
  float max_angle = 0.f;
  for (const meshes::Triangle& t : sphere.triangles) {
    for (int c = 0; c < 3; ++c) {
      const float dot = sphere.positions[t[c]].dot(sphere.positions[t[(c + 1) % 3]]);
      max_angle = std::max(max_angle, std::acos(std::clamp(dot, -1.f, 1.f)));
    }
  }
  const meshes::Mesh refined = meshes::loop_subdivide(sphere, 1);
  ASSERT_EQ(refined.vertex_count(), sphere.vertex_count() + edge_count(sphere));
  float lo = 2.f, hi = 0.f;
  for (const meshes::Vec3& p : refined.positions) {
    lo = std::min(lo, p.norm());
    hi = std::max(hi, p.norm());
  }
  EXPECT_LE(hi, 1.f + 1e-6f);
  EXPECT_GE(lo, std::cos(max_angle) - 1e-6f);
  // And it did move the new vertices off the chords: the edge midpoints alone would sit at
  // cos(a / 2) at best, Loop's weights pull them further out.
  EXPECT_GT(lo, 0.97f);
}

TEST(LoopSubdivision, WrittenPlyLoadsBackUnchanged) {
  const meshes::Mesh refined = meshes::loop_subdivide(icosahedron(), 1);
  const std::filesystem::path dir = PRTR_TEST_TMPDIR;
  std::filesystem::create_directories(dir);
  const std::filesystem::path path = dir / "loop_icosahedron.ply";
  meshes::write_ply(path, refined);
  meshes::LoadOptions no_weld;
  no_weld.weld_tolerance = -1.0;
  const meshes::Mesh back = meshes::load_mesh(path, no_weld);
  ASSERT_EQ(back.vertex_count(), refined.vertex_count());
  ASSERT_EQ(back.triangle_count(), refined.triangle_count());
  for (std::size_t i = 0; i < back.vertex_count(); ++i) {
    EXPECT_EQ(back.positions[i], refined.positions[i]) << "vertex " << i;
  }
  EXPECT_EQ(back.triangles, refined.triangles);
}

TEST(LoopSubdivision, NonManifoldInputIsRefusedByName) {
  meshes::Mesh m = icosahedron();
  m.triangles.push_back(m.triangles[0]);  // a third face on the same edges
  EXPECT_THROW(meshes::loop_subdivide(m, 1), meshes::MeshError);
}

}  // namespace
