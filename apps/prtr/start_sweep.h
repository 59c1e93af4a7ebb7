// apps/prtr/start_sweep.h: the temporaries a killed run left behind are removed when the next
// command starts, from every folder that command writes into, before it writes anything.
#pragma once

#include <CLI/CLI.hpp>

namespace prtr_app {

// Sweeps (common::sweep_stale_temporaries) the folders of the parsed subcommand's outputs:
// the folders of its -o/--output and --png files, its --out folder and its --cache folder
// (the default cache when the command has --cache and none was given). Folders that do not
// exist yet are left alone. Each removed file is named on stderr.
void sweep_command_folders(const CLI::App& command);

}  // namespace prtr_app
