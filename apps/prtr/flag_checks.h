// apps/prtr/flag_checks.h: the validators every command's numeric flags use, so that every
// range error reads the same: the flag, the range a person would write and the value given
// ("--clusters: must be an integer between 1 and 65536, got '0'"). Each parses the text
// itself: CLI11 would turn an empty value into 0, wrap "-1" into 2^64 - 1 for an unsigned
// flag, let NaN through a range (every comparison with NaN is false) and print a range's
// unbounded end as a 300-digit number. Exit 2 naming the flag.
#pragma once

#include "commands.h"

#include "common/output_path.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

namespace prtr_app {

namespace detail {

inline std::string quoted(const std::string& text) {
  return "'" + text + "'";
}

// Whole-text integer parse; nullopt for empty text, trailing characters or overflow.
inline std::optional<long long> parse_integer(const std::string& text) {
  long long value = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (text.empty() || ec != std::errc() || ptr != end) return std::nullopt;
  return value;
}

// "%g" with up to 9 significant digits: 1e+06, 0.01, 65536.
inline std::string number_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

}  // namespace detail

// An integer in [lo, hi].
inline CLI::Validator integer_in(long long lo, long long hi) {
  const std::string range =
      "an integer between " + std::to_string(lo) + " and " + std::to_string(hi);
  return CLI::Validator(
      [lo, hi, range](std::string& text) -> std::string {
        const auto v = detail::parse_integer(text);
        if (!v || *v < lo || *v > hi) return "must be " + range + ", got " + detail::quoted(text);
        return {};
      },
      "INT in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
}

// Any unsigned 64-bit integer (seeds): digits only, so "-1" is refused rather than wrapped.
inline CLI::Validator unsigned_integer() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        std::uint64_t value = 0;
        const char* end = text.data() + text.size();
        const auto [ptr, ec] = std::from_chars(text.data(), end, value);
        if (text.empty() || ec != std::errc() || ptr != end)
          return "must be a whole number from 0 to 2^64 - 1, got " + detail::quoted(text);
        return {};
      },
      "UINT64");
}

// A finite real number in [lo, hi].
inline CLI::Validator number_in(double lo, double hi) {
  const std::string range =
      "a number between " + detail::number_text(lo) + " and " + detail::number_text(hi);
  return CLI::Validator(
      [lo, hi, range](std::string& text) -> std::string {
        double value = 0;
        const char* end = text.data() + text.size();
        const auto [ptr, ec] = std::from_chars(text.data(), end, value);
        if (text.empty() || ec != std::errc() || ptr != end || !std::isfinite(value) ||
            value < lo || value > hi)
          return "must be " + range + ", got " + detail::quoted(text);
        return {};
      },
      "NUMBER in [" + detail::number_text(lo) + ", " + detail::number_text(hi) + "]");
}

// Angles in degrees: a million degrees is still exact enough to turn by, and bounds the
// products that follow.
inline CLI::Validator angle_degrees() {
  return number_in(-1e6, 1e6);
}

// Refuses, before any work, an output that would destroy an input, replace another output or
// replace a special file (common/output_path.h): a usage error naming the flag.
inline void check_outputs(const std::vector<common::NamedPath>& outputs,
                          const std::vector<common::NamedPath>& inputs) {
  if (const std::string problem = common::outputs_problem(outputs, inputs); !problem.empty())
    throw UsageError(problem);
}

// "0.5,0.4,0.3" as numbers (std::stod's syntax, each item whole); nullopt if an item is not
// a number. Ranges and counts are the caller's to check.
inline std::optional<std::vector<double>> parse_number_list(const std::string& text) {
  std::vector<double> values;
  std::size_t begin = 0;
  while (begin <= text.size()) {
    const std::size_t comma = std::min(text.find(',', begin), text.size());
    const std::string item = text.substr(begin, comma - begin);
    try {
      std::size_t used = 0;
      values.push_back(std::stod(item, &used));
      if (used != item.size()) return std::nullopt;
    } catch (const std::exception&) {
      return std::nullopt;
    }
    begin = comma + 1;
  }
  return values;
}

// A flag checked by `check` whose default shows in --help: the form most flags take.
template <class T>
CLI::Option* add_checked_option(CLI::App* cmd, const std::string& name, T& value,
                                const std::string& help, const CLI::Validator& check) {
  return cmd->add_option(name, value, help)->check(check)->capture_default_str();
}

}  // namespace prtr_app
