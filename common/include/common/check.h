// common/check.h: invariant checks for debug builds, in the style of pbrt's DCHECK.
//
// Two kinds of checks, kept apart on purpose:
//  - Bad input (a damaged file, a flag out of range, a mesh without frames) is always
//    checked and reported with a typed exception whose message names the input and the fix
//    (docs/ARCHITECTURE.md). Those stay plain `if (...) throw ...`.
//  - An internal invariant (a buffer the code itself sized, a sorted order it built) can only
//    fail through a bug. PRTR_DCHECK states it; Debug builds abort with the expression and its
//    place, Release builds (NDEBUG) compile it out, so hot loops pay nothing.
#pragma once

#include <cstdio>
#include <cstdlib>

#ifdef NDEBUG
// sizeof keeps the expression compiled (names checked, no unused-variable warnings) but never
// evaluates it.
#define PRTR_DCHECK(condition) static_cast<void>(sizeof(static_cast<bool>(condition)))
#else
#define PRTR_DCHECK(condition) \
  ((condition) ? static_cast<void>(0) : ::common::dcheck_failed(#condition, __FILE__, __LINE__))
#endif

namespace common {

[[noreturn]] inline void dcheck_failed(const char* condition, const char* file, int line) {
  std::fprintf(stderr, "%s:%d: internal invariant failed: %s (a bug in prtr)\n", file, line,
               condition);
  std::abort();
}

}  // namespace common
