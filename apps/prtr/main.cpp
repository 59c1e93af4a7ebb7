// prtr: the command-line front end of the PRT engine. One binary, one subcommand per
// workflow; see README.md.
#include "commands.h"
#include "start_sweep.h"

#include <cstdio>
#include <exception>
#include <map>
#include <string>

int main(int argc, char** argv) {
  CLI::App app{"prtr: precomputed radiance transfer for glossy meshes (bake, compress, relight)"};
  app.set_version_flag("--version", "prtr 0.1.0");
  app.require_subcommand(1);
  app.failure_message(CLI::FailureMessage::simple);

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
  add(prtr_app::add_info_command);
  add(prtr_app::add_gl_info_command);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version exit 0; every other parse failure is a usage error.
    return app.exit(e) == 0 ? 0 : 2;
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
