// cpca/src/splitmix.h (private): a small, portable generator (splitmix64) for seeded starts;
// std's distributions differ between standard libraries, so results would too.
#pragma once

#include <cstdint>

namespace cpca::detail {

// Uniform in [0, 1) with 53 random bits; advances `state`.
inline double next_uniform(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  z ^= z >> 31;
  return double(z >> 11) * 0x1.0p-53;
}

}  // namespace cpca::detail
