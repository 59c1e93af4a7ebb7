// prt/transfer_file.h: the versioned binary file of a TransferSet. The layout is documented
// byte by byte in docs/FORMATS.md (with a NumPy reader); in short: a fixed 128-byte
// little-endian header starting with the magic "PRTRXFER" and a version, then the float32
// payload in TransferSet's layout, then nothing. The header carries a checksum of the
// payload, so a truncated or damaged file is detected before it is used.
#pragma once

#include "prt/transfer.h"

#include <cstdint>
#include <filesystem>
#include <stdexcept>

namespace prt {

inline constexpr std::uint32_t kTransferFileVersion = 1;

class TransferFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Written atomically (common/atomic_file.h): a crash leaves the old file or none.
void write_transfer(const std::filesystem::path& path, const TransferSet& set);

// Reads and validates everything: magic, version, header fields in range, file size equal
// to header + payload, payload checksum, finite values. Each failure is a TransferFileError
// whose message names the file and the problem and says what to do (usually: bake again).
TransferSet read_transfer(const std::filesystem::path& path);

// Header only (data left empty), with the same header checks and the file-size check but no
// payload read; for `prtr info` and staleness checks on large files.
TransferSet read_transfer_header(const std::filesystem::path& path);

}  // namespace prt
