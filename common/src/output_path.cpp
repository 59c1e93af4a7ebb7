// The output-path policy of common/output_path.h.
#include "common/output_path.h"

#include "common/atomic_file.h"
#include "common/input_file.h"

#include <sys/stat.h>

namespace common {

namespace fs = std::filesystem;

std::string output_target_problem(const fs::path& target) {
  struct stat st;
  // lstat: a symbolic link is judged as itself, not as what it points to.
  if (::lstat(target.c_str(), &st) != 0) return {};  // does not exist (or cannot be seen): fine
  return file_type_problem(unsigned(st.st_mode));
}

void check_output_target(const fs::path& target) {
  if (const std::string problem = output_target_problem(target); !problem.empty())
    throw IoError(target.string() + ": " + problem + "; write to another path");
}

bool same_file(const fs::path& a, const fs::path& b) {
  std::error_code ec;
  if (fs::exists(a, ec) && fs::exists(b, ec)) {
    const bool same = fs::equivalent(a, b, ec);
    if (!ec) return same;
  }
  return fs::absolute(a, ec).lexically_normal() == fs::absolute(b, ec).lexically_normal();
}

std::string outputs_problem(const std::vector<NamedPath>& outputs,
                            const std::vector<NamedPath>& inputs) {
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    const NamedPath& out = outputs[i];
    if (out.path.empty()) continue;
    if (const std::string problem = output_target_problem(out.path); !problem.empty())
      return out.name + " " + out.path.string() + " " + problem + "; write to another path";
    for (const NamedPath& in : inputs) {
      if (!in.path.empty() && same_file(out.path, in.path)) {
        return out.name + " " + out.path.string() + " is the input " + in.name +
               "; writing there would destroy it: write to another path";
      }
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (!outputs[j].path.empty() && same_file(out.path, outputs[j].path)) {
        return out.name + " and " + outputs[j].name + " both name " + out.path.string() +
               "; one would replace the other: give each its own path";
      }
    }
  }
  return {};
}

}  // namespace common
