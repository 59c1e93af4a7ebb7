// The .prtc compressed file: exact round trips, deterministic bytes, one distinct message per
// kind of damage, no partial output on a failed write, and the byte offsets that
// docs/FORMATS.md promises to NumPy users.
#include "cpca/compressed_file.h"

#include "common/atomic_file.h"
#include "common/hash.h"

#include "test_support.h"

#include <gtest/gtest.h>
#include <sys/resource.h>

#include <algorithm>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <string>

namespace {

namespace fs = std::filesystem;
using cpca::CompressedSet;

// Offsets from docs/FORMATS.md, repeated on purpose: the test proves the document.
constexpr std::size_t kOffVersion = 8;
constexpr std::size_t kOffHeaderBytes = 12;
constexpr std::size_t kOffOrder = 16;
constexpr std::size_t kOffChannels = 20;
constexpr std::size_t kOffColumns = 24;
constexpr std::size_t kOffClusterCount = 28;
constexpr std::size_t kOffComponentCount = 32;
constexpr std::size_t kOffMethod = 36;
constexpr std::size_t kOffSolver = 40;
constexpr std::size_t kOffOverdraw = 44;
constexpr std::size_t kOffIterations = 48;
constexpr std::size_t kOffMeshPathBytes = 52;
constexpr std::size_t kOffVertexCount = 56;
constexpr std::size_t kOffSeed = 64;
constexpr std::size_t kOffMeshHash = 72;
constexpr std::size_t kOffTransferHash = 80;
constexpr std::size_t kOffAlpha = 88;
constexpr std::size_t kOffPayloadBytes = 96;
constexpr std::size_t kOffPayloadChecksum = 104;
constexpr std::size_t kOffMeshPathChecksum = 112;
constexpr std::size_t kOffHeaderChecksum = 120;
constexpr std::size_t kHeaderBytes = 128;

fs::path scratch(const std::string& name) {
  return test_support::scratch("compressed_file", name);
}
using test_support::patch;
using test_support::peek;
using test_support::slurp;

void reseal_header(const fs::path& p) {
  test_support::reseal_header(p, kOffHeaderChecksum);
}

std::size_t payload_offset(const CompressedSet& set) {
  return kHeaderBytes + (set.mesh_path.size() + 7) / 8 * 8;
}

// Recomputes the payload checksum (then the header's), so that a patched value is caught by
// the value checks rather than the checksum.
void reseal_payload(const fs::path& p, std::size_t offset) {
  const std::string bytes = slurp(p);
  patch<std::uint64_t>(p, kOffPayloadChecksum,
                       common::fnv1a(bytes.data() + offset, bytes.size() - offset));
  reseal_header(p);
}

CompressedSet make_set(int order, int channels, bool glossy, std::uint64_t vertices, int clusters,
                       int components, std::uint32_t rng_seed) {
  CompressedSet set;
  set.order = order;
  set.channels = channels;
  set.columns = glossy ? order * order : 1;
  set.mesh_hash = 0xfedcba9876543210ULL + rng_seed;
  set.transfer_hash = 0x0badc0ffee123456ULL ^ rng_seed;
  set.mesh_path = "/usr/share/glmark2/models/bunny.obj";
  set.vertex_count = vertices;
  set.cluster_count = clusters;
  set.component_count = components;
  set.method = rng_seed % 2 ? cpca::ClusterMethod::kIterative : cpca::ClusterMethod::kLbg;
  set.solver = rng_seed % 3 ? cpca::PcaSolver::kEigen : cpca::PcaSolver::kPowerIteration;
  set.alpha = 0.05 * rng_seed;
  set.overdraw_reduction = rng_seed % 2 == 0;
  set.seed = 0x0123456789abcdefULL + rng_seed;
  set.iterations = int(7 + rng_seed);
  std::mt19937 rng(rng_seed);
  std::uniform_real_distribution<float> u(-2.f, 2.f);
  set.cluster_of.resize(vertices);
  for (std::uint64_t p = 0; p < vertices; ++p) set.cluster_of[p] = std::uint32_t(rng() % clusters);
  const std::size_t d = set.dimension();
  set.weights.resize(vertices * components);
  set.means.resize(std::size_t(clusters) * d);
  set.bases.resize(std::size_t(clusters) * components * d);
  for (auto* v : {&set.weights, &set.means, &set.bases})
    for (float& x : *v) x = u(rng);
  return set;
}

template <class T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && test_support::same_bytes(a.data(), b.data(), a.size() * sizeof(T));
}

void expect_same_header(const CompressedSet& a, const CompressedSet& b) {
  EXPECT_EQ(a.order, b.order);
  EXPECT_EQ(a.channels, b.channels);
  EXPECT_EQ(a.columns, b.columns);
  EXPECT_EQ(a.mesh_hash, b.mesh_hash);
  EXPECT_EQ(a.transfer_hash, b.transfer_hash);
  EXPECT_EQ(a.mesh_path, b.mesh_path);
  EXPECT_EQ(a.vertex_count, b.vertex_count);
  EXPECT_EQ(a.cluster_count, b.cluster_count);
  EXPECT_EQ(a.component_count, b.component_count);
  EXPECT_EQ(a.method, b.method);
  EXPECT_EQ(a.solver, b.solver);
  EXPECT_EQ(std::memcmp(&a.alpha, &b.alpha, sizeof(double)), 0) << a.alpha << " " << b.alpha;
  EXPECT_EQ(a.overdraw_reduction, b.overdraw_reduction);
  EXPECT_EQ(a.seed, b.seed);
  EXPECT_EQ(a.iterations, b.iterations);
}

void expect_same(const CompressedSet& a, const CompressedSet& b) {
  expect_same_header(a, b);
  EXPECT_TRUE(same_bits(a.cluster_of, b.cluster_of));
  EXPECT_TRUE(same_bits(a.weights, b.weights));  // bitwise: -0 and denormals count too
  EXPECT_TRUE(same_bits(a.means, b.means));
  EXPECT_TRUE(same_bits(a.bases, b.bases));
}

// Runs read_compressed and returns the error message, failing unless it names the file and
// contains `expected`.
std::string read_error(const fs::path& p, const std::string& expected) {
  return test_support::error_of<cpca::CompressedFileError>(
      p, [](const fs::path& q) { cpca::read_compressed(q); }, expected);
}

// --- Round trips ---------------------------------------------------------------------------

TEST(CompressedFile, RoundTripIsExact) {
  struct Case {
    int order, channels;
    bool glossy;
    std::uint64_t vertices;
    int clusters, components;
    std::string mesh_path;
  };
  // Path lengths 0, 1, 7, 8, 9 and a multi-byte one cover the padding to 8 bytes.
  const Case cases[] = {
      {1, 1, false, 1, 1, 0, ""},          {3, 3, false, 20, 4, 2, "m"},
      {2, 1, true, 30, 5, 3, "abcdefg"},   {3, 3, true, 17, 17, 4, "abcdefgh"},
      {4, 1, true, 40, 3, 8, "mesh.obj/"}, {10, 1, false, 12, 2, 100, "/tmp/Häschen 🐇/bunny.obj"},
  };
  std::uint32_t seed = 1;
  for (const Case& c : cases) {
    CompressedSet set =
        make_set(c.order, c.channels, c.glossy, c.vertices, c.clusters, c.components, seed++);
    set.mesh_path = c.mesh_path;
    set.means[0] = -0.f;
    set.means.back() = std::numeric_limits<float>::denorm_min();
    // The largest magnitudes a compressed file holds.
    if (!set.weights.empty()) set.weights.back() = -1e12f;
    if (!set.bases.empty()) set.bases[0] = 1e12f;
    set.cluster_of.back() = std::uint32_t(c.clusters - 1);
    const fs::path p = scratch("round_trip_" + std::to_string(seed) + ".prtc");
    SCOPED_TRACE(p.string());
    cpca::write_compressed(p, set);
    EXPECT_EQ(fs::file_size(p),
              payload_offset(set) + 4 * (set.cluster_of.size() + set.weights.size() +
                                         set.means.size() + set.bases.size()));
    expect_same(cpca::read_compressed(p), set);

    // Same set, same bytes: the header is zeroed before it is filled.
    const fs::path q = scratch("round_trip_again_" + std::to_string(seed) + ".prtc");
    cpca::write_compressed(q, set);
    EXPECT_EQ(slurp(p), slurp(q));
  }
}

TEST(CompressedFile, HeaderOnlyReadSkipsPayload) {
  const CompressedSet set = make_set(3, 1, true, 200, 10, 4, 11);
  const fs::path p = scratch("header_only.prtc");
  cpca::write_compressed(p, set);
  const CompressedSet header = cpca::read_compressed_header(p);
  expect_same_header(header, set);
  EXPECT_TRUE(header.cluster_of.empty() && header.weights.empty() && header.means.empty() &&
              header.bases.empty());

  // The header read checks the file size but not the payload.
  patch<std::uint8_t>(p, payload_offset(set) + 1000, 0xff);
  EXPECT_NO_THROW(cpca::read_compressed_header(p));
  read_error(p, "payload damaged");
  fs::resize_file(p, fs::file_size(p) - 4);
  EXPECT_THROW(cpca::read_compressed_header(p), cpca::CompressedFileError);
}

TEST(CompressedFile, DocumentedOffsets) {
  CompressedSet set = make_set(2, 3, true, 9, 3, 2, 4);
  set.mesh_path = "bunny.obj";  // 9 bytes, padded to 16
  const fs::path p = scratch("documented.prtc");
  cpca::write_compressed(p, set);
  const std::string b = slurp(p);

  EXPECT_EQ(b.substr(0, 8), "PRTRCMPR");
  EXPECT_EQ(peek<std::uint32_t>(b, kOffVersion), 2u);
  EXPECT_EQ(peek<std::uint32_t>(b, kOffHeaderBytes), 128u);
  EXPECT_EQ(peek<std::uint32_t>(b, kOffOrder), 2u);
  EXPECT_EQ(peek<std::uint32_t>(b, kOffChannels), 3u);
  EXPECT_EQ(peek<std::uint32_t>(b, kOffColumns), 4u);
  EXPECT_EQ(peek<std::uint32_t>(b, kOffClusterCount), 3u);
  EXPECT_EQ(peek<std::uint32_t>(b, kOffComponentCount), 2u);
  EXPECT_EQ(peek<std::uint32_t>(b, kOffMethod), 0u);    // seed 4: lbg
  EXPECT_EQ(peek<std::uint32_t>(b, kOffSolver), 1u);    // seed 4: eigen
  EXPECT_EQ(peek<std::uint32_t>(b, kOffOverdraw), 1u);  // seed 4: on
  EXPECT_EQ(peek<std::uint32_t>(b, kOffIterations), 11u);
  EXPECT_EQ(peek<std::uint32_t>(b, kOffMeshPathBytes), 9u);
  EXPECT_EQ(peek<std::uint64_t>(b, kOffVertexCount), 9u);
  EXPECT_EQ(peek<std::uint64_t>(b, kOffSeed), set.seed);
  EXPECT_EQ(peek<std::uint64_t>(b, kOffMeshHash), set.mesh_hash);
  EXPECT_EQ(peek<std::uint64_t>(b, kOffTransferHash), set.transfer_hash);
  EXPECT_EQ(peek<double>(b, kOffAlpha), set.alpha);
  const std::size_t payload = 4 * (9 + 9 * 2 + 3 * 48 + 3 * 2 * 48);  // D = 3 * 4 * 4 = 48
  EXPECT_EQ(peek<std::uint64_t>(b, kOffPayloadBytes), payload);
  EXPECT_EQ(b.size(), 128 + 16 + payload);
  EXPECT_EQ(peek<std::uint64_t>(b, kOffPayloadChecksum),
            common::fnv1a(b.data() + 144, b.size() - 144));
  EXPECT_EQ(peek<std::uint64_t>(b, kOffMeshPathChecksum), common::fnv1a("bunny.obj", 9));
  EXPECT_EQ(peek<std::uint64_t>(b, kOffHeaderChecksum), common::fnv1a(b.data(), 120));
  EXPECT_EQ(b.substr(128, 9), "bunny.obj");
  EXPECT_EQ(b.substr(137, 7), std::string(7, '\0'));

  // Arrays back to back: ids (V), weights (V x N), means (K x D), bases (K x N x D).
  const std::size_t ids = 144, weights = ids + 4 * 9, means = weights + 4 * 9 * 2,
                    bases = means + 4 * 3 * 48;
  EXPECT_EQ(peek<std::uint32_t>(b, ids + 4 * 5), set.cluster_of[5]);
  EXPECT_EQ(peek<float>(b, weights + 4 * (7 * 2 + 1)), set.weight_row(7)(1));
  EXPECT_EQ(peek<float>(b, means + 4 * (2 * 48 + 30)), set.mean(2)(30));
  EXPECT_EQ(peek<float>(b, bases + 4 * ((1 * 2 + 1) * 48 + 47)), set.basis(1)(1, 47));
}

// --- Damage: each kind is its own message, naming the file --------------------------------

TEST(CompressedFile, EachCorruptionHasItsOwnMessage) {
  const CompressedSet set = make_set(2, 1, true, 10, 4, 3, 3);  // D = 16, path 35 bytes
  const std::size_t off = payload_offset(set);
  const std::size_t weights = off + 4 * 10, means = weights + 4 * 30, bases = means + 4 * 64;
  const std::size_t size = bases + 4 * 4 * 3 * 16;
  test_support::DamageMessages messages;
  const auto fresh = [&](const std::string& name) {
    const fs::path p = scratch("damaged_" + name + ".prtc");
    cpca::write_compressed(p, set);
    return p;
  };
  const auto check = [&](const std::string& name, const fs::path& p, const std::string& expected) {
    messages.record(name, read_error(p, expected));
  };
  // A header field set to `value` with the header checksum recomputed.
  const auto field = [&](const std::string& name, std::size_t offset, std::uint32_t value,
                         const std::string& expected) {
    const fs::path p = fresh(name);
    patch<std::uint32_t>(p, offset, value);
    reseal_header(p);
    check(name, p, expected);
  };

  {
    const fs::path p = fresh("header_cut");
    fs::resize_file(p, 60);
    check("truncated header", p, "truncated header");
  }
  {
    const fs::path p = fresh("payload_cut");
    fs::resize_file(p, size - 3);
    check("truncated", p,
          "truncated: expected " + std::to_string(size) + " bytes, found " +
              std::to_string(size - 3));
  }
  {
    const fs::path p = fresh("trailing");
    std::ofstream(p, std::ios::binary | std::ios::app) << "x";
    check("trailing", p, "trailing bytes: expected " + std::to_string(size));
  }
  {
    const fs::path p = fresh("magic");
    patch<char>(p, 3, 'X');
    check("magic", p, "not a prtr compressed file (it starts with \"PRTXCMPR\"");
  }
  field("version3", kOffVersion, 3, "written by a newer prtr version (file format version 3");
  field("version1", kOffVersion, 1, "written by an older prtr version (file format version 1");
  field("version0", kOffVersion, 0, "written by an older prtr version (file format version 0");
  field("header_bytes", kOffHeaderBytes, 64, "header size 64 bytes");
  field("order11", kOffOrder, 11, "SH order 11 out of range");
  field("channels2", kOffChannels, 2, "channel count 2 out of range");
  field("columns3", kOffColumns, 3, "column count 3 out of range");
  field("clusters0", kOffClusterCount, 0, "cluster count 0 out of range");
  field("clusters11", kOffClusterCount, 11, "cluster count 11 out of range");
  field("components17", kOffComponentCount, 17, "component count 17 out of range");
  field("method6", kOffMethod, 6, "cluster method 6 out of range");
  field("solver5", kOffSolver, 5, "PCA solver 5 out of range");
  field("overdraw2", kOffOverdraw, 2, "overdraw flag 2 out of range");
  field("iterations", kOffIterations, 0x80000000u, "iteration count 2147483648 out of range");
  field("path_length", kOffMeshPathBytes, 5000, "mesh path of 5000 bytes out of range");
  {
    const fs::path p = fresh("alpha_nan");
    patch<double>(p, kOffAlpha, std::numeric_limits<double>::quiet_NaN());
    reseal_header(p);
    check("alpha NaN", p, "geometry weight alpha nan out of range");
  }
  {
    const fs::path p = fresh("vertices");
    patch<std::uint64_t>(p, kOffVertexCount, (std::uint64_t(1) << 40) + 1);
    reseal_header(p);
    check("vertex count", p, "vertex count 1099511627777 out of range");
  }
  {
    const fs::path p = fresh("payload_bytes");
    patch<std::uint64_t>(p, kOffPayloadBytes, size - off + 4);
    reseal_header(p);
    check("payload bytes", p,
          "payload size mismatch: the header says " + std::to_string(size - off + 4) + " bytes");
  }
  {
    const fs::path p = fresh("header_flip");
    patch<std::uint8_t>(p, kOffTransferHash + 2, 0x77);
    check("header checksum", p, "header damaged");
  }
  {
    const fs::path p = fresh("path_flip");
    patch<char>(p, kHeaderBytes + 5, 'Q');
    check("path checksum", p, "mesh path damaged");
  }
  {
    // A lone continuation byte with the path checksum recomputed.
    const fs::path p = fresh("path_utf8");
    patch<std::uint8_t>(p, kHeaderBytes + 2, 0x80);
    const std::string b = slurp(p);
    patch<std::uint64_t>(p, kOffMeshPathChecksum,
                         common::fnv1a(b.data() + kHeaderBytes, set.mesh_path.size()));
    reseal_header(p);
    check("path utf8", p, "mesh path is not UTF-8 (byte 2)");
  }
  {
    const fs::path p = fresh("padding");
    patch<char>(p, kHeaderBytes + set.mesh_path.size(), 'x');
    check("padding", p, "mesh path padding is not zero");
  }
  {
    const fs::path p = fresh("payload_flip");
    patch<std::uint8_t>(p, means + 9, 0x42);
    check("payload checksum", p, "payload damaged");
  }
  {
    const fs::path p = fresh("cluster_id");
    patch<std::uint32_t>(p, off + 4 * 6, 4);
    reseal_payload(p, off);
    check("cluster id", p, "vertex 6 has cluster id 4, but there are only 4 clusters");
  }
  {
    const fs::path p = fresh("weight_nan");
    patch<float>(p, weights + 4 * (5 * 3 + 2), std::numeric_limits<float>::quiet_NaN());
    reseal_payload(p, off);
    check("weight NaN", p, "non-finite weight nan at vertex 5, component 2");
  }
  {
    const fs::path p = fresh("mean_inf");
    patch<float>(p, means + 4 * (3 * 16 + 7), std::numeric_limits<float>::infinity());
    reseal_payload(p, off);
    check("mean inf", p, "non-finite mean value inf at cluster 3, entry 7");
  }
  {
    const fs::path p = fresh("basis_nan");
    patch<float>(p, bases + 4 * ((2 * 3 + 1) * 16 + 15), -std::numeric_limits<float>::infinity());
    reseal_payload(p, off);
    check("basis -inf", p, "non-finite basis value -inf at cluster 2, component 1, entry 15");
  }
  {
    // Finite, but it overflows single precision once lit: NaN pixels with exit 0 before.
    const fs::path p = fresh("mean_huge");
    patch<float>(p, means + 4 * (1 * 16 + 2), 3e38f);
    reseal_payload(p, off);
    check("mean 3e38", p, "huge (beyond +-1e12) mean value 3");
  }
  {
    const fs::path p = scratch("no_such_file.prtc");
    fs::remove(p);
    check("missing", p, "no such compressed file");
  }
  {
    const fs::path p = scratch("a_directory.prtc");
    fs::create_directories(p);
    check("directory", p, "is a directory");
  }

  messages.expect_distinct(34);
}

// --- Writing ---------------------------------------------------------------------------------

TEST(CompressedFile, WriterRefusesWhatTheReaderWouldAndKeepsOldFile) {
  const fs::path p = scratch("refused.prtc");
  const CompressedSet good = make_set(2, 1, false, 6, 2, 1, 6);
  cpca::write_compressed(p, good);
  const std::string before = slurp(p);

  std::map<std::string, CompressedSet> bad;
  bad["mesh path of 4097 bytes"] = good;
  bad["mesh path of 4097 bytes"].mesh_path = std::string(4097, 'a');
  bad["is not UTF-8 without NUL (byte 1)"] = good;
  bad["is not UTF-8 without NUL (byte 1)"].mesh_path = std::string("a\xff", 2);
  bad["SH order 11"] = good;
  bad["SH order 11"].order = 11;
  bad["has cluster id 2"] = good;
  bad["has cluster id 2"].cluster_of[3] = 2;
  bad["a weight is NaN"] = good;
  bad["a weight is NaN"].weights[1] = std::numeric_limits<float>::quiet_NaN();
  bad["alpha -1"] = good;
  bad["alpha -1"].alpha = -1.0;
  bad["mean array has the wrong length"] = good;
  bad["mean array has the wrong length"].means.pop_back();
  for (const auto& [expected, set] : bad) {
    try {
      cpca::write_compressed(p, set);
      ADD_FAILURE() << "expected std::invalid_argument for " << expected;
    } catch (const std::invalid_argument& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find(p.string()), std::string::npos) << msg;
      EXPECT_NE(msg.find(expected), std::string::npos) << msg;
    }
  }
  EXPECT_EQ(slurp(p), before);

  // The longest allowed path is accepted.
  CompressedSet longest = good;
  longest.mesh_path = std::string(cpca::kMaxMeshPathBytes, 'b');
  cpca::write_compressed(p, longest);
  EXPECT_EQ(cpca::read_compressed(p).mesh_path, longest.mesh_path);
}

TEST(CompressedFile, MissingDirectoryThrowsAndLeavesNothing) {
  const fs::path dir = scratch("no_such_dir");
  fs::remove_all(dir);
  const fs::path p = dir / "out.prtc";
  try {
    cpca::write_compressed(p, make_set(2, 1, false, 5, 2, 1, 5));
    FAIL() << "expected common::IoError";
  } catch (const common::IoError& e) {
    EXPECT_NE(std::string(e.what()).find(p.string()), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir));
}

TEST(CompressedFile, FailedWriteLeavesNoFileAndNoTemporary) {
  const fs::path dir = scratch("failed_write");
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path p = dir / "bunny.prtc";
  const CompressedSet big = make_set(4, 1, true, 500, 20, 8, 8);  // ~200 KB
  {
    test_support::FileSizeLimit limit(64 * 1024);
    if (!limit.ok()) GTEST_SKIP() << "cannot lower RLIMIT_FSIZE here";
    try {
      cpca::write_compressed(p, big);
      ADD_FAILURE() << "expected common::IoError";
    } catch (const common::IoError& e) {
      EXPECT_NE(std::string(e.what()).find(p.string()), std::string::npos) << e.what();
    }
  }
  EXPECT_TRUE(fs::is_empty(dir)) << "a file or temporary file was left in " << dir;
}

}  // namespace
