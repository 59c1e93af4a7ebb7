#include "common/mapped_file.h"

#include "common/atomic_file.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <string>

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

namespace common {

MappedFile::MappedFile(const std::filesystem::path& path) : path_(path.string()) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    throw IoError(path.string() + ": cannot open for mapping (" + std::strerror(errno) + ")");
  }
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    const int e = errno;
    ::close(fd);
    throw IoError(path.string() + ": cannot stat (" + std::strerror(e) + ")");
  }
  size_ = static_cast<std::size_t>(st.st_size);
  if (size_ > 0) {
    void* p = ::mmap(nullptr, size_, PROT_READ, MAP_SHARED, fd, 0);
    if (p == MAP_FAILED) {
      const int e = errno;
      ::close(fd);
      throw IoError(path.string() + ": cannot map (" + std::strerror(e) + ")");
    }
    data_ = static_cast<const unsigned char*>(p);
  }
  fd_ = fd;  // kept for read()
}

MappedFile::~MappedFile() {
  if (data_) ::munmap(const_cast<unsigned char*>(data_), size_);
  if (fd_ >= 0) ::close(fd_);
}

void MappedFile::read(std::size_t offset, void* out, std::size_t bytes) const {
  if (offset > size_ || bytes > size_ - offset)
    throw IoError(path_ + ": read past the end of the mapped file");
  read_exact(fd_, out, bytes, offset, path_.c_str());
}

void MappedFile::release(std::size_t offset, std::size_t bytes) const {
  if (!data_ || offset >= size_) return;
  const std::size_t page = static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
  std::size_t begin = (offset + page - 1) / page * page;
  std::size_t end = std::min(size_, offset + bytes);
  if (end != size_) end = end / page * page;
  if (end <= begin) return;
  // A clean shared file mapping: dropping it loses nothing, later reads fault it back in.
  ::madvise(const_cast<unsigned char*>(data_) + begin, end - begin, MADV_DONTNEED);
}

namespace {

// pread or pwrite until all `bytes` moved, retrying short transfers and EINTR; a transfer of
// nothing is `at_zero` ("unexpected end of file", "disk full?").
template <class Byte, class Io>
void transfer_exact(Io io, int fd, Byte* p, std::size_t bytes, std::uint64_t offset,
                    const char* what, const char* verb, const char* at_zero) {
  while (bytes > 0) {
    const ssize_t n = io(fd, p, bytes, static_cast<off_t>(offset));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      throw IoError(std::string(what) + ": " + verb + " failed (" +
                    (n == 0 ? std::string(at_zero) : std::strerror(errno)) + ")");
    }
    p += n;
    bytes -= static_cast<std::size_t>(n);
    offset += static_cast<std::uint64_t>(n);
  }
}

}  // namespace

void read_exact(int fd, void* out, std::size_t bytes, std::uint64_t offset, const char* what) {
  transfer_exact(::pread, fd, static_cast<unsigned char*>(out), bytes, offset, what, "read",
                 "unexpected end of file");
}

void write_exact(int fd, const void* data, std::size_t bytes, std::uint64_t offset,
                 const char* what) {
  transfer_exact(::pwrite, fd, static_cast<const unsigned char*>(data), bytes, offset, what,
                 "write", "disk full?");
}

}  // namespace common
