// The surface light field's renderer: the model's checks, the builder from a compressed set,
// the CPU reconstruction against analytic answers, and the one-pass GL image against the CPU
// reference (under OSMesa, and again under EGL through the ".egl" copies of these tests).
#include "render/slf_from_compressed.h"
#include "render/slf_model.h"
#include "render/slf_reference.h"
#include "render/slf_renderer.h"

#include "meshes/atlas.h"
#include "meshes/procedural.h"
#include "probes/procedural.h"
#include "render/gl_context.h"
#include "render/supersample.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <random>
#include <string>
#include <vector>

namespace {

using Eigen::Vector2f;
using Eigen::Vector3d;
using Eigen::Vector3f;

// A quad p0 p1 p2 p3 (counter-clockwise seen from the front) as two triangles sharing one
// chart: uv runs linearly over [uv0, uv1]^2, so the surface map is continuous across the
// diagonal and either triangle gives the same lookup there.
void add_quad(render::SlfModel& m, const Vector3f& p0, const Vector3f& p1, const Vector3f& p2,
              const Vector3f& p3, const Vector2f& uv0, const Vector2f& uv1) {
  const Vector3f n = (p1 - p0).cross(p3 - p0).normalized();
  const Vector3f p[4] = {p0, p1, p2, p3};
  const Vector2f t[4] = {uv0, {uv1.x(), uv0.y()}, uv1, {uv0.x(), uv1.y()}};
  for (int i : {0, 1, 2, 0, 2, 3}) {
    m.positions.push_back(p[i]);
    m.normals.push_back(n);
    m.uv.push_back(t[i]);
  }
}

using ClusterOf = std::function<int(int x, int y)>;
using WeightOf = std::function<float(int x, int y, int j)>;
// Cluster c, slice s, grid direction (column i, row j), channel.
using ViewOf = std::function<float(int c, int s, int i, int j, int channel)>;

void fill_maps(render::SlfModel& m, const ClusterOf& cluster, const WeightOf& weight,
               const ViewOf& view) {
  const int k = m.components;
  m.texel_cluster.resize(std::size_t(m.map_width) * m.map_height);
  m.texel_weights.resize(m.texel_cluster.size() * std::size_t(k));
  for (int y = 0; y < m.map_height; ++y)
    for (int x = 0; x < m.map_width; ++x) {
      const std::size_t t = std::size_t(y) * m.map_width + x;
      m.texel_cluster[t] = cluster(x, y);
      for (int j = 0; j < k; ++j) m.texel_weights[t * k + j] = weight(x, y, j);
    }
  m.texel_positions = render::texel_points_from_uv(m);
  m.view_maps.resize(std::size_t(m.clusters) * (k + 1) * m.slice_floats());
  for (int c = 0; c < m.clusters; ++c)
    for (int s = 0; s <= k; ++s)
      for (int j = 0; j < m.grid.elevation; ++j)
        for (int i = 0; i < m.grid.azimuth; ++i)
          for (int ch = 0; ch < 3; ++ch)
            m.view_maps[((std::size_t(c) * (k + 1) + s) * m.grid.directions() +
                         std::size_t(j) * m.grid.azimuth + i) *
                            3 +
                        ch] = view(c, s, i, j, ch);
}

render::SlfModel one_quad_model(int x_size, int y_size, prt::SlfGrid grid, int k, int clusters) {
  render::SlfModel m;
  add_quad(m, {-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, {0, 0}, {1, 1});
  m.map_width = x_size;
  m.map_height = y_size;
  m.grid = grid;
  m.components = k;
  m.clusters = clusters;
  return m;
}

Vector3d random_direction(std::mt19937& rng) {
  std::normal_distribution<double> g;
  Vector3d d;
  do d = Vector3d(g(rng), g(rng), g(rng));
  while (d.norm() < 1e-3);
  return d.normalized();
}

// --- The model's checks --------------------------------------------------------------------

render::SlfModel valid_model() {
  render::SlfModel m = one_quad_model(4, 3, {4, 2}, 2, 3);
  fill_maps(
      m, [](int x, int y) { return (x + y) % 4 - 1; },  // -1 (unused) .. 2
      [](int x, int y, int j) { return float(x - y + j); },
      [](int c, int s, int i, int j, int ch) { return float(c + s + i + j + ch); });
  return m;
}

void expect_refused(const render::SlfModel& m, const std::string& names) {
  try {
    m.validate();
    ADD_FAILURE() << "accepted a model with a bad " << names;
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(names), std::string::npos)
        << "the message does not name " << names << ": " << e.what();
  }
}

TEST(SlfModel, ValidateAcceptsAConsistentModel) {
  EXPECT_NO_THROW(valid_model().validate());
}

TEST(SlfModel, ValidateRefusesEachInconsistentSize) {
  using M = render::SlfModel;
  const std::vector<std::pair<std::string, std::function<void(M&)>>> cases = {
      {"positions", [](M& m) { m.positions.clear(); }},
      {"positions", [](M& m) { m.positions.pop_back(); }},
      {"normals", [](M& m) { m.normals.pop_back(); }},
      {"uv", [](M& m) { m.uv.push_back(Vector2f::Zero()); }},
      {"uv", [](M& m) { m.uv[2] = Vector2f(1.5f, 0.f); }},
      {"surface map", [](M& m) { m.map_width = 0; }},
      {"azimuth", [](M& m) { m.grid.azimuth = 0; }},
      {"elevation", [](M& m) { m.grid.elevation = 5000; }},
      {"components", [](M& m) { m.components = -1; }},
      {"clusters", [](M& m) { m.clusters = 0; }},
      {"texel_cluster", [](M& m) { m.texel_cluster.pop_back(); }},
      {"texel_weights", [](M& m) { m.texel_weights.push_back(0.f); }},
      {"view_maps", [](M& m) { m.view_maps.pop_back(); }},
      {"texel_positions", [](M& m) { m.texel_positions.pop_back(); }},
      {"texel_positions[3]", [](M& m) { m.texel_positions[3].y() = INFINITY; }},
      // The arrays sized for other k, X or eta.
      {"texel_weights", [](M& m) { m.components = 3; }},
      {"texel_cluster", [](M& m) { m.map_height = 4; }},
      {"view_maps", [](M& m) { m.clusters = 4; }},
      {"view_maps", [](M& m) { m.grid.azimuth = 5; }},
      {"cluster 3", [](M& m) { m.texel_cluster[5] = 3; }},
      {"cluster -2", [](M& m) { m.texel_cluster[5] = -2; }},
      {"texel_weights[7]", [](M& m) { m.texel_weights[7] = std::nanf(""); }},
      {"view_maps[11]", [](M& m) { m.view_maps[11] = INFINITY; }},
      {"corner 4", [](M& m) { m.positions[4].x() = std::nanf(""); }},
  };
  for (const auto& [names, spoil] : cases) {
    render::SlfModel m = valid_model();
    spoil(m);
    expect_refused(m, names);
  }
}

// --- The CPU reconstruction against analytic answers -----------------------------------------

// k = 0, one texel: the radiance is the view map alone. Red is the row centre's polar
// coordinate xi2 (linear in the row, so bilinear interpolation returns xi2 itself between
// the first and last row centres, and clamps beyond); green is the column index, which the
// interpolation wraps from the last column back to column 0 across the seam xi1 = 0 = 2.
TEST(SlfReference, ViewMapIsInterpolatedBilinearlyWithWrapAndPoleClamp) {
  const prt::SlfGrid grid{12, 7};
  render::SlfModel m = one_quad_model(1, 1, grid, 0, 1);
  fill_maps(
      m, [](int, int) { return 0; }, [](int, int, int) { return 0.f; },
      [&](int, int, int i, int j, int ch) {
        return ch == 0 ? float((j + 0.5) / grid.elevation) : ch == 1 ? float(i) : 2.f;
      });
  m.validate();
  std::mt19937 rng(7);
  const double z = grid.azimuth, w = grid.elevation;
  auto expected = [&](const Vector3d& d) {
    const Eigen::Vector2d xi = prt::slf_coordinates(d);
    const double red = std::clamp(xi.y(), 0.5 / w, 1.0 - 0.5 / w);
    const double s = xi.x() * z / 2 - 0.5;
    double green = s;
    if (s < 0) green = (z - 1) * -s;                         // column Z - 1 toward 0
    if (s > z - 1) green = (z - 1) * (1.0 - (s - (z - 1)));  // and again past the last
    return Vector3d(red, green, 2.0);
  };
  for (int n = 0; n < 2000; ++n) {
    const Vector3d d = random_direction(rng);
    const Vector3f got = render::slf_radiance(m, {0.3f, 0.6f}, d);
    EXPECT_LT((got.cast<double>() - expected(d)).cwiseAbs().maxCoeff(), 2e-6)
        << "direction " << d.transpose();
  }
  // Exactly at a grid direction the stored value comes back; exactly on the seam, the mean of
  // the last and the first column.
  for (int column = 0; column < grid.directions(); ++column) {
    const Vector3f got =
        render::slf_radiance(m, {0.5f, 0.5f}, prt::slf_grid_direction(grid, column));
    EXPECT_NEAR(got.y(), float(column % grid.azimuth), 1e-4f);
  }
  const Vector3d seam = prt::slf_direction(0.0, 0.5);
  EXPECT_NEAR(render::slf_radiance(m, {0.5f, 0.5f}, seam).y(), (z - 1) / 2, 1e-4);
}

// k = 1, one cluster, view maps constant in direction (mean c, the component 1): the radiance
// is c + the bilinear interpolation of the weights, here linear in the texel index, so
// c + 0.1 (u X - 1/2) + 0.2 (v Y - 1/2) inside the texel centres, whatever the direction.
TEST(SlfReference, RadianceVaryingOnlyAcrossTheSurfaceIsBilinearInSpace) {
  render::SlfModel m = one_quad_model(9, 5, {6, 4}, 1, 1);
  fill_maps(
      m, [](int, int) { return 0; }, [](int x, int y, int) { return 0.1f * x + 0.2f * y; },
      [](int, int s, int, int, int ch) { return s == 0 ? 0.25f * (ch + 1) : 1.f; });
  m.validate();
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.5f / 9, 1.f - 0.5f / 9), v(0.5f / 5, 1.f - 0.5f / 5);
  for (int n = 0; n < 500; ++n) {
    const Vector2f uv(u(rng), v(rng));
    const double spatial = 0.1 * (uv.x() * 9 - 0.5) + 0.2 * (uv.y() * 5 - 0.5);
    const Vector3f got = render::slf_radiance(m, uv, random_direction(rng));
    for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(got[ch], 0.25 * (ch + 1) + spatial, 2e-6);
  }
  // Beyond the outer texel centres the map clamps: the border texel's value.
  EXPECT_NEAR(render::slf_radiance(m, {0.f, 0.f}, Vector3d::UnitZ()).x(), 0.25, 1e-6);
  EXPECT_NEAR(render::slf_radiance(m, {1.f, 1.f}, Vector3d::UnitZ()).x(), 0.25 + 0.8 + 0.8, 1e-6);
}

// Each texel is reconstructed in its own cluster: a checkerboard of two clusters whose means
// are 1 and 3 (k = 0) gives the bilinear blend of the two values by the texels' weights, and
// an unused texel contributes nothing (its weight is not handed to the others).
TEST(SlfReference, EachTexelUsesItsOwnClusterAndUnusedTexelsWeighNothing) {
  render::SlfModel m = one_quad_model(4, 4, {4, 2}, 0, 2);
  fill_maps(
      m, [](int x, int y) { return (x == 3 && y == 3) ? -1 : (x + y) % 2; },
      [](int, int, int) { return 0.f; }, [](int c, int, int, int, int) { return c ? 3.f : 1.f; });
  m.validate();
  // Between texels (0,0) (cluster 0) and (1,0) (cluster 1), a quarter of the way.
  const float x = (0.5f + 0.25f) / 4, y = 0.5f / 4;
  EXPECT_NEAR(render::slf_radiance(m, {x, y}, Vector3d::UnitY()).x(), 0.75 * 1 + 0.25 * 3, 1e-6);
  // Midway between (2,3) (cluster 1) and the unused (3,3): half of cluster 1's value.
  EXPECT_NEAR(render::slf_radiance(m, {3.0f / 4, 3.5f / 4}, Vector3d::UnitY()).x(), 0.5 * 3, 1e-6);
}

// Negative reconstructions are clamped to 0 per channel after the spatial blend: two texels
// of two clusters (k = 0) whose red is -1 and 3 give 1 halfway (a clamp of each texel
// first would give 1.5), 0 a fifth of the way (-1 * 0.8 + 3 * 0.2 = -0.2) with green
// untouched, and 0 over the negative texel itself.
TEST(SlfReference, NegativeRadianceIsClampedAfterTheSpatialBlend) {
  render::SlfModel m = one_quad_model(2, 1, {4, 2}, 0, 2);
  fill_maps(
      m, [](int x, int) { return x; }, [](int, int, int) { return 0.f; },
      [](int c, int, int, int, int ch) { return ch == 0 ? (c ? 3.f : -1.f) : 0.5f; });
  m.validate();
  const float y = 0.5f;
  EXPECT_NEAR(render::slf_radiance(m, {0.5f, y}, Vector3d::UnitY()).x(), 1.0, 1e-6);
  const Vector3f near_negative = render::slf_radiance(m, {(0.5f + 0.2f) / 2, y}, Vector3d::UnitY());
  EXPECT_EQ(near_negative.x(), 0.f);  // -1 * 0.8 + 3 * 0.2 = -0.2
  EXPECT_NEAR(near_negative.y(), 0.5, 1e-6);
  EXPECT_EQ(render::slf_radiance(m, {0.f, y}, Vector3d::UnitX()).x(), 0.f);
}

// --- From the compression's output --------------------------------------------------------

// A hand-made atlas of two triangles on a 4 x 3 map with unused texels between, a 4 x 4 grid
// (order 4 SH layout: 16 directions, 3 channels, so dimension() = 3 Z W) and a random
// compressed set: every owned texel's reconstruction at a grid direction is the set's own
// reconstruction of its row there.
TEST(SlfFromCompressed, RowsAreTheOwnedTexelsInOrder) {
  meshes::Mesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  meshes::Atlas atlas;
  atlas.width = 4;
  atlas.height = 3;
  atlas.uv = {{0.1f, 0.1f}, {0.4f, 0.1f}, {0.4f, 0.4f}, {0.6f, 0.6f}, {0.9f, 0.9f}, {0.6f, 0.9f}};
  atlas.texel_triangle = {0, 0, -1, 1, 0, -1, 1, 1, -1, -1, 1, 1};
  atlas.texel_barycentric.assign(12, Eigen::Vector2f::Zero());
  const prt::SlfGrid grid{4, 4};
  cpca::CompressedSet set;
  set.order = 4;
  set.channels = 3;
  set.columns = 1;
  set.vertex_count = 8;
  set.cluster_count = 3;
  set.component_count = 2;
  ASSERT_EQ(set.dimension(), std::size_t(3 * grid.directions()));
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> value(-1.f, 1.f);
  set.cluster_of = {0, 1, 2, 2, 1, 0, 1, 2};
  for (std::size_t i = 0; i < 8 * 2; ++i) set.weights.push_back(value(rng));
  for (std::size_t i = 0; i < 3 * set.dimension(); ++i) set.means.push_back(value(rng));
  for (std::size_t i = 0; i < 3 * 2 * set.dimension(); ++i) set.bases.push_back(value(rng));

  const render::SlfModel m = render::slf_model_from_compressed(mesh, atlas, grid, set);
  EXPECT_EQ(m.positions.size(), 6u);
  EXPECT_EQ(m.uv, atlas.uv);
  EXPECT_EQ(m.components, 2);
  EXPECT_EQ(m.clusters, 3);
  std::vector<float> row(set.dimension());
  std::uint64_t r = 0;
  for (int t = 0; t < 12; ++t) {
    if (atlas.texel_triangle[std::size_t(t)] < 0) {
      EXPECT_EQ(m.texel_cluster[std::size_t(t)], -1);
      continue;
    }
    EXPECT_EQ(m.texel_cluster[std::size_t(t)], std::int32_t(set.cluster_of[r]));
    cpca::reconstruct_vertex(set, r, row.data());
    const Vector2f centre((t % 4 + 0.5f) / 4, (t / 4 + 0.5f) / 3);
    for (int column = 0; column < grid.directions(); ++column) {
      const Vector3f got = render::slf_radiance(m, centre, prt::slf_grid_direction(grid, column));
      for (int ch = 0; ch < 3; ++ch)
        EXPECT_NEAR(got[ch], std::max(row[std::size_t(column) * 3 + std::size_t(ch)], 0.f), 1e-5)
            << "texel " << t << " direction " << column;
    }
    ++r;
  }
  // One row too few for the atlas: refused, naming both counts.
  cpca::CompressedSet short_set = set;
  short_set.vertex_count = 7;
  short_set.cluster_of.pop_back();
  short_set.weights.resize(14);
  try {
    render::slf_model_from_compressed(mesh, atlas, grid, short_set);
    ADD_FAILURE() << "accepted 7 rows for 8 owned texels";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("owns 8 texels"), std::string::npos) << e.what();
  }
  // A grid that does not match the rows' length.
  EXPECT_THROW(render::slf_model_from_compressed(mesh, atlas, {8, 4}, set), std::invalid_argument);
}

// --- The GL image against the CPU reference ------------------------------------------------

// Two quads, the nearer one partly covering the farther, with their own charts in one map;
// clusters in blocks (fragments inside a block take the shared-cluster path, those on block
// borders the four-cluster one), a few unused texels, k = 5 (a partly used weight layer),
// view maps smooth in direction but different per cluster and slice, and no symmetry between
// the columns on either side of the seam.
render::SlfModel scene_model() {
  render::SlfModel m;
  add_quad(m, {-1.2f, -1.f, -0.4f}, {1.f, -1.2f, -0.5f}, {1.1f, 1.f, -0.3f}, {-1.f, 1.1f, -0.4f},
           {0.f, 0.f}, {0.5f, 1.f});
  add_quad(m, {-0.3f, -0.6f, 0.3f}, {0.9f, -0.5f, 0.2f}, {0.8f, 0.7f, 0.4f}, {-0.4f, 0.6f, 0.3f},
           {0.5f, 0.f}, {1.f, 1.f});
  m.map_width = 40;
  m.map_height = 24;
  m.grid = {10, 6};
  m.components = 5;
  m.clusters = 7;
  const int k = m.components;
  fill_maps(
      m,
      [](int x, int y) {
        if (x >= 8 && x <= 9 && y >= 10 && y <= 11) return -1;
        return (x / 7 + 2 * (y / 6)) % 7;
      },
      [](int x, int y, int j) {
        return float(0.3 * std::sin(0.4 * x + 0.7 * j) + 0.2 * std::cos(0.5 * y - j));
      },
      [&](int c, int s, int i, int j, int ch) {
        const double a = 2 * std::numbers::pi * (i + 0.5) / 10, p = (j + 0.5) / 6;
        const double base = s == 0 ? 1.0 + 0.2 * c : 0.5 / (1 + s);
        return float(base * (1.0 + 0.3 * std::sin(a + 0.5 * c + s + ch) + 0.4 * p * (ch + 1)) +
                     0.05 * i * (s == k));
      });
  m.validate();
  return m;
}

// The scene with red lowered by 1.5 in every cluster mean: the reconstruction's red is
// negative over part of each quad (a smooth function, so exactly 0 only where clamped).
render::SlfModel negative_scene_model() {
  render::SlfModel m = scene_model();
  const std::size_t slice = m.slice_floats();
  for (int c = 0; c < m.clusters; ++c)
    for (std::size_t d = 0; d < slice; d += 3)
      m.view_maps[std::size_t(c) * std::size_t(m.components + 1) * slice + d] -= 1.5f;
  m.validate();
  return m;
}

struct Comparison {
  int coverage_differs = 0, value_differs = 0, covered = 0;
  double worst = 0;  // relative to the largest radiance, over the pixels within tolerance
};

Comparison compare(const render::Image& gl, const render::Image& cpu, double tolerance) {
  Comparison c;
  double scale = 0;
  for (std::size_t i = 0; i < cpu.rgba.size(); ++i)
    if (i % 4 != 3) scale = std::max(scale, double(std::abs(cpu.rgba[i])));
  std::vector<double> errors;
  for (int y = 0; y < cpu.height; ++y)
    for (int x = 0; x < cpu.width; ++x) {
      const float* a = gl.pixel(x, y);
      const float* b = cpu.pixel(x, y);
      if (a[3] != b[3]) {
        ++c.coverage_differs;
        continue;
      }
      double e = 0;
      for (int ch = 0; ch < 3; ++ch) e = std::max(e, double(std::abs(a[ch] - b[ch])) / scale);
      if (b[3] == 1.f) ++c.covered;
      if (e > tolerance)
        ++c.value_differs;
      else
        c.worst = std::max(c.worst, e);
    }
  return c;
}

// GL's rasterisation and the ray cast may give a pixel whose centre lies within rounding of
// an edge to different triangles (or none): a handful of pixels along the silhouettes and
// the nearer quad's outline. Everywhere else the two agree to float rounding.
constexpr double kImageTolerance = 1e-4;
constexpr int kEdgePixels = 12;

// Every way to shade; the screen paths with and without the shared-cluster fast path
// (texture space reconstructs each texel alone and ignores it).
const std::pair<render::SlfShading, bool> kVariants[] = {{render::SlfShading::kOnePass, true},
                                                         {render::SlfShading::kOnePass, false},
                                                         {render::SlfShading::kDeferred, true},
                                                         {render::SlfShading::kDeferred, false},
                                                         {render::SlfShading::kTextureSpace, true}};

// A camera at `eye` looking at the origin, near and far planes around the test scenes.
render::Camera camera_at(const Vector3d& eye, int width, int height) {
  render::Camera camera;
  camera.eye = eye;
  camera.width = width;
  camera.height = height;
  camera.near_plane = 0.5;
  camera.far_plane = 10;
  return camera;
}

// Every path's image of `model` against the CPU reference (per texel for texture space),
// over a solid background: at most kEdgePixels differ, and the corner pixel, a miss, is the
// background with alpha 0. `where` labels the failures; `min_covered` pixels must be covered.
void expect_every_path_matches_the_reference(const render::SlfModel& model,
                                             const render::Camera& camera, const std::string& where,
                                             int min_covered) {
  const render::SlfReferenceOptions reference_options{true, Vector3f(0.1f, 0.2f, 0.3f)};
  render::Background background;
  background.use_probe = false;
  background.colour = render::Rgb(0.1f, 0.2f, 0.3f);
  const render::Image cpu = render::render_slf_reference(model, camera, reference_options);
  render::SlfReferenceOptions per_texel = reference_options;
  per_texel.texel_directions = true;
  const render::Image cpu_per_texel = render::render_slf_reference(model, camera, per_texel);
  for (const auto& [shading, fast] : kVariants) {
    render::GlDebugLog log;
    render::SlfRenderer renderer(model, nullptr, {true, fast, shading});
    renderer.set_background(background);
    renderer.render(camera);
    EXPECT_EQ(renderer.shading(), shading);
    const render::Image gl = renderer.read_image();
    const bool texel_space = shading == render::SlfShading::kTextureSpace;
    const Comparison c = compare(gl, texel_space ? cpu_per_texel : cpu, kImageTolerance);
    const std::string label = where +
                              (fast ? ", shared-cluster path" : ", four texels everywhere") + ", " +
                              render::kSlfShadingNames.name(shading);
    EXPECT_GT(c.covered, min_covered) << label;
    EXPECT_LE(c.coverage_differs + c.value_differs, kEdgePixels)
        << label << " (worst of the others " << c.worst << ")";
    EXPECT_TRUE(log.messages().empty()) << label << ": " << log.messages().front();
    EXPECT_FLOAT_EQ(gl.pixel(0, 0)[2], 0.3f) << label;
    EXPECT_EQ(gl.pixel(0, 0)[3], 0.f) << label;
  }
}

TEST(SlfRenderer, ImageMatchesTheCpuReferenceOnEveryPathAndAtThePoles) {
  render::GlContext ctx;
  const render::SlfModel model = scene_model();
  render::Camera front;  // looks down -Z: the view directions straddle the seam xi1 = 0
  front.eye = {0.15, 0.1, 3.2};
  front.target = {0, 0, 0};
  front.width = 97;
  front.height = 71;
  front.near_plane = 0.5;
  front.far_plane = 10;
  // From high above and slightly in front: view directions near the +Y pole, where the
  // polar rows clamp, and across the seam again.
  render::Camera above = front;
  above.eye = {0.05, 3.0, 0.9};
  above.up = {0, 0, -1};
  for (const render::Camera& camera : {front, above})
    expect_every_path_matches_the_reference(model, camera, camera.eye.y() > 1 ? "above" : "front",
                                            camera.width * camera.height / 4);
}

// Where the reconstruction goes negative, both renderers clamp it to 0 at the same point:
// every pixel is >= 0, a good share of the covered pixels have red exactly 0 (it is never
// 0 by accident in a smooth field), and GL still matches the CPU reference on every path.
TEST(SlfRenderer, NegativeReconstructionRendersClampedOnBothPaths) {
  render::GlContext ctx;
  const render::SlfModel model = negative_scene_model();
  const render::Camera camera = camera_at({0.15, 0.1, 3.2}, 64, 48);
  const render::Image cpu = render::render_slf_reference(model, camera);
  struct Counts {
    int negative = 0, zero_red = 0, covered = 0;
  };
  auto count = [](const render::Image& image) {
    Counts n;
    for (std::size_t i = 0; i < image.rgba.size(); i += 4) {
      for (int ch = 0; ch < 3; ++ch) n.negative += image.rgba[i + std::size_t(ch)] < 0.f;
      if (image.rgba[i + 3] != 1.f) continue;
      ++n.covered;
      n.zero_red += image.rgba[i] == 0.f;
    }
    return n;
  };
  const Counts on_cpu = count(cpu);
  EXPECT_EQ(on_cpu.negative, 0);
  EXPECT_GT(on_cpu.zero_red, on_cpu.covered / 10);
  EXPECT_LT(on_cpu.zero_red, on_cpu.covered * 9 / 10);
  render::SlfReferenceOptions per_texel;
  per_texel.texel_directions = true;
  const render::Image cpu_per_texel = render::render_slf_reference(model, camera, per_texel);
  render::Background background;
  background.use_probe = false;
  for (const auto& [shading, fast] : kVariants) {
    const std::string variant =
        std::string(render::kSlfShadingNames.name(shading)) + (fast ? "" : ", four texels");
    render::SlfRenderer renderer(model, nullptr, {true, fast, shading});
    renderer.set_background(background);
    renderer.render(camera);
    const render::Image gl = renderer.read_image();
    const render::Image& reference =
        shading == render::SlfShading::kTextureSpace ? cpu_per_texel : cpu;
    const Counts on_gl = count(gl);
    EXPECT_EQ(on_gl.negative, 0) << variant;
    EXPECT_NEAR(on_gl.zero_red, count(reference).zero_red, kEdgePixels) << variant;
    const Comparison c = compare(gl, reference, kImageTolerance);
    EXPECT_LE(c.coverage_differs + c.value_differs, kEdgePixels) << variant;
  }
}

// Back faces are culled as the reference culls them: seen from behind, only the background.
TEST(SlfRenderer, BackFacesAreCulledLikeTheReference) {
  render::GlContext ctx;
  const render::SlfModel model = scene_model();
  render::Camera behind;
  behind.eye = {0.1, 0.2, -3.0};
  behind.width = 40;
  behind.height = 30;
  for (int variant = 0; variant < 6; ++variant) {
    const bool cull = variant % 2 == 0;
    const render::SlfShading shading = variant < 2   ? render::SlfShading::kOnePass
                                       : variant < 4 ? render::SlfShading::kDeferred
                                                     : render::SlfShading::kTextureSpace;
    render::SlfRenderer renderer(model, nullptr, {cull, true, shading});
    render::Background background;
    background.use_probe = false;
    renderer.set_background(background);
    renderer.render(behind);
    const render::Image cpu = render::render_slf_reference(
        model, behind, {cull, Vector3f::Zero(), shading == render::SlfShading::kTextureSpace});
    const Comparison c = compare(renderer.read_image(), cpu, kImageTolerance);
    EXPECT_EQ(c.covered > 0, !cull);
    EXPECT_LE(c.coverage_differs + c.value_differs, kEdgePixels);
  }
}

// The probe behind the mesh (alpha 0), unrotated; the mesh's pixels do not change with it.
TEST(SlfRenderer, ProbeBackgroundFillsTheMisses) {
  render::GlContext ctx;
  const render::SlfModel model = scene_model();
  const probes::Probe probe = probes::make_from_function(64, 32, [](const Vector3d& d) {
    return probes::Rgb(float(1.0 + 0.5 * d.x()), float(1.0 + 0.5 * d.y()),
                       float(1.0 - 0.5 * d.z()));
  });
  render::Camera camera;
  camera.width = 48;
  camera.height = 36;
  camera.fov_y_degrees = 70;
  render::SlfImageOptions with_probe;
  const render::Image a = render::render_slf_image(model, camera, &probe, with_probe);
  render::SlfImageOptions solid;
  solid.background.use_probe = false;
  const render::Image b = render::render_slf_image(model, camera, &probe, solid);
  int misses = 0;
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width; ++x) {
      const float* pa = a.pixel(x, y);
      const float* pb = b.pixel(x, y);
      ASSERT_EQ(pa[3], pb[3]);
      if (pa[3] == 1.f) {
        for (int ch = 0; ch < 3; ++ch) EXPECT_EQ(pa[ch], pb[ch]);
        continue;
      }
      ++misses;
      const probes::Rgb expected = probe.lookup(camera.pixel_direction(x, y));
      for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(pa[ch], expected[ch], 0.03) << x << ", " << y;
      EXPECT_EQ(pb[0], 0.f);
    }
  EXPECT_GT(misses, camera.width * camera.height / 4);
}

// Supersampling is the box filter of the larger frame, and the larger frame is the reference's.
TEST(SlfRenderer, SupersampledImageIsTheFilteredLargeReference) {
  render::GlContext ctx;
  const render::SlfModel model = scene_model();
  render::Camera camera;
  camera.width = 30;
  camera.height = 22;
  for (const render::SlfShading shading :
       {render::SlfShading::kOnePass, render::SlfShading::kTextureSpace}) {
    render::SlfImageOptions o;
    o.supersample = 2;
    o.renderer.shading = shading;
    const render::Image gl = render::render_slf_image(model, camera, nullptr, o);
    ASSERT_EQ(gl.width, 30);
    render::SlfReferenceOptions r;
    r.texel_directions = shading == render::SlfShading::kTextureSpace;
    const render::Image cpu = render::box_downsample(
        render::render_slf_reference(model, render::supersampled(camera, 2), r), 2);
    // A pixel that one renderer covers at one more subsample than the other differs by a
    // quarter of its radiance: few, on the outlines.
    const Comparison c = compare(gl, cpu, kImageTolerance);
    EXPECT_LE(c.coverage_differs + c.value_differs, kEdgePixels);
  }
  render::SlfImageOptions o;
  EXPECT_THROW(render::render_slf_image(model, camera, nullptr, {{}, {}, 0}),
               std::invalid_argument);
}

// --- Texture space ---------------------------------------------------------------------------

// A closed mesh on its conformal atlas: a sphere of 2,048 triangles on a 128 x 128 map, clusters
// in patches over the sphere, weights varying over the surface, view maps smooth in
// direction and different per cluster.
render::SlfModel sphere_model() {
  constexpr int kSide = 128;
  const meshes::Mesh mesh = meshes::make_sphere(1.f, 32, 32);
  const meshes::Atlas atlas = meshes::make_atlas(mesh, kSide, kSide);
  render::SlfModel m;
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t)
    for (std::uint32_t v : mesh.triangles[t]) {
      m.positions.push_back(mesh.positions[v]);
      m.normals.push_back(mesh.positions[v].normalized());
    }
  m.uv = atlas.uv;
  m.map_width = m.map_height = kSide;
  m.grid = {12, 6};
  m.components = 3;
  m.clusters = 6;
  const std::vector<Vector3f> points = meshes::texel_points(mesh, atlas);
  fill_maps(
      m,
      [&](int x, int y) {
        const std::size_t t = std::size_t(y) * kSide + std::size_t(x);
        if (atlas.texel_triangle[t] < 0) return -1;
        const Vector3f p = points[t];
        return (p.x() > 0) + 2 * (p.y() > 0.3f) + 2 * (p.y() > -0.3f);
      },
      [&](int x, int y, int j) {
        const Vector3f p = points[std::size_t(y) * kSide + std::size_t(x)];
        return float(0.3 * std::sin(2.0 * p.x() + j) + 0.2 * std::cos(3.0 * p.z() - j));
      },
      [](int c, int s, int i, int j, int ch) {
        const double a = 2 * std::numbers::pi * (i + 0.5) / 12, p = (j + 0.5) / 6;
        return float((s == 0 ? 1.0 + 0.1 * c : 0.3) *
                     (1.0 + 0.4 * std::sin(a + c + s + ch) + 0.3 * p * (ch + 1)));
      });
  m.texel_positions = points;  // the atlas's sample points, not fill_maps' guess from uv
  m.validate();
  return m;
}

// The texels each texel shades are those its own triangle reads: seen from outside, about
// half the sphere's blocks face away and are skipped, yet every frame matches the reference,
// including frames after another viewpoint left the radiance map holding other texels, and
// a close-up whose frustum holds only part of the sphere.
TEST(SlfRenderer, TextureSpaceShadesOnlyTheBlocksInViewAndMissesNone) {
  render::GlContext ctx;
  const render::SlfModel model = sphere_model();
  render::SlfRenderer renderer(model, nullptr, {true, true, render::SlfShading::kTextureSpace});
  render::Background background;
  background.use_probe = false;
  renderer.set_background(background);
  render::SlfReferenceOptions per_texel;
  per_texel.texel_directions = true;
  render::Camera camera = camera_at(Vector3d::Zero(), 80, 60);
  camera.near_plane = 0.1;
  camera.far_plane = 20;
  const Vector3d eyes[] = {{0.3, 0.2, 3.5}, {-3.2, 1.0, -0.8}, {0.4, -3.4, 0.5}, {0.9, 0.5, 1.2}};
  for (const Vector3d& eye : eyes) {
    camera.eye = eye;
    renderer.render(camera);
    const long long shaded = renderer.texels_shaded();
    EXPECT_GT(shaded, 0);
    EXPECT_LT(shaded, renderer.texels_in_blocks() * 65 / 100) << eye.transpose();
    const Comparison c =
        compare(renderer.read_image(), render::render_slf_reference(model, camera, per_texel),
                kImageTolerance);
    EXPECT_GT(c.covered, 200) << eye.transpose();
    EXPECT_LE(c.coverage_differs + c.value_differs, kEdgePixels)
        << eye.transpose() << " (worst of the others " << c.worst << ")";
  }
}

// Texture space and the fragment's own direction differ by the angle a texel subtends at the
// eye: on the sphere from 3.5 away that is well under a percent of the radiance.
TEST(SlfRenderer, TextureSpaceIsCloseToTheFragmentsOwnDirection) {
  render::GlContext ctx;
  const render::SlfModel model = sphere_model();
  const render::Camera camera = camera_at({0.3, 0.2, 3.5}, 80, 60);
  const render::Image per_fragment = render::render_slf_reference(model, camera);
  render::SlfImageOptions o;
  o.renderer.shading = render::SlfShading::kTextureSpace;
  const Comparison c =
      compare(render::render_slf_image(model, camera, nullptr, o), per_fragment, 0.01);
  EXPECT_LE(c.coverage_differs + c.value_differs, kEdgePixels);
  EXPECT_GT(c.worst, kImageTolerance);  // they are not the same function
}

// The automatic choice shades in texture space when a frame covers more pixels than the
// blocks in view hold texels, and on the screen when it covers fewer.
TEST(SlfRenderer, AutomaticShadingFollowsTheCostOfEachPath) {
  render::GlContext ctx;
  const render::SlfModel model = sphere_model();
  render::SlfRenderer renderer(model, nullptr);
  render::Camera camera = camera_at({0.3, 0.2, 3.5}, 320, 240);
  for (int frame = 0; frame < 2; ++frame) {
    renderer.render(camera);
    EXPECT_EQ(renderer.shading(), render::SlfShading::kTextureSpace) << frame;
  }
  camera.width = 24;
  camera.height = 18;
  for (int frame = 0; frame < 2; ++frame) {
    renderer.render(camera);
    EXPECT_NE(renderer.shading(), render::SlfShading::kTextureSpace) << frame;
  }
}

// A grid of reflected directions: each texel looks its view up mirrored about its own
// normal, in the CPU reference (against the view-grid model looked up at the mirror image by
// hand) and on every GL path (against that reference).
render::SlfModel in_space(render::SlfModel m, prt::SlfDirectionSpace space) {
  m.grid.space = space;
  m.texel_normals = render::texel_normals_from_uv(m);
  return m;
}
render::SlfModel reflected(const render::SlfModel& m) {
  return in_space(m, prt::SlfDirectionSpace::kReflected);
}

TEST(SlfReference, ReflectedGridLooksUpEachTexelsMirrorImage) {
  const render::SlfModel view = sphere_model();
  const render::SlfModel mirrored = reflected(view);
  EXPECT_NO_THROW(mirrored.validate());
  const Vector3d eye(0.4, 1.5, 2.5);
  const int side = view.map_width;
  int checked = 0;
  for (int x : {20, 33, 47, 70, 101})
    for (int y : {12, 30, 51, 88, 113}) {
      const std::size_t t = std::size_t(y) * side + std::size_t(x);
      if (view.texel_cluster[t] < 0) continue;
      const Vector2f centre((x + 0.5f) / side, (y + 0.5f) / side);
      const Vector3d n = mirrored.texel_normals[t].cast<double>();
      // On this sphere the normal is the point's direction from the centre.
      EXPECT_LT((n - view.texel_positions[t].cast<double>().normalized()).norm(), 0.02);
      const Vector3d d = (eye - view.texel_positions[t].cast<double>()).normalized();
      const Vector3f expected = render::slf_radiance(view, centre, 2 * n.dot(d) * n - d);
      EXPECT_LT((render::slf_radiance_toward(mirrored, centre, eye) - expected).norm(),
                1e-5 * expected.norm())
          << x << ", " << y;
      // The fragment's direction is mirrored about the texel's normal too.
      EXPECT_LT((render::slf_radiance(mirrored, centre, 3.0 * d) - expected).norm(),
                1e-5 * expected.norm());
      ++checked;
    }
  EXPECT_GT(checked, 10);
  // Reflected directions need each texel's normal; view directions take none.
  render::SlfModel bad = mirrored;
  bad.texel_normals.clear();
  expect_refused(bad, "texel_normals");
  bad = view;
  bad.texel_normals = mirrored.texel_normals;
  expect_refused(bad, "texel_normals");
}

TEST(SlfRenderer, ReflectedGridMatchesTheCpuReferenceOnEveryPath) {
  render::GlContext ctx;
  const render::SlfModel model = reflected(sphere_model());
  for (const Vector3d& eye : {Vector3d(0.3, 0.2, 3.5), Vector3d(-2.0, 2.4, 1.0)}) {
    const render::Camera camera = camera_at(eye, 80, 60);
    expect_every_path_matches_the_reference(model, camera, eye.y() > 1 ? "above" : "front",
                                            camera.width * camera.height / 8);
    // The view grid's image differs: the lookup really is mirrored.
    const render::SlfReferenceOptions options{true, Vector3f::Zero()};
    EXPECT_GT(compare(render::render_slf_reference(sphere_model(), camera, options),
                      render::render_slf_reference(model, camera, options), 0.01)
                  .value_differs,
              100);
  }
}

// A grid of local directions: each texel looks its view up over its own hemisphere, polar
// from its normal and azimuth from the world's up projected onto its tangent plane. The CPU
// reference against the view maps read at those coordinates, written out here (bilinear in
// azimuth and polar, wrapped and clamped), and every GL path against that reference.
TEST(SlfReference, LocalGridLooksUpEachTexelsViewOverItsHemisphere) {
  const render::SlfModel m = in_space(sphere_model(), prt::SlfDirectionSpace::kLocal);
  EXPECT_NO_THROW(m.validate());
  const Vector3d eye(0.4, 1.5, 2.5);
  const int side = m.map_width, z = m.grid.azimuth, w = m.grid.elevation;
  int checked = 0;
  for (int x : {20, 33, 47, 70, 101})
    for (int y : {12, 30, 51, 88, 113}) {
      const std::size_t t = std::size_t(y) * side + std::size_t(x);
      if (m.texel_cluster[t] < 0) continue;
      const Vector3d n = m.texel_normals[t].cast<double>();
      const Vector3d d = (eye - m.texel_positions[t].cast<double>()).normalized();
      const Vector3d up = (Vector3d::UnitY() - n.y() * n).normalized();
      const double azimuth = std::atan2(d.dot(up.cross(n)), d.dot(up));  // in (-pi, pi]
      const double polar = std::acos(std::clamp(d.dot(n), -1.0, 1.0));
      const double s = (azimuth / M_PI + 1.0) * 0.5 * z - 0.5;
      const double r = std::min(1.0, polar / (M_PI / 2)) * w - 0.5;
      const int i0 = int(std::floor(s)), j0 = int(std::floor(r));
      const int cluster = m.texel_cluster[t];
      Vector3d expected = Vector3d::Zero();
      for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b) {
          const int i = ((i0 + a) % z + z) % z, j = std::clamp(j0 + b, 0, w - 1);
          const double weight = (a ? s - i0 : 1 - (s - i0)) * (b ? r - j0 : 1 - (r - j0));
          for (int slice = 0; slice <= m.components; ++slice) {
            const double coefficient =
                slice == 0 ? 1.0 : m.texel_weights[t * m.components + std::size_t(slice - 1)];
            const float* rgb = m.view_slice(cluster, slice) + 3 * std::size_t(j * z + i);
            expected += weight * coefficient * Vector3d(rgb[0], rgb[1], rgb[2]);
          }
        }
      const Vector2f centre((x + 0.5f) / side, (y + 0.5f) / side);
      const Vector3f e = expected.cwiseMax(0.0).cast<float>();
      EXPECT_LT((render::slf_radiance_toward(m, centre, eye) - e).norm(), 1e-5 * e.norm() + 1e-7)
          << x << ", " << y;
      EXPECT_LT((render::slf_radiance(m, centre, 3.0 * d) - e).norm(), 1e-5 * e.norm() + 1e-7);
      ++checked;
    }
  EXPECT_GT(checked, 10);
  render::SlfModel bad = m;
  bad.texel_normals.clear();
  expect_refused(bad, "texel_normals");
}

TEST(SlfRenderer, LocalGridMatchesTheCpuReferenceOnEveryPath) {
  render::GlContext ctx;
  const render::SlfModel model = in_space(sphere_model(), prt::SlfDirectionSpace::kLocal);
  for (const Vector3d& eye : {Vector3d(0.3, 0.2, 3.5), Vector3d(-2.0, 2.4, 1.0)}) {
    const render::Camera camera = camera_at(eye, 80, 60);
    expect_every_path_matches_the_reference(model, camera, eye.y() > 1 ? "above" : "front",
                                            camera.width * camera.height / 8);
    const render::SlfReferenceOptions options{true, Vector3f::Zero()};
    EXPECT_GT(compare(render::render_slf_reference(reflected(sphere_model()), camera, options),
                      render::render_slf_reference(model, camera, options), 0.01)
                  .value_differs,
              100);
  }
}

// The CPU reference's per-texel directions: at a texel centre the texel alone, toward the
// eye from its own point; between centres the bilinear blend of the four, each so.
TEST(SlfReference, TexelDirectionsBlendEachTexelTowardTheEye) {
  const render::SlfModel m = sphere_model();
  const Vector3d eye(0.4, 1.5, 2.5);
  const int side = m.map_width;
  for (int x : {20, 33, 47, 70, 101})
    for (int y : {12, 30, 51, 88, 113}) {
      const std::size_t t = std::size_t(y) * side + std::size_t(x);
      if (m.texel_cluster[t] < 0) continue;
      const Vector2f centre((x + 0.5f) / side, (y + 0.5f) / side);
      const Vector3f toward = render::slf_radiance_toward(m, centre, eye);
      const Vector3f expected =
          render::slf_radiance(m, centre, eye - m.texel_positions[t].cast<double>());
      EXPECT_LT((toward - expected).norm(), 1e-6 * expected.norm()) << x << ", " << y;
      // A quarter of the way to the next texel in x and y.
      const Vector2f between((x + 0.75f) / side, (y + 0.75f) / side);
      Eigen::Vector3d blend = Eigen::Vector3d::Zero();
      for (int b = 0; b < 2; ++b)
        for (int a = 0; a < 2; ++a) {
          const std::size_t u = std::size_t(y + b) * side + std::size_t(x + a);
          if (m.texel_cluster[u] < 0) continue;
          const Vector2f c((x + a + 0.5f) / side, (y + b + 0.5f) / side);
          blend +=
              (a ? 0.25 : 0.75) * (b ? 0.25 : 0.75) *
              render::slf_radiance(m, c, eye - m.texel_positions[u].cast<double>()).cast<double>();
        }
      EXPECT_LT((render::slf_radiance_toward(m, between, eye).cast<double>() - blend).norm(),
                1e-5 * blend.norm())
          << x << ", " << y;
    }
}

// A texel's point is where its centre falls on the surface: on a flat square mapped
// linearly over [0, 1]^2, (2u - 1, 2v - 1, 0).
TEST(SlfModel, TexelPointsFromUvAreTheSurfaceUnderEachCentre) {
  render::SlfModel m = one_quad_model(8, 6, {4, 2}, 0, 1);
  m.texel_cluster.assign(48, 0);
  m.texel_cluster[9] = -1;
  const std::vector<Vector3f> points = render::texel_points_from_uv(m);
  ASSERT_EQ(points.size(), 48u);
  for (int y = 0; y < 6; ++y)
    for (int x = 0; x < 8; ++x) {
      const std::size_t t = std::size_t(y) * 8 + std::size_t(x);
      const Vector3f expected =
          t == 9 ? Vector3f::Zero() : Vector3f(2 * (x + 0.5f) / 8 - 1, 2 * (y + 0.5f) / 6 - 1, 0);
      EXPECT_LT((points[t] - expected).norm(), 1e-5) << x << ", " << y;
    }
}

}  // namespace
