// The .prtx transfer file, version 2. docs/FORMATS.md ("Transfer file (.prtx), version 2")
// is the byte-by-byte description; the offsets below must stay in step with its table.
//
// The header is serialised field by field at fixed offsets (never by writing a struct, whose
// padding and layout are the compiler's), little-endian, with its own checksum so that a
// damaged seed or mesh hash is caught too, not only a damaged payload. The payload is
// TransferSet::data as is: written and read in one call each, never copied or parsed per
// element, because a bunny bake is ~180 MB.
#include "prt/transfer_file.h"

#include "prt/sh.h"

#include "common/atomic_file.h"
#include "common/binary_file.h"
#include "common/hash.h"
#include "common/mapped_file.h"
#include "common/output_path.h"

#include <algorithm>
#include <array>
#include <bit>
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

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace prt {
namespace {

namespace fs = std::filesystem;

// The payload is written straight from memory, so the host must already be little-endian.
static_assert(std::endian::native == std::endian::little,
              "the .prtx format is little-endian; add byte swapping for big-endian hosts");
static_assert(sizeof(float) == 4 && std::numeric_limits<float>::is_iec559);
static_assert(sizeof(std::size_t) >= 8, "payloads may exceed 4 GiB");

// --- Layout (docs/FORMATS.md) ----------------------------------------------------------------
constexpr std::size_t kHeaderBytes = 128;
constexpr std::array<char, 8> kMagic = {'P', 'R', 'T', 'R', 'X', 'F', 'E', 'R'};

constexpr std::size_t kOffMagic = 0;              // char[8]
constexpr std::size_t kOffVersion = 8;            // u32
constexpr std::size_t kOffHeaderBytes = 12;       // u32
constexpr std::size_t kOffKind = 16;              // u32
constexpr std::size_t kOffOrder = 20;             // u32
constexpr std::size_t kOffChannels = 24;          // u32
constexpr std::size_t kOffSamples = 28;           // u32
constexpr std::size_t kOffBounces = 32;           // u32
constexpr std::size_t kOffMaterialKind = 36;      // u32
constexpr std::size_t kOffVertexCount = 40;       // u64
constexpr std::size_t kOffSeed = 48;              // u64
constexpr std::size_t kOffMeshHash = 56;          // u64
constexpr std::size_t kOffAlbedo = 64;            // f32[3]
constexpr std::size_t kOffSpecular = 76;          // f32
constexpr std::size_t kOffExponent = 80;          // f32
constexpr std::size_t kOffRoughness = 84;         // f32
constexpr std::size_t kOffF0 = 88;                // f32
constexpr std::size_t kOffViewFit = 92;           // u32 (version 2; was reserved)
constexpr std::size_t kOffPayloadFloats = 96;     // u64
constexpr std::size_t kOffPayloadChecksum = 104;  // u64
constexpr std::size_t kOffMasking = 112;          // u32 (version 2; was reserved)
constexpr std::size_t kOffReserved = 116;         // u32, zero
constexpr std::size_t kOffHeaderChecksum = 120;   // u64, FNV-1a of bytes [0, 120)
static_assert(kOffHeaderChecksum + 8 == kHeaderBytes);

// --- Ranges ------------------------------------------------------------------------------------
constexpr std::int64_t kMaxBounces = 16;
constexpr std::uint64_t kMaxVertexCount = std::uint64_t(1) << 40;
constexpr float kMaxExponent = 10000.f;

constexpr const char* kRebake = "bake it again with prtr bake";

using Header = common::VersionedHeader;
static_assert(kHeaderBytes == common::kVersionedHeaderBytes);
constexpr common::VersionedFormat kFormat{"transfer file",
                                          ".prtx file written by prtr bake",
                                          "create it with prtr bake",
                                          kRebake,
                                          kMagic,
                                          kTransferFileVersion};

std::string num(float v) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.9g", static_cast<double>(v));
  return buf;
}

// The header values that have a range, widened so that the writer (ints) and the reader
// (u32/u64 from disk) share one check.
struct Fields {
  std::int64_t kind = 0, order = 0, channels = 0, samples = 0, bounces = 0, material_kind = 0;
  std::int64_t view_fit = 0, masking = 0;
  std::uint64_t vertex_count = 0;
  float albedo[3] = {0, 0, 0};
  float specular = 0, exponent = 0, roughness = 0, f0 = 0;
};

Fields fields_of(const TransferSet& set) {
  Fields f;
  f.kind = static_cast<std::int64_t>(set.kind);
  f.order = set.order;
  f.channels = set.channels;
  f.samples = set.samples;
  f.bounces = set.bounces;
  f.material_kind = static_cast<std::int64_t>(set.material.kind);
  f.view_fit = static_cast<std::int64_t>(set.view_fit);
  f.masking = static_cast<std::int64_t>(set.material.masking);
  f.vertex_count = set.vertex_count;
  for (int c = 0; c < 3; ++c) f.albedo[c] = set.material.albedo[c];
  f.specular = set.material.specular;
  f.exponent = set.material.exponent;
  f.roughness = set.material.roughness;
  f.f0 = set.material.f0;
  return f;
}

// lo <= v <= hi, false for NaN.
bool within(float v, float lo, float hi) {
  return v >= lo && v <= hi;
}

// The first field out of range, as "<field> <value> <what is allowed>", or "" when all are
// in range. Material parameters are checked for the model that uses them (Material's own
// ranges); unused ones only need to be finite.
std::string field_problem(const Fields& f) {
  const auto out = [](const char* name, std::int64_t v, const char* allowed) {
    return std::string(name) + " " + std::to_string(v) + " out of range (" + allowed + ")";
  };
  if (f.kind < 0 || f.kind > 1) return out("transfer kind", f.kind, "0 diffuse, 1 glossy");
  if (f.order < 1 || f.order > kMaxOrder) return out("SH order", f.order, "1 to 10");
  if (f.channels != 1 && f.channels != 3) return out("channel count", f.channels, "1 or 3");
  if (f.samples < 1 || f.samples > std::numeric_limits<int>::max())
    return out("sample count", f.samples, "at least 1");
  if (f.bounces < 0 || f.bounces > kMaxBounces) return out("bounce count", f.bounces, "0 to 16");
  if (f.material_kind < 0 || f.material_kind > 2)
    return out("material kind", f.material_kind, "0 lambert, 1 phong, 2 cook-torrance");
  // Only fits the renderers evaluate are baked; the benchmarks' HSH never reaches a file.
  if (f.view_fit < 0 || f.view_fit > 2)
    return out("view fit", f.view_fit, "0 hemisphere, 1 even, 2 least-squares");
  if (f.masking < 0 || f.masking > 1) return out("masking", f.masking, "0 smith, 1 v-groove");
  if (f.vertex_count > kMaxVertexCount) {
    return "vertex count " + std::to_string(f.vertex_count) + " out of range (at most 2^40)";
  }

  const auto bad = [](const std::string& name, float v, const char* allowed) {
    return "material " + name + " " + num(v) + " out of range (" + allowed + ")";
  };
  const auto kind = static_cast<MaterialKind>(f.material_kind);
  const bool specular_lobe = kind != MaterialKind::kLambert;
  for (int c = 0; c < 3; ++c) {
    if (!within(f.albedo[c], 0.f, 1.f))
      return bad("albedo[" + std::to_string(c) + "]", f.albedo[c], "0 to 1");
  }
  if (!std::isfinite(f.specular) || (specular_lobe && !within(f.specular, 0.f, 1.f)))
    return bad("specular", f.specular, "0 to 1");
  if (!std::isfinite(f.exponent) ||
      (kind == MaterialKind::kPhong && !within(f.exponent, 0.f, kMaxExponent)))
    return bad("exponent", f.exponent, "0 to 10000");
  if (!std::isfinite(f.roughness) ||
      (kind == MaterialKind::kCookTorrance && !(f.roughness > 0.f && f.roughness <= 1.f)))
    return bad("roughness", f.roughness, "above 0, at most 1");
  if (!std::isfinite(f.f0) || (kind == MaterialKind::kCookTorrance && !within(f.f0, 0.f, 1.f)))
    return bad("f0", f.f0, "0 to 1");
  return {};
}

// vertex_count x floats_per_vertex, or false on overflow.
bool payload_floats_of(std::uint64_t vertex_count, std::uint64_t floats_per_vertex,
                       std::uint64_t* out) {
  return !__builtin_mul_overflow(vertex_count, floats_per_vertex, out);
}

// "vertex V, channel C, entry (i, j)" of a flat payload index.
std::string locate(const TransferSet& set, std::size_t index) {
  const std::size_t per_vertex = set.floats_per_vertex();
  const std::size_t per_channel = set.floats_per_channel();
  const std::size_t cols = static_cast<std::size_t>(set.columns());
  const std::size_t in_channel = index % per_vertex % per_channel;
  return "vertex " + std::to_string(index / per_vertex) + ", channel " +
         std::to_string(index % per_vertex / per_channel) + ", entry (" +
         std::to_string(in_channel / cols) + ", " + std::to_string(in_channel % cols) + ")";
}

// Index of the first NaN or Inf, or data.size() when all are finite.
std::size_t first_non_finite(const std::vector<float>& data) {
  for (std::size_t i = 0; i < data.size(); ++i)
    if (!std::isfinite(data[i])) return i;
  return data.size();
}

// Transfer values are O(1) (radiance per unit radiance); one past kMaxTransferValue can only
// be damage, and it would overflow single precision once multiplied by the lighting.
constexpr float kMaxTransferValue = 1e12f;

std::size_t first_out_of_range(const std::vector<float>& data) {
  for (std::size_t i = 0; i < data.size(); ++i)
    if (!(std::abs(data[i]) <= kMaxTransferValue)) return i;
  return data.size();
}

// Every field but the payload: the writer must not copy a whole bake.
TransferSet without_payload(const TransferSet& set) {
  TransferSet s;
  s.kind = set.kind;
  s.order = set.order;
  s.channels = set.channels;
  s.vertex_count = set.vertex_count;
  s.samples = set.samples;
  s.bounces = set.bounces;
  s.seed = set.seed;
  s.material = set.material;
  s.view_fit = set.view_fit;
  s.mesh_hash = set.mesh_hash;
  s.payload_checksum = set.payload_checksum;
  return s;
}

Header encode_header(const TransferSet& set, std::uint64_t payload_floats,
                     std::uint64_t payload_checksum) {
  Header h = common::begin_header(kFormat);  // zero: padding and reserved fields
  common::put_field<std::uint32_t>(h, kOffKind, static_cast<std::uint32_t>(set.kind));
  common::put_field<std::uint32_t>(h, kOffOrder, static_cast<std::uint32_t>(set.order));
  common::put_field<std::uint32_t>(h, kOffChannels, static_cast<std::uint32_t>(set.channels));
  common::put_field<std::uint32_t>(h, kOffSamples, static_cast<std::uint32_t>(set.samples));
  common::put_field<std::uint32_t>(h, kOffBounces, static_cast<std::uint32_t>(set.bounces));
  common::put_field<std::uint32_t>(h, kOffMaterialKind,
                                   static_cast<std::uint32_t>(set.material.kind));
  common::put_field<std::uint64_t>(h, kOffVertexCount, set.vertex_count);
  common::put_field<std::uint64_t>(h, kOffSeed, set.seed);
  common::put_field<std::uint64_t>(h, kOffMeshHash, set.mesh_hash);
  for (int c = 0; c < 3; ++c)
    common::put_field<float>(h, kOffAlbedo + 4 * c, set.material.albedo[c]);
  common::put_field<float>(h, kOffSpecular, set.material.specular);
  common::put_field<float>(h, kOffExponent, set.material.exponent);
  common::put_field<float>(h, kOffRoughness, set.material.roughness);
  common::put_field<float>(h, kOffF0, set.material.f0);
  common::put_field<std::uint32_t>(h, kOffViewFit, static_cast<std::uint32_t>(set.view_fit));
  common::put_field<std::uint32_t>(h, kOffMasking,
                                   static_cast<std::uint32_t>(set.material.masking));
  common::put_field<std::uint64_t>(h, kOffPayloadFloats, payload_floats);
  common::put_field<std::uint64_t>(h, kOffPayloadChecksum, payload_checksum);
  common::seal_header(h);
  return h;
}

// The header's fields, checked: ranges, reserved bytes, payload size, header checksum.
// `payload_floats` gets the payload size it records.
TransferSet decode(const Header& h, const std::string& name, std::uint64_t* payload_floats_out) {
  const auto fail = [&](const std::string& problem) {
    return TransferFileError(name + ": " + problem);
  };
  Fields f;
  f.kind = common::get_field<std::uint32_t>(h, kOffKind);
  f.order = common::get_field<std::uint32_t>(h, kOffOrder);
  f.channels = common::get_field<std::uint32_t>(h, kOffChannels);
  f.samples = common::get_field<std::uint32_t>(h, kOffSamples);
  f.bounces = common::get_field<std::uint32_t>(h, kOffBounces);
  f.material_kind = common::get_field<std::uint32_t>(h, kOffMaterialKind);
  f.vertex_count = common::get_field<std::uint64_t>(h, kOffVertexCount);
  for (int c = 0; c < 3; ++c) f.albedo[c] = common::get_field<float>(h, kOffAlbedo + 4 * c);
  f.specular = common::get_field<float>(h, kOffSpecular);
  f.exponent = common::get_field<float>(h, kOffExponent);
  f.roughness = common::get_field<float>(h, kOffRoughness);
  f.f0 = common::get_field<float>(h, kOffF0);
  f.view_fit = common::get_field<std::uint32_t>(h, kOffViewFit);
  f.masking = common::get_field<std::uint32_t>(h, kOffMasking);
  if (const std::string problem = field_problem(f); !problem.empty()) {
    throw fail(problem + " in the header; the file is damaged: " + kRebake);
  }
  if (common::get_field<std::uint32_t>(h, kOffReserved) != 0) {
    throw fail("reserved header bytes are not zero; the file is damaged: " + std::string(kRebake));
  }

  TransferSet set;
  set.kind = static_cast<TransferKind>(f.kind);
  set.order = static_cast<int>(f.order);
  set.channels = static_cast<int>(f.channels);
  set.samples = static_cast<int>(f.samples);
  set.bounces = static_cast<int>(f.bounces);
  set.vertex_count = f.vertex_count;
  set.seed = common::get_field<std::uint64_t>(h, kOffSeed);
  set.mesh_hash = common::get_field<std::uint64_t>(h, kOffMeshHash);
  set.payload_checksum = common::get_field<std::uint64_t>(h, kOffPayloadChecksum);
  set.material.kind = static_cast<MaterialKind>(f.material_kind);
  set.material.albedo = Eigen::Vector3f(f.albedo[0], f.albedo[1], f.albedo[2]);
  set.material.specular = f.specular;
  set.material.exponent = f.exponent;
  set.material.roughness = f.roughness;
  set.material.f0 = f.f0;
  set.material.masking = static_cast<Masking>(f.masking);
  set.view_fit = static_cast<ViewFit>(f.view_fit);

  // Sizes: vertex_count <= 2^40 and floats_per_vertex <= 3 * 100 * 100, so the product fits
  // in 64 bits; the checks stay in case either limit grows.
  const std::uint64_t payload_floats = common::get_field<std::uint64_t>(h, kOffPayloadFloats);
  std::uint64_t expected_floats = 0;
  if (!payload_floats_of(set.vertex_count, set.floats_per_vertex(), &expected_floats) ||
      payload_floats != expected_floats) {
    throw fail("payload size mismatch: the header says " + std::to_string(payload_floats) +
               " floats, but " + std::to_string(set.vertex_count) + " vertices x " +
               std::to_string(set.floats_per_vertex()) + " floats per vertex is " +
               std::to_string(expected_floats) + "; the header is damaged: " + kRebake);
  }
  if (const std::string problem = common::header_checksum_problem(h, kFormat); !problem.empty())
    throw fail(problem);
  *payload_floats_out = payload_floats;
  return set;
}

TransferSet read(const fs::path& path, bool with_payload) {
  const std::string name = path.string();
  const auto fail = [&](const std::string& problem) {
    return TransferFileError(name + ": " + problem);
  };
  common::OpenedVersionedFile opened = common::open_versioned(path, kFormat);
  if (!opened.problem.empty()) throw fail(opened.problem);
  std::ifstream& in = opened.stream;
  const std::uintmax_t size = opened.size;
  const Header& h = opened.header;
  std::uint64_t payload_floats = 0;
  TransferSet set = decode(h, name, &payload_floats);
  std::uint64_t expected_size = 0;
  if (__builtin_mul_overflow(payload_floats, std::uint64_t(4), &expected_size) ||
      __builtin_add_overflow(expected_size, std::uint64_t(kHeaderBytes), &expected_size)) {
    throw fail("payload of " + std::to_string(payload_floats) +
               " floats is too large for any file; the header is damaged: " + kRebake);
  }
  const auto size_problem = [&](std::uintmax_t found) {
    return fail(common::file_size_problem(expected_size, found, kFormat));
  };
  if (size != expected_size) throw size_problem(size);
  if (!with_payload) return set;

  // One read straight into the vector; the file size was checked above, so a short read
  // means the file changed under us.
  set.data.resize(payload_floats);
  const std::size_t payload_bytes = payload_floats * sizeof(float);
  in.read(reinterpret_cast<char*>(set.data.data()), std::streamsize(payload_bytes));
  if (std::size_t(in.gcount()) != payload_bytes) {
    throw size_problem(kHeaderBytes + std::size_t(in.gcount()));
  }
  if (const std::string problem = common::checksum_problem(
          "payload", common::fnv1a(set.data.data(), payload_bytes),
          common::get_field<std::uint64_t>(h, kOffPayloadChecksum), kFormat);
      !problem.empty())
    throw fail(problem);
  if (const std::size_t i = first_out_of_range(set.data); i != set.data.size()) {
    throw fail((std::isfinite(set.data[i]) ? "value beyond +-1e12 " : "non-finite value ") +
               num(set.data[i]) + " at " + locate(set, i) + "; the file is damaged: " + kRebake);
  }
  return set;
}

}  // namespace

void write_transfer(const fs::path& path, const TransferSet& set) {
  const auto refuse = [&](const std::string& problem) {
    return std::invalid_argument(path.string() + ": cannot write the transfer set: " + problem);
  };
  // Refuse what read_transfer would refuse before touching the directory.
  if (const std::string problem = field_problem(fields_of(set)); !problem.empty())
    throw refuse(problem);
  std::uint64_t expected_floats = 0;
  if (!payload_floats_of(set.vertex_count, set.floats_per_vertex(), &expected_floats) ||
      set.data.size() != expected_floats) {
    throw refuse("data holds " + std::to_string(set.data.size()) + " floats, but " +
                 std::to_string(set.vertex_count) + " vertices x " +
                 std::to_string(set.floats_per_vertex()) + " floats per vertex is " +
                 std::to_string(expected_floats));
  }
  if (const std::size_t i = first_non_finite(set.data); i != set.data.size())
    throw refuse("non-finite value " + num(set.data[i]) + " at " + locate(set, i));
  TransferFileWriter writer(path, set);
  writer.append(set.data.data(), set.data.size());
  writer.commit();
}

// The header goes first as zeros and is written over once the payload checksum is known:
// the payload streams through in vertex order, and FNV-1a continues across blocks, so the
// file is the same bytes write_transfer produces from the whole set at once.
TransferFileWriter::TransferFileWriter(const fs::path& path, const TransferSet& shape)
    : shape_(without_payload(shape)), hash_(common::kFnvOffset) {
  const auto refuse = [&](const std::string& problem) {
    return std::invalid_argument(path.string() + ": cannot write the transfer set: " + problem);
  };
  // Refuse what read_transfer would refuse, so that every written file can be read back.
  if (const std::string problem = field_problem(fields_of(shape_)); !problem.empty())
    throw refuse(problem);
  if (!payload_floats_of(shape_.vertex_count, shape_.floats_per_vertex(), &expected_)) {
    throw refuse("vertex count " + std::to_string(shape_.vertex_count) + " is too large");
  }
  file_ = std::make_unique<common::AtomicFile>(path);
  const Header zeros{};
  file_->write(zeros.data(), zeros.size());
}

TransferFileWriter::~TransferFileWriter() {
  if (place_fd_ >= 0) ::close(place_fd_);
}

namespace {
// The FNV-1a checksum of the `floats` payload floats after the header of the file open at fd.
std::uint64_t payload_checksum(int fd, std::uint64_t floats, const fs::path& name) {
  const std::uint64_t bytes = kHeaderBytes + floats * sizeof(float);
  std::uint64_t hash = common::kFnvOffset;
  std::vector<unsigned char> buffer(std::size_t(16) << 20);
  for (std::uint64_t at = kHeaderBytes; at < bytes; at += buffer.size()) {
    const std::size_t n = std::size_t(std::min<std::uint64_t>(buffer.size(), bytes - at));
    common::read_exact(fd, buffer.data(), n, at, name.c_str());
    hash = common::fnv1a(buffer.data(), n, hash);
  }
  return hash;
}

// Throws std::invalid_argument naming `file` and the value's place at the first non-finite
// value of data, the payload's floats [first, first + floats).
void check_finite(const fs::path& file, const TransferSet& shape, const float* data,
                  std::size_t floats, std::uint64_t first) {
  for (std::size_t i = 0; i < floats; ++i) {
    if (!(std::abs(data[i]) <= kMaxTransferValue)) {
      throw std::invalid_argument(
          file.string() + ": cannot write the transfer set: " +
          (std::isfinite(data[i]) ? "value beyond +-1e12 " : "non-finite value ") + num(data[i]) +
          " at " + locate(shape, first + i));
    }
  }
}

// Writes rows [first_vertex, first_vertex + count) of `shape` at their place in the transfer
// file open at fd (named `file` in messages, `written` when the write fails), after checking
// that they are in the mesh, fit the `remaining` floats of the writer and are finite. Returns
// the floats written.
std::uint64_t place_rows(int fd, const fs::path& file, const fs::path& written,
                         const TransferSet& shape, std::uint64_t first_vertex, const float* data,
                         std::uint64_t count, std::uint64_t remaining) {
  if (first_vertex > shape.vertex_count || count > shape.vertex_count - first_vertex) {
    throw std::invalid_argument(file.string() + ": cannot write the transfer set: vertices [" +
                                std::to_string(first_vertex) + ", " +
                                std::to_string(first_vertex + count) + ") are outside the mesh");
  }
  const std::uint64_t floats = count * shape.floats_per_vertex();
  if (floats > remaining) {
    throw std::invalid_argument(
        file.string() + ": cannot write the transfer set: " + std::to_string(floats) +
        " floats placed with " + std::to_string(remaining) + " left to write");
  }
  const std::uint64_t first = first_vertex * shape.floats_per_vertex();
  check_finite(file, shape, data, floats, first);
  common::write_exact(fd, data, floats * sizeof(float), kHeaderBytes + first * sizeof(float),
                      written.c_str());
  return floats;
}
}  // namespace

void TransferFileWriter::append(const float* data, std::size_t floats) {
  if (place_fd_ >= 0)
    throw std::logic_error("TransferFileWriter: append() after place() on the same file");
  if (floats > expected_ - written_) {
    throw std::invalid_argument(file_->target().string() +
                                ": cannot write the transfer set: more than " +
                                std::to_string(expected_) + " floats appended");
  }
  check_finite(file_->target(), shape_, data, floats, written_);
  hash_ = common::fnv1a(data, floats * sizeof(float), hash_);
  if (floats > 0) file_->write(data, floats * sizeof(float));
  written_ += floats;
}

void TransferFileWriter::place(std::uint64_t first_vertex, const float* data, std::uint64_t count) {
  if (written_ > 0 && place_fd_ < 0)
    throw std::logic_error("TransferFileWriter: place() after append() on the same file");
  if (place_fd_ < 0) {
    place_fd_ = ::open(file_->temporary().c_str(), O_RDWR | O_CLOEXEC);
    if (place_fd_ < 0)
      throw common::IoError(file_->target().string() + ": cannot reopen the temporary file (" +
                            std::strerror(errno) + ")");
  }
  written_ += place_rows(place_fd_, file_->target(), file_->temporary(), shape_, first_vertex, data,
                         count, expected_ - written_);
}

void TransferFileWriter::commit() {
  if (written_ != expected_) {
    throw std::invalid_argument(file_->target().string() +
                                ": cannot write the transfer set: " + std::to_string(written_) +
                                " of " + std::to_string(expected_) + " floats were written");
  }
  if (place_fd_ >= 0) hash_ = payload_checksum(place_fd_, expected_, file_->temporary());
  const Header h = encode_header(shape_, expected_, hash_);
  const int fd = ::open(file_->temporary().c_str(), O_WRONLY | O_CLOEXEC);
  if (fd < 0 || ::pwrite(fd, h.data(), h.size(), 0) != static_cast<ssize_t>(h.size())) {
    const std::string why = std::strerror(errno);
    if (fd >= 0) ::close(fd);
    throw common::IoError(file_->target().string() + ": cannot write the header (" + why + ")");
  }
  ::close(fd);
  file_->commit();  // its fsync covers the header written through the second descriptor
}

fs::path partial_transfer_path(const fs::path& path) {
  return path.parent_path() / (path.filename().string() + ".partial");
}

TransferSliceWriter::TransferSliceWriter(const fs::path& path, const TransferSet& shape,
                                         std::uint64_t first_vertex, std::uint64_t end_vertex)
    : shape_(without_payload(shape)), partial_(partial_transfer_path(path)) {
  const auto refuse = [&](const std::string& problem) {
    return std::invalid_argument(path.string() + ": cannot write the transfer set: " + problem);
  };
  if (const std::string problem = field_problem(fields_of(shape_)); !problem.empty())
    throw refuse(problem);
  std::uint64_t total = 0;
  if (!payload_floats_of(shape_.vertex_count, shape_.floats_per_vertex(), &total))
    throw refuse("vertex count " + std::to_string(shape_.vertex_count) + " is too large");
  if (first_vertex > end_vertex || end_vertex > shape_.vertex_count)
    throw refuse("vertex range [" + std::to_string(first_vertex) + ", " +
                 std::to_string(end_vertex) + ") is outside the mesh");
  first_float_ = first_vertex * shape_.floats_per_vertex();
  expected_ = (end_vertex - first_vertex) * shape_.floats_per_vertex();
  // No O_TRUNC: the other writers may have written their slices already.
  fd_ = ::open(partial_.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0) {
    throw common::IoError(partial_.string() + ": cannot open the shared partial file (" +
                          std::strerror(errno) + ")");
  }
}

TransferSliceWriter::~TransferSliceWriter() {
  if (fd_ >= 0) ::close(fd_);
}

void TransferSliceWriter::append(const float* data, std::size_t floats) {
  if (placed_) throw std::logic_error("TransferSliceWriter: append() after place()");
  if (floats > expected_ - written_) {
    throw std::invalid_argument(partial_.string() + ": cannot write the transfer set: more than " +
                                std::to_string(expected_) + " floats appended to the slice");
  }
  check_finite(partial_, shape_, data, floats, first_float_ + written_);
  common::write_exact(fd_, data, floats * sizeof(float),
                      kHeaderBytes + (first_float_ + written_) * sizeof(float), partial_.c_str());
  written_ += floats;
}

void TransferSliceWriter::place(std::uint64_t first_vertex, const float* data,
                                std::uint64_t count) {
  if (written_ > 0 && !placed_)
    throw std::logic_error("TransferSliceWriter: place() after append()");
  written_ +=
      place_rows(fd_, partial_, partial_, shape_, first_vertex, data, count, expected_ - written_);
  placed_ = true;
}

void TransferSliceWriter::close() {
  if (written_ != expected_) {
    throw std::invalid_argument(
        partial_.string() + ": cannot write the transfer set: " + std::to_string(written_) +
        " of the slice's " + std::to_string(expected_) + " floats were appended");
  }
  const int fd = fd_;
  fd_ = -1;
  if (::fsync(fd) != 0 || ::close(fd) != 0)
    throw common::IoError(partial_.string() + ": cannot flush (" + std::strerror(errno) + ")");
}

void commit_transfer_slices(const fs::path& path, const TransferSet& shape) {
  const fs::path partial = partial_transfer_path(path);
  std::uint64_t floats = 0;
  if (!payload_floats_of(shape.vertex_count, shape.floats_per_vertex(), &floats))
    throw std::invalid_argument(path.string() + ": too many vertices");
  const int fd = ::open(partial.c_str(), O_RDWR | O_CLOEXEC);
  if (fd < 0) {
    throw TransferFileError(partial.string() + ": cannot open the partial file (" +
                            std::strerror(errno) + "); did every process see this directory?");
  }
  try {
    const std::uint64_t bytes = kHeaderBytes + floats * sizeof(float);
    struct stat st {};
    if (::fstat(fd, &st) != 0 || std::uint64_t(st.st_size) < bytes) {
      throw TransferFileError(partial.string() +
                              ": shorter than the payload; did every process "
                              "write its slice to the same directory?");
    }
    const Header h =
        encode_header(without_payload(shape), floats, payload_checksum(fd, floats, partial));
    if (::pwrite(fd, h.data(), h.size(), 0) != static_cast<ssize_t>(h.size()) ||
        ::ftruncate(fd, off_t(bytes)) != 0 || ::fsync(fd) != 0) {
      throw common::IoError(partial.string() + ": cannot write the header (" +
                            std::strerror(errno) + ")");
    }
  } catch (...) {
    ::close(fd);
    throw;
  }
  ::close(fd);
  common::check_output_target(path);
  if (::rename(partial.c_str(), path.c_str()) != 0) {
    throw common::IoError(path.string() + ": cannot replace the file (" + std::strerror(errno) +
                          ")");
  }
}

std::array<unsigned char, kTransferHeaderBytes> encode_transfer_header(
    const TransferSet& shape, std::uint64_t payload_checksum) {
  std::uint64_t floats = 0;
  if (const std::string problem = field_problem(fields_of(shape)); !problem.empty())
    throw std::invalid_argument("cannot encode the transfer header: " + problem);
  if (!payload_floats_of(shape.vertex_count, shape.floats_per_vertex(), &floats))
    throw std::invalid_argument("cannot encode the transfer header: too many vertices");
  return encode_header(shape, floats, payload_checksum);
}

TransferSet decode_transfer_header(const std::array<unsigned char, kTransferHeaderBytes>& header,
                                   const std::string& name) {
  if (std::memcmp(header.data(), kMagic.data(), kMagic.size()) != 0 ||
      common::get_field<std::uint32_t>(header, 8) != kTransferFileVersion) {
    throw TransferFileError(name + ": the transfer header inside is not a version " +
                            std::to_string(kTransferFileVersion) + " .prtx header; " + kRebake);
  }
  std::uint64_t floats = 0;
  return decode(header, name, &floats);
}

TransferSet read_transfer(const fs::path& path) {
  return read(path, true);
}

TransferSet read_transfer_header(const fs::path& path) {
  return read(path, false);
}

}  // namespace prt
