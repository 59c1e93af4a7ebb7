// common/json.h: the one place every JSON output of prtr is serialised, so that
// all of them treat text the same way.
#pragma once

#include <nlohmann/json.hpp>

#include <string>

namespace common {

// Insertion order keeps the keys in the order the schemas in the README list them.
using Json = nlohmann::ordered_json;

// One line, no trailing newline. File names are bytes on Linux and need not be UTF-8, while
// JSON text must be: invalid sequences become U+FFFD instead of making the dump throw, so a
// strange file name costs a readable character, never the report.
inline std::string dump_json(const Json& value) {
  return value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace common
