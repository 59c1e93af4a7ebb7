#include "common/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <random>

namespace common {
namespace {

std::string errno_text() {
  return std::strerror(errno);
}

}  // namespace

AtomicFile::AtomicFile(std::filesystem::path target) : target_(std::move(target)) {
  const std::filesystem::path dir =
      target_.has_parent_path() ? target_.parent_path() : std::filesystem::path(".");
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) {
    throw IoError(target_.string() + ": directory " + dir.string() +
                  " does not exist; create it first or choose another output path");
  }
  // A unique name in the same directory, so the final rename stays on one file system.
  std::random_device rd;
  for (int attempt = 0; attempt < 16 && fd_ < 0; ++attempt) {
    // Built with append: GCC 12 reports a false -Wrestrict on chained operator+ here.
    std::string name = ".";
    name.append(target_.filename().string())
        .append(".tmp-")
        .append(std::to_string(::getpid()))
        .append("-")
        .append(std::to_string(rd() & 0xffffff));
    temp_ = dir / name;
    fd_ = ::open(temp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (fd_ < 0 && errno != EEXIST) break;
  }
  if (fd_ < 0) {
    throw IoError(target_.string() + ": cannot create a temporary file in " + dir.string() + " (" +
                  errno_text() + ")");
  }
}

AtomicFile::~AtomicFile() {
  if (fd_ >= 0) ::close(fd_);
  if (!committed_) {
    std::error_code ec;
    std::filesystem::remove(temp_, ec);
  }
}

void AtomicFile::write(const void* data, std::size_t bytes) {
  const char* p = static_cast<const char*>(data);
  while (bytes > 0) {
    const ssize_t n = ::write(fd_, p, bytes);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw IoError(target_.string() + ": write failed (" + errno_text() + ")");
    }
    p += n;
    bytes -= static_cast<std::size_t>(n);
  }
}

void AtomicFile::commit() {
  if (::fsync(fd_) != 0) throw IoError(target_.string() + ": fsync failed (" + errno_text() + ")");
  if (::close(fd_) != 0) {
    fd_ = -1;
    throw IoError(target_.string() + ": close failed (" + errno_text() + ")");
  }
  fd_ = -1;
  if (::rename(temp_.c_str(), target_.c_str()) != 0) {
    throw IoError(target_.string() + ": cannot replace the file (" + errno_text() + ")");
  }
  committed_ = true;
}

void write_file_atomically(const std::filesystem::path& target, const void* data,
                           std::size_t bytes) {
  AtomicFile file(target);
  file.write(data, bytes);
  file.commit();
}

}  // namespace common
