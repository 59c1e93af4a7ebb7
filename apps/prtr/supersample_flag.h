// apps/prtr/supersample_flag.h: --supersample N, the one anti-aliasing flag of every command
// that writes frames (render/supersample.h): N x N samples per pixel, box-filtered; 1 is off.
#pragma once

#include <CLI/CLI.hpp>

namespace prtr_app {

inline constexpr int kDefaultSupersample = 2;

void add_supersample_flag(CLI::App* cmd, int& factor);

}  // namespace prtr_app
