// Transfer shards and their merge; see prt/transfer_shard.h and docs/FORMATS.md.
#include "prt/transfer_shard.h"

#include "common/atomic_file.h"
#include "common/binary_file.h"
#include "common/hash.h"
#include "common/mapped_file.h"
#include "prt/transfer_file.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <sstream>
#include <stdexcept>
#include <string>

#include <fcntl.h>
#include <unistd.h>

namespace prt {
namespace {

namespace fs = std::filesystem;

constexpr std::size_t kOffIndex = 16;              // u32
constexpr std::size_t kOffCount = 20;              // u32
constexpr std::size_t kOffFirst = 24;              // u64
constexpr std::size_t kOffEnd = 32;                // u64
constexpr std::size_t kShardPayloadFloats = 40;    // u64
constexpr std::size_t kShardPayloadChecksum = 48;  // u64
constexpr std::size_t kPrefixBytes = common::kVersionedHeaderBytes + kTransferHeaderBytes;

constexpr common::VersionedFormat kShardFormat{"transfer shard",
                                               "shard written by prtr bake --shard",
                                               "create it with prtr bake --shard k/n",
                                               "bake that shard again with prtr bake --shard",
                                               {'P', 'R', 'T', 'R', 'S', 'H', 'R', 'D'},
                                               1};

struct Shard {
  fs::path path;
  ShardRange range;
  std::uint64_t floats = 0, checksum = 0;
  std::array<unsigned char, kTransferHeaderBytes> transfer_header{};
  TransferSet shape;
};

TransferFileError error(const std::string& message) {
  return TransferFileError(message);
}

Shard open_shard(const fs::path& path) {
  const std::string name = path.string();
  common::OpenedVersionedFile opened = common::open_versioned(path, kShardFormat);
  if (!opened.problem.empty()) throw error(name + ": " + opened.problem);
  if (const std::string p = common::header_checksum_problem(opened.header, kShardFormat);
      !p.empty())
    throw error(name + ": " + p);
  Shard s;
  s.path = path;
  s.range.index = common::get_field<std::uint32_t>(opened.header, kOffIndex);
  s.range.count = common::get_field<std::uint32_t>(opened.header, kOffCount);
  s.range.first = common::get_field<std::uint64_t>(opened.header, kOffFirst);
  s.range.end = common::get_field<std::uint64_t>(opened.header, kOffEnd);
  s.floats = common::get_field<std::uint64_t>(opened.header, kShardPayloadFloats);
  s.checksum = common::get_field<std::uint64_t>(opened.header, kShardPayloadChecksum);
  opened.stream.read(reinterpret_cast<char*>(s.transfer_header.data()), kTransferHeaderBytes);
  if (opened.stream.gcount() != std::streamsize(kTransferHeaderBytes))
    throw error(name + ": truncated before its transfer header; " + kShardFormat.remedy);
  s.shape = decode_transfer_header(s.transfer_header, name);
  const ShardRange expected = shard_range(s.shape.vertex_count, s.range.index, s.range.count);
  if (s.range.count == 0 || s.range.index >= s.range.count || s.range.first != expected.first ||
      s.range.end != expected.end ||
      s.floats != (s.range.end - s.range.first) * s.shape.floats_per_vertex()) {
    throw error(name + ": shard " + std::to_string(s.range.index) + "/" +
                std::to_string(s.range.count) + " records vertices [" +
                std::to_string(s.range.first) + ", " + std::to_string(s.range.end) + ") and " +
                std::to_string(s.floats) + " floats, which do not fit a bake of " +
                std::to_string(s.shape.vertex_count) + " vertices; " + kShardFormat.remedy);
  }
  if (const std::string p =
          common::file_size_problem(kPrefixBytes + 4 * s.floats, opened.size, kShardFormat);
      !p.empty())
    throw error(name + ": " + p);
  return s;
}

// The first header field in which two bakes differ, as "name (a vs b)"; empty if none.
std::string first_difference(const TransferSet& a, const TransferSet& b) {
  const auto str = [](auto v) {
    std::ostringstream o;
    o.precision(9);
    o << v;
    return o.str();
  };
  const std::pair<const char*, std::pair<std::string, std::string>> fields[] = {
      {"mesh hash", {common::hex64(a.mesh_hash), common::hex64(b.mesh_hash)}},
      {"vertex count", {str(a.vertex_count), str(b.vertex_count)}},
      {"kind", {kTransferKindNames.name(a.kind), kTransferKindNames.name(b.kind)}},
      {"order", {str(a.order), str(b.order)}},
      {"samples", {str(a.samples), str(b.samples)}},
      {"bounces", {str(a.bounces), str(b.bounces)}},
      {"seed", {str(a.seed), str(b.seed)}},
      {"channels", {str(a.channels), str(b.channels)}},
      {"material", {str(int(a.material.kind)), str(int(b.material.kind))}},
  };
  for (const auto& [name, values] : fields) {
    if (values.first != values.second)
      return std::string(name) + " " + values.first + " vs " + values.second;
  }
  return "material parameters";
}

// Shards 0..n-1 of one bake, each once, in index order.
std::vector<Shard> checked_shards(const std::vector<fs::path>& paths) {
  if (paths.empty()) throw error("merge: no shards given");
  std::vector<Shard> shards;
  for (const fs::path& p : paths) shards.push_back(open_shard(p));
  const Shard& ref = shards.front();
  for (const Shard& s : shards) {
    if (s.transfer_header != ref.transfer_header) {
      throw error(s.path.string() + " and " + ref.path.string() +
                  " are shards of different bakes (" + first_difference(s.shape, ref.shape) +
                  "); bake every shard from the same mesh with the same flags");
    }
    if (s.range.count != ref.range.count) {
      throw error(s.path.string() + " is one of " + std::to_string(s.range.count) + " shards but " +
                  ref.path.string() + " one of " + std::to_string(ref.range.count) +
                  "; bake every shard with the same --shard n");
    }
  }
  std::sort(shards.begin(), shards.end(),
            [](const Shard& a, const Shard& b) { return a.range.index < b.range.index; });
  const std::uint32_t n = ref.range.count;
  for (std::uint32_t k = 0; k < n; ++k) {
    if (k < shards.size() && shards[k].range.index == k) {
      if (k + 1 < shards.size() && shards[k + 1].range.index == k) {
        throw error("shard " + std::to_string(k) + "/" + std::to_string(n) + " is given twice: " +
                    shards[k].path.string() + " and " + shards[k + 1].path.string());
      }
      continue;
    }
    throw error("shard " + std::to_string(k) + "/" + std::to_string(n) +
                " is missing; bake it with prtr bake --shard " + std::to_string(k) + "/" +
                std::to_string(n) + " and merge all " + std::to_string(n));
  }
  if (shards.size() > n) {
    throw error("shard " + std::to_string(shards[n].range.index) + "/" + std::to_string(n) +
                " is given twice: " + shards[n - 1].path.string() + " and " +
                shards[n].path.string());
  }
  return shards;
}

}  // namespace

ShardRange shard_range(std::uint64_t vertex_count, std::uint32_t index, std::uint32_t count) {
  ShardRange r;
  r.index = index;
  r.count = count;
  if (count == 0 || index >= count) return r;
  // floor(V k / n) without forming V k: with V = q n + r it is q k + floor(r k / n), and
  // r k < n^2 < 2^64.
  const std::uint64_t q = vertex_count / count, r_ = vertex_count % count;
  const auto at = [&](std::uint64_t k) { return q * k + r_ * k / count; };
  r.first = at(index);
  r.end = at(std::uint64_t(index) + 1);
  return r;
}

TransferShardWriter::TransferShardWriter(const fs::path& path, const TransferSet& shape,
                                         const ShardRange& range)
    : range_(range), floats_per_vertex_(shape.floats_per_vertex()), hash_(common::kFnvOffset) {
  transfer_header_ = encode_transfer_header(shape, 0);
  expected_ = (range.end - range.first) * floats_per_vertex_;
  file_ = std::make_unique<common::AtomicFile>(path);
  const std::array<unsigned char, kPrefixBytes> zeros{};
  file_->write(zeros.data(), zeros.size());
}

TransferShardWriter::~TransferShardWriter() = default;

void TransferShardWriter::append(const float* data, std::size_t floats) {
  if (floats > expected_ - written_)
    throw std::invalid_argument(file_->target().string() + ": more floats than the shard holds");
  hash_ = common::fnv1a(data, floats * sizeof(float), hash_);
  if (floats > 0) file_->write(data, floats * sizeof(float));
  written_ += floats;
}

void TransferShardWriter::commit() {
  if (written_ != expected_)
    throw std::invalid_argument(file_->target().string() + ": the shard is incomplete");
  common::VersionedHeader h = common::begin_header(kShardFormat);
  common::put_field<std::uint32_t>(h, kOffIndex, range_.index);
  common::put_field<std::uint32_t>(h, kOffCount, range_.count);
  common::put_field<std::uint64_t>(h, kOffFirst, range_.first);
  common::put_field<std::uint64_t>(h, kOffEnd, range_.end);
  common::put_field<std::uint64_t>(h, kShardPayloadFloats, expected_);
  common::put_field<std::uint64_t>(h, kShardPayloadChecksum, hash_);
  common::seal_header(h);
  std::array<unsigned char, kPrefixBytes> prefix{};
  std::memcpy(prefix.data(), h.data(), h.size());
  std::memcpy(prefix.data() + h.size(), transfer_header_.data(), transfer_header_.size());
  const int fd = ::open(file_->temporary().c_str(), O_WRONLY | O_CLOEXEC);
  if (fd < 0 || ::pwrite(fd, prefix.data(), prefix.size(), 0) != ssize_t(prefix.size())) {
    const std::string why = std::strerror(errno);
    if (fd >= 0) ::close(fd);
    throw common::IoError(file_->target().string() + ": cannot write the header (" + why + ")");
  }
  ::close(fd);
  file_->commit();
}

void merge_shards(const std::vector<fs::path>& paths, const fs::path& output) {
  const std::vector<Shard> shards = checked_shards(paths);
  TransferFileWriter writer(output, shards.front().shape);
  const std::size_t block = std::size_t(16) << 20;  // floats per read: 64 MiB
  std::vector<float> buffer;
  for (const Shard& s : shards) {
    const int fd = ::open(s.path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) throw error(s.path.string() + ": cannot open (" + std::strerror(errno) + ")");
    std::uint64_t hash = common::kFnvOffset;
    try {
      for (std::uint64_t at = 0; at < s.floats; at += block) {
        const std::size_t n = std::size_t(std::min<std::uint64_t>(block, s.floats - at));
        buffer.resize(n);
        common::read_exact(fd, buffer.data(), n * sizeof(float), kPrefixBytes + at * 4,
                           s.path.c_str());
        hash = common::fnv1a(buffer.data(), n * sizeof(float), hash);
        writer.append(buffer.data(), n);
      }
    } catch (...) {
      ::close(fd);
      throw;
    }
    ::close(fd);
    if (const std::string p = common::checksum_problem("payload", hash, s.checksum, kShardFormat);
        !p.empty())
      throw error(s.path.string() + ": " + p);
  }
  writer.commit();
}

}  // namespace prt
