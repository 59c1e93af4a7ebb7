// apps/prtr/supersample_flag.h: --supersample N, the one anti-aliasing flag of every command
// that writes frames (render/supersample.h): N x N samples per pixel, box-filtered; 1 is off.
#pragma once

#include <CLI/CLI.hpp>

#include <string>

namespace prtr_app {

inline constexpr int kDefaultSupersample = 2;

// `what` says what is anti-aliased; `max` bounds N.
void add_supersample_flag(CLI::App* cmd, int& factor,
                          const std::string& what = "the written frames", int max = 8);

}  // namespace prtr_app
