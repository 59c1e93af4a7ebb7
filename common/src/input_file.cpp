// The input half of the path policy (common/input_file.h).
#include "common/input_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace common {

std::string file_type_problem(unsigned mode) {
  if (S_ISREG(mode)) return {};
  if (S_ISDIR(mode)) return "is a directory";
  if (S_ISLNK(mode)) return "is a symbolic link (not a regular file)";
  if (S_ISCHR(mode)) return "is a character device (not a regular file)";
  if (S_ISBLK(mode)) return "is a block device (not a regular file)";
  if (S_ISFIFO(mode)) return "is a FIFO (not a regular file)";
  if (S_ISSOCK(mode)) return "is a socket (not a regular file)";
  return "is not a regular file";
}

InputFile::InputFile(InputFile&& other) noexcept
    : file(other.release()), size(other.size), problem(std::move(other.problem)) {}

InputFile::~InputFile() {
  if (file != nullptr) std::fclose(file);
}

InputFile open_input_file(const std::filesystem::path& path, std::uint64_t max_bytes) {
  InputFile in;
  // O_NONBLOCK: opening a FIFO for reading would otherwise wait for a writer.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    in.problem = std::string("cannot be opened (") + std::strerror(errno) + ")";
    return in;
  }
  struct stat st;
  if (::fstat(fd, &st) != 0) {
    in.problem = std::string("cannot be inspected (") + std::strerror(errno) + ")";
  } else if (std::string type = file_type_problem(unsigned(st.st_mode)); !type.empty()) {
    in.problem = std::move(type);
  } else if (std::uint64_t(st.st_size) > max_bytes) {
    in.problem = "has " + std::to_string(st.st_size) + " bytes, over the limit of " +
                 std::to_string(max_bytes);
  }
  // A regular file never blocks, so the flag can go; reads then behave as usual.
  if (in.problem.empty() && ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) & ~O_NONBLOCK) != 0)
    in.problem = std::string("cannot be read (") + std::strerror(errno) + ")";
  if (in.problem.empty()) in.file = ::fdopen(fd, "rb");
  if (in.file == nullptr) {
    ::close(fd);
    if (in.problem.empty())
      in.problem = std::string("cannot be read (") + std::strerror(errno) + ")";
    return in;
  }
  in.size = std::uint64_t(st.st_size);
  return in;
}

}  // namespace common
