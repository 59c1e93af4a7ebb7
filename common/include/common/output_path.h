// common/output_path.h: what an output path may be, checked in one place by every writer and
// every command.
//
// Outputs are written to a temporary beside the target and renamed over it. A rename
// replaces whatever the name denotes, so renaming over /dev/null, a FIFO or a symbolic link
// would replace that special file (as root, /dev/null itself), not write through it. So an
// output may be a path that does not exist yet, or an existing regular file, which is
// replaced whole; anything else is refused before any work starts and again just before the
// rename. An output may also never be one of the command's inputs, or another output of the
// same command: that would destroy the input, or lose one of the two outputs.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace common {

// "" when `target` may be written, else why not ("is a character device (not a regular
// file)", "is a directory", ...).
std::string output_target_problem(const std::filesystem::path& target);

// Throws IoError "<target>: <problem>; write to another path" when output_target_problem
// finds one. Writers call it just before renaming their temporary over the target.
void check_output_target(const std::filesystem::path& target);

// Whether two paths name the same file: the same device and inode when both exist, else the
// same absolute, normalised path.
bool same_file(const std::filesystem::path& a, const std::filesystem::path& b);

struct NamedPath {
  std::string name;  // how the user gave it: a flag ("-o") or an argument ("MESH")
  std::filesystem::path path;
};

// The first problem with a command's outputs, as a one-line message naming the flag, or ""
// when there is none: an output that may not be written (output_target_problem), that is
// one of `inputs`, or that is another of `outputs`. Empty paths are ignored (unset options).
std::string outputs_problem(const std::vector<NamedPath>& outputs,
                            const std::vector<NamedPath>& inputs);

}  // namespace common
