// prt/mapped_transfer.h: a .prtx read through a memory map instead of into memory, for
// bakes larger than the memory a process should hold (prtr compress out of core,
// docs/ARCHITECTURE.md "Scale"). It is checked as read_transfer checks a file (header,
// size, payload checksum, finite values), but the payload is streamed through the map once
// for that, dropping each chunk's pages after it, so opening costs no resident memory.
#pragma once

#include "common/mapped_file.h"
#include "prt/transfer.h"

#include <cstdint>
#include <filesystem>

namespace prt {

class MappedTransfer {
 public:
  // Throws TransferFileError (prt/transfer_file.h) naming the file and the problem.
  explicit MappedTransfer(const std::filesystem::path& path);

  // Every header field, payload_checksum included; data is empty.
  const TransferSet& header() const { return header_; }
  // vertex_count x floats_per_vertex floats, vertex-major (prt/transfer.h).
  const float* payload() const;
  // Drops the pages of vertices [first, first + count) from this process (see MappedFile).
  void release(std::uint64_t first, std::uint64_t count) const;
  // Copies the rows of vertices rows[0..count) to out (count x floats_per_vertex floats) with
  // pread, runs of consecutive vertices in one read: random access that leaves no pages
  // resident (see MappedFile::read).
  void read_rows(const std::uint32_t* rows, std::size_t count, float* out) const;

 private:
  TransferSet header_;
  common::MappedFile file_;
};

}  // namespace prt
