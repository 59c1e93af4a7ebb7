// common/format_bytes.h: byte counts as people read them in messages and reports.
#pragma once

#include <cstdint>
#include <string>

namespace common {

// "512 B", "34.0 MiB", "1.2 GiB" (binary units, one decimal above bytes).
std::string format_bytes(std::uint64_t bytes);

}  // namespace common
