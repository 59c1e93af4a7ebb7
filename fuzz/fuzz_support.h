// fuzz/fuzz_support.h: what every libFuzzer target here shares. The loaders under test take
// paths, so each input is written to a file first; the file lives in memory (/dev/shm) where
// that works, so that the write costs microseconds, and in $TMPDIR or /tmp otherwise.
#pragma once

#include "common/hash.h"

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace fuzz_support {

// A path ending in `extension` that belongs to this process alone (libFuzzer's -fork and
// -jobs modes run several processes side by side). /dev/shm first; where it is missing, full,
// read-only or not ours to write (a container without a tmpfs there), $TMPDIR, then /tmp.
inline const std::filesystem::path& scratch_path(const std::string& extension) {
  static const std::filesystem::path path = [&] {
    namespace fs = std::filesystem;
    std::vector<fs::path> bases{"/dev/shm"};
    if (const char* tmpdir = std::getenv("TMPDIR"); tmpdir && *tmpdir) bases.emplace_back(tmpdir);
    bases.emplace_back("/tmp");
    const std::string name = "prtr-fuzz-" + std::to_string(::getpid());
    for (const fs::path& base : bases) {
      std::error_code ec;
      const fs::path dir = base / name;
      fs::create_directories(dir, ec);
      const fs::path file = dir / ("input" + extension);
      if (!ec && std::ofstream(file, std::ios::binary | std::ios::trunc).put('x')) return file;
    }
    std::fprintf(stderr, "fuzz: cannot write a scratch file in /dev/shm, $TMPDIR or /tmp\n");
    std::abort();
  }();
  return path;
}

inline const std::filesystem::path& write_input(const std::uint8_t* data, std::size_t size,
                                                const std::string& extension) {
  const std::filesystem::path& path = scratch_path(extension);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
  // A short write (the scratch file system filled up) would feed the loader another input
  // than libFuzzer recorded; stop rather than report findings that do not reproduce.
  if (!out.flush()) {
    std::fprintf(stderr, "fuzz: cannot write %s\n", path.c_str());
    std::abort();
  }
  return path;
}

// One input through a loader that reads files: the loader's documented errors are
// exceptions, so only a crash, a sanitizer report or a leak is a finding.
template <class Load>
int load_file_input(const std::uint8_t* data, std::size_t size, const std::string& extension,
                    const Load& load) {
  const std::filesystem::path& path = write_input(data, size, extension);
  try {
    load(path);
  } catch (const std::exception&) {
  }
  return 0;
}

inline void put_u64(std::uint8_t* at, std::uint64_t v) {
  std::memcpy(at, &v, sizeof v);
}

// The layouts below mirror prt/src/transfer_file.cpp and cpca/src/compressed_file.cpp: a
// 128-byte header whose last 8 bytes are the FNV-1a of the 120 before them.
constexpr std::size_t kHeaderBytes = 128;
constexpr std::size_t kHeaderChecksum = 120;

// .prtx: payload checksum at 104 over everything after the header.
inline void reseal_transfer(std::uint8_t* data, std::size_t size) {
  if (size < kHeaderBytes) return;
  put_u64(data + 104, common::fnv1a(data + kHeaderBytes, size - kHeaderBytes));
  put_u64(data + kHeaderChecksum, common::fnv1a(data, kHeaderChecksum));
}

// .prtc: mesh path (length at 52, padded to 8 bytes) after the header, checksum at 112; the
// payload after it, checksum at 104.
inline void reseal_compressed(std::uint8_t* data, std::size_t size) {
  if (size < kHeaderBytes) return;
  std::uint32_t path_bytes = 0;
  std::memcpy(&path_bytes, data + 52, 4);
  const std::size_t block = (std::size_t(path_bytes) + 7) / 8 * 8;
  if (block <= size - kHeaderBytes) {
    put_u64(data + 112, common::fnv1a(data + kHeaderBytes, path_bytes));
    put_u64(data + 104, common::fnv1a(data + kHeaderBytes + block, size - kHeaderBytes - block));
  }
  put_u64(data + kHeaderChecksum, common::fnv1a(data, kHeaderChecksum));
}

}  // namespace fuzz_support
