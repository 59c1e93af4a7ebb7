// apps/prtr/subprocess.h: runs the external tools prtr hands work to (ffmpeg, python3 for the
// plot) without a shell, so that file names with quotes or spaces reach them unchanged.
#pragma once

#include <string>
#include <vector>

namespace prtr_app {

// Runs argv[0] (searched on PATH) with the arguments and waits. Returns its exit status, or
// -1 when it could not be started (not installed) or died from a signal. With `silent`, its
// stdout and stderr go to /dev/null.
int run_program(const std::vector<std::string>& argv, bool silent = false);

}  // namespace prtr_app
