// Tests for meshes/atlas.h: every bilinear lookup inside a chart reads only its triangle's
// texels (random points, the lookup written out here independently of the packer), texels
// are owned once, texel counts follow triangle areas, gutter samples lie on their triangle,
// and bad sizes are refused.
#include "meshes/atlas.h"
#include "meshes/procedural.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

namespace {

using meshes::Atlas;
using meshes::Mesh;

// A sphere plus a few slivers, a zero-area triangle and a tiny triangle, so that charts of
// very different sizes share the packing.
Mesh test_mesh() {
  Mesh mesh = meshes::make_sphere(1.f, 16, 8);
  const auto base = std::uint32_t(mesh.positions.size());
  mesh.positions.push_back({3, 0, 0});
  mesh.positions.push_back({4, 0, 0});
  mesh.positions.push_back({3, 1e-3f, 0});  // sliver
  mesh.positions.push_back({5, 0, 0});      // collinear with the first two: zero area
  mesh.positions.push_back({3, 0, 1e-4f});  // tiny
  mesh.triangles.push_back({base, base + 1, base + 2});
  mesh.triangles.push_back({base, base + 1, base + 3});
  mesh.triangles.push_back({base, base + 4, base + 1});
  mesh.triangles.push_back({base, base, base});  // one repeated vertex
  return mesh;
}

// The texel (x, y) a bilinear lookup at texture coordinate uv reads first; it also reads
// x + 1 and y + 1 (texel centres at (i + 0.5) / size).
std::pair<int, int> lookup_base(const Atlas& atlas, const Eigen::Vector2d& uv) {
  return {int(std::floor(uv.x() * atlas.width - 0.5)),
          int(std::floor(uv.y() * atlas.height - 0.5))};
}

TEST(Atlas, EveryLookupInsideAChartReadsOnlyItsTriangle) {
  const Mesh mesh = test_mesh();
  const Atlas atlas = meshes::make_atlas(mesh, 128, 96);
  ASSERT_EQ(atlas.uv.size(), 3 * mesh.triangles.size());
  ASSERT_EQ(atlas.texel_triangle.size(), std::size_t(128 * 96));
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(0, 1);
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Eigen::Vector2d a = atlas.uv[3 * t].cast<double>(),
                          b = atlas.uv[3 * t + 1].cast<double>(),
                          c = atlas.uv[3 * t + 2].cast<double>();
    for (int k = 0; k < 200; ++k) {
      double u = unit(rng), v = unit(rng);
      if (u + v > 1) u = 1 - u, v = 1 - v;
      // Corners and edges too: the first samples are the corners.
      if (k < 3) u = k == 1, v = k == 2;
      const Eigen::Vector2d p = (1 - u - v) * a + u * b + v * c;
      const auto [x, y] = lookup_base(atlas, p);
      for (int dy = 0; dy < 2; ++dy) {
        for (int dx = 0; dx < 2; ++dx) {
          ASSERT_GE(x + dx, 0);
          ASSERT_GE(y + dy, 0);
          ASSERT_LT(x + dx, atlas.width);
          ASSERT_LT(y + dy, atlas.height);
          ASSERT_EQ(atlas.texel_triangle[std::size_t(y + dy) * atlas.width + x + dx], int(t))
              << "triangle " << t << " at (" << p.x() << ", " << p.y() << ")";
        }
      }
    }
  }
}

TEST(Atlas, TexelCountsFollowAreaAndSamplesLieOnTheirTriangle) {
  const Mesh mesh = meshes::make_torus(1.f, 0.35f, 24, 12);  // triangles of unequal areas
  const Atlas atlas = meshes::make_atlas(mesh, 256, 256);
  std::vector<int> inside(mesh.triangles.size(), 0), owned(mesh.triangles.size(), 0);
  for (int y = 0; y < atlas.height; ++y) {
    for (int x = 0; x < atlas.width; ++x) {
      const std::size_t at = std::size_t(y) * atlas.width + x;
      const int t = atlas.texel_triangle[at];
      if (t < 0) continue;
      ++owned[t];
      const Eigen::Vector2f w = atlas.texel_barycentric[at];
      ASSERT_GE(w.x(), 0.f);
      ASSERT_GE(w.y(), 0.f);
      ASSERT_LE(w.x() + w.y(), 1.f + 1e-6f);
      // The sample maps back to the texel centre when the centre is inside the chart.
      const Eigen::Vector2f p = (1 - w.x() - w.y()) * atlas.uv[3 * t] +
                                w.x() * atlas.uv[3 * t + 1] + w.y() * atlas.uv[3 * t + 2];
      const Eigen::Vector2f centre((x + 0.5f) / atlas.width, (y + 0.5f) / atlas.height);
      if ((p - centre).norm() < 1e-6f) ++inside[t];
    }
  }
  // Interior texels per unit area: the same for every triangle up to the chart's boundary,
  // which a leg of L texels crosses in about 2 L + 2 texels.
  double total_inside = 0, total_area = 0;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    total_inside += inside[t];
    total_area += 0.5 * meshes::double_area(mesh, mesh.triangles[t]);
    EXPECT_GE(owned[t], inside[t]);
  }
  const double density = total_inside / total_area;
  EXPECT_GT(total_inside, 0.25 * atlas.width * atlas.height);  // the packing is not wasteful
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const double area = 0.5 * meshes::double_area(mesh, mesh.triangles[t]);
    const double expected = density * area, leg = std::sqrt(2 * expected);
    EXPECT_NEAR(inside[t], expected, 2 * leg + 2) << "triangle " << t;
  }
}

TEST(Atlas, DegenerateTrianglesGetAChartAndOwnTexels) {
  const Mesh mesh = test_mesh();
  const Atlas atlas = meshes::make_atlas(mesh, 128, 96);
  const int degenerate = int(mesh.triangles.size()) - 1;
  int owned = 0;
  for (std::int32_t t : atlas.texel_triangle) owned += t == degenerate;
  EXPECT_EQ(owned, 4);  // a point chart: the 2 x 2 texels around it
  EXPECT_EQ(atlas.used_texels(),
            std::size_t(std::count_if(atlas.texel_triangle.begin(), atlas.texel_triangle.end(),
                                      [](std::int32_t t) { return t >= 0; })));
}

TEST(Atlas, BadSizesAreRefused) {
  const Mesh mesh = meshes::make_sphere(1.f, 16, 8);  // 224 triangles
  EXPECT_THROW(meshes::make_atlas(mesh, 0, 64), std::invalid_argument);
  EXPECT_THROW(meshes::make_atlas(mesh, 64, -3), std::invalid_argument);
  EXPECT_THROW(meshes::make_atlas(mesh, 100000, 64), std::invalid_argument);
  try {
    meshes::make_atlas(mesh, 16, 16);  // 16 cells of 4 x 4 hold 32 triangles, not 224
    FAIL() << "a 16 x 16 atlas cannot hold 224 charts";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("too small"), std::string::npos) << e.what();
  }
  EXPECT_THROW(meshes::make_atlas(Mesh{}, 64, 64), std::invalid_argument);
}

}  // namespace
