// common/atomic_file.h: write a file so that readers see either the old file or the whole
// new one, never a part. Data goes to a temporary file in the same directory, is flushed to
// disk, and is renamed over the target on commit(). If commit() is never reached (an
// exception, an early return), the destructor removes the temporary file.
#pragma once

#include <cstddef>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

namespace common {

class IoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class AtomicFile {
 public:
  // Creates the temporary file next to `target`; throws IoError naming the target when the
  // directory does not exist or is not writable.
  explicit AtomicFile(std::filesystem::path target);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  // Throws IoError (naming the target) when the write fails, e.g. the disk is full.
  void write(const void* data, std::size_t bytes);
  // Flushes, fsyncs and renames over the target. Throws IoError on failure.
  void commit();

  const std::filesystem::path& target() const { return target_; }
  const std::filesystem::path& temporary() const { return temp_; }

 private:
  std::filesystem::path target_;
  std::filesystem::path temp_;
  int fd_ = -1;
  bool committed_ = false;
};

// Convenience: the whole file from one buffer.
void write_file_atomically(const std::filesystem::path& target, const void* data,
                           std::size_t bytes);

}  // namespace common
