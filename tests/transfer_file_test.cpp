// The .prtx transfer file: exact round trips, deterministic bytes, one distinct message per
// kind of damage, and the byte offsets that docs/FORMATS.md promises to NumPy users.
#include "prt/transfer_file.h"

#include "prt/mapped_transfer.h"

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
#include <numeric>
#include <random>
#include <set>
#include <sstream>
#include <string>

namespace {

namespace fs = std::filesystem;
using prt::TransferKind;
using prt::TransferSet;

// Offsets from docs/FORMATS.md, repeated here on purpose: the test proves the document.
constexpr std::size_t kOffVersion = 8;
constexpr std::size_t kOffHeaderBytes = 12;
constexpr std::size_t kOffKind = 16;
constexpr std::size_t kOffOrder = 20;
constexpr std::size_t kOffChannels = 24;
constexpr std::size_t kOffSamples = 28;
constexpr std::size_t kOffBounces = 32;
constexpr std::size_t kOffMaterialKind = 36;
constexpr std::size_t kOffVertexCount = 40;
constexpr std::size_t kOffSeed = 48;
constexpr std::size_t kOffMeshHash = 56;
constexpr std::size_t kOffAlbedo = 64;
constexpr std::size_t kOffSpecular = 76;
constexpr std::size_t kOffExponent = 80;
constexpr std::size_t kOffRoughness = 84;
constexpr std::size_t kOffF0 = 88;
constexpr std::size_t kOffPayloadFloats = 96;
constexpr std::size_t kOffPayloadChecksum = 104;
constexpr std::size_t kOffHeaderChecksum = 120;
constexpr std::size_t kPayloadOffset = 128;

fs::path scratch(const std::string& name) {
  return test_support::scratch("transfer_file", name);
}
using test_support::patch;
using test_support::peek;
using test_support::slurp;

void reseal_header(const fs::path& p) {
  test_support::reseal_header(p, kOffHeaderChecksum);
}

TransferSet make_set(TransferKind kind, int order, int channels, std::uint64_t vertices,
                     prt::MaterialKind material, std::uint32_t rng_seed) {
  TransferSet set;
  set.kind = kind;
  set.order = order;
  set.channels = channels;
  set.vertex_count = vertices;
  set.samples = 1024 + int(rng_seed);
  set.bounces = int(rng_seed % 4);
  set.seed = 0x0123456789abcdefULL ^ rng_seed;
  set.mesh_hash = 0xfedcba9876543210ULL + rng_seed;
  set.material.kind = material;
  set.material.albedo =
      channels == 1 ? Eigen::Vector3f::Constant(0.45f) : Eigen::Vector3f(0.7f, 0.25f, 0.125f);
  set.material.specular = 0.2f;
  set.material.exponent = 17.5f;
  set.material.roughness = 0.35f;
  set.material.f0 = 0.05f;
  std::mt19937 rng(rng_seed);
  std::uniform_real_distribution<float> u(-4.f, 4.f);
  set.data.resize(vertices * set.floats_per_vertex());
  for (float& x : set.data) x = u(rng);
  return set;
}

void expect_same(const TransferSet& a, const TransferSet& b) {
  EXPECT_EQ(a.kind, b.kind);
  EXPECT_EQ(a.order, b.order);
  EXPECT_EQ(a.channels, b.channels);
  EXPECT_EQ(a.vertex_count, b.vertex_count);
  EXPECT_EQ(a.samples, b.samples);
  EXPECT_EQ(a.bounces, b.bounces);
  EXPECT_EQ(a.seed, b.seed);
  EXPECT_EQ(a.mesh_hash, b.mesh_hash);
  EXPECT_EQ(a.material.kind, b.material.kind);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(a.material.albedo[c], b.material.albedo[c]) << c;
  EXPECT_EQ(a.material.specular, b.material.specular);
  EXPECT_EQ(a.material.exponent, b.material.exponent);
  EXPECT_EQ(a.material.roughness, b.material.roughness);
  EXPECT_EQ(a.material.f0, b.material.f0);
  ASSERT_EQ(a.data.size(), b.data.size());
  // Bitwise, so that -0 and denormals count too.
  EXPECT_TRUE(
      test_support::same_bytes(a.data.data(), b.data.data(), a.data.size() * sizeof(float)));
}

// Runs `read` and returns the TransferFileError's message, failing if it names neither the
// file nor `expected`.
template <class Read>
std::string error_of(const fs::path& p, Read read, const std::string& expected) {
  return test_support::error_of<prt::TransferFileError>(p, read, expected);
}

std::string read_error(const fs::path& p, const std::string& expected) {
  return error_of(
      p, [](const fs::path& q) { prt::read_transfer(q); }, expected);
}

// --- Round trips ---------------------------------------------------------------------------

TEST(TransferFile, KindNames) {
  EXPECT_STREQ(prt::kTransferKindNames.name(TransferKind::kDiffuse), "diffuse");
  EXPECT_STREQ(prt::kTransferKindNames.name(TransferKind::kGlossy), "glossy");
}

TEST(TransferFile, RoundTripIsExact) {
  struct Case {
    TransferKind kind;
    int order, channels;
    prt::MaterialKind material;
  };
  const Case cases[] = {
      {TransferKind::kDiffuse, 1, 1, prt::MaterialKind::kLambert},
      {TransferKind::kDiffuse, 6, 3, prt::MaterialKind::kLambert},
      {TransferKind::kGlossy, 4, 1, prt::MaterialKind::kPhong},
      {TransferKind::kGlossy, 5, 3, prt::MaterialKind::kCookTorrance},
      {TransferKind::kGlossy, 10, 1, prt::MaterialKind::kPhong},
  };
  std::uint32_t seed = 1;
  for (const Case& c : cases) {
    TransferSet set = make_set(c.kind, c.order, c.channels, 37, c.material, seed++);
    // Values a text or rounding path would lose.
    set.data[0] = -0.f;
    set.data[1] = std::numeric_limits<float>::denorm_min();
    set.data[2] = 1e12f;  // the largest magnitude a transfer file holds
    set.data.back() = -1e12f;
    const fs::path p = scratch("round_trip_" + std::to_string(seed) + ".prtx");
    prt::write_transfer(p, set);
    EXPECT_EQ(fs::file_size(p), kPayloadOffset + 4 * set.data.size());
    SCOPED_TRACE(p.string());
    expect_same(prt::read_transfer(p), set);
  }
}

TEST(TransferFile, TwoWritesAreBitIdentical) {
  const TransferSet set = make_set(TransferKind::kGlossy, 3, 3, 50, prt::MaterialKind::kPhong, 9);
  const fs::path a = scratch("same_a.prtx"), b = scratch("same_b.prtx");
  prt::write_transfer(a, set);
  prt::write_transfer(b, set);
  const std::string bytes_a = slurp(a);
  EXPECT_EQ(bytes_a.size(), kPayloadOffset + 4 * set.data.size());
  EXPECT_EQ(bytes_a, slurp(b));
}

// A bake with bounces finishes vertices in a spatial order and places their rows: in any
// order and any run lengths, the file equals one written in vertex order, checksum included.
TEST(TransferFile, PlacedRowsEqualAppendedRows) {
  const TransferSet set = make_set(TransferKind::kGlossy, 3, 3, 101, prt::MaterialKind::kPhong, 4);
  const fs::path appended = scratch("appended.prtx"), placed = scratch("placed.prtx");
  prt::write_transfer(appended, set);
  std::vector<std::uint64_t> starts;  // runs of 1-4 vertices, placed in a shuffled order
  for (std::uint64_t v = 0; v < set.vertex_count; v += 1 + v % 4) starts.push_back(v);
  std::shuffle(starts.begin(), starts.end(), std::mt19937(3));
  const std::size_t per_vertex = set.floats_per_vertex();
  prt::TransferFileWriter writer(placed, set);
  for (const std::uint64_t v : starts) {
    const std::uint64_t count = std::min<std::uint64_t>(1 + v % 4, set.vertex_count - v);
    writer.place(v, set.data.data() + v * per_vertex, count);
  }
  writer.commit();
  EXPECT_EQ(slurp(placed), slurp(appended));
  expect_same(prt::read_transfer(placed), set);
}

TEST(TransferFile, PlacingRefusesStrayRowsAndAMissingRowLeavesNoFile) {
  const TransferSet set =
      make_set(TransferKind::kDiffuse, 2, 1, 10, prt::MaterialKind::kLambert, 5);
  const std::size_t per_vertex = set.floats_per_vertex();
  const fs::path p = scratch("placed_refused.prtx");
  fs::remove(p);
  {
    prt::TransferFileWriter writer(p, set);
    EXPECT_THROW(writer.place(9, set.data.data(), 2), std::invalid_argument);  // past the mesh
    std::vector<float> bad(set.data.begin(), set.data.begin() + per_vertex);
    bad[1] = std::numeric_limits<float>::quiet_NaN();
    try {
      writer.place(3, bad.data(), 1);
      ADD_FAILURE() << "a NaN was placed";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("vertex 3"), std::string::npos) << e.what();
    }
    for (std::uint64_t v = 0; v < 9; ++v) writer.place(v, set.data.data() + v * per_vertex, 1);
    EXPECT_THROW(writer.append(set.data.data(), per_vertex), std::logic_error);
    EXPECT_THROW(writer.commit(), std::invalid_argument);  // vertex 9 is missing
  }
  EXPECT_FALSE(fs::exists(p));
  prt::TransferFileWriter appending(p, set);
  appending.append(set.data.data(), per_vertex);
  EXPECT_THROW(appending.place(1, set.data.data() + per_vertex, 1), std::logic_error);
}

// Ranks of a bake with bounces each own a range of a spatial order, not of the index order:
// each places its rows wherever they belong in the shared partial file.
TEST(TransferFile, SlicesPlacedFromAnotherOrderCommitToTheFile) {
  const TransferSet set = make_set(TransferKind::kGlossy, 2, 1, 57, prt::MaterialKind::kPhong, 6);
  const fs::path expected = scratch("slices_expected.prtx"), out = scratch("slices_placed.prtx");
  prt::write_transfer(expected, set);
  fs::remove(out);
  std::vector<std::uint64_t> order(set.vertex_count);
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), std::mt19937(8));
  const std::size_t per_vertex = set.floats_per_vertex();
  const std::uint64_t split = 20;  // rank 0 owns order[0, 20), rank 1 order[20, 57)
  prt::TransferSliceWriter rank0(out, set, 0, split), rank1(out, set, split, set.vertex_count);
  for (std::uint64_t i = set.vertex_count; i-- > 0;) {
    prt::TransferSliceWriter& w = i < split ? rank0 : rank1;
    w.place(order[i], set.data.data() + order[i] * per_vertex, 1);
  }
  EXPECT_THROW(rank0.place(order[0], set.data.data(), 1), std::invalid_argument);  // overrun
  EXPECT_THROW(rank0.append(set.data.data(), 0), std::logic_error);
  rank0.close();
  rank1.close();
  prt::commit_transfer_slices(out, set);
  EXPECT_EQ(slurp(out), slurp(expected));

  prt::TransferSliceWriter stray(scratch("slices_stray.prtx"), set, 0, 2);
  EXPECT_THROW(stray.place(56, set.data.data(), 2), std::invalid_argument);  // past the mesh
  stray.append(set.data.data(), per_vertex);
  EXPECT_THROW(stray.place(1, set.data.data() + per_vertex, 1), std::logic_error);
}

TEST(TransferFile, HeaderOnlyReadSkipsPayload) {
  // 1500 vertices x 36 x 36 floats: 7.8 MB, enough that reading it would be noticeable.
  const TransferSet set =
      make_set(TransferKind::kGlossy, 6, 1, 1500, prt::MaterialKind::kCookTorrance, 4);
  const fs::path p = scratch("header_only.prtx");
  prt::write_transfer(p, set);
  const TransferSet header = prt::read_transfer_header(p);
  EXPECT_TRUE(header.data.empty());
  TransferSet expected = set;
  expected.data.clear();
  expect_same(header, expected);

  // The header read still checks the file size, but not the payload.
  patch<std::uint8_t>(p, kPayloadOffset + 12345, 0xff);
  EXPECT_NO_THROW(prt::read_transfer_header(p));
  fs::resize_file(p, fs::file_size(p) - 4);
  error_of(
      p, [](const fs::path& q) { prt::read_transfer_header(q); }, "truncated: expected");
}

TEST(TransferFile, MappedRowsReadAsTheyWereWritten) {
  const TransferSet set = make_set(TransferKind::kGlossy, 3, 3, 50, prt::MaterialKind::kPhong, 12);
  const fs::path p = scratch("mapped_rows.prtx");
  prt::write_transfer(p, set);
  const prt::MappedTransfer mapped(p);
  const std::size_t row = set.floats_per_vertex();
  // Runs (3 4 5, 48 49) read as one pread each, single rows, a repeat and the last row.
  const std::vector<std::uint32_t> rows = {3, 4, 5, 0, 48, 49, 17, 17, 2};
  std::vector<float> out(rows.size() * row, -1.f);
  mapped.read_rows(rows.data(), rows.size(), out.data());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    SCOPED_TRACE(i);
    EXPECT_TRUE(std::equal(out.begin() + std::ptrdiff_t(i * row),
                           out.begin() + std::ptrdiff_t((i + 1) * row),
                           set.data.begin() + std::ptrdiff_t(rows[i] * row)));
  }
  const std::uint32_t past = 50;
  EXPECT_THROW(mapped.read_rows(&past, 1, out.data()), common::IoError);
}

// --- The documented layout, read the way docs/FORMATS.md's NumPy snippet reads it ----------

TEST(TransferFile, DocumentedOffsetsAndIndexFormula) {
  const TransferSet set =
      make_set(TransferKind::kGlossy, 3, 3, 11, prt::MaterialKind::kCookTorrance, 21);
  const fs::path p = scratch("documented.prtx");
  prt::write_transfer(p, set);
  const std::string bytes = slurp(p);

  EXPECT_EQ(bytes.substr(0, 8), "PRTRXFER");
  EXPECT_EQ(peek<std::uint32_t>(bytes, kOffVersion), 2u);
  EXPECT_EQ(peek<std::uint32_t>(bytes, kOffHeaderBytes), 128u);
  EXPECT_EQ(peek<std::uint32_t>(bytes, kOffKind), 1u);
  EXPECT_EQ(peek<std::uint32_t>(bytes, kOffOrder), 3u);
  EXPECT_EQ(peek<std::uint32_t>(bytes, kOffChannels), 3u);
  EXPECT_EQ(peek<std::uint32_t>(bytes, kOffSamples), std::uint32_t(set.samples));
  EXPECT_EQ(peek<std::uint32_t>(bytes, kOffBounces), std::uint32_t(set.bounces));
  EXPECT_EQ(peek<std::uint32_t>(bytes, kOffMaterialKind), 2u);
  EXPECT_EQ(peek<std::uint64_t>(bytes, kOffVertexCount), 11u);
  EXPECT_EQ(peek<std::uint64_t>(bytes, kOffSeed), set.seed);
  EXPECT_EQ(peek<std::uint64_t>(bytes, kOffMeshHash), set.mesh_hash);
  for (int c = 0; c < 3; ++c)
    EXPECT_EQ(peek<float>(bytes, kOffAlbedo + 4 * c), set.material.albedo[c]);
  EXPECT_EQ(peek<float>(bytes, kOffSpecular), set.material.specular);
  EXPECT_EQ(peek<float>(bytes, kOffExponent), set.material.exponent);
  EXPECT_EQ(peek<float>(bytes, kOffRoughness), set.material.roughness);
  EXPECT_EQ(peek<float>(bytes, kOffF0), set.material.f0);
  EXPECT_EQ(peek<std::uint64_t>(bytes, kOffPayloadFloats), set.data.size());
  EXPECT_EQ(peek<std::uint64_t>(bytes, kOffPayloadChecksum),
            common::fnv1a(bytes.data() + kPayloadOffset, bytes.size() - kPayloadOffset));
  EXPECT_EQ(peek<std::uint64_t>(bytes, kOffHeaderChecksum),
            common::fnv1a(bytes.data(), kOffHeaderChecksum));
  EXPECT_EQ(peek<std::uint32_t>(bytes, 92), std::uint32_t(set.view_fit));           // view_fit
  EXPECT_EQ(peek<std::uint32_t>(bytes, 112), std::uint32_t(set.material.masking));  // masking
  for (std::size_t i = 116; i < 120; ++i) EXPECT_EQ(bytes[i], 0) << "reserved byte " << i;

  // index ((p * C + c) * rows + i) * cols + j, rows = n = order^2, cols = n for glossy.
  const std::size_t C = 3, n = 9, cols = n;
  const auto at = [&](std::size_t vertex, std::size_t c, std::size_t i, std::size_t j) {
    return peek<float>(bytes, kPayloadOffset + 4 * (((vertex * C + c) * n + i) * cols + j));
  };
  // The first float of vertex 1, channel 0 sits right after vertex 0's C * n * n floats.
  EXPECT_EQ(at(1, 0, 0, 0), peek<float>(bytes, kPayloadOffset + 4 * C * n * n));
  EXPECT_EQ(at(1, 0, 0, 0), set.transfer(1, 0)(0, 0));
  EXPECT_EQ(at(7, 2, 4, 6), set.transfer(7, 2)(4, 6));
  EXPECT_EQ(at(10, 1, 8, 0), set.transfer(10, 1)(8, 0));
}

// --- Damage: each kind is its own message, naming the file --------------------------------

TEST(TransferFile, EachCorruptionHasItsOwnMessage) {
  const TransferSet set = make_set(TransferKind::kGlossy, 2, 3, 5, prt::MaterialKind::kPhong, 3);
  const std::size_t payload_bytes = 4 * set.data.size();
  test_support::DamageMessages messages;
  const auto fresh = [&](const std::string& name) {
    const fs::path p = scratch("damaged_" + name + ".prtx");
    prt::write_transfer(p, set);
    return p;
  };
  const auto check = [&](const std::string& name, const fs::path& p, const std::string& expected) {
    messages.record(name, read_error(p, expected));
  };

  {
    const fs::path p = fresh("header_cut");
    fs::resize_file(p, 100);
    check("truncated header", p, "truncated header");
  }
  {
    const fs::path p = fresh("payload_cut");
    fs::resize_file(p, kPayloadOffset + payload_bytes - 6);
    check("truncated payload", p,
          "truncated: expected " + std::to_string(kPayloadOffset + payload_bytes) +
              " bytes, found " + std::to_string(kPayloadOffset + payload_bytes - 6));
  }
  {
    const fs::path p = fresh("trailing");
    std::ofstream(p, std::ios::binary | std::ios::app) << "garbage";
    check("trailing bytes", p, "trailing bytes");
  }
  {
    const fs::path p = fresh("magic");
    patch<char>(p, 0, 'X');
    check("wrong magic", p, "not a prtr transfer file");
  }
  {
    const fs::path p = fresh("version3");
    patch<std::uint32_t>(p, kOffVersion, 3);
    reseal_header(p);
    check("version 3", p, "written by a newer prtr version (file format version 3");
  }
  {
    // Version 1 held the thesis's hemisphere projection: refused, never re-read as version 2.
    const fs::path p = fresh("version1");
    patch<std::uint32_t>(p, kOffVersion, 1);
    reseal_header(p);
    check("version 1", p, "written by an older prtr version (file format version 1");
  }
  {
    const fs::path p = fresh("view_fit");
    patch<std::uint32_t>(p, 92, 7);
    reseal_header(p);
    check("view fit", p, "view fit 7 out of range");
  }
  {
    const fs::path p = fresh("version0");
    patch<std::uint32_t>(p, kOffVersion, 0);
    reseal_header(p);
    check("version 0", p, "written by an older prtr version (file format version 0");
  }
  {
    const fs::path p = fresh("header_bytes");
    patch<std::uint32_t>(p, kOffHeaderBytes, 256);
    reseal_header(p);
    check("header bytes", p, "header size 256 bytes");
  }
  {
    const fs::path p = fresh("kind7");
    patch<std::uint32_t>(p, kOffKind, 7);
    reseal_header(p);
    check("kind 7", p, "transfer kind 7 out of range");
  }
  {
    const fs::path p = fresh("order0");
    patch<std::uint32_t>(p, kOffOrder, 0);
    reseal_header(p);
    check("order 0", p, "SH order 0 out of range");
  }
  {
    const fs::path p = fresh("order11");
    patch<std::uint32_t>(p, kOffOrder, 11);
    reseal_header(p);
    check("order 11", p, "SH order 11 out of range");
  }
  {
    const fs::path p = fresh("channels2");
    patch<std::uint32_t>(p, kOffChannels, 2);
    reseal_header(p);
    check("channels 2", p, "channel count 2 out of range");
  }
  {
    const fs::path p = fresh("samples0");
    patch<std::uint32_t>(p, kOffSamples, 0);
    reseal_header(p);
    check("samples 0", p, "sample count 0 out of range");
  }
  {
    const fs::path p = fresh("bounces17");
    patch<std::uint32_t>(p, kOffBounces, 17);
    reseal_header(p);
    check("bounces 17", p, "bounce count 17 out of range");
  }
  {
    const fs::path p = fresh("material3");
    patch<std::uint32_t>(p, kOffMaterialKind, 3);
    reseal_header(p);
    check("material 3", p, "material kind 3 out of range");
  }
  {
    const fs::path p = fresh("albedo");
    patch<float>(p, kOffAlbedo + 4, 1.5f);
    reseal_header(p);
    check("albedo", p, "material albedo[1] 1.5 out of range");
  }
  {
    const fs::path p = fresh("exponent_nan");
    patch<float>(p, kOffExponent, std::numeric_limits<float>::quiet_NaN());
    reseal_header(p);
    check("exponent NaN", p, "material exponent nan out of range");
  }
  {
    const fs::path p = fresh("huge_vertex_count");
    patch<std::uint64_t>(p, kOffVertexCount, (std::uint64_t(1) << 40) + 1);
    reseal_header(p);
    check("vertex count", p, "vertex count 1099511627777 out of range");
  }
  {
    const fs::path p = fresh("payload_floats");
    patch<std::uint64_t>(p, kOffPayloadFloats, set.data.size() + 1);
    reseal_header(p);
    check("payload floats", p,
          "payload size mismatch: the header says " + std::to_string(set.data.size() + 1));
  }
  {
    // A consistent header for 2^40 vertices: no overflow, just a file far too small.
    const fs::path p = fresh("giant");
    const std::uint64_t v = std::uint64_t(1) << 40;
    patch<std::uint64_t>(p, kOffVertexCount, v);
    patch<std::uint64_t>(p, kOffPayloadFloats, v * set.floats_per_vertex());
    reseal_header(p);
    check("giant", p,
          "truncated: expected " + std::to_string(128 + 4 * v * set.floats_per_vertex()));
  }
  {
    const fs::path p = fresh("header_flip");
    patch<std::uint8_t>(p, kOffMeshHash + 3, 0x5a);
    check("header checksum", p, "header damaged");
  }
  {
    const fs::path p = fresh("payload_flip");
    const std::string bytes = slurp(p);
    patch<std::uint8_t>(p, kPayloadOffset + 17, std::uint8_t(bytes[kPayloadOffset + 17] ^ 0x10));
    check("payload checksum", p, "payload damaged");
  }
  // Both checksums recomputed after a payload patch, so that only the value checks can object.
  const auto reseal_payload = [&](const fs::path& p) {
    const std::string bytes = slurp(p);
    patch<std::uint64_t>(p, kOffPayloadChecksum,
                         common::fnv1a(bytes.data() + kPayloadOffset, payload_bytes));
    reseal_header(p);
  };
  {
    // A NaN with both checksums recomputed: only the finite check can catch it. Float 22 of a
    // 3-channel order-2 glossy set (48 floats per vertex, 16 per channel) is vertex 0,
    // channel 1, entry (1, 2).
    const fs::path p = fresh("nan");
    patch<float>(p, kPayloadOffset + 4 * 22, std::numeric_limits<float>::quiet_NaN());
    reseal_payload(p);
    check("nan", p, "non-finite value nan at vertex 0, channel 1, entry (1, 2)");
  }
  {
    const fs::path p = fresh("inf");
    patch<float>(p, kPayloadOffset + 4 * (48 * 3 + 5), std::numeric_limits<float>::infinity());
    reseal_payload(p);
    check("inf", p, "non-finite value inf at vertex 3, channel 0, entry (1, 1)");
  }
  {
    const fs::path p = fresh("huge");
    patch<float>(p, kPayloadOffset + 4 * 7, -3e38f);
    reseal_payload(p);
    check("huge", p, "value beyond +-1e12 -3");
  }
  {
    const fs::path p = scratch("no_such_file.prtx");
    fs::remove(p);
    check("missing", p, "no such transfer file");
  }
  {
    const fs::path p = scratch("a_directory.prtx");
    fs::create_directories(p);
    check("directory", p, "is a directory");
  }

  messages.expect_distinct(28);
}

// --- Writing ---------------------------------------------------------------------------------

TEST(TransferFile, MissingDirectoryThrowsAndLeavesNothing) {
  const TransferSet set = make_set(TransferKind::kDiffuse, 3, 1, 4, prt::MaterialKind::kLambert, 5);
  const fs::path dir = scratch("no_such_dir");
  fs::remove_all(dir);
  const fs::path p = dir / "out.prtx";
  try {
    prt::write_transfer(p, set);
    FAIL() << "expected common::IoError";
  } catch (const common::IoError& e) {
    EXPECT_NE(std::string(e.what()).find(p.string()), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir));
}

TEST(TransferFile, WriterRefusesInconsistentSetsAndKeepsOldFile) {
  const fs::path p = scratch("refused.prtx");
  const TransferSet good =
      make_set(TransferKind::kDiffuse, 2, 1, 3, prt::MaterialKind::kLambert, 6);
  prt::write_transfer(p, good);
  const std::string before = slurp(p);

  TransferSet short_data = good;
  short_data.data.pop_back();
  TransferSet nan = good;
  nan.data[5] = std::numeric_limits<float>::quiet_NaN();
  TransferSet order = good;
  order.order = 11;
  TransferSet negative = good;
  negative.bounces = -1;
  for (const TransferSet* bad : {&short_data, &nan, &order, &negative}) {
    try {
      prt::write_transfer(p, *bad);
      ADD_FAILURE() << "expected std::invalid_argument";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(p.string()), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(slurp(p), before);
}

TEST(TransferFile, FailedWriteKeepsOldFileAndNoTemporary) {
  const fs::path dir = scratch("failed_write");
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path p = dir / "bake.prtx";
  prt::write_transfer(p, make_set(TransferKind::kDiffuse, 2, 1, 3, prt::MaterialKind::kLambert, 7));
  const std::string before = slurp(p);

  // 64 KiB limit, 500 KB file.
  const TransferSet big = make_set(TransferKind::kGlossy, 4, 1, 500, prt::MaterialKind::kPhong, 8);
  {
    test_support::FileSizeLimit limit(64 * 1024);
    if (!limit.ok()) GTEST_SKIP() << "cannot lower RLIMIT_FSIZE here";
    try {
      prt::write_transfer(p, big);
      ADD_FAILURE() << "expected common::IoError";
    } catch (const common::IoError& e) {
      EXPECT_NE(std::string(e.what()).find(p.string()), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(slurp(p), before);
  int files = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    ++files;
    EXPECT_EQ(e.path(), p) << "left behind";
  }
  EXPECT_EQ(files, 1);
}

}  // namespace
