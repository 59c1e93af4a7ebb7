// Thesis ch. 4.1 (eq. 8): the triangles the multipass renderer draws (GL_PRIMITIVES_GENERATED per
// pass) equal the cost model's prediction (cpca::overdraw) for every strategy and several budgets;
// the false-colour pictures put the right colours where hand-placed triangles project; the
// benchmark's report renders its rows.
#include "cpca/supercluster.h"
#include "cpca/supercluster_strategy.h"
#include "meshes/procedural.h"
#include "overdraw/report.h"
#include "render/false_colour.h"
#include "render/gl_context.h"
#include "render/renderer.h"
#include "test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <set>
#include <string>

namespace {

// A compressed set for `mesh` with random constants (the counts do not depend on them) and
// clusters that are spatially coherent patches: longitude sector x latitude band of the
// vertex position, like a real clustering, so strategies have overdraw to remove.
cpca::CompressedSet patch_set(const meshes::Mesh& mesh, int sectors, int bands) {
  cpca::CompressedSet s;
  s.order = 2;
  s.channels = 1;
  s.columns = 4;  // glossy, n = 4
  s.vertex_count = mesh.vertex_count();
  s.cluster_count = sectors * bands;
  s.component_count = 2;
  const std::size_t D = s.dimension();
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-0.5f, 0.5f);
  s.cluster_of.resize(mesh.vertex_count());
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
    const meshes::Vec3& p = mesh.positions[v];
    const double phi = std::atan2(double(p.z()), double(p.x())) + std::numbers::pi;  // [0, 2 pi]
    const double y = std::clamp(double(p.y()), -1.0, 1.0);
    const int sector = std::min(sectors - 1, int(phi / (2 * std::numbers::pi) * sectors));
    const int band = std::min(bands - 1, int((y + 1) / 2 * bands));
    s.cluster_of[v] = std::uint32_t(band * sectors + sector);
  }
  s.weights.resize(mesh.vertex_count() * 2);
  for (float& w : s.weights) w = u(rng);
  s.means.resize(std::size_t(s.cluster_count) * D);
  for (float& m : s.means) m = u(rng);
  s.bases.resize(std::size_t(s.cluster_count) * 2 * D);
  for (float& b : s.bases) b = u(rng);
  return s;
}

std::vector<cpca::TriangleIndices> triangles_of(const meshes::Mesh& mesh) {
  std::vector<cpca::TriangleIndices> t;
  for (const meshes::Triangle& x : mesh.triangles) t.push_back({x[0], x[1], x[2]});
  return t;
}

TEST(OverdrawRenderer, MeasuredTrianglesEqualTheCostModelForEveryStrategyAndBudget) {
  render::GlContext context(4, 5);
  const meshes::Mesh mesh = meshes::make_sphere(1.f, 24, 12);
  const cpca::CompressedSet set = patch_set(mesh, 6, 4);  // 24 clusters
  const std::vector<cpca::TriangleIndices> triangles = triangles_of(mesh);
  const int cost = render::constant_layout(set).registers_per_cluster();
  // (N + 1) RGB radiance vectors of n = order^2 floats each, packed into vec4s.
  ASSERT_EQ(cost, ((set.component_count + 1) * set.order * set.order * 3 + 3) / 4);
  render::Camera camera = render::frame_sphere(Eigen::Vector3d::Zero(), 1.0, 64, 48);

  int configurations = 0;
  for (int per_pass : {1, 3, 5, 24}) {
    for (const cpca::NamedStrategy& strategy : cpca::supercluster_strategies()) {
      SCOPED_TRACE(std::string(strategy.name) + ", " + std::to_string(per_pass) + " per pass");
      cpca::SuperClusterInput input;
      input.cluster_of = set.cluster_of;
      input.triangles = triangles;
      input.cluster_count = set.cluster_count;
      input.per_pass = per_pass;
      const cpca::SuperClusters groups = cpca::group_clusters(strategy.name, input);
      const cpca::OverdrawStats predicted = cpca::overdraw(set.cluster_of, triangles, groups);

      render::RendererOptions ro;
      ro.mode = render::Mode::kMultipass;
      ro.register_budget = per_pass * cost;
      ro.clusters_per_pass = per_pass;
      ro.groups = groups;
      ro.count_primitives = true;
      // Culling must not change the count: GL counts primitives before rasterisation.
      ro.cull_back_faces = per_pass % 2 == 1;
      render::Renderer renderer(mesh, &set, nullptr, nullptr, ro);
      renderer.render(camera, prt::ShLighting::Ones(4, 3), Eigen::Matrix3d::Identity());
      const render::RenderStats& stats = renderer.stats();
      // GL's counts are the independent side: one query per pass, at least as many passes as
      // the capacity forces, and the reported overdraw is what GL drew over the mesh.
      ASSERT_EQ(stats.measured_triangles.size(), std::size_t(stats.passes));
      EXPECT_GE(stats.passes, (set.cluster_count + per_pass - 1) / per_pass);
      EXPECT_EQ(stats.measured_triangles, predicted.triangles_per_pass);
      std::uint64_t drawn = 0;
      for (std::uint64_t m : stats.measured_triangles) drawn += m;
      EXPECT_EQ(drawn, predicted.triangles_drawn);
      EXPECT_DOUBLE_EQ(stats.average_overdraw, double(drawn) / double(mesh.triangle_count()));
      // One pass draws every triangle once; with several, patches' borders are drawn again.
      if (per_pass == set.cluster_count) {
        EXPECT_EQ(drawn, mesh.triangle_count());
      }
      if (per_pass == 1) {
        EXPECT_GT(drawn, mesh.triangle_count());
      }
      ++configurations;
    }
  }
  EXPECT_EQ(configurations, 4 * int(cpca::supercluster_strategies().size()));
}

// --- False-colour pictures -------------------------------------------------------------------

// Three unit squares (two triangles each) side by side in the z = 0 plane, facing +Z.
meshes::Mesh three_squares() {
  meshes::Mesh m;
  for (int s = 0; s < 3; ++s) {
    const float x0 = -1.8f + 1.2f * float(s);
    const std::uint32_t b = std::uint32_t(m.positions.size());
    m.positions.push_back({x0, -0.5f, 0.f});
    m.positions.push_back({x0 + 1.f, -0.5f, 0.f});
    m.positions.push_back({x0 + 1.f, 0.5f, 0.f});
    m.positions.push_back({x0, 0.5f, 0.f});
    m.triangles.push_back({b, b + 1, b + 2});
    m.triangles.push_back({b, b + 2, b + 3});
  }
  return m;
}

render::Camera front_camera() {
  render::Camera c;
  c.eye = {0, 0, 4};
  c.target = {0, 0, 0};
  c.width = 160;
  c.height = 80;
  return c;
}

// Pixel whose centre is nearest to the projection of p (row 0 at the top).
std::pair<int, int> project(const render::Camera& c, const Eigen::Vector3d& p) {
  const Eigen::Vector4d clip = c.clip_from_world() * p.homogeneous();
  const double x = (clip.x() / clip.w() * 0.5 + 0.5) * c.width;
  const double y = (0.5 - clip.y() / clip.w() * 0.5) * c.height;
  return {int(std::floor(x)), int(std::floor(y))};
}

TEST(FalseColour, OverdrawPictureColoursEachTriangleByItsPassCount) {
  const meshes::Mesh mesh = three_squares();
  const render::Camera camera = front_camera();
  const std::vector<std::uint8_t> counts{1, 1, 2, 2, 3, 3};
  render::PictureOptions options;
  options.shade = false;
  options.legend = false;
  const render::Picture p = render::overdraw_picture(mesh, camera, counts, options);
  ASSERT_EQ(p.width, 160);
  ASSERT_EQ(p.height, 80);
  for (int s = 0; s < 3; ++s) {
    const double cx = -1.3 + 1.2 * s;
    // Inside each triangle of the square (below and above its diagonal).
    for (const Eigen::Vector3d& q :
         {Eigen::Vector3d(cx + 0.3, -0.3, 0), Eigen::Vector3d(cx - 0.3, 0.3, 0)}) {
      const auto [x, y] = project(camera, q);
      EXPECT_EQ(p.at(x, y), render::kPassCountPalette[s]) << "square " << s;
    }
  }
  // Between squares and above them: background.
  for (const Eigen::Vector3d& q : {Eigen::Vector3d(-0.7, 0, 0), Eigen::Vector3d(0, 0.9, 0)}) {
    const auto [x, y] = project(camera, q);
    EXPECT_EQ(p.at(x, y), render::kPictureBackground);
  }
  // Counts above 3 share the "3+" colour.
  const std::vector<std::uint8_t> big{1, 1, 2, 2, 7, 7};
  const render::Picture q = render::overdraw_picture(mesh, camera, big, options);
  EXPECT_EQ(q.rgb, p.rgb);
}

TEST(FalseColour, LegendShowsThePaletteAndShadingKeepsTheHue) {
  const meshes::Mesh mesh = three_squares();
  const render::Camera camera = front_camera();
  const std::vector<std::uint8_t> counts{1, 1, 2, 2, 3, 3};
  const render::Picture p = render::overdraw_picture(mesh, camera, counts);  // shaded, legend
  for (int c = 1; c <= 3; ++c) {
    const render::Rect r = render::legend_swatch(p.height, c);
    ASSERT_LT(r.x0, r.x1);
    ASSERT_LT(r.y0, r.y1);
    for (int y = r.y0; y < r.y1; ++y)
      for (int x = r.x0; x < r.x1; ++x)
        ASSERT_EQ(p.at(x, y), render::kPassCountPalette[c - 1]) << "swatch " << c;
  }
  // Shaded: the squares face the eye almost head on, so the colour is the palette colour
  // scaled by 0.35 + 0.65 cos with cos close to 1 (>= 0.9 here).
  const auto [x, y] = project(camera, Eigen::Vector3d(1.1, -0.3, 0));
  const render::Colour8 got = p.at(x, y);
  for (int ch = 0; ch < 3; ++ch) {
    EXPECT_LE(got[ch], render::kPassCountPalette[2][ch]);
    EXPECT_GE(got[ch], std::floor(render::kPassCountPalette[2][ch] * (0.35 + 0.65 * 0.9)));
  }
}

TEST(FalseColour, ClusterPictureUsesTheNearestVertexsCluster) {
  const meshes::Mesh mesh = three_squares();
  const render::Camera camera = front_camera();
  // Square 0: corners in clusters 0, 1, 2, 3; squares 1 and 2 entirely in 4 and 5.
  const std::vector<std::uint32_t> cluster_of{0, 1, 2, 3, 4, 4, 4, 4, 5, 5, 5, 5};
  render::PictureOptions options;
  options.shade = false;
  const render::Picture p = render::cluster_picture(mesh, camera, cluster_of, options);
  const Eigen::Vector3d corners[4] = {
      {-1.7, -0.4, 0}, {-0.9, -0.4, 0}, {-0.9, 0.4, 0}, {-1.7, 0.4, 0}};
  for (int v = 0; v < 4; ++v) {
    const auto [x, y] = project(camera, corners[v]);
    EXPECT_EQ(p.at(x, y), render::cluster_colour(std::uint32_t(v))) << "corner " << v;
  }
  const auto [x1, y1] = project(camera, Eigen::Vector3d(-0.1, 0.1, 0));
  EXPECT_EQ(p.at(x1, y1), render::cluster_colour(4));
  const auto [x2, y2] = project(camera, Eigen::Vector3d(1.1, -0.2, 0));
  EXPECT_EQ(p.at(x2, y2), render::cluster_colour(5));
  std::set<render::Colour8> distinct;
  for (std::uint32_t k = 0; k < 6; ++k) distinct.insert(render::cluster_colour(k));
  EXPECT_EQ(distinct.size(), 6u);
}

TEST(FalseColour, NearerTriangleWinsAndBadInputIsRefused) {
  meshes::Mesh mesh;
  // Triangle 0 at z = 0, triangle 1 in front of it at z = 1, both covering the centre.
  mesh.positions = {{-1, -1, 0}, {1, -1, 0}, {0, 1, 0}, {-1, -1, 1}, {1, -1, 1}, {0, 1, 1}};
  mesh.triangles = {{0, 1, 2}, {3, 4, 5}};
  const render::Camera camera = front_camera();
  const render::TriangleIdBuffer ids = render::rasterize_triangle_ids(mesh, camera);
  const auto [x, y] = project(camera, Eigen::Vector3d(0, 0, 1));
  EXPECT_EQ(ids.triangle[std::size_t(y) * ids.width + x], 1);
  EXPECT_EQ(ids.triangle[0], -1);  // the top-left corner sees nothing
  EXPECT_THROW(render::overdraw_picture(mesh, camera, std::vector<std::uint8_t>{1}),
               std::invalid_argument);
  EXPECT_THROW(render::overdraw_picture(mesh, camera, std::vector<std::uint8_t>{1, 0}),
               std::invalid_argument);
  EXPECT_THROW(render::cluster_picture(mesh, camera, std::vector<std::uint32_t>{0, 1}),
               std::invalid_argument);
}

TEST(FalseColour, PngKeepsColoursByteForByte) {
  render::Picture p(7, 5, {10, 20, 30});
  p.set(3, 2, render::kPassCountPalette[1]);
  const auto path = test_support::scratch("overdraw", "picture.png");
  render::write_picture_png(path, p);
  const render::Image back = render::read_image(path);
  ASSERT_EQ(back.width, 7);
  ASSERT_EQ(back.height, 5);
  // read_image gives the stored 8-bit values / 255 (no colour conversion for our own file).
  EXPECT_EQ(std::lround(back.pixel(3, 2)[1] * 255), render::kPassCountPalette[1][1]);
  EXPECT_EQ(std::lround(back.pixel(0, 0)[2] * 255), 30);
}

// --- Report ----------------------------------------------------------------------------------

TEST(OverdrawReport, TablesCsvAndJsonCarryEveryRow) {
  overdraw::OverdrawReport r;
  r.mesh = "m.obj";
  r.triangles = 100;
  for (int k : {64, 128})
    for (const char* method : {"original", "both"})
      for (const char* strategy : {"order", "ils"}) {
        overdraw::OverdrawRow row;
        row.clusters = k;
        row.method = method;
        row.budget = "thesis";
        row.strategy = strategy;
        row.average_overdraw = 1.0 + k / 512.0 + (std::string(strategy) == "ils" ? 0 : 0.1);
        row.clustering_seconds = 233;
        r.rows.push_back(row);
      }
  r.modes.push_back({64, "singlepass", std::nan(""), 1.0, 0.0, 0.0});
  const std::string md = overdraw::markdown(r);
  EXPECT_NE(md.find("### 64 clusters, thesis budget"), std::string::npos);
  EXPECT_NE(md.find("| original | ils | 3 m 53 s | 1.125000 |"), std::string::npos) << md;
  const std::string table = overdraw::csv(r);
  EXPECT_EQ(std::count(table.begin(), table.end(), '\n'), 1 + 8);
  const nlohmann::json js = nlohmann::json::parse(overdraw::json(r));
  ASSERT_EQ(js.at("rows").size(), 8u);
  // Row 5 is K = 128, original, ils: 1 + 128/512 exactly.
  EXPECT_EQ(js.at("rows").at(5).at("average_overdraw").get<double>(), 1.25);
  EXPECT_EQ(js.at("rows").at(5).at("method").get<std::string>(), "original");
  EXPECT_EQ(js.at("rows").at(5).at("strategy").get<std::string>(), "ils");
  // Not a number has no JSON spelling: it is written as null, as before the library.
  EXPECT_TRUE(js.at("modes").at(0).at("fps").is_null());
  EXPECT_EQ(overdraw::format_duration(12.44), "12.4 s");
}

// Under each table: the lowest-overdraw row whose Average SE and image RMSE are within 1.05 x
// the original's (a lower-overdraw row with 1.2 x the SE is passed over), with its bound's gap
// and what equal compact passes draw.
TEST(OverdrawReport, BestRowWithinTheErrorAndItsGap) {
  overdraw::OverdrawReport r;
  const auto add = [&](const char* method, double od, double bound, double se, double rmse) {
    overdraw::OverdrawRow row;
    row.clusters = 256;
    row.method = method;
    row.budget = "thesis";
    row.strategy = "ils";
    row.average_overdraw = od;
    row.overdraw_bound = bound;
    row.average_se = se;
    row.image_rmse = rmse;
    row.equal_patches_overdraw = 1.07;
    r.rows.push_back(row);
  };
  add("original", 1.4, 1.3, 1.0, 1.0);
  add("patch-first", 1.10, 1.08, 1.2, 1.0);
  add("patch-eps", 1.125, 1.1, 1.0, 1.04);
  const std::string md = overdraw::markdown(r);
  EXPECT_NE(md.find("| original | ils | 0.0 s | 1.400000 | 1.3000 |"), std::string::npos) << md;
  EXPECT_NE(md.find("Best row with Average SE and image RMSE <= 1.05 x original's: patch-eps / "
                    "ils, overdraw 1.1250 (SE 1.000 x, RMSE 1.040 x); its bound 1.1000, gap "
                    "0.0250; lowest bound of the table 1.0800; equal compact passes of the mesh "
                    "alone (METIS, error ignored) draw 1.0700."),
            std::string::npos)
      << md;
  const nlohmann::json js = nlohmann::json::parse(overdraw::json(r));
  EXPECT_EQ(js.at("rows").at(2).at("overdraw_bound").get<double>(), 1.1);
  EXPECT_EQ(js.at("rows").at(2).at("equal_patches_overdraw").get<double>(), 1.07);
}

// Every string field carries a file name or a GL string the user does not control: quotes,
// backslashes, control characters and bytes that are not UTF-8 must still give valid JSON.
TEST(OverdrawReport, JsonSurvivesHostileStrings) {
  const std::string hostile = std::string(
                                  "a\"b\\c\n\t\x01"
                                  "d") +
                              "\xff\xfe" + "\xc3(" + "\xe9t\xc3\xa9";
  overdraw::OverdrawReport r;
  r.mesh = r.probe = r.transfer = r.bake = r.gl_renderer = hostile;
  overdraw::OverdrawRow row;
  row.method = row.budget = row.strategy = hostile;
  r.rows.push_back(row);
  r.modes.push_back({1, hostile, 1.0, 1.0, 0.0, 0.0});
  nlohmann::json js;
  ASSERT_NO_THROW(js = nlohmann::json::parse(overdraw::json(r)));
  // The valid parts survive byte for byte; each invalid byte becomes U+FFFD.
  const std::string replaced =
      "a\"b\\c\n\t\x01"
      "d\xef\xbf\xbd\xef\xbf\xbd\xef\xbf\xbd(\xef\xbf\xbdt\xc3\xa9";
  for (const char* key : {"mesh", "probe", "transfer", "bake", "gl_renderer"})
    EXPECT_EQ(js.at(key).get<std::string>(), replaced) << key;
  EXPECT_EQ(js.at("rows").at(0).at("strategy").get<std::string>(), replaced);
  EXPECT_EQ(js.at("modes").at(0).at("mode").get<std::string>(), replaced);
}

}  // namespace
