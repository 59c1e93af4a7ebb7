// The .slfc file (pipeline/slf_file.h). Everything after the header is one checksummed
// block, built in memory and written in one call: a bunny's file is tens of megabytes.
#include "pipeline/slf_file.h"

#include "common/atomic_file.h"
#include "common/binary_file.h"
#include "common/hash.h"

#include <cmath>
#include <cstring>
#include <vector>

namespace pipeline {
namespace {

constexpr common::VersionedFormat kSlfcFormat{"compressed surface light field file",
                                              ".slfc file written by prtr slf",
                                              "create it with prtr slf",
                                              "make it again with prtr slf",
                                              {'P', 'R', 'T', 'R', 'S', 'L', 'F', 'C'},
                                              kSlfcFileVersion,
                                              1};

// Bytes 16-47, 56-91 and 112 hold the bake's settings as the .slf does (prt::put_slf_settings).
constexpr std::size_t kSlfcOffRows = 48, kSlfcOffClusters = 92, kSlfcOffComponents = 96,
                      kSlfcOffMeshPath = 100, kSlfcOffProbeName = 102,
                      kSlfcOffPayloadChecksum = 104;
constexpr std::size_t kSettingsBytes = 48;

std::size_t padded(std::size_t bytes) {
  return (bytes + 7) / 8 * 8;
}

// Sizes of the blocks after the header, from the header's fields; false when they overflow.
struct Sizes {
  std::uint64_t rows = 0, dimension = 0, clusters = 0, components = 0;
  std::uint64_t names = 0, ids = 0, weights = 0, means = 0, bases = 0, total = 0;
};
bool sizes_of(std::uint64_t rows, std::uint64_t dimension, std::uint64_t clusters,
              std::uint64_t components, std::size_t path_bytes, std::size_t name_bytes, Sizes* s) {
  s->rows = rows;
  s->dimension = dimension;
  s->clusters = clusters;
  s->components = components;
  s->names = padded(path_bytes) + padded(name_bytes);
  std::uint64_t a = 0, b = 0;
  if (__builtin_mul_overflow(rows, components, &a) || __builtin_mul_overflow(a, 4, &s->weights))
    return false;
  if (__builtin_mul_overflow(clusters, dimension, &a) || __builtin_mul_overflow(a, 4, &s->means))
    return false;
  if (__builtin_mul_overflow(clusters, components, &a) ||
      __builtin_mul_overflow(a, dimension, &b) || __builtin_mul_overflow(b, 4, &s->bases))
    return false;
  s->ids = padded(rows * 4);
  const std::uint64_t parts[] = {s->names, kSettingsBytes, s->ids, s->weights, s->means, s->bases};
  s->total = 0;
  for (std::uint64_t p : parts)
    if (__builtin_add_overflow(s->total, p, &s->total)) return false;
  return true;
}

void append(std::vector<unsigned char>& out, const void* data, std::size_t bytes) {
  const auto* p = static_cast<const unsigned char*>(data);
  out.insert(out.end(), p, p + bytes);
}
void pad(std::vector<unsigned char>& out) {
  out.resize(padded(out.size()), 0);
}

std::string slfc_problem(const CompressedSlf& slf) {
  const cpca::CompressedSet& set = slf.set;
  const prt::SlfShape& b = slf.bake;
  if (slf.mesh_path.size() > kMaxSlfcNameBytes || slf.probe_name.size() > kMaxSlfcNameBytes)
    return "the mesh path or probe name is longer than " + std::to_string(kMaxSlfcNameBytes) +
           " bytes";
  if (b.atlas_width < 4 || b.atlas_width > 8192 || b.atlas_height < 4 || b.atlas_height > 8192)
    return "atlas size " + std::to_string(b.atlas_width) + " x " + std::to_string(b.atlas_height) +
           " is outside [4, 8192]";
  if (std::string problem = prt::slf_layout_problem(b); !problem.empty()) return problem;
  try {
    b.grid.validate();
    b.material.validate();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  if (b.spp < 1 || b.bounces < 0 || b.bounces > 16 || b.light_samples < 0 ||
      b.light_samples > prt::kMaxLightSamples)
    return "spp, bounces or light samples out of range";
  if (b.rows > std::uint64_t(b.atlas_width) * std::uint64_t(b.atlas_height) ||
      b.first_row > b.rows || b.row_count > b.rows - b.first_row || b.row_count == 0)
    return "rows [" + std::to_string(b.first_row) + ", " +
           std::to_string(b.first_row + b.row_count) + ") do not fit the " +
           std::to_string(b.rows) + " rows of the atlas";
  if (set.order != 1 || set.channels != 3 ||
      std::uint64_t(set.columns) != std::uint64_t(b.grid.directions()))
    return "the compressed set's layout (order " + std::to_string(set.order) + ", " +
           std::to_string(set.channels) + " channels, " + std::to_string(set.columns) +
           " columns) is not order 1, 3 channels, Z W columns";
  if (set.vertex_count != b.row_count)
    return "the compressed set has " + std::to_string(set.vertex_count) + " rows, not " +
           std::to_string(b.row_count);
  if (set.cluster_count < 1 || std::uint64_t(set.cluster_count) > set.vertex_count)
    return "cluster count " + std::to_string(set.cluster_count) + " is outside 1..rows";
  if (set.component_count < 0 || std::size_t(set.component_count) > set.dimension())
    return "component count " + std::to_string(set.component_count) + " is outside 0..dimension";
  const std::size_t v = set.vertex_count, k = std::size_t(set.cluster_count),
                    n = std::size_t(set.component_count), d = set.dimension();
  if (set.cluster_of.size() != v || set.weights.size() != v * n || set.means.size() != k * d ||
      set.bases.size() != k * n * d)
    return "an array of the compressed set has the wrong length";
  for (std::size_t p = 0; p < v; ++p)
    if (set.cluster_of[p] >= k)
      return "row " + std::to_string(p) + " has cluster id " + std::to_string(set.cluster_of[p]) +
             " >= " + std::to_string(k);
  for (const std::vector<float>* a : {&set.weights, &set.means, &set.bases})
    for (float x : *a)
      if (!std::isfinite(x)) return "a weight, mean or basis value is NaN or infinite";
  return {};
}

}  // namespace

void write_slfc(const std::filesystem::path& path, const CompressedSlf& slf) {
  if (const std::string problem = slfc_problem(slf); !problem.empty()) {
    throw std::invalid_argument(path.string() +
                                ": cannot write the compressed surface light field: " + problem);
  }
  const cpca::CompressedSet& set = slf.set;
  const prt::SlfShape& b = slf.bake;
  std::vector<unsigned char> body;
  append(body, slf.mesh_path.data(), slf.mesh_path.size());
  pad(body);
  append(body, slf.probe_name.data(), slf.probe_name.size());
  pad(body);
  const std::uint64_t settings64[4] = {b.seed, set.seed, b.first_row, b.row_count};
  const std::uint32_t settings32[4] = {std::uint32_t(set.method), std::uint32_t(set.solver),
                                       std::uint32_t(std::max(0, set.iterations)), 0};
  append(body, settings64, sizeof settings64);
  append(body, settings32, sizeof settings32);
  append(body, set.cluster_of.data(), set.cluster_of.size() * 4);
  pad(body);
  append(body, set.weights.data(), set.weights.size() * 4);
  append(body, set.means.data(), set.means.size() * 4);
  append(body, set.bases.data(), set.bases.size() * 4);

  common::VersionedHeader h = common::begin_header(kSlfcFormat);
  prt::put_slf_settings(h, b);
  common::put_field(h, kSlfcOffRows, b.rows);
  common::put_field(h, kSlfcOffClusters, std::uint32_t(set.cluster_count));
  common::put_field(h, kSlfcOffComponents, std::uint32_t(set.component_count));
  common::put_field(h, kSlfcOffMeshPath, std::uint16_t(slf.mesh_path.size()));
  common::put_field(h, kSlfcOffProbeName, std::uint16_t(slf.probe_name.size()));
  common::put_field(h, kSlfcOffPayloadChecksum, common::fnv1a(body.data(), body.size()));
  common::seal_header(h);
  common::AtomicFile file(path);
  file.write(h.data(), h.size());
  file.write(body.data(), body.size());
  file.commit();
}

CompressedSlf read_slfc(const std::filesystem::path& path) {
  const auto fail = [&](const std::string& problem) {
    return SlfcFileError(path.string() + ": " + problem);
  };
  const std::string damaged = std::string("; the file is damaged: ") + kSlfcFormat.remedy;
  common::OpenedVersionedFile f = common::open_versioned(path, kSlfcFormat);
  if (!f.problem.empty()) throw fail(f.problem);
  const common::VersionedHeader& h = f.header;
  CompressedSlf slf;
  prt::SlfShape& b = slf.bake;
  prt::get_slf_settings(h, b);
  b.rows = common::get_field<std::uint64_t>(h, kSlfcOffRows);
  const std::uint64_t clusters = common::get_field<std::uint32_t>(h, kSlfcOffClusters);
  const std::uint64_t components = common::get_field<std::uint32_t>(h, kSlfcOffComponents);
  const std::size_t path_bytes = common::get_field<std::uint16_t>(h, kSlfcOffMeshPath);
  const std::size_t name_bytes = common::get_field<std::uint16_t>(h, kSlfcOffProbeName);
  if (b.atlas_width < 4 || b.atlas_width > 8192 || b.atlas_height < 4 || b.atlas_height > 8192 ||
      b.grid.azimuth < 1 || b.grid.azimuth > 4096 || b.grid.elevation < 1 ||
      b.grid.elevation > 4096 ||
      b.rows > std::uint64_t(b.atlas_width) * std::uint64_t(b.atlas_height) || clusters < 1 ||
      clusters > b.rows || path_bytes > kMaxSlfcNameBytes || name_bytes > kMaxSlfcNameBytes)
    throw fail("header fields out of range" + damaged);
  if (const std::string problem = prt::slf_layout_problem(b); !problem.empty())
    throw fail("header field " + problem + damaged);
  if (const std::string problem = common::header_checksum_problem(h, kSlfcFormat); !problem.empty())
    throw fail(problem);
  // The rows stored are in the body; bound the size by the whole matrix first, then read the
  // names and settings and check the exact size.
  const std::uint64_t dimension = 3 * std::uint64_t(b.grid.directions());
  if (components > dimension) throw fail("header fields out of range" + damaged);
  Sizes most;
  if (!sizes_of(b.rows, dimension, clusters, components, path_bytes, name_bytes, &most))
    throw fail("sizes in the header overflow" + damaged);
  const std::uint64_t prefix = padded(path_bytes) + padded(name_bytes) + kSettingsBytes;
  if (f.size < common::kVersionedHeaderBytes + prefix)
    throw fail(
        common::file_size_problem(common::kVersionedHeaderBytes + prefix, f.size, kSlfcFormat));
  std::vector<unsigned char> head(prefix);
  f.stream.read(reinterpret_cast<char*>(head.data()), std::streamsize(prefix));
  if (std::uint64_t(f.stream.gcount()) != prefix) throw fail("could not read the file");
  slf.mesh_path.assign(reinterpret_cast<const char*>(head.data()), path_bytes);
  slf.probe_name.assign(reinterpret_cast<const char*>(head.data() + padded(path_bytes)),
                        name_bytes);
  std::uint64_t settings64[4];
  std::uint32_t settings32[4];
  std::memcpy(settings64, head.data() + padded(path_bytes) + padded(name_bytes), sizeof settings64);
  std::memcpy(settings32, head.data() + padded(path_bytes) + padded(name_bytes) + 32,
              sizeof settings32);
  b.seed = settings64[0];
  b.first_row = settings64[2];
  b.row_count = settings64[3];
  if (b.first_row > b.rows || b.row_count > b.rows - b.first_row || b.row_count < clusters)
    throw fail("rows stored out of range" + damaged);
  Sizes s;
  sizes_of(b.row_count, dimension, clusters, components, path_bytes, name_bytes, &s);
  if (const std::string problem =
          common::file_size_problem(common::kVersionedHeaderBytes + s.total, f.size, kSlfcFormat);
      !problem.empty())
    throw fail(problem);
  std::vector<unsigned char> rest(s.total - prefix);
  f.stream.read(reinterpret_cast<char*>(rest.data()), std::streamsize(rest.size()));
  if (std::uint64_t(f.stream.gcount()) != rest.size()) throw fail("could not read the file");
  std::uint64_t hash = common::fnv1a(head.data(), head.size());
  hash = common::fnv1a(rest.data(), rest.size(), hash);
  if (const std::string problem = common::checksum_problem(
          "payload", hash, common::get_field<std::uint64_t>(h, kSlfcOffPayloadChecksum),
          kSlfcFormat);
      !problem.empty())
    throw fail(problem);
  cpca::CompressedSet& set = slf.set;
  set.order = 1;
  set.channels = 3;
  set.columns = b.grid.directions();
  set.mesh_hash = b.mesh_hash;
  set.mesh_path = slf.mesh_path;
  set.vertex_count = b.row_count;
  set.cluster_count = int(clusters);
  set.component_count = int(components);
  set.seed = settings64[1];
  set.method = cpca::ClusterMethod(settings32[0]);
  set.solver = cpca::PcaSolver(settings32[1]);
  set.iterations = int(std::min<std::uint32_t>(settings32[2], 1u << 30));
  const unsigned char* at = rest.data();
  set.cluster_of.resize(s.rows);
  std::memcpy(set.cluster_of.data(), at, s.rows * 4);
  at += s.ids;
  set.weights.resize(s.weights / 4);
  std::memcpy(set.weights.data(), at, s.weights);
  at += s.weights;
  set.means.resize(s.means / 4);
  std::memcpy(set.means.data(), at, s.means);
  at += s.means;
  set.bases.resize(s.bases / 4);
  std::memcpy(set.bases.data(), at, s.bases);
  if (const std::string problem = slfc_problem(slf); !problem.empty())
    throw fail(problem + damaged);
  return slf;
}

}  // namespace pipeline
