// apps/prtr/commands.h: the subcommands of prtr. Each registers its flags on a CLI11 app
// and returns a runner; the runner throws on failure and main() maps errors to exit codes
// (2 for usage errors, 1 for failures).
#pragma once

#include <CLI/CLI.hpp>

#include <functional>
#include <memory>

namespace prtr_app {

using Runner = std::function<void()>;

// Registers subcommand `name` with its flags; the runner calls run(options, subcommand) once
// the command line has been parsed into them.
template <class Options>
Runner add_command(CLI::App& app, const char* name, const char* about,
                   void (*add_flags)(CLI::App*, Options&), void (*run)(const Options&, CLI::App*)) {
  auto options = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(name, about);
  add_flags(cmd, *options);
  return [options, cmd, run] { run(*options, cmd); };
}

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
Runner add_slf_command(CLI::App& app);
Runner add_path_trace_command(CLI::App& app);
Runner add_compare_command(CLI::App& app);

// A usage error found after parsing (e.g. flags that contradict each other): exit code 2.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace prtr_app
