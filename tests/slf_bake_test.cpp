// Tests for prt/slf_bake.h: a Lambert sphere under a white sky gives a constant matrix (the
// albedo, every texel and direction, silhouette views included), with or without shared
// light samples; the shared-light estimator agrees with the paths' own; the streamed file
// holds the in-memory bake, row ranges baked apart join to the whole bake's bytes, the file
// records how the atlas was cut and the light samples (a version 1 file, from before
// conformal charts, reads as per-triangle; versions 1 and 2 as no light samples), and damaged
// files are refused with messages naming the file.
#include "prt/slf_bake.h"
#include "common/hash.h"
#include "meshes/atlas.h"
#include "meshes/frames.h"
#include "meshes/procedural.h"
#include "probes/procedural.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>

namespace {

namespace fs = std::filesystem;
using test_support::scratch;

// A coarse sphere shaded flat: every triangle has its own corners with the face's normal, so
// no sample direction above a texel's shading plane is blocked by its own triangle and the
// white sky's answer is exact (interpolated normals on 8 x 4 facets tilt by up to 22 degrees
// and lose a few percent of the sky to the surface itself).
meshes::Mesh flat_sphere() {
  const meshes::Mesh smooth = meshes::make_sphere(1.f, 8, 4);
  meshes::Mesh flat;
  for (const meshes::Triangle& t : smooth.triangles) {
    const auto base = std::uint32_t(flat.positions.size());
    const meshes::Vec3 n = (smooth.positions[t[1]] - smooth.positions[t[0]])
                               .cross(smooth.positions[t[2]] - smooth.positions[t[0]])
                               .normalized();
    for (int c = 0; c < 3; ++c) {
      flat.positions.push_back(smooth.positions[t[c]]);
      flat.normals.push_back(n);
    }
    flat.triangles.push_back({base, base + 1, base + 2});
  }
  meshes::compute_tangents(flat);
  return flat;
}

struct Scene {
  meshes::Mesh mesh = flat_sphere();
  meshes::Atlas atlas = meshes::make_atlas(mesh, 24, 24);
  probes::Probe sky = probes::make_constant(32, 16, probes::Rgb(1, 1, 1));
};

prt::SlfBakeOptions lambert_options(int spp) {
  prt::SlfBakeOptions o;
  o.grid = {8, 4};
  o.spp = spp;
  o.material.kind = prt::MaterialKind::kLambert;
  o.material.albedo = Eigen::Vector3f::Constant(0.6f);
  return o;
}

TEST(SlfBake, LambertSphereUnderWhiteSkyIsConstant) {
  const Scene s;
  for (int light_samples : {0, 8}) {
    prt::SlfBakeOptions o = lambert_options(128);
    o.light_samples = light_samples;
    const prt::SlfMatrix m = prt::bake_slf(s.mesh, s.atlas, s.sky, o);
    ASSERT_EQ(m.shape.rows, s.atlas.used_texels());
    ASSERT_EQ(m.shape.row_count, m.shape.rows);
    ASSERT_EQ(m.shape.columns(), std::size_t(3 * 8 * 4));
    ASSERT_EQ(m.data.size(), m.shape.rows * m.shape.columns());
    double sum = 0;
    for (float v : m.data) {
      EXPECT_NEAR(v, 0.6, 0.12) << light_samples;
      sum += v;
    }
    EXPECT_NEAR(sum / double(m.data.size()), 0.6, 0.006) << light_samples;
  }
}

// The shared-light estimator against the paths' own (a second code path through the same
// integral): a glossy sphere under a sun and a sky, two bakes with each. The mean radiance of
// each row of cells (polar band) over all texels agrees, and the squared difference between
// the estimators is what their noises (each from its own two bakes) make, with no room for
// a per-cell bias: a missing or doubled MIS weight shows in both.
TEST(SlfBake, SharedLightSamplesAgreeWithThePathsOwn) {
  const Scene s;
  const Eigen::Vector3d sun_direction = Eigen::Vector3d(0.3, 0.8, 0.5).normalized();
  const probes::Probe sun = probes::make_from_function(64, 32, [&](const Eigen::Vector3d& d) {
    const double disc = d.dot(sun_direction) > std::cos(0.2) ? 1.0 : 0.0;
    return probes::Rgb(float(0.3 + 20 * disc), float(0.4 + 18 * disc), float(0.6 + 15 * disc));
  });
  prt::SlfBakeOptions o;
  o.grid = {8, 4};
  o.material.kind = prt::MaterialKind::kCookTorrance;
  o.material.roughness = 0.2f;
  o.material.specular = 0.5f;
  o.material.albedo = Eigen::Vector3f::Constant(0.3f);
  o.spp = 64;
  std::vector<prt::SlfMatrix> own, shared;
  // Four seeds: bakes with one seed share their paths' numbers, so their noises correlate.
  for (std::uint64_t seed : {1, 2}) {
    o.seed = seed;
    o.light_samples = 0;
    own.push_back(prt::bake_slf(s.mesh, s.atlas, sun, o));
    o.seed = seed + 2;
    o.light_samples = 4;
    shared.push_back(prt::bake_slf(s.mesh, s.atlas, sun, o));
  }
  const std::size_t columns = own[0].shape.columns();
  std::vector<double> band_own(4, 0.0), band_shared(4, 0.0);
  double between = 0, own_twice = 0, shared_twice = 0;
  for (std::size_t i = 0; i < own[0].data.size(); ++i) {
    const std::size_t band = (i % columns) / 3 / 8;
    band_own[band] += own[0].data[i] + own[1].data[i];
    band_shared[band] += shared[0].data[i] + shared[1].data[i];
    between += std::pow(double(own[0].data[i]) - shared[0].data[i], 2);
    own_twice += std::pow(double(own[0].data[i]) - own[1].data[i], 2);
    shared_twice += std::pow(double(shared[0].data[i]) - shared[1].data[i], 2);
  }
  for (int band = 0; band < 4; ++band) {
    EXPECT_GT(band_shared[band], 0.0);
    EXPECT_NEAR(band_shared[band] / band_own[band], 1.0, 0.03) << band;
  }
  // E[between] = var_own + var_shared = (own_twice + shared_twice) / 2, plus any bias^2.
  const double noise = (own_twice + shared_twice) / 2;
  EXPECT_NEAR(between / noise, 1.0, 0.25);
}

TEST(SlfBake, FileHoldsTheBakeAndPartsJoinToIt) {
  const Scene s;
  prt::SlfBakeOptions o = lambert_options(2);
  o.material.kind = prt::MaterialKind::kPhong;  // view-dependent, so the grid matters
  o.material.albedo = Eigen::Vector3f(0.2f, 0.3f, 0.4f);
  o.block_rows = 37;  // several blocks, the last one short
  std::uint64_t calls = 0, last = 0;
  o.progress = [&](std::uint64_t done, std::uint64_t total) {
    ++calls;
    last = done;
    EXPECT_LE(done, total);
  };
  const prt::SlfMatrix whole = prt::bake_slf(s.mesh, s.atlas, s.sky, o);
  EXPECT_GE(calls, 1u);
  EXPECT_EQ(last, whole.shape.rows);
  const fs::path path = scratch("slf_bake", "whole.slf");
  const prt::SlfShape shape = prt::bake_slf_to_file(s.mesh, s.atlas, s.sky, o, path);
  const prt::SlfMatrix read = prt::read_slf(path);
  EXPECT_EQ(read.data, whole.data);
  EXPECT_EQ(read.shape.rows, shape.rows);
  EXPECT_EQ(read.shape.mesh_hash, meshes::content_hash(s.mesh));
  EXPECT_EQ(read.shape.probe_hash, prt::probe_hash(s.sky));
  EXPECT_EQ(read.shape.material.albedo, o.material.albedo);
  EXPECT_EQ(read.shape.grid.azimuth, 8);
  EXPECT_EQ(prt::read_slf_header(path).row_count, whole.shape.rows);

  // write_slf gives the same bytes as the streamed bake.
  const fs::path copy = scratch("slf_bake", "copy.slf");
  prt::write_slf(copy, whole);
  EXPECT_EQ(test_support::slurp(copy), test_support::slurp(path));

  // Two ranges baked apart, joined in either order.
  const std::uint64_t split = whole.shape.rows / 3;
  o.progress = {};
  o.first_row = split;
  o.end_row = 0;
  const fs::path second = scratch("slf_bake", "part1.slf");
  prt::bake_slf_to_file(s.mesh, s.atlas, s.sky, o, second);
  o.first_row = 0;
  o.end_row = split;
  const fs::path first = scratch("slf_bake", "part0.slf");
  prt::bake_slf_to_file(s.mesh, s.atlas, s.sky, o, first);
  const prt::SlfMatrix joined = prt::join_slf_parts({second, first});
  EXPECT_EQ(joined.data, whole.data);
  EXPECT_EQ(joined.shape.row_count, whole.shape.rows);
  test_support::error_of<prt::SlfFileError>(
      second, [&](const fs::path& p) { prt::join_slf_parts({p}); }, "starts at row");
  // A part of the other direction space is another matrix.
  o.grid.space = prt::SlfDirectionSpace::kReflected;
  const fs::path mirrored = scratch("slf_bake", "part0_reflected.slf");
  prt::bake_slf_to_file(s.mesh, s.atlas, s.sky, o, mirrored);
  test_support::error_of<prt::SlfFileError>(
      second,
      [&](const fs::path& p) {
        prt::join_slf_parts({mirrored, p});
      },
      "other settings");

  o.end_row = whole.shape.rows + 1;
  EXPECT_THROW(prt::bake_slf(s.mesh, s.atlas, s.sky, o), std::invalid_argument);
}

// The header as version 1 wrote it: version 1 and a u32 width at 16 (its high half, where
// version 2 keeps the charts, zero), the header checksum at 120 recomputed.
std::string as_version(std::string bytes, std::uint32_t version, std::uint16_t charts) {
  std::memcpy(bytes.data() + 8, &version, 4);
  std::memcpy(bytes.data() + 18, &charts, 2);
  const std::uint64_t sum = common::fnv1a(bytes.data(), 120);
  std::memcpy(bytes.data() + 120, &sum, 8);
  return bytes;
}

TEST(SlfBake, TheFileRecordsTheChartsAndLightSamplesAndOlderVersionsRead) {
  const Scene s;
  const meshes::Atlas per_triangle =
      meshes::make_atlas(s.mesh, 24, 24, {meshes::AtlasCharts::kPerTriangle});
  ASSERT_EQ(s.atlas.charts, meshes::AtlasCharts::kConformal);
  const fs::path conformal_path = scratch("slf_bake", "conformal.slf");
  prt::SlfBakeOptions o = lambert_options(1);
  o.light_samples = 5;
  prt::bake_slf_to_file(s.mesh, s.atlas, s.sky, o, conformal_path);
  EXPECT_EQ(prt::read_slf(conformal_path).shape.charts, meshes::AtlasCharts::kConformal);
  EXPECT_EQ(prt::read_slf(conformal_path).shape.light_samples, 5);
  EXPECT_EQ(prt::read_slf(conformal_path).shape.bounces, 1);
  // Versions 1 and 2 knew no shared light samples (their u32 bounces had zero high bytes).
  const fs::path path = scratch("slf_bake", "per_triangle.slf");
  o.light_samples = 0;
  prt::bake_slf_to_file(s.mesh, per_triangle, s.sky, o, path);
  const prt::SlfMatrix v2 = prt::read_slf(path);
  EXPECT_EQ(v2.shape.charts, meshes::AtlasCharts::kPerTriangle);
  EXPECT_EQ(v2.shape.rows, per_triangle.used_texels());

  const std::string bytes = test_support::slurp(path);
  const fs::path old = test_support::write_scratch("slf_bake", "v1.slf", as_version(bytes, 1, 0));
  const prt::SlfMatrix v1 = prt::read_slf(old);
  EXPECT_EQ(v1.shape.charts, meshes::AtlasCharts::kPerTriangle);
  EXPECT_EQ(v1.shape.atlas_width, 24);
  EXPECT_EQ(v1.data, v2.data);
  const auto read = [](const fs::path& p) { prt::read_slf(p); };
  // Version 1 had no charts field: bytes 18-19 belonged to its width.
  test_support::error_of<prt::SlfFileError>(
      test_support::write_scratch("slf_bake", "v1wide.slf", as_version(bytes, 1, 1)), read,
      "atlas size");
  EXPECT_EQ(
      prt::read_slf(test_support::write_scratch("slf_bake", "v2.slf", as_version(bytes, 2, 1)))
          .shape.light_samples,
      0);
  test_support::error_of<prt::SlfFileError>(
      test_support::write_scratch("slf_bake", "charts.slf", as_version(bytes, 2, 7)), read,
      "atlas chart method 7 is unknown");
  test_support::error_of<prt::SlfFileError>(
      test_support::write_scratch("slf_bake", "v5.slf", as_version(bytes, 5, 0)), read,
      "newer prtr version");
  test_support::error_of<prt::SlfFileError>(
      test_support::write_scratch("slf_bake", "v0.slf", as_version(bytes, 0, 0)), read,
      "reads versions 1 to 4");
}

// The grid's direction space is recorded at 46 (a u16 beside the masking at 44 since version
// 4); versions 1 to 3, whose u32 masking left 46-47 zero, read as view directions, and a space
// no build knows is refused.
TEST(SlfBake, TheFileRecordsTheDirectionSpace) {
  const Scene s;
  prt::SlfBakeOptions o = lambert_options(1);
  o.grid.space = prt::SlfDirectionSpace::kReflected;
  o.material.masking = prt::Masking::kVGroove;
  const fs::path path = scratch("slf_bake", "reflected.slf");
  prt::bake_slf_to_file(s.mesh, s.atlas, s.sky, o, path);
  const prt::SlfMatrix reflected = prt::read_slf(path);
  EXPECT_EQ(reflected.shape.grid.space, prt::SlfDirectionSpace::kReflected);
  EXPECT_EQ(reflected.shape.material.masking, prt::Masking::kVGroove);
  std::string bytes = test_support::slurp(path);
  const auto read = [](const fs::path& p) { prt::read_slf(p); };
  const std::uint16_t unknown = 7;
  std::memcpy(bytes.data() + 46, &unknown, 2);
  test_support::error_of<prt::SlfFileError>(
      test_support::write_scratch("slf_bake", "space7.slf", as_version(bytes, 4, 0)), read,
      "direction space 7 is unknown");
  const std::uint16_t zero = 0;
  std::memcpy(bytes.data() + 46, &zero, 2);
  const prt::SlfMatrix v3 =
      prt::read_slf(test_support::write_scratch("slf_bake", "v3.slf", as_version(bytes, 3, 0)));
  EXPECT_EQ(v3.shape.grid.space, prt::SlfDirectionSpace::kView);
  EXPECT_EQ(v3.shape.material.masking, prt::Masking::kVGroove);
}

// On a plane facing +Y, the mirror image about the normal of a direction at lat-long cell
// (i, j) is the direction half a turn around the pole, in cell (i + Z/2, j): the reflected
// bake must hold, cell for cell, what the view bake holds half a turn away (differing by no
// more than two view bakes of different seeds do), and differ from the view bake at the
// same cell under a probe that is brighter toward +X.
// A plane facing +Y, its 8 x 8 atlas, a probe brighter toward +X (and toward -Z by
// `toward_minus_z`), and a glossy Phong bake of it without bounces.
struct GlossyPlane {
  meshes::Mesh plane = meshes::make_plane(2.f, 1);
  meshes::Atlas atlas = meshes::make_atlas(plane, 8, 8);
  probes::Probe probe;
  prt::SlfBakeOptions o;
  explicit GlossyPlane(double toward_minus_z) {
    probe = probes::make_from_function(64, 32, [toward_minus_z](const Eigen::Vector3d& d) {
      const float v = float(1.0 + 0.8 * d.x() + 0.3 * d.y() - toward_minus_z * d.z());
      return probes::Rgb(v, 0.5f * v, 0.25f);
    });
    o.spp = 128;
    o.bounces = 0;
    o.material.kind = prt::MaterialKind::kPhong;
    o.material.exponent = 8;
    o.material.specular = 0.6f;
    o.material.albedo = Eigen::Vector3f::Constant(0.2f);
  }
  prt::SlfMatrix bake() const { return prt::bake_slf(plane, atlas, probe, o); }
};

TEST(SlfBake, AReflectedGridHoldsTheMirroredViewsRadiance) {
  GlossyPlane p(0.0);
  prt::SlfBakeOptions& o = p.o;
  o.grid = {8, 4};
  const prt::SlfMatrix view = p.bake();
  o.grid.space = prt::SlfDirectionSpace::kReflected;
  o.seed = 2;
  const prt::SlfMatrix mirrored = p.bake();
  ASSERT_EQ(view.data.size(), mirrored.data.size());
  double shifted = 0, same = 0;
  const int z = o.grid.azimuth;
  for (std::uint64_t r = 0; r < view.shape.row_count; ++r)
    for (int j = 0; j < o.grid.elevation; ++j)
      for (int i = 0; i < z; ++i)
        for (int c = 0; c < 3; ++c) {
          const double m = mirrored.row(r)[3 * (j * z + i) + c];
          const double v_half = view.row(r)[3 * (j * z + (i + z / 2) % z) + c];
          const double v_same = view.row(r)[3 * (j * z + i) + c];
          shifted += (m - v_half) * (m - v_half);
          same += (m - v_same) * (m - v_same);
        }
  // The two bakes' noise: the view bake again with the reflected one's seed.
  o.grid.space = prt::SlfDirectionSpace::kView;
  const prt::SlfMatrix view_again = p.bake();
  double noise = 0;
  for (std::size_t k = 0; k < view.data.size(); ++k)
    noise += double(view.data[k] - view_again.data[k]) * double(view.data[k] - view_again.data[k]);
  EXPECT_LT(std::sqrt(shifted / noise), 1.2);
  EXPECT_GT(std::sqrt(same / noise), 4.0);
}

// Reflection about the normal is its own inverse and keeps the angle to the normal, so a
// cell's views are as far from the horizon as the cell; a grid of views is the identity.
// The bake's cell samples take the polar angle by its cosine: the same direction as Eq. 1 at
// xi2 = acos(c) / pi, poles and equator included.
TEST(SlfDirections, DirectionAtACosineIsEquationOne) {
  for (double xi1 : {0.0, 0.3, 1.0, 1.7, 1.999})
    for (double c : {1.0, 0.9, 0.31, 0.0, -0.5, -0.999, -1.0}) {
      const Eigen::Vector3d expected = prt::slf_direction(xi1, std::acos(c) / std::numbers::pi);
      const Eigen::Vector3d d = prt::slf_direction_at_cosine(xi1, c);
      EXPECT_LT((d - expected).norm(), 1e-15) << xi1 << " " << c;
      EXPECT_NEAR(d.norm(), 1.0, 1e-15);
    }
}

TEST(SlfDirections, ReflectedSpaceMirrorsAboutTheNormal) {
  std::mt19937 rng(5);
  std::normal_distribution<double> g;
  prt::SlfGrid reflected;
  reflected.space = prt::SlfDirectionSpace::kReflected;
  const prt::SlfGrid view;
  for (int i = 0; i < 100; ++i) {
    const Eigen::Vector3d n = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
    const Eigen::Vector3d v = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
    const Eigen::Vector3d r = prt::slf_grid_space(reflected, v, n);
    EXPECT_NEAR(r.norm(), 1.0, 1e-12);
    EXPECT_NEAR(r.dot(n), v.dot(n), 1e-12);
    EXPECT_NEAR((r + v - 2 * v.dot(n) * n).norm(), 0.0, 1e-12);  // v's tangent part flipped
    EXPECT_LT((prt::slf_grid_space(reflected, r, n) - v).norm(), 1e-12);
    EXPECT_EQ(prt::slf_grid_space(view, v, n), v);
  }
  // Toward the normal, the view is its own reflection.
  const Eigen::Vector3d n(0, 1, 0);
  EXPECT_LT((prt::slf_grid_space(reflected, n, n) - n).norm(), 1e-15);
}

// The local grid's frame, written out independently: the pole the normal, azimuth 0 the
// world's up projected onto the tangent plane; polar over [0, pi / 2], the horizon's row for
// views below it; an exact round trip back to the view.
TEST(SlfDirections, LocalSpaceIsTheViewInTheTexelsFrame) {
  std::mt19937 rng(7);
  std::normal_distribution<double> g;
  prt::SlfGrid local;
  local.space = prt::SlfDirectionSpace::kLocal;
  EXPECT_TRUE(prt::slf_grid_uses_normals(local));
  EXPECT_NEAR(prt::slf_polar_span(local), M_PI / 2, 1e-15);
  for (int i = 0; i < 100; ++i) {
    const Eigen::Vector3d n = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
    const Eigen::Vector3d v = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
    const Eigen::Matrix3d f = prt::slf_local_frame(n);
    EXPECT_NEAR((f.transpose() * f - Eigen::Matrix3d::Identity()).norm(), 0.0, 1e-12);
    EXPECT_LT((f.col(1) - f.col(0).cross(n)).norm(), 1e-12);
    EXPECT_LT((f.col(2) - n).norm(), 1e-15);
    const Eigen::Vector3d up_tangent = (Eigen::Vector3d::UnitY() - n.y() * n).normalized();
    EXPECT_LT((f.col(0) - up_tangent).norm(), 1e-12);
    const Eigen::Vector3d l = prt::slf_grid_space(local, v, n);
    EXPECT_NEAR(l.norm(), 1.0, 1e-12);
    EXPECT_LT((prt::slf_grid_view(local, l, n) - v).norm(), 1e-12);
    const Eigen::Vector2d xi = prt::slf_grid_coordinates(local, l);
    const double polar = std::acos(std::clamp(v.dot(n), -1.0, 1.0));
    EXPECT_NEAR(xi.y(), std::min(1.0, polar / (M_PI / 2)), 1e-9);
    // Azimuth from the up tangent, toward t x n (Eq. 1's +X from its -Z).
    const double azimuth = std::atan2(v.dot(up_tangent.cross(n)), v.dot(up_tangent));
    EXPECT_NEAR(std::remainder(M_PI * (xi.x() - 1.0) - azimuth, 2 * M_PI), 0.0, 1e-9);
    // The reflection lies half a turn around the local pole from the view.
    if (v.dot(n) > 0) {
      prt::SlfGrid reflected;
      reflected.space = prt::SlfDirectionSpace::kReflected;
      const Eigen::Vector2d r = prt::slf_grid_coordinates(
          local, prt::slf_grid_space(local, prt::slf_grid_space(reflected, v, n), n));
      EXPECT_NEAR(r.y(), xi.y(), 1e-9);
      EXPECT_NEAR(std::remainder(M_PI * (r.x() - xi.x()) - M_PI, 2 * M_PI), 0.0, 1e-9);
    }
  }
  // Along the pole's axis the frame falls back to the world's -Z, and stays a frame.
  for (const double y : {1.0, -1.0}) {
    const Eigen::Matrix3d f = prt::slf_local_frame({0, y, 0});
    EXPECT_LT((f.col(0) + Eigen::Vector3d::UnitZ()).norm(), 1e-15);
    EXPECT_NEAR(std::abs(f.determinant()), 1.0, 1e-15);
  }
  // The pole and the horizon: the first row's edge and the last's.
  const Eigen::Vector3d n = Eigen::Vector3d(1, 2, 3).normalized();
  const Eigen::Vector3d t = prt::slf_local_frame(n).col(0);
  EXPECT_NEAR(prt::slf_grid_coordinates(local, prt::slf_grid_space(local, n, n)).y(), 0.0, 1e-7);
  EXPECT_NEAR(prt::slf_grid_coordinates(local, prt::slf_grid_space(local, t, n)).y(), 1.0, 1e-12);
  EXPECT_EQ(prt::slf_grid_coordinates(local, prt::slf_grid_space(local, -n, n)).y(), 1.0);
  // A cell centre's polar angle spans the hemisphere, not the sphere.
  local.elevation = 4;
  EXPECT_NEAR(prt::slf_grid_direction(local, 3 * local.azimuth).y(), std::cos(3.5 * M_PI / 8),
              1e-12);
}

// On a plane facing +Y the local frame is the world's (the pole +Y, azimuth 0 toward -Z), and
// the local grid's W rows over the hemisphere are the upper W of a view grid of 2 W rows over
// the sphere, cell for cell: the two bakes must agree there to within two view bakes of
// different seeds, and differ from the view grid of W rows at the same cell.
TEST(SlfBake, ALocalGridHoldsTheUpperHalfOfAViewGridOfTwiceTheRows) {
  GlossyPlane p(0.4);
  prt::SlfBakeOptions& o = p.o;
  o.grid = {8, 8};
  const prt::SlfMatrix view = p.bake();
  o.seed = 2;
  const prt::SlfMatrix view_again = p.bake();
  o.grid = {8, 4, prt::SlfDirectionSpace::kLocal};
  const prt::SlfMatrix local = p.bake();
  o.grid = {8, 4};
  const prt::SlfMatrix coarse = p.bake();
  ASSERT_EQ(local.shape.row_count, view.shape.row_count);
  const std::size_t upper = 3 * 8 * 4;  // floats of the view grid's upper 4 rows
  ASSERT_EQ(local.shape.columns(), upper);
  double held = 0, noise = 0, same_cell = 0;
  for (std::uint64_t r = 0; r < view.shape.row_count; ++r)
    for (std::size_t k = 0; k < upper; ++k) {
      const double l = local.row(r)[k], v = view.row(r)[k];
      held += (l - v) * (l - v);
      noise += (v - view_again.row(r)[k]) * (v - view_again.row(r)[k]);
      same_cell += (l - coarse.row(r)[k]) * (l - coarse.row(r)[k]);
    }
  EXPECT_LT(std::sqrt(held / noise), 1.2);
  EXPECT_GT(std::sqrt(same_cell / noise), 4.0);
}

TEST(SlfBake, DamagedFilesAreRefusedNamingTheFile) {
  const Scene s;
  const fs::path good = scratch("slf_bake", "good.slf");
  prt::bake_slf_to_file(s.mesh, s.atlas, s.sky, lambert_options(1), good);
  const std::string bytes = test_support::slurp(good);
  const auto damaged = [&](const std::string& name, const std::string& content) {
    return test_support::write_scratch("slf_bake", name, content);
  };
  const auto read = [](const fs::path& p) { prt::read_slf(p); };
  test_support::error_of<prt::SlfFileError>(damaged("short.slf", bytes.substr(0, 100)), read,
                                            "truncated header");
  test_support::error_of<prt::SlfFileError>(damaged("cut.slf", bytes.substr(0, bytes.size() - 4)),
                                            read, "truncated");
  test_support::error_of<prt::SlfFileError>(damaged("long.slf", bytes + "xx"), read,
                                            "trailing bytes");
  std::string flipped = bytes;
  flipped[bytes.size() - 3] ^= 0x10;
  test_support::error_of<prt::SlfFileError>(damaged("flip.slf", flipped), read, "payload damaged");
  std::string header = bytes;
  header[60] ^= 0x01;  // the mesh hash
  test_support::error_of<prt::SlfFileError>(damaged("header.slf", header), read, "header damaged");
  std::string magic = bytes;
  magic[0] = 'X';
  test_support::error_of<prt::SlfFileError>(damaged("magic.slf", magic), read, "magic");
  test_support::error_of<prt::SlfFileError>(scratch("slf_bake", "missing.slf"), read,
                                            "create it with prtr slf");
}

}  // namespace
