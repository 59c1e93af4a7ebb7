// cpca/compressed_file.h: the versioned binary file of a CompressedSet (.prtc). The layout is
// documented byte by byte in docs/FORMATS.md ("Compressed file (.prtc), version 1", with a
// NumPy reader); in short: a fixed 128-byte little-endian header starting with the magic
// "PRTRCMPR" and a version, then the mesh path (its length is in the header, at most
// kMaxMeshPathBytes, zero-padded to a multiple of 8), then the payload: cluster ids (u32),
// weights, means and bases (f32), then nothing. The header carries checksums of itself, of
// the mesh path and of the payload, so damage is detected before anything is used.
#pragma once

#include "cpca/compressed.h"

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <stdexcept>

namespace cpca {

// Version 2: compressed from version-2 transfer files (prt/transfer_file.h), whose glossy
// view side is fitted without the horizon step; version 1 files are refused, not re-read.
inline constexpr std::uint32_t kCompressedFileVersion = 2;
// Long enough for any PATH_MAX path on Linux; a bound so that a damaged length cannot make
// the reader allocate gigabytes.
inline constexpr std::size_t kMaxMeshPathBytes = 4096;

class CompressedFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Refuses (std::invalid_argument naming the file) any set that validate() or the reader
// would refuse, so that every written file can be read back. Written atomically
// (common/atomic_file.h): a failure leaves the old file or none, and no temporary file.
void write_compressed(const std::filesystem::path& path, const CompressedSet& set);

// Reads and checks everything: magic, version, header fields in range, file size equal to
// header + mesh path + payload, the three checksums, cluster ids below K, finite values. Each
// failure is a CompressedFileError whose message names the file, the problem and the fix.
CompressedSet read_compressed(const std::filesystem::path& path);

// Header and mesh path only (the four arrays left empty), with every check up to and
// including the file size and the mesh path's checksum, but no payload read; for `prtr info`
// and staleness checks.
CompressedSet read_compressed_header(const std::filesystem::path& path);

}  // namespace cpca
