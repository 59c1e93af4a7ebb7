// Tests for meshes/atlas.h, meshes/charts.h and meshes/conformal_map.h.
//
// Per-triangle charts: every bilinear lookup inside a chart reads only its triangle's texels
// (random points, the lookup written out here independently of the packer), texels are owned
// once, texel counts follow triangle areas, gutter samples lie on their triangle, and bad
// sizes are refused.
//
// Conformal charts: LSCM maps a planar grid by a similarity (the analytic answer), the
// embedding check refuses flips and overlaps, and on a UV sphere, an icosphere and the
// Stanford bunny every lookup inside a chart reads only texels of that chart sampling points
// near the lookup's, texture area per chart follows surface area, no triangle flips, and the
// bunny fits 256 x 256.
#include "meshes/atlas.h"
#include "meshes/charts.h"
#include "meshes/conformal_map.h"
#include "meshes/load.h"
#include "meshes/procedural.h"
#include "meshes/weld.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <numbers>
#include <random>
#include <stdexcept>
#include <vector>

namespace {

using meshes::Atlas;
using meshes::Mesh;

constexpr meshes::AtlasOptions kPerTriangle{meshes::AtlasCharts::kPerTriangle};

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
  const Atlas atlas = meshes::make_atlas(mesh, 128, 96, kPerTriangle);
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
  const Atlas atlas = meshes::make_atlas(mesh, 256, 256, kPerTriangle);
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

// Each used texel's point lies on the surface: on a torus (R 1, r 0.35) at the tube's radius
// from its centre circle, up to the flat faces' departure from it (under 0.025 at 24 x 12,
// inward where the torus is convex, outward across its saddle); where the
// texel's centre is inside its triangle's uv, it is the point the centre maps to (solved here
// from the uv triangle, not from the atlas's barycentrics). Unused texels are the origin; an
// atlas of another mesh is refused.
TEST(Atlas, TexelPointsAreTheSurfaceUnderEachTexel) {
  const Mesh mesh = meshes::make_torus(1.f, 0.35f, 24, 12);
  const Atlas atlas = meshes::make_atlas(mesh, 128, 128);
  const std::vector<Eigen::Vector3f> points = meshes::texel_points(mesh, atlas);
  ASSERT_EQ(points.size(), std::size_t(128 * 128));
  int used = 0, under_centre = 0;
  for (std::size_t t = 0; t < points.size(); ++t) {
    const Eigen::Vector3f p = points[t];
    const int triangle = atlas.texel_triangle[t];
    if (triangle < 0) {
      EXPECT_EQ(p, Eigen::Vector3f::Zero());
      continue;
    }
    ++used;
    const float tube = std::hypot(Eigen::Vector2f(p.x(), p.z()).norm() - 1.f, p.y());
    EXPECT_NEAR(tube, 0.35f, 0.025f) << "texel " << t;
    const Eigen::Vector2f a = atlas.uv[3 * std::size_t(triangle)],
                          b = atlas.uv[3 * std::size_t(triangle) + 1],
                          c = atlas.uv[3 * std::size_t(triangle) + 2];
    const Eigen::Vector2f centre((float(t % 128) + 0.5f) / 128, (float(t / 128) + 0.5f) / 128);
    Eigen::Matrix2f m;
    m << (b - a), (c - a);
    const Eigen::Vector2f w = m.inverse() * (centre - a);
    if (w.minCoeff() < 1e-4f || w.sum() > 1.f - 1e-4f) continue;
    ++under_centre;
    const meshes::Triangle& tri = mesh.triangles[std::size_t(triangle)];
    const Eigen::Vector3f expected = (1 - w.sum()) * mesh.positions[tri[0]] +
                                     w.x() * mesh.positions[tri[1]] +
                                     w.y() * mesh.positions[tri[2]];
    EXPECT_LT((p - expected).norm(), 1e-4f) << "texel " << t;
  }
  EXPECT_GT(used, 128 * 128 / 3);
  EXPECT_GT(under_centre, used / 2);
  Mesh fewer = mesh;
  fewer.triangles.resize(10);
  EXPECT_THROW(meshes::texel_points(fewer, atlas), std::invalid_argument);
}

// A texel's normal is the unit vertex normal interpolated at its point: on a torus, the
// direction from the tube's centre line through the point (to the facets' deviation), the
// face's where the mesh has no normals, and zero where no triangle reads the texel.
TEST(Atlas, TexelNormalsAreTheShadingNormalsAtEachPoint) {
  const Mesh mesh = meshes::make_torus(1.f, 0.35f, 24, 12);
  ASSERT_TRUE(mesh.has_frames());
  const Atlas atlas = meshes::make_atlas(mesh, 128, 128);
  const std::vector<Eigen::Vector3f> points = meshes::texel_points(mesh, atlas);
  const std::vector<Eigen::Vector3f> normals = meshes::texel_normals(mesh, atlas);
  Mesh bare = mesh;
  bare.normals.clear();
  bare.tangents.clear();
  const std::vector<Eigen::Vector3f> faces = meshes::texel_normals(bare, atlas);
  ASSERT_EQ(normals.size(), points.size());
  int used = 0;
  for (std::size_t t = 0; t < normals.size(); ++t) {
    const int triangle = atlas.texel_triangle[t];
    if (triangle < 0) {
      EXPECT_EQ(normals[t], Eigen::Vector3f::Zero());
      continue;
    }
    ++used;
    const Eigen::Vector3f p = points[t];
    const Eigen::Vector3f ring = Eigen::Vector3f(p.x(), 0.f, p.z()).normalized();
    const Eigen::Vector3f outward = (p - ring).normalized();
    EXPECT_NEAR(normals[t].norm(), 1.f, 1e-5f) << "texel " << t;
    EXPECT_GT(normals[t].dot(outward), 0.995f) << "texel " << t;
    const meshes::Triangle& tri = mesh.triangles[std::size_t(triangle)];
    const Eigen::Vector3f face = (mesh.positions[tri[1]] - mesh.positions[tri[0]])
                                     .cross(mesh.positions[tri[2]] - mesh.positions[tri[0]])
                                     .normalized();
    EXPECT_LT((faces[t] - face).norm(), 1e-5f) << "texel " << t;
  }
  EXPECT_GT(used, 128 * 128 / 3);
}

TEST(Atlas, DegenerateTrianglesGetAChartAndOwnTexels) {
  const Mesh mesh = test_mesh();
  const Atlas atlas = meshes::make_atlas(mesh, 128, 96, kPerTriangle);
  const int degenerate = int(mesh.triangles.size()) - 1;
  int owned = 0;
  for (std::int32_t t : atlas.texel_triangle) owned += t == degenerate;
  EXPECT_EQ(owned, 4);  // a point chart: the 2 x 2 texels around it
  EXPECT_EQ(atlas.used_texels(),
            std::size_t(std::count_if(atlas.texel_triangle.begin(), atlas.texel_triangle.end(),
                                      [](std::int32_t t) { return t >= 0; })));
}

TEST(Atlas, PerTriangleChartsAreTheirTriangles) {
  const Mesh mesh = test_mesh();
  const Atlas atlas = meshes::make_atlas(mesh, 128, 96, kPerTriangle);
  ASSERT_EQ(atlas.triangle_chart.size(), mesh.triangles.size());
  EXPECT_EQ(atlas.chart_count, int(mesh.triangles.size()));
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    EXPECT_EQ(atlas.triangle_chart[t], int(t));
}

TEST(Atlas, BadSizesAreRefused) {
  const Mesh mesh = meshes::make_sphere(1.f, 16, 8);  // 224 triangles
  EXPECT_THROW(meshes::make_atlas(mesh, 0, 64, kPerTriangle), std::invalid_argument);
  EXPECT_THROW(meshes::make_atlas(mesh, 64, -3, kPerTriangle), std::invalid_argument);
  EXPECT_THROW(meshes::make_atlas(mesh, 100000, 64, kPerTriangle), std::invalid_argument);
  try {
    meshes::make_atlas(mesh, 16, 16, kPerTriangle);  // 16 cells of 4 x 4 hold 32 triangles, not 224
    FAIL() << "a 16 x 16 atlas cannot hold 224 charts";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("too small"), std::string::npos) << e.what();
  }
  EXPECT_THROW(meshes::make_atlas(Mesh{}, 64, 64), std::invalid_argument);
  EXPECT_THROW(meshes::make_atlas(mesh, 0, 64), std::invalid_argument);  // conformal too
}

// --- Least-squares conformal maps -------------------------------------------------------

struct ChartInput {
  std::vector<Eigen::Vector3d> positions;
  std::vector<meshes::ChartTriangle> triangles;
};

ChartInput chart_of(const Mesh& mesh) {
  ChartInput in;
  for (const meshes::Vec3& p : mesh.positions) in.positions.push_back(p.cast<double>());
  for (const meshes::Triangle& t : mesh.triangles)
    in.triangles.push_back({int(t[0]), int(t[1]), int(t[2])});
  return in;
}

double angle(const Eigen::VectorXd& a, const Eigen::VectorXd& b, const Eigen::VectorXd& c) {
  const Eigen::VectorXd u = b - a, v = c - a;
  return std::acos(std::clamp(u.dot(v) / (u.norm() * v.norm()), -1.0, 1.0));
}

TEST(ConformalMap, APlanarGridMapsByASimilarity) {
  // A grid of the plane y = 1, its points jittered so that triangles differ: the conformal
  // energy is zero only for a similarity, which keeps every angle and one length ratio.
  Mesh mesh = meshes::make_plane(3.f, 12, 1.f);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> jitter(-0.04f, 0.04f);
  for (meshes::Vec3& p : mesh.positions) p += meshes::Vec3(jitter(rng), 0, jitter(rng));
  const ChartInput in = chart_of(mesh);
  const std::vector<Eigen::Vector2d> uv = meshes::conformal_map(in.positions, in.triangles);
  ASSERT_EQ(uv.size(), in.positions.size());
  EXPECT_LT(meshes::conformal_energy(in.positions, in.triangles, uv), 1e-20);
  EXPECT_TRUE(meshes::is_embedded_disk(uv, in.triangles));
  const double ratio = (uv[1] - uv[0]).norm() / (in.positions[1] - in.positions[0]).norm();
  for (const meshes::ChartTriangle& t : in.triangles) {
    for (int c = 0; c < 3; ++c) {
      const int a = t[c], b = t[(c + 1) % 3], d = t[(c + 2) % 3];
      EXPECT_NEAR(angle(uv[a], uv[b], uv[d]),
                  angle(in.positions[a], in.positions[b], in.positions[d]), 1e-5);
    }
    EXPECT_NEAR((uv[t[1]] - uv[t[0]]).norm(),
                ratio * (in.positions[t[1]] - in.positions[t[0]]).norm(), 1e-9);
  }
  // The pinned pair keeps its 3D distance, so the similarity's scale is 1.
  EXPECT_NEAR(ratio, 1.0, 1e-9);
}

TEST(ConformalMap, ASphericalCapIsNearlyConformalAndEmbedded) {
  // A curved chart cannot be mapped with zero energy, but its map stays one-to-one.
  Mesh sphere = meshes::make_sphere(1.f, 32, 16);
  Mesh cap;
  std::map<std::uint32_t, std::uint32_t> index;
  for (const meshes::Triangle& t : sphere.triangles) {
    bool upper = true;
    for (std::uint32_t v : t) upper = upper && sphere.positions[v].y() > 0.3f;
    if (!upper || meshes::double_area(sphere, t) <= 0) continue;
    meshes::Triangle out;
    for (int c = 0; c < 3; ++c) {
      const auto [it, fresh] = index.emplace(t[c], std::uint32_t(cap.positions.size()));
      if (fresh) cap.positions.push_back(sphere.positions[t[c]]);
      out[c] = it->second;
    }
    cap.triangles.push_back(out);
  }
  // The pole's split vertices are one point: weld them so the cap is a disk.
  const meshes::PositionGroups groups = meshes::group_equal_positions(cap.positions);
  for (meshes::Triangle& t : cap.triangles)
    for (std::uint32_t& v : t) v = groups.first[groups.group[v]];
  Mesh welded;
  std::map<std::uint32_t, std::uint32_t> used;
  for (meshes::Triangle& t : cap.triangles) {
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;
    meshes::Triangle out;
    for (int c = 0; c < 3; ++c) {
      const auto [it, fresh] = used.emplace(t[c], std::uint32_t(welded.positions.size()));
      if (fresh) welded.positions.push_back(cap.positions[t[c]]);
      out[c] = it->second;
    }
    welded.triangles.push_back(out);
  }
  const ChartInput in = chart_of(welded);
  const std::vector<Eigen::Vector2d> uv = meshes::conformal_map(in.positions, in.triangles);
  ASSERT_EQ(uv.size(), in.positions.size());
  EXPECT_TRUE(meshes::is_embedded_disk(uv, in.triangles));
  EXPECT_LT(meshes::conformal_energy(in.positions, in.triangles, uv), 0.05);
}

TEST(ConformalMap, TheEmbeddingCheckRefusesFlipsOverlapsAndNonDisks) {
  // Two triangles sharing edge 1-2, a unit square.
  std::vector<Eigen::Vector2d> uv = {{0, 0}, {1, 0}, {0, 1}, {1, 1}};
  const std::vector<meshes::ChartTriangle> square = {{0, 1, 2}, {1, 3, 2}};
  EXPECT_TRUE(meshes::is_embedded_disk(uv, square));
  std::vector<Eigen::Vector2d> folded = uv;
  folded[3] = {-0.5, -0.5};  // the second triangle flips over the first
  EXPECT_FALSE(meshes::is_embedded_disk(folded, square));
  // A strip of triangles each positive but curling over its own start.
  std::vector<Eigen::Vector2d> spiral;
  std::vector<meshes::ChartTriangle> strip;
  for (int i = 0; i <= 16; ++i) {
    const double a = 2 * std::numbers::pi * i / 12.0;  // more than a full turn
    spiral.emplace_back(std::cos(a), std::sin(a));
    spiral.emplace_back(2 * std::cos(a), 2 * std::sin(a));
  }
  for (int i = 0; i < 16; ++i) {
    strip.push_back({2 * i, 2 * i + 1, 2 * i + 2});
    strip.push_back({2 * i + 1, 2 * i + 3, 2 * i + 2});
  }
  for (const auto& t : strip) {
    const Eigen::Vector2d e1 = spiral[t[1]] - spiral[t[0]], e2 = spiral[t[2]] - spiral[t[0]];
    ASSERT_GT(e1.x() * e2.y() - e1.y() * e2.x(), 0);  // every triangle counter-clockwise
  }
  EXPECT_FALSE(meshes::is_embedded_disk(spiral, strip));
  strip.resize(12);  // half a turn: embedded
  EXPECT_TRUE(meshes::is_embedded_disk(spiral, strip));
  // Two triangles meeting at one vertex only: not a disk.
  const std::vector<Eigen::Vector2d> bow = {{0, 0}, {1, 0}, {0, 1}, {-1, 0}, {0, -1}};
  EXPECT_FALSE(meshes::is_embedded_disk(bow, {{0, 1, 2}, {0, 3, 4}}));
}

// --- Conformal atlases --------------------------------------------------------------------

// Counter-clockwise unit icosahedron split `levels` times, midpoints pushed onto the sphere:
// 10 4^levels + 2 vertices (642 at 3 levels).
Mesh icosphere(int levels) {
  const float g = (1.f + std::sqrt(5.f)) / 2.f;
  Mesh m;
  m.positions = {{-1, g, 0},  {1, g, 0},  {-1, -g, 0}, {1, -g, 0}, {0, -1, g},  {0, 1, g},
                 {0, -1, -g}, {0, 1, -g}, {g, 0, -1},  {g, 0, 1},  {-g, 0, -1}, {-g, 0, 1}};
  for (meshes::Vec3& p : m.positions) p.normalize();
  m.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                 {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                 {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                 {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> middle;
    const auto split = [&](std::uint32_t a, std::uint32_t b) {
      const auto [it, fresh] = middle.emplace(std::minmax(a, b), std::uint32_t(m.positions.size()));
      if (fresh) m.positions.push_back((m.positions[a] + m.positions[b]).normalized());
      return it->second;
    };
    std::vector<meshes::Triangle> finer;
    for (const meshes::Triangle& t : m.triangles) {
      const std::uint32_t ab = split(t[0], t[1]), bc = split(t[1], t[2]), ca = split(t[2], t[0]);
      finer.insert(finer.end(), {{t[0], ab, ca}, {t[1], bc, ab}, {t[2], ca, bc}, {ab, bc, ca}});
    }
    m.triangles = finer;
  }
  return m;
}

Eigen::Vector3d surface_point(const Mesh& mesh, int t, const Eigen::Vector3d& w) {
  const meshes::Triangle& tri = mesh.triangles[t];
  return w[0] * mesh.positions[tri[0]].cast<double>() +
         w[1] * mesh.positions[tri[1]].cast<double>() +
         w[2] * mesh.positions[tri[2]].cast<double>();
}

struct AtlasFigures {
  double used = 0;         // fraction of the texels owned
  double interior = 0;     // fraction of the texels whose centres lie inside a chart
  double stretch_max = 0;  // sqrt(texture area / surface area) per triangle, over its mean
  double stretch_min = 0;
  double stretch_rms = 0;  // RMS of (stretch - 1), area-weighted
};

// The checks every conformal atlas must pass, written independently of the builder:
//  - every triangle keeps its orientation in the atlas (positive texel-space area);
//  - texture area per chart over surface area is one density for all charts;
//  - bilinear lookups at random points of every triangle (corners included) read four owned
//    texels of the triangle's own chart, each sampling a surface point within `near` texel
//    widths (in 3D, at the atlas's density) of the lookup's point.
AtlasFigures check_conformal_atlas(const Mesh& mesh, const Atlas& atlas, double near) {
  const std::size_t count = mesh.triangles.size();
  EXPECT_EQ(atlas.uv.size(), 3 * count);
  EXPECT_EQ(atlas.triangle_chart.size(), count);
  std::vector<double> chart_texture(atlas.chart_count, 0), chart_surface(atlas.chart_count, 0);
  std::vector<double> chart_rounding(atlas.chart_count, 0);  // float uv's error on the area
  const double ulp = std::max(atlas.width, atlas.height) * std::ldexp(1.0, -23);
  std::vector<double> texture(count), surface(count);
  for (std::size_t t = 0; t < count; ++t) {
    const int chart = atlas.triangle_chart[t];
    EXPECT_GE(chart, 0);
    EXPECT_LT(chart, atlas.chart_count);
    if (chart < 0 || chart >= atlas.chart_count) return {};
    Eigen::Vector2d q[3];
    for (int c = 0; c < 3; ++c)
      q[c] = atlas.uv[3 * t + c].cast<double>().cwiseProduct(
          Eigen::Vector2d(atlas.width, atlas.height));
    const Eigen::Vector2d e1 = q[1] - q[0], e2 = q[2] - q[0];
    texture[t] = 0.5 * (e1.x() * e2.y() - e1.y() * e2.x());
    surface[t] = 0.5 * double(meshes::double_area(mesh, mesh.triangles[t]));
    chart_texture[chart] += texture[t];
    chart_surface[chart] += surface[t];
    chart_rounding[chart] +=
        ulp * ((q[1] - q[0]).norm() + (q[2] - q[1]).norm() + (q[0] - q[2]).norm());
    const meshes::Triangle& tri = mesh.triangles[t];
    double longest = 0;
    for (int c = 0; c < 3; ++c)
      longest = std::max(
          longest,
          double((mesh.positions[tri[(c + 1) % 3]] - mesh.positions[tri[c]]).squaredNorm()));
    if (surface[t] > 1e-6 * longest) {  // not degenerate
      EXPECT_GT(texture[t], 0) << "triangle " << t << " flipped";
    }
  }
  double all_texture = 0, all_surface = 0;
  for (int c = 0; c < atlas.chart_count; ++c)
    all_texture += chart_texture[c], all_surface += chart_surface[c];
  const double density = all_texture / all_surface;  // texels per unit area
  for (int c = 0; c < atlas.chart_count; ++c) {
    if (chart_surface[c] > 0) {
      EXPECT_NEAR(chart_texture[c], density * chart_surface[c],
                  1e-6 * chart_texture[c] + chart_rounding[c])
          << "chart " << c;
    }
  }

  AtlasFigures figures;
  figures.used = double(atlas.used_texels()) / (double(atlas.width) * atlas.height);
  for (int y = 0; y < atlas.height; ++y) {
    for (int x = 0; x < atlas.width; ++x) {
      const std::size_t at = std::size_t(y) * atlas.width + x;
      const int t = atlas.texel_triangle[at];
      if (t < 0) continue;
      const Eigen::Vector2f w = atlas.texel_barycentric[at];
      const Eigen::Vector2f p = (1 - w.x() - w.y()) * atlas.uv[3 * t] +
                                w.x() * atlas.uv[3 * t + 1] + w.y() * atlas.uv[3 * t + 2];
      const Eigen::Vector2f centre((x + 0.5f) / atlas.width, (y + 0.5f) / atlas.height);
      if ((p - centre).norm() < 1e-5f) figures.interior += 1;
    }
  }
  figures.interior /= double(atlas.width) * atlas.height;
  figures.stretch_min = INFINITY;
  double weighted = 0;
  for (std::size_t t = 0; t < count; ++t) {
    if (!(surface[t] > 1e-9 * all_surface / double(count))) continue;
    const double s = std::sqrt(std::max(texture[t], 0.0) / (surface[t] * density));
    figures.stretch_max = std::max(figures.stretch_max, s);
    figures.stretch_min = std::min(figures.stretch_min, s);
    figures.stretch_rms += surface[t] * (s - 1) * (s - 1);
    weighted += surface[t];
  }
  figures.stretch_rms = std::sqrt(figures.stretch_rms / weighted);

  const double texel = 1 / std::sqrt(density);  // a texel's width on the surface
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(0, 1);
  for (std::size_t t = 0; t < count; ++t) {
    const int chart = atlas.triangle_chart[t];
    // About 4 points per texel of the triangle, at least 12.
    const int points = std::clamp(int(4 * std::max(texture[t], 0.0)), 12, 400);
    for (int k = 0; k < points; ++k) {
      double u = unit(rng), v = unit(rng);
      if (u + v > 1) u = 1 - u, v = 1 - v;
      if (k < 3) u = k == 1, v = k == 2;
      const Eigen::Vector3d w(1 - u - v, u, v);
      const Eigen::Vector2d p = w[0] * atlas.uv[3 * t].cast<double>() +
                                w[1] * atlas.uv[3 * t + 1].cast<double>() +
                                w[2] * atlas.uv[3 * t + 2].cast<double>();
      const Eigen::Vector3d point = surface_point(mesh, int(t), w);
      const auto [x, y] = lookup_base(atlas, p);
      for (int dy = 0; dy < 2; ++dy) {
        for (int dx = 0; dx < 2; ++dx) {
          const int i = x + dx, j = y + dy;
          if (i < 0 || j < 0 || i >= atlas.width || j >= atlas.height) {
            ADD_FAILURE() << "triangle " << t << " reads outside the atlas at (" << i << ", " << j
                          << ")";
            return figures;
          }
          const std::size_t at = std::size_t(j) * atlas.width + i;
          const int owner = atlas.texel_triangle[at];
          if (owner < 0 || atlas.triangle_chart[owner] != chart) {
            ADD_FAILURE() << "triangle " << t << " (chart " << chart << ") reads texel (" << i
                          << ", " << j << ") of triangle " << owner;
            return figures;
          }
          const Eigen::Vector2f b = atlas.texel_barycentric[at];
          const Eigen::Vector3d sample =
              surface_point(mesh, owner, Eigen::Vector3d(1 - b.x() - b.y(), b.x(), b.y()));
          if ((sample - point).norm() > near * texel) {
            ADD_FAILURE() << "triangle " << t << " reads texel (" << i << ", " << j
                          << ") sampling a point " << (sample - point).norm() / texel
                          << " texels away; owner " << owner;
            return figures;
          }
        }
      }
    }
  }
  return figures;
}

void print(const char* name, const Mesh& mesh, const Atlas& atlas, const AtlasFigures& f,
           double seconds) {
  std::printf(
      "%s: %zu triangles, %d charts, %dx%d, %.1f %% of texels used (%.1f %% inside charts), "
      "built in %.3f s; area stretch sqrt(uv/3D) per triangle over its mean: min %.3f max %.3f "
      "RMS deviation %.3f\n",
      name, mesh.triangles.size(), atlas.chart_count, atlas.width, atlas.height, 100 * f.used,
      100 * f.interior, seconds, f.stretch_min, f.stretch_max, f.stretch_rms);
}

// Interior lookups read texels whose centres are within sqrt(2) texels of the point, and a
// texel samples its chart's point nearest its centre (within sqrt(2) more); a chart's area
// stretch is at most 2 either way: 2 x 2 sqrt(2) < 6 texel widths, Euclidean in 3D.
constexpr double kNear = 6;

TEST(ConformalAtlas, UvSphere) {
  const Mesh mesh = meshes::make_sphere(1.f, 32, 16);  // split seam, degenerate pole triangles
  const auto start = std::chrono::steady_clock::now();
  const Atlas atlas = meshes::make_atlas(mesh, 128, 128);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const AtlasFigures f = check_conformal_atlas(mesh, atlas, kNear);
  print("uv sphere", mesh, atlas, f, seconds);
  EXPECT_LT(atlas.chart_count, int(mesh.triangles.size()) / 8);  // charts of many triangles
  EXPECT_LE(f.stretch_max, 2.0 + 1e-3);
  EXPECT_GE(f.stretch_min, 0.5 - 1e-3);
}

TEST(ConformalAtlas, SliversDegenerateTrianglesOpenBoxesAndTori) {
  // Degenerate and tiny triangles become charts of their own; an open box's faces meet at
  // right angles (beyond the normal cone) and have a border; a torus is not a disk anywhere.
  for (const auto& [name, mesh] :
       {std::pair{"slivers", test_mesh()}, std::pair{"open box", meshes::make_open_box(2.f, 8)},
        std::pair{"torus", meshes::make_torus(1.f, 0.35f, 48, 24)},
        std::pair{"plane and sphere", meshes::make_plane_and_sphere()}}) {
    SCOPED_TRACE(name);
    const auto start = std::chrono::steady_clock::now();
    const Atlas atlas = meshes::make_atlas(mesh, 128, 128);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_EQ(atlas.charts, meshes::AtlasCharts::kConformal);
    const AtlasFigures f = check_conformal_atlas(mesh, atlas, kNear);
    print(name, mesh, atlas, f, seconds);
    EXPECT_LT(atlas.chart_count, int(mesh.triangles.size()) / 4 + 8);
  }
}

TEST(ConformalAtlas, Icosphere) {
  const Mesh mesh = icosphere(3);
  ASSERT_EQ(mesh.positions.size(), 642u);
  const auto start = std::chrono::steady_clock::now();
  const Atlas atlas = meshes::make_atlas(mesh, 256, 256);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const AtlasFigures f = check_conformal_atlas(mesh, atlas, kNear);
  print("icosphere", mesh, atlas, f, seconds);
  EXPECT_LT(atlas.chart_count, 40);
  EXPECT_GT(f.used, 0.5);
  // The same mesh and options give the same atlas (files rebuild it from the mesh).
  const Atlas again = meshes::make_atlas(mesh, 256, 256);
  EXPECT_EQ(again.texel_triangle, atlas.texel_triangle);
  EXPECT_EQ(again.uv, atlas.uv);
}

TEST(ConformalAtlas, TheBunnyFits256x256) {
  constexpr const char* kBunny = "/usr/share/glmark2/models/bunny.obj";
  if (!std::filesystem::exists(kBunny))
    GTEST_SKIP() << kBunny << " missing: install glmark2-data (scripts/setup.sh)";
  const Mesh mesh = meshes::load_mesh(kBunny);
  // Per triangle it needs at least 8 texels a triangle: 557 K.
  EXPECT_THROW(meshes::make_atlas(mesh, 256, 256, kPerTriangle), std::invalid_argument);
  const auto start = std::chrono::steady_clock::now();
  const Atlas atlas = meshes::make_atlas(mesh, 256, 256);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const AtlasFigures f = check_conformal_atlas(mesh, atlas, kNear);
  print("bunny", mesh, atlas, f, seconds);
  EXPECT_GT(f.used, 0.4);
}

}  // namespace
