// common/atomic_file.h: write a file so that readers see either the old file or the whole
// new one, never a part. Data goes to a temporary file in the same directory, is flushed to
// disk, and is renamed over the target on commit(). If commit() is never reached (an
// exception, an early return), the destructor removes the temporary file; if the process is
// killed first, the next AtomicFile in that directory sweeps it (sweep_stale_temporaries).
#pragma once

#include <cstddef>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

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

// Removes the temporaries AtomicFile (or another user of temporary_path) left in `dir` when its
// process died before commit() or its destructor ran (kill -9, a crash, power loss): files
// named by temporary_path whose
// process no longer runs, or older than a day whatever their pid says (pids are reused, and
// a file from another machine or container names a pid that means nothing here). A writer
// that is still running is never disturbed. Returns the files removed; problems are ignored,
// since a missed sweep only costs disk space.
std::vector<std::filesystem::path> sweep_stale_temporaries(const std::filesystem::path& dir);

// A fresh temporary name next to `target`: .<name>.tmp-<pid>-<n>, with the target's extension
// appended when `keep_extension` (for writers that choose the format by the name, such as
// OpenImageIO's). Carrying the pid is what lets sweep_stale_temporaries tell a dead writer's
// file from a live one's.
std::filesystem::path temporary_path(const std::filesystem::path& target,
                                     bool keep_extension = false);

// Convenience: the whole file from one buffer.
void write_file_atomically(const std::filesystem::path& target, const void* data,
                           std::size_t bytes);

}  // namespace common
