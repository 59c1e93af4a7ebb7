// apps/prtr/commands.h: the subcommands of prtr. Each registers its flags on a CLI11 app
// and returns a runner; the runner throws on failure and main() maps errors to exit codes
// (2 for usage errors, 1 for failures).
#pragma once

#include <CLI/CLI.hpp>

#include <functional>

namespace prtr_app {

using Runner = std::function<void()>;

Runner add_mesh_command(CLI::App& app);
Runner add_probe_command(CLI::App& app);
Runner add_gl_info_command(CLI::App& app);
Runner add_bake_command(CLI::App& app);
Runner add_info_command(CLI::App& app);
Runner add_compress_command(CLI::App& app);
Runner add_relight_command(CLI::App& app);
Runner add_overdraw_command(CLI::App& app);
Runner add_render_command(CLI::App& app);
Runner add_merge_command(CLI::App& app);
Runner add_view_command(CLI::App& app);

// A usage error found after parsing (e.g. flags that contradict each other): exit code 2.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace prtr_app
