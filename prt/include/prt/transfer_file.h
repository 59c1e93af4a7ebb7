// prt/transfer_file.h: the versioned binary file of a TransferSet. The layout is documented
// byte by byte in docs/FORMATS.md (with a NumPy reader); in short: a fixed 128-byte
// little-endian header starting with the magic "PRTRXFER" and a version, then the float32
// payload in TransferSet's layout, then nothing. The header carries a checksum of the
// payload, so a truncated or damaged file is detected before it is used.
#pragma once

#include "common/atomic_file.h"
#include "prt/transfer.h"

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>

namespace prt {

// Version 2 records the view fit and Cook-Torrance's masking (prt/view_fit.h, material.h);
// version 1 held the thesis's hemisphere projection and is refused with "bake it again".
inline constexpr std::uint32_t kTransferFileVersion = 2;

class TransferFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Written atomically (common/atomic_file.h): a crash leaves the old file or none.
void write_transfer(const std::filesystem::path& path, const TransferSet& set);

// Writes a transfer file whose payload arrives in vertex order, block by block, so a bake
// never holds the whole payload: the bytes equal write_transfer's for the same values.
// Atomic like write_transfer; nothing appears at `path` unless commit() succeeds.
class TransferFileWriter {
 public:
  // `shape` gives every header field; its data is ignored. Throws std::invalid_argument for
  // fields read_transfer would refuse, common::IoError when the directory is not writable.
  TransferFileWriter(const std::filesystem::path& path, const TransferSet& shape);
  ~TransferFileWriter();
  TransferFileWriter(const TransferFileWriter&) = delete;
  TransferFileWriter& operator=(const TransferFileWriter&) = delete;

  // The next `floats` values of the payload; throws on a non-finite value or an overrun.
  void append(const float* data, std::size_t floats);
  // The payload rows of `count` consecutive vertices from `first_vertex`, written where they
  // belong, for a producer that finishes vertices out of order (a bake with bounces works in
  // a spatial order). Every vertex must be placed once; the checksum is then computed at
  // commit() from the file. Throws on a non-finite value, a range outside the mesh, or a
  // writer that was appended to.
  void place(std::uint64_t first_vertex, const float* data, std::uint64_t count);
  // Throws unless exactly the payload's floats were appended or placed.
  void commit();
  std::uint64_t expected_floats() const { return expected_; }

 private:
  TransferSet shape_;
  std::unique_ptr<common::AtomicFile> file_;
  std::uint64_t expected_ = 0, written_ = 0, hash_ = 0;
  int place_fd_ = -1;  // the temporary file, for place()'s positioned writes
};

// One of several processes that write one transfer file together (mpirun prtr bake): each
// writes the payload rows of its vertex range [first, end) straight to their place in a
// partial file beside `path` (partial_transfer_path), which all of them open, so nothing is
// merged afterwards. Once every writer has closed, one process calls commit_transfer_slices.
// The partial file is not the output: a job that dies leaves `path` untouched, and a rerun
// rewrites every byte of the partial file it reads.
class TransferSliceWriter {
 public:
  TransferSliceWriter(const std::filesystem::path& path, const TransferSet& shape,
                      std::uint64_t first_vertex, std::uint64_t end_vertex);
  ~TransferSliceWriter();
  TransferSliceWriter(const TransferSliceWriter&) = delete;
  TransferSliceWriter& operator=(const TransferSliceWriter&) = delete;

  // The next `floats` values of the slice; throws on a non-finite value or an overrun.
  void append(const float* data, std::size_t floats);
  // Rows of `count` vertices from `first_vertex`, anywhere in the mesh, written where they
  // belong: for a writer whose vertices are a range of another order (a bake with bounces
  // gives each rank a range of the spatial order). They count toward the slice's size, and
  // the writers together must write every row once. Throws on a non-finite value, rows
  // outside the mesh or an overrun.
  void place(std::uint64_t first_vertex, const float* data, std::uint64_t count);
  // Throws unless exactly the slice's floats were appended or placed; flushes them to disk.
  void close();

 private:
  TransferSet shape_;
  std::filesystem::path partial_;
  int fd_ = -1;
  std::uint64_t first_float_ = 0, expected_ = 0, written_ = 0;
  bool placed_ = false;  // rows went through place(), so append() has no cursor
};

std::filesystem::path partial_transfer_path(const std::filesystem::path& path);

// After every TransferSliceWriter of `path` closed: checksums the partial file's payload,
// writes the header, cuts the file to its size (a rerun may find a longer one) and renames
// it over `path`. Throws TransferFileError when the partial file is shorter than the payload.
void commit_transfer_slices(const std::filesystem::path& path, const TransferSet& shape);

// The 128-byte header alone, for containers that carry one (transfer shards,
// prt/transfer_shard.h). encode throws std::invalid_argument for fields out of range;
// decode checks it as read_transfer does and throws TransferFileError naming `name`.
inline constexpr std::size_t kTransferHeaderBytes = 128;
std::array<unsigned char, kTransferHeaderBytes> encode_transfer_header(
    const TransferSet& shape, std::uint64_t payload_checksum);
TransferSet decode_transfer_header(const std::array<unsigned char, kTransferHeaderBytes>& header,
                                   const std::string& name);

// Reads and validates everything: magic, version, header fields in range, file size equal
// to header + payload, payload checksum, finite values. Each failure is a TransferFileError
// whose message names the file and the problem and says what to do (usually: bake again).
TransferSet read_transfer(const std::filesystem::path& path);

// Header only (data left empty), with the same header checks and the file-size check but no
// payload read; for `prtr info` and staleness checks on large files.
TransferSet read_transfer_header(const std::filesystem::path& path);

}  // namespace prt
