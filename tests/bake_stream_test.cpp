// The streaming bake (prt::bake_to_file) against the whole-mesh bake written by
// write_transfer: the same bytes, whatever the block size, with and without bounces.
#include "prt/bake.h"
#include "prt/transfer_file.h"

#include "meshes/procedural.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

namespace {

namespace fs = std::filesystem;

prt::BakeOptions small_options(prt::TransferKind kind, int bounces) {
  prt::BakeOptions o;
  o.kind = kind;
  o.order = 3;
  o.samples = 64;
  o.bounces = bounces;
  o.seed = 7;
  o.material.kind = prt::MaterialKind::kPhong;
  o.material.albedo = Eigen::Vector3f(0.6f, 0.4f, 0.2f);  // three channels
  o.material.specular = 0.3f;
  return o;
}

// The torus's inner ring sees itself, so bounces read transfer far from the vertex's block.
meshes::Mesh torus() {
  return meshes::make_torus(1.f, 0.4f, 24, 12);
}

std::size_t files_in(const fs::path& dir) {
  std::size_t n = 0;
  for (const auto& e : fs::directory_iterator(dir)) n += e.is_regular_file();
  return n;
}

void expect_same_file(const meshes::Mesh& mesh, const prt::BakeOptions& o, std::uint64_t block,
                      const std::string& name) {
  const fs::path whole = test_support::scratch("bake_stream", name + "_whole.prtx");
  const fs::path streamed = test_support::scratch("bake_stream", name + "_streamed.prtx");
  prt::BakeStats whole_stats, stream_stats;
  prt::write_transfer(whole, prt::bake(mesh, o, &whole_stats));
  const std::size_t before = files_in(streamed.parent_path());
  const prt::TransferSet shape = prt::bake_to_file(mesh, o, streamed, block, &stream_stats);
  EXPECT_EQ(shape.vertex_count, mesh.vertex_count());
  EXPECT_TRUE(shape.data.empty());
  const std::string a = test_support::slurp(whole), b = test_support::slurp(streamed);
  ASSERT_EQ(a.size(), b.size()) << name;
  EXPECT_TRUE(a == b) << name << ": block " << block << " differs from the whole-mesh bake";
  // Only the output appeared: the scratch passes are gone.
  EXPECT_EQ(files_in(streamed.parent_path()), before + 1) << name;
  EXPECT_EQ(stream_stats.rays_shadow, whole_stats.rays_shadow);
  EXPECT_EQ(stream_stats.rays_bounce, whole_stats.rays_bounce);
  EXPECT_EQ(stream_stats.occluded_vertices, whole_stats.occluded_vertices);
  fs::remove(streamed);
}

TEST(StreamingBake, GlossyOneBounceEqualsTheWholeBakeForEveryBlockSize) {
  const meshes::Mesh mesh = torus();
  const prt::BakeOptions o = small_options(prt::TransferKind::kGlossy, 1);
  for (std::uint64_t block :
       {std::uint64_t(1), std::uint64_t(37), std::uint64_t(64), std::uint64_t(100000)}) {
    expect_same_file(mesh, o, block, "glossy1_" + std::to_string(block));
  }
}

TEST(StreamingBake, DiffuseTwoBouncesEqualTheWholeBake) {
  // Two bounces exercise the running sum kept on disk between passes.
  expect_same_file(torus(), small_options(prt::TransferKind::kDiffuse, 2), 37, "diffuse2");
}

TEST(StreamingBake, NoBouncesEqualsTheWholeBake) {
  expect_same_file(torus(), small_options(prt::TransferKind::kGlossy, 0), 50, "glossy0");
}

TEST(StreamingBake, TheFileReadsBackAndAFailedBakeLeavesNothing) {
  const fs::path dir = test_support::scratch("bake_stream", "fail");
  fs::create_directories(dir);
  prt::BakeOptions o = small_options(prt::TransferKind::kGlossy, 1);
  o.order = 0;  // invalid: refused before anything is written
  EXPECT_THROW(prt::bake_to_file(torus(), o, dir / "bad.prtx", 16), std::invalid_argument);
  EXPECT_EQ(files_in(dir), 0u);
}

}  // namespace
