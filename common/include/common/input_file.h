// common/input_file.h: what a file that is read may be, and how it is opened; the input half
// of the path policy whose output half is common/output_path.h.
//
// Files are read by name in two ways: named by the user (a mesh, a probe) and named inside
// another file (a glTF buffer, a .prtc's mesh). Either name can denote a FIFO, which blocks
// an open for reading until a writer appears, or a device such as /dev/zero, which never
// ends. So a file to be read must be a regular file of bounded size, and that is checked on
// the open descriptor: opened without blocking, then judged by fstat, so a name swapped
// between a check and the open cannot slip anything else in.
#pragma once

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>

namespace common {

// Why a file of this st_mode is not a regular file ("is a FIFO (not a regular file)", ...),
// or "" for a regular file.
std::string file_type_problem(unsigned mode);

// An input opened for reading. `file` is null and `problem` says why when the path is not a
// regular file of at most `max_bytes`, or cannot be opened.
struct InputFile {
  std::FILE* file = nullptr;
  std::uint64_t size = 0;
  std::string problem;

  // Hands the stream over to the caller, who then closes it.
  std::FILE* release() {
    std::FILE* f = file;
    file = nullptr;
    return f;
  }
  InputFile() = default;
  InputFile(InputFile&& other) noexcept;
  InputFile& operator=(InputFile&&) = delete;
  ~InputFile();
};

InputFile open_input_file(const std::filesystem::path& path, std::uint64_t max_bytes);

}  // namespace common
