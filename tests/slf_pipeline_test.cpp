// Tests for pipeline/slf.h and pipeline/slf_file.h: the SLF pipeline's error figures agree
// with cpca's own and with a reconstruction from the written file, the cache is used and
// survives a damaged entry, and .slfc files round-trip (recording the atlas's charts; a
// version 1 file reads as per-triangle) and refuse damage naming the file.
#include "common/hash.h"
#include "meshes/frames.h"
#include "meshes/procedural.h"
#include "pipeline/slf.h"
#include "pipeline/slf_file.h"
#include "probes/procedural.h"
#include "prt/slf_filter.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <string>

namespace {

namespace fs = std::filesystem;
using test_support::scratch;

struct Scene {
  meshes::Mesh mesh = meshes::make_sphere(1.f, 8, 4);
  // Light from one side, so that texels differ and the clustering has work to do.
  probes::Probe probe = probes::make_from_function(32, 16, [](const Eigen::Vector3d& d) {
    return probes::Rgb(float(1.2 + d.x()), float(1.0 + 0.5 * d.y()), float(0.6 + 0.4 * d.z()));
  });
};

pipeline::SlfSettings settings() {
  pipeline::SlfSettings s;
  s.atlas_width = s.atlas_height = 24;
  s.bake.grid = {6, 3};
  s.bake.spp = 2;
  s.bake.material.kind = prt::MaterialKind::kPhong;
  s.bake.material.exponent = 8.f;
  s.compress.clusters = 4;
  s.compress.components = 3;
  return s;
}

TEST(SlfPipeline, ErrorFiguresMatchCpcaAndTheWrittenFile) {
  const Scene scene;
  const pipeline::SlfRun run =
      pipeline::make_slf(scene.mesh, "sphere.obj", scene.probe, "gradient", settings(), {}, {});
  const pipeline::CompressedSlf& slf = run.slf;
  ASSERT_TRUE(slf.complete());
  EXPECT_EQ(slf.set.dimension(), std::size_t(3 * 18));
  EXPECT_EQ(slf.set.vertex_count, slf.bake.rows);
  EXPECT_FALSE(run.bake_cached);
  // cpca's Average SE is the squared error per row: RMS^2 times the row's length.
  EXPECT_NEAR(run.rms_error * run.rms_error * 54, run.report.error.average_squared_error,
              1e-4 * run.report.error.average_squared_error + 1e-12);
  EXPECT_GT(run.rms_error, 0);
  EXPECT_LT(run.relative_rms_error, 0.5);
  EXPECT_EQ(run.raw_floats, slf.bake.rows * 54);
  EXPECT_EQ(run.compressed_floats, slf.bake.rows * 3 + 4 * 4 * 54);

  const fs::path path = scratch("slf_pipeline", "sphere.slfc");
  pipeline::write_slfc(path, slf);
  const pipeline::CompressedSlf read = pipeline::read_slfc(path);
  EXPECT_EQ(read.mesh_path, slf.mesh_path);
  EXPECT_EQ(read.probe_name, "gradient");
  EXPECT_EQ(read.bake.rows, slf.bake.rows);
  EXPECT_EQ(read.bake.grid.azimuth, 6);
  EXPECT_EQ(read.bake.charts, meshes::AtlasCharts::kConformal);
  EXPECT_EQ(read.bake.material.exponent, 8.f);
  EXPECT_EQ(read.bake.mesh_hash, meshes::content_hash(scene.mesh));
  EXPECT_EQ(read.bake.probe_hash, prt::probe_hash(scene.probe));
  EXPECT_EQ(read.set.cluster_of, slf.set.cluster_of);
  EXPECT_EQ(read.set.weights, slf.set.weights);
  EXPECT_EQ(read.set.means, slf.set.means);
  EXPECT_EQ(read.set.bases, slf.set.bases);

  // The file reconstructs the bake, after the texel filter, as closely as the run said: bake
  // and filter again (deterministic) and compare.
  const meshes::Atlas atlas = meshes::make_atlas(scene.mesh, 24, 24);
  prt::SlfMatrix matrix = prt::bake_slf(scene.mesh, atlas, scene.probe, settings().bake);
  ASSERT_EQ(settings().filter.radius, 1);
  prt::filter_slf_texels(matrix, scene.mesh, atlas, settings().filter);
  double error = 0;
  std::vector<float> row(54);
  for (std::uint64_t r = 0; r < matrix.shape.row_count; ++r) {
    cpca::reconstruct_vertex(read.set, r, row.data());
    for (int c = 0; c < 54; ++c) error += std::pow(double(row[c]) - matrix.row(r)[c], 2);
  }
  EXPECT_NEAR(std::sqrt(error / (54.0 * double(matrix.shape.row_count))), run.rms_error,
              1e-5 * run.rms_error);
}

TEST(SlfPipeline, CacheIsReadBackAndADamagedEntryIsRebaked) {
  const Scene scene;
  const fs::path cache = scratch("slf_pipeline", "cache");
  fs::remove_all(cache);
  std::vector<std::string> warnings;
  pipeline::Reporter reporter;
  reporter.warning = [&](const std::string& line) { warnings.push_back(line); };
  const pipeline::SlfRun first =
      pipeline::make_slf(scene.mesh, "sphere.obj", scene.probe, "p", settings(), cache, reporter);
  EXPECT_FALSE(first.bake_cached);
  ASSERT_TRUE(fs::exists(first.bake_path));
  const pipeline::SlfRun second =
      pipeline::make_slf(scene.mesh, "sphere.obj", scene.probe, "p", settings(), cache, reporter);
  EXPECT_TRUE(second.bake_cached);
  EXPECT_EQ(second.slf.set.bases, first.slf.set.bases);
  EXPECT_TRUE(warnings.empty());
  // Another spp is another entry.
  pipeline::SlfSettings other = settings();
  other.bake.spp = 3;
  EXPECT_FALSE(
      pipeline::make_slf(scene.mesh, "sphere.obj", scene.probe, "p", other, cache, reporter)
          .bake_cached);
  // A damaged entry is reported and baked again, to the same result.
  test_support::patch(first.bake_path, fs::file_size(first.bake_path) - 4, float(7));
  const pipeline::SlfRun third =
      pipeline::make_slf(scene.mesh, "sphere.obj", scene.probe, "p", settings(), cache, reporter);
  EXPECT_FALSE(third.bake_cached);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("payload damaged"), std::string::npos) << warnings[0];
  EXPECT_EQ(third.slf.set.bases, first.slf.set.bases);
}

TEST(SlfPipeline, BadSettingsAndDamagedFilesAreRefused) {
  const Scene scene;
  pipeline::SlfSettings s = settings();
  s.compress.clusters = 100000;
  EXPECT_THROW(pipeline::make_slf(scene.mesh, "m", scene.probe, "p", s, {}, {}),
               std::invalid_argument);
  s = settings();
  s.charts = meshes::AtlasCharts::kPerTriangle;
  s.atlas_width = s.atlas_height = 8;  // 56 triangles need 28 cells of 4 x 4
  EXPECT_THROW(pipeline::make_slf(scene.mesh, "m", scene.probe, "p", s, {}, {}),
               std::invalid_argument);
  s.charts = meshes::AtlasCharts::kConformal;
  s.atlas_width = s.atlas_height = 4;  // more charts than 2 x 2 cells
  EXPECT_THROW(pipeline::make_slf(scene.mesh, "m", scene.probe, "p", s, {}, {}),
               std::invalid_argument);

  const pipeline::SlfRun run =
      pipeline::make_slf(scene.mesh, "sphere.obj", scene.probe, "gradient", settings(), {}, {});
  const fs::path good = scratch("slf_pipeline", "good.slfc");
  pipeline::write_slfc(good, run.slf);
  const std::string bytes = test_support::slurp(good);
  const auto read = [](const fs::path& p) { pipeline::read_slfc(p); };
  const auto damaged = [&](const std::string& name, const std::string& content) {
    return test_support::write_scratch("slf_pipeline", name, content);
  };
  test_support::error_of<pipeline::SlfcFileError>(damaged("short.slfc", bytes.substr(0, 64)), read,
                                                  "truncated header");
  test_support::error_of<pipeline::SlfcFileError>(
      damaged("cut.slfc", bytes.substr(0, bytes.size() - 8)), read, "truncated");
  test_support::error_of<pipeline::SlfcFileError>(damaged("long.slfc", bytes + "12345678"), read,
                                                  "trailing bytes");
  std::string flipped = bytes;
  flipped[bytes.size() - 5] ^= 0x20;
  test_support::error_of<pipeline::SlfcFileError>(damaged("flip.slfc", flipped), read,
                                                  "payload damaged");
  std::string header = bytes;
  header[57] ^= 0x01;  // the mesh hash
  test_support::error_of<pipeline::SlfcFileError>(damaged("header.slfc", header), read,
                                                  "header damaged");
  test_support::error_of<pipeline::SlfcFileError>(damaged("slf.slfc", bytes.substr(0, 8) + ""),
                                                  read, "truncated header");
  test_support::error_of<pipeline::SlfcFileError>(scratch("slf_pipeline", "none.slfc"), read,
                                                  "create it with prtr slf");
  // A version 1 file (u32 width at 16, so no charts field; u32 bounces at 36, so no light
  // samples; the checksum recomputed) reads as per-triangle charts and no shared light
  // samples, which were all version 1 had.
  ASSERT_EQ(run.slf.bake.charts, meshes::AtlasCharts::kConformal);
  EXPECT_EQ(pipeline::read_slfc(good).bake.light_samples, prt::SlfBakeOptions{}.light_samples);
  std::string old = bytes;
  const std::uint32_t version = 1;
  std::memcpy(old.data() + 8, &version, 4);
  old[18] = old[19] = 0;
  old[38] = old[39] = 0;
  const std::uint64_t sum = common::fnv1a(old.data(), 120);
  std::memcpy(old.data() + 120, &sum, 8);
  const pipeline::CompressedSlf v1 = pipeline::read_slfc(damaged("v1.slfc", old));
  EXPECT_EQ(v1.bake.charts, meshes::AtlasCharts::kPerTriangle);
  EXPECT_EQ(v1.bake.atlas_width, 24);
  EXPECT_EQ(v1.bake.light_samples, 0);
  EXPECT_EQ(v1.bake.bounces, run.slf.bake.bounces);
  EXPECT_EQ(v1.set.weights, run.slf.set.weights);
  std::string unknown = bytes;
  unknown[18] = 9;
  const std::uint64_t resealed = common::fnv1a(unknown.data(), 120);
  std::memcpy(unknown.data() + 120, &resealed, 8);
  test_support::error_of<pipeline::SlfcFileError>(damaged("charts.slfc", unknown), read,
                                                  "atlas chart method 9 is unknown");

  pipeline::CompressedSlf bad = run.slf;
  bad.set.cluster_of[0] = 99;
  EXPECT_THROW(pipeline::write_slfc(scratch("slf_pipeline", "bad.slfc"), bad),
               std::invalid_argument);
}

}  // namespace
