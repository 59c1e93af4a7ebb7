#include "supersample_flag.h"

#include "flag_checks.h"

namespace prtr_app {

void add_supersample_flag(CLI::App* cmd, int& factor, const std::string& what, int max) {
  add_checked_option(
      cmd, "--supersample", factor,
      "Anti-aliasing of " + what + ": render N x N samples per pixel and box-filter (1: off)",
      integer_in(1, max));
}

}  // namespace prtr_app
