#include "start_sweep.h"

#include "common/atomic_file.h"
#include "pipeline/pipeline.h"

#include <cstdio>
#include <filesystem>
#include <set>
#include <string>

namespace prtr_app {

namespace fs = std::filesystem;

void sweep_command_folders(const CLI::App& command) {
  std::set<fs::path> folders;
  for (const CLI::Option* option : command.get_options()) {
    const bool file = option->check_lname("output") || option->check_lname("png");
    const bool folder = option->check_lname("out");
    const bool cache = option->check_lname("cache");
    if (!file && !folder && !cache) continue;
    // The value given, else the default the command will use.
    std::string value = option->count() > 0 ? option->as<std::string>() : option->get_default_str();
    if (value.empty() && cache) value = pipeline::default_cache_dir().string();
    if (value.empty()) continue;
    const fs::path path(value);
    folders.insert(file ? (path.has_parent_path() ? path.parent_path() : fs::path(".")) : path);
  }
  for (const fs::path& folder : folders) {
    for (const fs::path& removed : common::sweep_stale_temporaries(folder)) {
      std::fprintf(stderr, "prtr: removed %s, left by an interrupted run\n",
                   removed.string().c_str());
    }
  }
}

}  // namespace prtr_app
