// The .prtc compressed file, version 1. docs/FORMATS.md ("Compressed file (.prtc), version
// 1") is the byte-by-byte description; the offsets below must stay in step with its table.
//
// Same design as the .prtx transfer file (prt/src/transfer_file.cpp): the header is
// serialised field by field at fixed offsets, little-endian, with its own checksum; sizes are
// computed with overflow checks and compared with the file size before anything is
// allocated; the arrays are written and read in one call each. The mesh path follows the
// header because it has a variable length; it has its own checksum so that a header-only
// read (prtr info) can trust it without reading the payload.
#include "cpca/compressed_file.h"

#include "common/atomic_file.h"
#include "common/binary_file.h"
#include "common/hash.h"

#include <array>
#include <bit>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <string>
#include <system_error>
#include <type_traits>
#include <vector>

namespace cpca {
namespace {

namespace fs = std::filesystem;

static_assert(std::endian::native == std::endian::little,
              "the .prtc format is little-endian; add byte swapping for big-endian hosts");
static_assert(sizeof(float) == 4 && std::numeric_limits<float>::is_iec559);
static_assert(sizeof(double) == 8 && std::numeric_limits<double>::is_iec559);
static_assert(sizeof(std::size_t) >= 8, "payloads may exceed 4 GiB");

// --- Layout (docs/FORMATS.md) ----------------------------------------------------------------
constexpr std::size_t kHeaderBytes = 128;
constexpr std::array<char, 8> kMagic = {'P', 'R', 'T', 'R', 'C', 'M', 'P', 'R'};

constexpr std::size_t kOffMagic = 0;               // char[8]
constexpr std::size_t kOffVersion = 8;             // u32
constexpr std::size_t kOffHeaderBytes = 12;        // u32
constexpr std::size_t kOffOrder = 16;              // u32
constexpr std::size_t kOffChannels = 20;           // u32
constexpr std::size_t kOffColumns = 24;            // u32
constexpr std::size_t kOffClusterCount = 28;       // u32
constexpr std::size_t kOffComponentCount = 32;     // u32
constexpr std::size_t kOffMethod = 36;             // u32
constexpr std::size_t kOffSolver = 40;             // u32
constexpr std::size_t kOffOverdraw = 44;           // u32, 0 or 1
constexpr std::size_t kOffIterations = 48;         // u32
constexpr std::size_t kOffMeshPathBytes = 52;      // u32
constexpr std::size_t kOffVertexCount = 56;        // u64
constexpr std::size_t kOffSeed = 64;               // u64
constexpr std::size_t kOffMeshHash = 72;           // u64
constexpr std::size_t kOffTransferHash = 80;       // u64
constexpr std::size_t kOffAlpha = 88;              // f64
constexpr std::size_t kOffPayloadBytes = 96;       // u64
constexpr std::size_t kOffPayloadChecksum = 104;   // u64
constexpr std::size_t kOffMeshPathChecksum = 112;  // u64
constexpr std::size_t kOffHeaderChecksum = 120;    // u64, FNV-1a of bytes [0, 120)
static_assert(kOffHeaderChecksum + 8 == kHeaderBytes);

// --- Ranges ------------------------------------------------------------------------------------
constexpr std::int64_t kMaxOrder = 10;
constexpr std::uint64_t kMaxVertexCount = std::uint64_t(1) << 40;

constexpr const char* kRecompress = "compress it again with prtr compress";

using Header = common::VersionedHeader;
static_assert(kHeaderBytes == common::kVersionedHeaderBytes);
constexpr common::VersionedFormat kFormat{"compressed file",
                                          ".prtc file written by prtr compress",
                                          "create it with prtr compress",
                                          kRecompress,
                                          kMagic,
                                          kCompressedFileVersion};

std::string num(double v) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

// The mesh path is padded with zeros so that the payload starts 8-byte aligned (for readers
// that map the file).
std::size_t padded(std::size_t bytes) {
  return (bytes + 7) / 8 * 8;
}

// Strict UTF-8 (no overlong forms, surrogates or code points above U+10FFFF) without NUL,
// so that the path prints and round-trips through any tool. The first bad byte's offset, or
// s.size() when the string is valid.
std::size_t first_bad_utf8(const std::string& s) {
  std::size_t i = 0;
  while (i < s.size()) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (c == 0) return i;
    std::size_t extra = 0;
    std::uint32_t cp = 0, min = 0;
    if (c < 0x80) {
      ++i;
      continue;
    } else if ((c & 0xe0) == 0xc0) {
      extra = 1, cp = c & 0x1f, min = 0x80;
    } else if ((c & 0xf0) == 0xe0) {
      extra = 2, cp = c & 0x0f, min = 0x800;
    } else if ((c & 0xf8) == 0xf0) {
      extra = 3, cp = c & 0x07, min = 0x10000;
    } else {
      return i;
    }
    if (extra >= s.size() - i) return i;  // cut short by the end of the string
    for (std::size_t k = 1; k <= extra; ++k) {
      const auto d = static_cast<unsigned char>(s[i + k]);
      if ((d & 0xc0) != 0x80) return i;
      cp = (cp << 6) | (d & 0x3f);
    }
    if (cp < min || cp > 0x10ffff || (cp >= 0xd800 && cp <= 0xdfff)) return i;
    i += extra + 1;
  }
  return s.size();
}

// The header values that have a range, widened so that the writer (ints) and the reader
// (u32/u64 from disk) share one check.
struct Fields {
  std::int64_t order = 0, channels = 0, columns = 0, clusters = 0, components = 0;
  std::int64_t method = 0, solver = 0, overdraw = 0, iterations = 0;
  std::uint64_t vertex_count = 0, mesh_path_bytes = 0;
  double alpha = 0.0;
};

Fields fields_of(const CompressedSet& set) {
  Fields f;
  f.order = set.order;
  f.channels = set.channels;
  f.columns = set.columns;
  f.clusters = set.cluster_count;
  f.components = set.component_count;
  f.method = static_cast<std::int64_t>(set.method);
  f.solver = static_cast<std::int64_t>(set.solver);
  f.overdraw = set.overdraw_reduction ? 1 : 0;
  f.iterations = set.iterations;
  f.vertex_count = set.vertex_count;
  f.mesh_path_bytes = set.mesh_path.size();
  f.alpha = set.alpha;
  return f;
}

// The first field out of range, as "<field> <value> out of range (<allowed>)", or "" when
// all are in range. Later checks may rely on earlier ones (columns on order, components on
// the dimension).
std::string field_problem(const Fields& f) {
  const auto out = [](const char* name, std::int64_t v, const std::string& allowed) {
    return std::string(name) + " " + std::to_string(v) + " out of range (" + allowed + ")";
  };
  if (f.order < 1 || f.order > kMaxOrder) return out("SH order", f.order, "1 to 10");
  if (f.channels != 1 && f.channels != 3) return out("channel count", f.channels, "1 or 3");
  const std::int64_t n = f.order * f.order;
  if (f.columns != 1 && f.columns != n) {
    return out(
        "column count", f.columns,
        "1 for diffuse, " + std::to_string(n) + " for glossy at order " + std::to_string(f.order));
  }
  if (f.vertex_count < 1 || f.vertex_count > kMaxVertexCount) {
    return "vertex count " + std::to_string(f.vertex_count) + " out of range (1 to 2^40)";
  }
  const std::int64_t max_clusters =
      std::min<std::int64_t>(std::int64_t(f.vertex_count), std::numeric_limits<int>::max());
  if (f.clusters < 1 || f.clusters > max_clusters) {
    return out("cluster count", f.clusters,
               "1 to the vertex count " + std::to_string(max_clusters));
  }
  const std::int64_t dimension = f.channels * n * f.columns;
  if (f.components < 0 || f.components > dimension) {
    return out("component count", f.components, "0 to the dimension " + std::to_string(dimension));
  }
  if (f.method < 0 || f.method > 5)
    return out("cluster method", f.method,
               "0 lbg, 1 iterative, 2 patch-first, 3 joint, 4 patch-joint");
  if (f.solver < 0 || f.solver > 1) return out("PCA solver", f.solver, "0 power, 1 eigen");
  if (f.overdraw < 0 || f.overdraw > 1) return out("overdraw flag", f.overdraw, "0 or 1");
  if (f.iterations < 0 || f.iterations > std::numeric_limits<int>::max())
    return out("iteration count", f.iterations, "0 to 2^31-1");
  if (!(std::isfinite(f.alpha) && f.alpha >= 0.0))
    return "geometry weight alpha " + num(f.alpha) + " out of range (finite, at least 0)";
  if (f.mesh_path_bytes > kMaxMeshPathBytes) {
    return "mesh path of " + std::to_string(f.mesh_path_bytes) + " bytes out of range (at most " +
           std::to_string(kMaxMeshPathBytes) + ")";
  }
  return {};
}

struct Sizes {
  std::uint64_t ids = 0, weights = 0, means = 0, bases = 0;  // element counts
  std::uint64_t payload_bytes = 0;
};

// Element counts of the four arrays and the payload's byte size, or false on overflow.
// Assumes field_problem() passed, so the dimension is at most 3 * 100 * 100.
bool sizes_of(const Fields& f, Sizes* s) {
  const auto dimension = std::uint64_t(f.channels * f.order * f.order * f.columns);
  const auto k = std::uint64_t(f.clusters), n = std::uint64_t(f.components);
  std::uint64_t total = 0;
  s->ids = f.vertex_count;
  return !__builtin_mul_overflow(f.vertex_count, n, &s->weights) &&
         !__builtin_mul_overflow(k, dimension, &s->means) &&
         !__builtin_mul_overflow(s->means, n, &s->bases) &&
         !__builtin_add_overflow(s->ids, s->weights, &total) &&
         !__builtin_add_overflow(total, s->means, &total) &&
         !__builtin_add_overflow(total, s->bases, &total) &&
         !__builtin_mul_overflow(total, std::uint64_t(4), &s->payload_bytes);
}

template <class T>
std::uint64_t hash_of(const std::vector<T>& v, std::uint64_t hash) {
  return common::fnv1a(v.data(), v.size() * sizeof(T), hash);
}

std::uint64_t payload_checksum_of(const CompressedSet& set) {
  std::uint64_t h = hash_of(set.cluster_of, common::kFnvOffset);
  h = hash_of(set.weights, h);
  h = hash_of(set.means, h);
  return hash_of(set.bases, h);
}

// The first problem among the arrays' values (ids below K, finite floats), as a phrase naming
// where it is, or "".
std::string value_problem(const CompressedSet& set) {
  const std::size_t k = std::size_t(set.cluster_count), n = std::size_t(set.component_count);
  const std::size_t d = set.dimension();
  for (std::size_t p = 0; p < set.cluster_of.size(); ++p) {
    if (set.cluster_of[p] >= k) {
      return "vertex " + std::to_string(p) + " has cluster id " +
             std::to_string(set.cluster_of[p]) + ", but there are only " + std::to_string(k) +
             " clusters";
    }
  }
  // Stored values are O(1) to O(100); past kMaxValue they can only be damage, and they would
  // overflow single precision once multiplied by the lighting (NaN pixels).
  constexpr float kMaxValue = 1e12f;
  const auto bad = [](float v) { return !(std::abs(v) <= kMaxValue); };
  const auto what = [](float v) {
    return std::string(std::isfinite(v) ? "huge (beyond +-1e12) " : "non-finite ");
  };
  for (std::size_t i = 0; i < set.weights.size(); ++i) {
    if (bad(set.weights[i])) {
      return what(set.weights[i]) + "weight " + num(set.weights[i]) + " at vertex " +
             std::to_string(i / n) + ", component " + std::to_string(i % n);
    }
  }
  for (std::size_t i = 0; i < set.means.size(); ++i) {
    if (bad(set.means[i])) {
      return what(set.means[i]) + "mean value " + num(set.means[i]) + " at cluster " +
             std::to_string(i / d) + ", entry " + std::to_string(i % d);
    }
  }
  for (std::size_t i = 0; i < set.bases.size(); ++i) {
    if (bad(set.bases[i])) {
      return what(set.bases[i]) + "basis value " + num(set.bases[i]) + " at cluster " +
             std::to_string(i / (n * d)) + ", component " + std::to_string(i / d % n) + ", entry " +
             std::to_string(i % d);
    }
  }
  return {};
}

Header encode_header(const CompressedSet& set, const Sizes& sizes) {
  Header h = common::begin_header(kFormat);
  common::put_field<std::uint32_t>(h, kOffOrder, std::uint32_t(set.order));
  common::put_field<std::uint32_t>(h, kOffChannels, std::uint32_t(set.channels));
  common::put_field<std::uint32_t>(h, kOffColumns, std::uint32_t(set.columns));
  common::put_field<std::uint32_t>(h, kOffClusterCount, std::uint32_t(set.cluster_count));
  common::put_field<std::uint32_t>(h, kOffComponentCount, std::uint32_t(set.component_count));
  common::put_field<std::uint32_t>(h, kOffMethod, static_cast<std::uint32_t>(set.method));
  common::put_field<std::uint32_t>(h, kOffSolver, static_cast<std::uint32_t>(set.solver));
  common::put_field<std::uint32_t>(h, kOffOverdraw, set.overdraw_reduction ? 1u : 0u);
  common::put_field<std::uint32_t>(h, kOffIterations, std::uint32_t(set.iterations));
  common::put_field<std::uint32_t>(h, kOffMeshPathBytes, std::uint32_t(set.mesh_path.size()));
  common::put_field<std::uint64_t>(h, kOffVertexCount, set.vertex_count);
  common::put_field<std::uint64_t>(h, kOffSeed, set.seed);
  common::put_field<std::uint64_t>(h, kOffMeshHash, set.mesh_hash);
  common::put_field<std::uint64_t>(h, kOffTransferHash, set.transfer_hash);
  common::put_field<double>(h, kOffAlpha, set.alpha);
  common::put_field<std::uint64_t>(h, kOffPayloadBytes, sizes.payload_bytes);
  common::put_field<std::uint64_t>(h, kOffPayloadChecksum, payload_checksum_of(set));
  common::put_field<std::uint64_t>(h, kOffMeshPathChecksum,
                                   common::fnv1a(set.mesh_path.data(), set.mesh_path.size()));
  common::seal_header(h);
  return h;
}

Fields decode_fields(const Header& h) {
  Fields f;
  f.order = common::get_field<std::uint32_t>(h, kOffOrder);
  f.channels = common::get_field<std::uint32_t>(h, kOffChannels);
  f.columns = common::get_field<std::uint32_t>(h, kOffColumns);
  f.clusters = common::get_field<std::uint32_t>(h, kOffClusterCount);
  f.components = common::get_field<std::uint32_t>(h, kOffComponentCount);
  f.method = common::get_field<std::uint32_t>(h, kOffMethod);
  f.solver = common::get_field<std::uint32_t>(h, kOffSolver);
  f.overdraw = common::get_field<std::uint32_t>(h, kOffOverdraw);
  f.iterations = common::get_field<std::uint32_t>(h, kOffIterations);
  f.mesh_path_bytes = common::get_field<std::uint32_t>(h, kOffMeshPathBytes);
  f.vertex_count = common::get_field<std::uint64_t>(h, kOffVertexCount);
  f.alpha = common::get_field<double>(h, kOffAlpha);
  return f;
}

// The set's header fields (checked fields `f`; the hashes straight from the header).
CompressedSet set_from(const Fields& f, const Header& h) {
  CompressedSet set;
  set.order = int(f.order);
  set.channels = int(f.channels);
  set.columns = int(f.columns);
  set.vertex_count = f.vertex_count;
  set.cluster_count = int(f.clusters);
  set.component_count = int(f.components);
  set.method = static_cast<ClusterMethod>(f.method);
  set.solver = static_cast<PcaSolver>(f.solver);
  set.overdraw_reduction = f.overdraw != 0;
  set.iterations = int(f.iterations);
  set.alpha = f.alpha;
  set.seed = common::get_field<std::uint64_t>(h, kOffSeed);
  set.mesh_hash = common::get_field<std::uint64_t>(h, kOffMeshHash);
  set.transfer_hash = common::get_field<std::uint64_t>(h, kOffTransferHash);
  return set;
}

// The mesh path block (path, then zero padding) against its checksum, or empty.
std::string mesh_path_problem(const std::string& block, const Fields& f, const Header& h) {
  const std::string path = block.substr(0, f.mesh_path_bytes);
  if (std::string problem = common::checksum_problem(
          "mesh path", common::fnv1a(path.data(), path.size()),
          common::get_field<std::uint64_t>(h, kOffMeshPathChecksum), kFormat);
      !problem.empty())
    return problem;
  if (const std::size_t i = first_bad_utf8(path); i != path.size())
    return "mesh path is not UTF-8 (byte " + std::to_string(i) +
           "); the file is damaged: " + kRecompress;
  if (block.find_first_not_of('\0', f.mesh_path_bytes) != std::string::npos)
    return "mesh path padding is not zero; the file is damaged: " + std::string(kRecompress);
  return {};
}

CompressedSet read(const fs::path& path, bool with_payload) {
  const std::string name = path.string();
  const auto fail = [&](const std::string& problem) {
    return CompressedFileError(name + ": " + problem);
  };

  common::OpenedVersionedFile opened = common::open_versioned(path, kFormat);
  if (!opened.problem.empty()) throw fail(opened.problem);
  std::ifstream& in = opened.stream;
  const std::uintmax_t size = opened.size;
  const Header& h = opened.header;

  const Fields f = decode_fields(h);
  if (const std::string problem = field_problem(f); !problem.empty()) {
    throw fail(problem + " in the header; the file is damaged: " + kRecompress);
  }

  Sizes sizes;
  const std::uint64_t payload_bytes = common::get_field<std::uint64_t>(h, kOffPayloadBytes);
  if (!sizes_of(f, &sizes) || payload_bytes != sizes.payload_bytes) {
    throw fail("payload size mismatch: the header says " + std::to_string(payload_bytes) +
               " bytes, but " + std::to_string(f.vertex_count) + " vertices, " +
               std::to_string(f.clusters) + " clusters and " + std::to_string(f.components) +
               " components need " + std::to_string(sizes.payload_bytes) +
               "; the header is damaged: " + kRecompress);
  }
  if (const std::string problem = common::header_checksum_problem(h, kFormat); !problem.empty())
    throw fail(problem);
  const std::size_t path_block = padded(f.mesh_path_bytes);
  std::uint64_t expected_size = 0;
  if (__builtin_add_overflow(payload_bytes, std::uint64_t(kHeaderBytes + path_block),
                             &expected_size)) {
    throw fail("payload of " + std::to_string(payload_bytes) +
               " bytes is too large for any file; the header is damaged: " + kRecompress);
  }
  const auto size_problem = [&](std::uintmax_t found) {
    return fail(common::file_size_problem(expected_size, found, kFormat));
  };
  if (size != expected_size) throw size_problem(size);

  CompressedSet set = set_from(f, h);

  // The file size was checked, so a short read below means the file changed under us.
  std::size_t offset = kHeaderBytes;
  const auto read_into = [&](void* dst, std::size_t bytes) {
    in.read(static_cast<char*>(dst), std::streamsize(bytes));
    offset += std::size_t(in.gcount());
    if (std::size_t(in.gcount()) != bytes) throw size_problem(offset);
  };
  std::string block(path_block, '\0');
  read_into(block.data(), path_block);
  set.mesh_path = block.substr(0, f.mesh_path_bytes);
  if (const std::string problem = mesh_path_problem(block, f, h); !problem.empty())
    throw fail(problem);
  if (!with_payload) return set;

  set.cluster_of.resize(sizes.ids);
  set.weights.resize(sizes.weights);
  set.means.resize(sizes.means);
  set.bases.resize(sizes.bases);
  read_into(set.cluster_of.data(), sizes.ids * 4);
  read_into(set.weights.data(), sizes.weights * 4);
  read_into(set.means.data(), sizes.means * 4);
  read_into(set.bases.data(), sizes.bases * 4);
  if (const std::string problem = common::checksum_problem(
          "payload", payload_checksum_of(set),
          common::get_field<std::uint64_t>(h, kOffPayloadChecksum), kFormat);
      !problem.empty())
    throw fail(problem);
  if (const std::string problem = value_problem(set); !problem.empty()) {
    throw fail(problem + "; the file is damaged: " + kRecompress);
  }
  return set;
}

}  // namespace

void write_compressed(const fs::path& path, const CompressedSet& set) {
  const auto refuse = [&](const std::string& problem) {
    return std::invalid_argument(path.string() + ": cannot write the compressed set: " + problem);
  };
  // Refuse what read_compressed would refuse, so that every written file can be read back.
  const Fields f = fields_of(set);
  if (const std::string problem = field_problem(f); !problem.empty()) throw refuse(problem);
  if (const std::size_t i = first_bad_utf8(set.mesh_path); i != set.mesh_path.size()) {
    throw refuse("mesh path \"" + common::printable(set.mesh_path.data(), set.mesh_path.size()) +
                 "\" is not UTF-8 without NUL (byte " + std::to_string(i) + ")");
  }
  try {
    validate(set);
  } catch (const std::invalid_argument& e) {
    throw refuse(e.what());
  }
  Sizes sizes;
  if (!sizes_of(f, &sizes)) throw refuse("the payload would exceed 2^64 bytes");

  const Header h = encode_header(set, sizes);
  const std::size_t pad = padded(set.mesh_path.size()) - set.mesh_path.size();
  const char zeros[8] = {};
  common::AtomicFile file(path);
  file.write(h.data(), h.size());
  file.write(set.mesh_path.data(), set.mesh_path.size());
  file.write(zeros, pad);
  file.write(set.cluster_of.data(), set.cluster_of.size() * 4);
  file.write(set.weights.data(), set.weights.size() * 4);
  file.write(set.means.data(), set.means.size() * 4);
  file.write(set.bases.data(), set.bases.size() * 4);
  file.commit();
}

CompressedSet read_compressed(const fs::path& path) {
  return read(path, true);
}

CompressedSet read_compressed_header(const fs::path& path) {
  return read(path, false);
}

}  // namespace cpca
