// prtr: the command-line front end of the PRT engine. One binary, one subcommand per
// workflow; see README.md.
#include "commands.h"
#include "flag_checks.h"
#include "start_sweep.h"

#include <tbb/global_control.h>

#include <cstdio>
#include <exception>
#include <map>
#include <memory>
#include <string>

int main(int argc, char** argv) {
  CLI::App app{"prtr: precomputed radiance transfer for glossy meshes (bake, compress, relight)"};
  app.set_version_flag("--version", "prtr 0.1.0");
  app.require_subcommand(1);
  app.failure_message(CLI::FailureMessage::simple);
  int threads = 0;
  app.add_option("--threads", threads,
                 "Worker threads at most (0: every core; under mpirun, each rank gets the node's "
                 "cores divided by its ranks). Results do not depend on it")
      ->check(prtr_app::integer_in(0, 65536))
      ->capture_default_str();

  std::map<const CLI::App*, prtr_app::Runner> runners;
  auto add = [&](prtr_app::Runner (*adder)(CLI::App&)) {
    prtr_app::Runner r = adder(app);
    runners[app.get_subcommands({}).back()] = std::move(r);
  };
  add(prtr_app::add_mesh_command);
  add(prtr_app::add_probe_command);
  add(prtr_app::add_bake_command);
  add(prtr_app::add_merge_command);
  add(prtr_app::add_compress_command);
  add(prtr_app::add_relight_command);
  add(prtr_app::add_overdraw_command);
  add(prtr_app::add_render_command);
  add(prtr_app::add_view_command);
  add(prtr_app::add_slf_command);
  add(prtr_app::add_path_trace_command);
  add(prtr_app::add_compare_command);
  add(prtr_app::add_info_command);
  add(prtr_app::add_gl_info_command);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version exit 0; every other parse failure is a usage error.
    return app.exit(e) == 0 ? 0 : 2;
  }
  std::unique_ptr<tbb::global_control> thread_cap;
  if (threads > 0) {
    thread_cap = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                       std::size_t(threads));
  }
  try {
    for (CLI::App* sub : app.get_subcommands()) {
      prtr_app::sweep_command_folders(*sub);
      runners.at(sub)();
    }
  } catch (const prtr_app::UsageError& e) {
    std::fprintf(stderr, "prtr: usage error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "prtr: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
