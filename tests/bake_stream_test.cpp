// The streaming bake (prt::bake_to_file) against the whole-mesh bake written by
// write_transfer: the same bytes, whatever the block size, with and without bounces.
#include "prt/bake.h"

#include "common/atomic_file.h"
#include "prt/transfer_file.h"
#include "prt/transfer_shard.h"

#include "meshes/procedural.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <barrier>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

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

// Returns the streaming bake's rows_gathered.
std::uint64_t expect_same_file(const meshes::Mesh& mesh, const prt::BakeOptions& o,
                               std::uint64_t block, const std::string& name) {
  // A directory per case: ctest runs cases in parallel, and this one counts its files.
  const fs::path whole = test_support::scratch("bake_stream_" + name, "whole.prtx");
  const fs::path streamed = test_support::scratch("bake_stream_" + name, "streamed.prtx");
  prt::BakeStats whole_stats, stream_stats;
  prt::write_transfer(whole, prt::bake(mesh, o, &whole_stats));
  const std::size_t before = files_in(streamed.parent_path());
  const prt::TransferSet shape = prt::bake_to_file(mesh, o, streamed, block, &stream_stats);
  EXPECT_EQ(shape.vertex_count, mesh.vertex_count());
  EXPECT_TRUE(shape.data.empty());
  const std::string a = test_support::slurp(whole), b = test_support::slurp(streamed);
  EXPECT_EQ(a.size(), b.size()) << name;
  EXPECT_TRUE(a == b) << name << ": block " << block << " differs from the whole-mesh bake";
  // Only the output appeared: the scratch passes are gone.
  EXPECT_EQ(files_in(streamed.parent_path()), before + 1) << name;
  EXPECT_EQ(stream_stats.rays_shadow, whole_stats.rays_shadow);
  EXPECT_EQ(stream_stats.rays_bounce, whole_stats.rays_bounce);
  EXPECT_EQ(stream_stats.occluded_vertices, whole_stats.occluded_vertices);
  EXPECT_EQ(whole_stats.rows_gathered, 0u);
  fs::remove(streamed);
  return stream_stats.rows_gathered;
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

TEST(StreamingBake, ABounceCacheSmallerThanThePassKeepsTheBits) {
  // The bounces read the previous pass through a cache of prt::kGatherBlocks blocks of rows.
  // 2,048 vertices: with blocks of 512 / kGatherBlocks the cache holds 512 rows, so groups of
  // dozens of vertices evict rows and read them again; with blocks of 32 / kGatherBlocks it
  // holds 32, so groups are a vertex or a few (the cache grows if one vertex needs more).
  const meshes::Mesh mesh = meshes::make_torus(1.f, 0.4f, 64, 32);
  const std::uint64_t v = mesh.vertex_count();
  const prt::BakeOptions o = small_options(prt::TransferKind::kDiffuse, 2);
  const std::uint64_t roomy = expect_same_file(mesh, o, 100000, "cache_roomy");
  const std::uint64_t small = expect_same_file(mesh, o, 512 / prt::kGatherBlocks, "cache_small");
  const std::uint64_t tiny = expect_same_file(mesh, o, 32 / prt::kGatherBlocks, "cache_tiny");
  // A cache that holds the whole pass reads each row at most once a bounce.
  EXPECT_GT(roomy, 0u);
  EXPECT_LE(roomy, 2 * v);
  // Smaller caches read rows again: the bits above are not the roomy cache's by accident.
  EXPECT_GT(small, roomy);
  EXPECT_GT(tiny, small);
}

TEST(StreamingBake, NoBouncesEqualsTheWholeBake) {
  expect_same_file(torus(), small_options(prt::TransferKind::kGlossy, 0), 50, "glossy0");
}

TEST(StreamingBake, TheFileReadsBackAndAFailedBakeLeavesNothing) {
  const fs::path dir = test_support::scratch("bake_stream_fail", "dir");
  fs::create_directories(dir);
  prt::BakeOptions o = small_options(prt::TransferKind::kGlossy, 1);
  o.order = 0;  // invalid: refused before anything is written
  EXPECT_THROW(prt::bake_to_file(torus(), o, dir / "bad.prtx", 16), std::invalid_argument);
  EXPECT_EQ(files_in(dir), 0u);
}

// A write that fails in the middle of a bake with bounces (here on the task that writes a
// block while the next one is computed) fails the bake with the file's name, and leaves
// neither the output nor any scratch file behind.
TEST(StreamingBake, AWriteFailingMidBakeFailsItAndLeavesNothing) {
  const fs::path dir = test_support::scratch("bake_stream_efbig", "dir");
  fs::remove_all(dir);
  fs::create_directories(dir);
  const prt::BakeOptions o = small_options(prt::TransferKind::kGlossy, 2);
  // Each pass is 288 x 243 floats (280 KB); 64 KB fails after a few blocks of 16 vertices.
  {
    test_support::FileSizeLimit limit(64 * 1024);
    if (!limit.ok()) GTEST_SKIP() << "cannot lower RLIMIT_FSIZE here";
    try {
      prt::bake_to_file(torus(), o, dir / "out.prtx", 16);
      ADD_FAILURE() << "the bake did not fail";
    } catch (const common::IoError& e) {
      EXPECT_NE(std::string(e.what()).find("out.prtx"), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(files_in(dir), 0u);
  // Nothing is left that a rerun would trip over.
  prt::bake_to_file(torus(), o, dir / "out.prtx", 16);
  EXPECT_EQ(files_in(dir), 1u);
}

// Bakes shards k/n of `o` (block 16) into the scratch directory; returns their paths.
std::vector<fs::path> bake_shards(const meshes::Mesh& mesh, const prt::BakeOptions& o,
                                  std::uint32_t n, const std::string& name) {
  std::vector<fs::path> paths;
  for (std::uint32_t k = 0; k < n; ++k) {
    paths.push_back(test_support::scratch("bake_stream", name + "_" + std::to_string(k)));
    prt::bake_shard_to_file(mesh, o, paths.back(), k, n, 16);
  }
  return paths;
}

// The message of the TransferFileError merge_shards throws, or "" if it merged.
std::string merge_error(const std::vector<fs::path>& shards, const fs::path& out) {
  try {
    prt::merge_shards(shards, out);
  } catch (const prt::TransferFileError& e) {
    return e.what();
  }
  return "";
}

TEST(Shards, MergedShardsEqualTheSingleBakeInAnyOrder) {
  const meshes::Mesh mesh = torus();
  const prt::BakeOptions o = small_options(prt::TransferKind::kGlossy, 0);
  const fs::path single = test_support::scratch("bake_stream", "single.prtx");
  prt::write_transfer(single, prt::bake(mesh, o));
  // 5 shards of 288 vertices: uneven ranges (57 and 58 vertices), blocks of 16 inside them.
  std::vector<fs::path> shards = bake_shards(mesh, o, 5, "five");
  std::swap(shards[0], shards[3]);
  const fs::path merged = test_support::scratch("bake_stream", "merged.prtx");
  ASSERT_EQ(merge_error(shards, merged), "");
  EXPECT_TRUE(test_support::slurp(single) == test_support::slurp(merged));
  // More shards than some ranges can fill: empty shards merge too.
  const meshes::Mesh tiny = meshes::make_plane(1.f, 1);  // 4 vertices
  const fs::path tiny_single = test_support::scratch("bake_stream", "tiny.prtx");
  prt::write_transfer(tiny_single, prt::bake(tiny, o));
  ASSERT_EQ(merge_error(bake_shards(tiny, o, 6, "tiny"), merged), "");
  EXPECT_TRUE(test_support::slurp(tiny_single) == test_support::slurp(merged));
}

TEST(Shards, MergeRefusesShardsThatDoNotBelongTogether) {
  const meshes::Mesh mesh = torus();
  const prt::BakeOptions o = small_options(prt::TransferKind::kGlossy, 0);
  const std::vector<fs::path> good = bake_shards(mesh, o, 3, "good");
  const fs::path out = test_support::scratch("bake_stream", "refused.prtx");
  fs::remove(out);

  prt::BakeOptions other_seed = o;
  other_seed.seed = 8;
  const std::vector<fs::path> seed8 = bake_shards(mesh, other_seed, 3, "seed8");
  std::string e = merge_error({good[0], seed8[1], good[2]}, out);
  EXPECT_NE(e.find("different bakes"), std::string::npos) << e;
  EXPECT_NE(e.find("seed"), std::string::npos) << e;

  const std::vector<fs::path> other_mesh =
      bake_shards(meshes::make_torus(1.f, 0.3f, 24, 12), o, 3, "mesh");
  e = merge_error({good[0], other_mesh[1], good[2]}, out);
  EXPECT_NE(e.find("mesh hash"), std::string::npos) << e;

  e = merge_error({good[0], good[2]}, out);
  EXPECT_NE(e.find("shard 1/3 is missing"), std::string::npos) << e;
  e = merge_error({good[0], good[1], good[1], good[2]}, out);
  EXPECT_NE(e.find("shard 1/3 is given twice"), std::string::npos) << e;

  const std::vector<fs::path> four = bake_shards(mesh, o, 4, "four");
  e = merge_error({good[0], good[1], four[3]}, out);
  EXPECT_NE(e.find("same --shard n"), std::string::npos) << e;

  // A damaged payload byte is caught by the shard's checksum, and nothing is written.
  std::string bytes = test_support::slurp(good[1]);
  bytes[bytes.size() - 3] ^= 0x40;
  const fs::path damaged = test_support::scratch("bake_stream", "damaged_shard");
  std::ofstream(damaged, std::ios::binary) << bytes;
  e = merge_error({good[0], damaged, good[2]}, out);
  EXPECT_NE(e.find("damaged"), std::string::npos) << e;
  EXPECT_FALSE(fs::exists(out));
}

// prt::bake_rank as mpirun runs it, with the ranks as threads and a std::barrier: every rank
// writes its rows into OUT.partial, one commits, and the file is the one-process bake's.
void expect_ranks_equal_one_process(const prt::BakeOptions& o, std::uint32_t ranks,
                                    std::uint64_t block, const std::string& name) {
  const meshes::Mesh mesh = torus();
  const fs::path one = test_support::scratch("bake_ranks_" + name, "one.prtx");
  const fs::path out = test_support::scratch("bake_ranks_" + name, "ranks.prtx");
  prt::bake_to_file(mesh, o, one, block);
  // A stale partial file, longer than the output, as a crashed job would leave.
  std::ofstream(prt::partial_transfer_path(out), std::ios::binary)
      << std::string(fs::file_size(one) + 999, '\x7f');
  std::barrier<> sync{std::ptrdiff_t(ranks)};
  std::vector<prt::TransferSet> shapes(ranks);
  std::vector<std::string> errors(ranks);
  std::vector<std::thread> threads;
  for (std::uint32_t r = 0; r < ranks; ++r) {
    threads.emplace_back([&, r] {
      try {
        shapes[r] = prt::bake_rank(
            mesh, o, out, r, ranks, [&] { sync.arrive_and_wait(); }, block);
      } catch (const std::exception& e) {
        errors[r] = e.what();
      }
    });
  }
  for (std::thread& t : threads) t.join();
  for (const std::string& e : errors) ASSERT_EQ(e, "") << name;
  prt::commit_transfer_slices(out, shapes[0]);
  EXPECT_FALSE(fs::exists(prt::partial_transfer_path(out))) << name;
  EXPECT_TRUE(test_support::slurp(one) == test_support::slurp(out)) << name << ": differs";
  for (const char* pass : {".pass0", ".pass1"}) fs::remove(out.string() + pass);
}

TEST(Ranks, RanksWritingOneFileEqualOneProcess) {
  expect_ranks_equal_one_process(small_options(prt::TransferKind::kGlossy, 0), 3, 16, "b0");
  expect_ranks_equal_one_process(small_options(prt::TransferKind::kDiffuse, 1), 2, 37, "b1");
  expect_ranks_equal_one_process(small_options(prt::TransferKind::kDiffuse, 2), 3, 8, "b2");
}

TEST(Ranks, ACommitRefusesAPartialFileShorterThanThePayload) {
  const fs::path out = test_support::scratch("bake_ranks_short", "short.prtx");
  const prt::BakeOptions o = small_options(prt::TransferKind::kGlossy, 0);
  const prt::TransferSet shape = prt::bake_rank(
      torus(), o, out, 0, 2, [] {}, 16);  // rank 1 never ran
  try {
    prt::commit_transfer_slices(out, shape);
    FAIL() << "a partial file with half a payload was committed";
  } catch (const prt::TransferFileError& e) {
    EXPECT_NE(std::string(e.what()).find("shorter than the payload"), std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(fs::exists(out));
}

TEST(Shards, BouncesAreRefusedByName) {
  try {
    prt::bake_shard_to_file(torus(), small_options(prt::TransferKind::kGlossy, 1),
                            test_support::scratch("bake_stream", "bounce_shard"), 0, 2);
    FAIL() << "a shard with bounces was baked";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("--bounces 0"), std::string::npos) << e.what();
  }
}

}  // namespace
