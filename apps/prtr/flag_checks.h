// apps/prtr/flag_checks.h: CLI11 validators the commands share. CLI::Range lets NaN through
// (every comparison with NaN is false), and an infinite angle or exposure only fails deep in
// the pipeline with a message that does not name the flag, so floating-point flags are
// checked for finiteness where they are parsed: exit 2 naming the flag.
#pragma once

#include "commands.h"

#include "common/output_path.h"

#include <CLI/CLI.hpp>

#include <cmath>
#include <string>
#include <vector>

namespace prtr_app {

inline CLI::Validator finite_number() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        double value = 0;
        if (!CLI::detail::lexical_cast(text, value)) return "'" + text + "' is not a number";
        if (!std::isfinite(value)) return "'" + text + "' is not a finite number";
        return {};
      },
      "FINITE");
}

// Refuses, before any work, an output that would destroy an input, replace another output or
// replace a special file (common/output_path.h): a usage error naming the flag.
inline void check_outputs(const std::vector<common::NamedPath>& outputs,
                          const std::vector<common::NamedPath>& inputs) {
  if (const std::string problem = common::outputs_problem(outputs, inputs); !problem.empty())
    throw UsageError(problem);
}

}  // namespace prtr_app
