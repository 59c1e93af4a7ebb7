// common/mapped_file.h: a read-only memory map of a whole file, for inputs larger than the
// memory a process should hold (a .prtx being compressed).
// Pages come from the page cache on first touch; release() drops this process's mappings of
// them so its resident set stays bounded by what it touched since, while the kernel keeps
// the pages cached for a cheap re-fault. Scattered small reads should use read() instead: a
// fault maps a whole page-cache folio (up to megabytes on file systems with large folios), so
// touching one 5 KB row through the map can make a megabyte resident.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

namespace common {

class MappedFile {
 public:
  // Throws IoError (common/atomic_file.h) naming the path when it cannot be opened or mapped.
  explicit MappedFile(const std::filesystem::path& path);
  ~MappedFile();
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;

  const unsigned char* data() const { return data_; }
  std::size_t size() const { return size_; }
  // Drops the resident pages of [offset, offset + bytes) from this mapping (whole pages
  // inside the range); their contents stay readable.
  void release(std::size_t offset, std::size_t bytes) const;
  void release() const { release(0, size_); }
  // Copies [offset, offset + bytes) with pread, leaving the mapping untouched. Throws IoError.
  void read(std::size_t offset, void* out, std::size_t bytes) const;

 private:
  std::string path_;
  int fd_ = -1;
  const unsigned char* data_ = nullptr;
  std::size_t size_ = 0;
};

// Reads exactly `bytes` at `offset` of the open descriptor `fd`; throws IoError naming
// `what` on a short read or an error.
void read_exact(int fd, void* out, std::size_t bytes, std::uint64_t offset, const char* what);
// Writes exactly `bytes` at `offset` of `fd` (pwrite, retried on short writes); throws
// IoError naming `what` on an error or a full disk.
void write_exact(int fd, const void* data, std::size_t bytes, std::uint64_t offset,
                 const char* what);

}  // namespace common
