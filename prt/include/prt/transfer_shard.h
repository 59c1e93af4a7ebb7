// prt/transfer_shard.h: one vertex range of a bake, for batch schedulers that split a bake
// over jobs (`prtr bake --shard k/n`), and the merge of all n into the .prtx one process
// would have written (`prtr merge`). Layout (docs/FORMATS.md, "Transfer shard"): a 128-byte
// shard header (magic "PRTRSHRD", version 1: shard index and count, vertex range, payload
// size and FNV-1a checksum, header checksum), then the whole bake's 128-byte .prtx header
// with a zero payload checksum, then the range's payload in .prtx layout.
#pragma once

#include "prt/transfer.h"

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <vector>

namespace common {
class AtomicFile;
}

namespace prt {

// The vertices shard k of n bakes: [V k / n, V (k + 1) / n).
struct ShardRange {
  std::uint32_t index = 0, count = 1;
  std::uint64_t first = 0, end = 0;
};
ShardRange shard_range(std::uint64_t vertex_count, std::uint32_t index, std::uint32_t count);

// Streams one shard's payload, like TransferFileWriter; atomic.
class TransferShardWriter {
 public:
  // `shape` holds the whole bake's header fields (data ignored).
  TransferShardWriter(const std::filesystem::path& path, const TransferSet& shape,
                      const ShardRange& range);
  ~TransferShardWriter();
  TransferShardWriter(const TransferShardWriter&) = delete;
  TransferShardWriter& operator=(const TransferShardWriter&) = delete;
  void append(const float* data, std::size_t floats);
  void commit();

 private:
  ShardRange range_;
  std::size_t floats_per_vertex_ = 0;
  std::unique_ptr<common::AtomicFile> file_;
  std::uint64_t expected_ = 0, written_ = 0, hash_ = 0;
  std::array<unsigned char, 128> transfer_header_{};
};

// Checks that `shards` are exactly shards 0..n-1 of one bake (same mesh, options, seed and
// material; each index once; ranges as shard_range gives them; payloads intact) and writes
// the merged .prtx atomically, byte for byte what one process would have written. Throws
// TransferFileError naming the offending file(s) and what to do; nothing is written then.
void merge_shards(const std::vector<std::filesystem::path>& shards,
                  const std::filesystem::path& output);

}  // namespace prt
