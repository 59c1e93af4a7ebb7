#!/usr/bin/env bash
# Builds everything except the benchmarks with AddressSanitizer and UndefinedBehaviorSanitizer
# in its own directory (build-sanitize) and runs the whole CTest suite there, leak detection
# on. Exits non-zero when the build fails, any test fails, or a sanitizer reports anything
# (UBSan halts on its first finding, so a report is a failed test).
#
#   bash scripts/sanitize.sh            # gcc (its sanitizer runtimes come with build-essential)
#   PRTR_SANITIZE_CC=clang bash scripts/sanitize.sh   # clang 14 (installed when missing)
#
# Environment: PRTR_SANITIZE_DIR (build directory), PRTR_JOBS (build and test parallelism,
# default nproc); extra arguments go to ctest (e.g. -R meshes to take a subset).
set -euo pipefail
cd "$(dirname "$0")/.."

compiler=${PRTR_SANITIZE_CC:-gcc}
dir=${PRTR_SANITIZE_DIR:-build-sanitize}
jobs=${PRTR_JOBS:-$(nproc)}

need_root() {
  if [[ $(id -u) -ne 0 ]]; then
    command -v sudo >/dev/null || { echo "sanitize: need root or sudo to install $*" >&2; exit 1; }
    echo sudo
  fi
}

case $compiler in
  gcc) cc=gcc cxx=g++ ;;
  clang)
    if ! command -v clang++ >/dev/null ||
       ! dpkg-query -W -f='${Status}' libclang-rt-14-dev 2>/dev/null | grep -q "install ok installed"; then
      echo "sanitize: installing clang libclang-rt-14-dev" >&2
      sudo_cmd=$(need_root clang)
      export DEBIAN_FRONTEND=noninteractive
      $sudo_cmd apt-get update -qq
      $sudo_cmd apt-get install -y -qq --no-install-recommends clang libclang-rt-14-dev >/dev/null
    fi
    cc=clang cxx=clang++ ;;
  *) echo "sanitize: PRTR_SANITIZE_CC must be gcc or clang, not '$compiler'" >&2; exit 2 ;;
esac

# -O1: the usual sanitizer trade-off, a third of -O2's compile time on this code (Eigen
# templates) while keeping the suite's run time within a few times the Release one.
flags="-O1 -g1 -DNDEBUG -fsanitize=address,undefined -fno-omit-frame-pointer"
# GCC's -Wmaybe-uninitialized misfires inside libstdc++'s <regex> once the sanitizers
# instrument it (GCC's manual warns that the sanitizers cause such false positives); the
# Release build keeps the warning.
[[ $compiler == gcc ]] && flags+=" -Wno-maybe-uninitialized"
# -no-pie: an instrumented position-independent prtr (250 MB) spends half of every start
# applying its relocations, and the suite starts it some thousand times (the CLI flag sweep
# alone 727); linked at a fixed address it starts in half the time (0.50 -> 0.25 s). Only
# executables: the image module stays position independent.
link="-fsanitize=address,undefined -no-pie"
start=$(date +%s)
CC=$cc CXX=$cxx cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=Sanitize \
  -DCMAKE_C_FLAGS_SANITIZE="$flags" -DCMAKE_CXX_FLAGS_SANITIZE="$flags" \
  -DCMAKE_EXE_LINKER_FLAGS_SANITIZE="$link" \
  -DPRTR_BUILD_BENCH=OFF -DPRTR_BUILD_TESTS=ON >/dev/null
cmake --build "$dir" -j "$jobs"
built=$(date +%s)

supp=$PWD/tests/lsan_mesa.supp
# intercept_tls_get_addr=0: up to GCC 13 (Debian 12 has 12) the runtime's __tls_get_addr hook
# takes a dynamic TLS block that happens to start 16 bytes past a page boundary for one with a
# pre-2.25 glibc header and reads a bogus range from the two words before it; the leak checker's
# tracer then segfaults at exit ("Tracer caught signal 11"), which with abort_on_error is a
# SIGABRT after the test has passed. Fixed upstream in LLVM 17 (D147459).
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:strict_string_checks=1:intercept_tls_get_addr=0
export LSAN_OPTIONS=suppressions=$supp:print_suppressions=0
export UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
status=0
(cd "$dir" && ctest --output-on-failure -j "$jobs" "$@") || status=$?
# LeakSanitizer stops every thread with ptrace at exit, and its tracer can itself crash ("Tracer
# caught signal 11 ... LeakSanitizer has encountered a fatal error") after a test has passed:
# a fault of the checker, not a finding, seen once in some twenty runs of the suite, in a GL
# test whose repeats all pass, and since in the CLI tests, after `prtr overdraw` (the CLI tests
# take 5-13 minutes each under the sanitizers on the 2-core machine, so rerunning one adds
# much of the suite again). They retry the one command instead (tests/cli_lib.sh, run). A
# `prtr view` server in view.browser once exited on SIGABRT after SIGTERM with every check
# passed, most likely the same crash (abort_on_error), but its stderr was not in the log; the
# view tests now print it when the server exits non-zero. Here, only when no sanitizer
# reported anything, the failed tests run once more, and the retry is announced.
log=$dir/Testing/Temporary/LastTest.log
if ((status != 0)) && [[ -f $log ]] &&
   grep -q "LeakSanitizer has encountered a fatal error" "$log" &&
   ! grep -qE "ERROR: (AddressSanitizer|LeakSanitizer: detected)|runtime error:|\[  FAILED  \]" "$log"; then
  echo "sanitize: LeakSanitizer's tracer crashed in a test that passed; running the failed" \
    "tests once more:" >&2
  cat "$dir/Testing/Temporary/LastTestsFailed.log" >&2 || true
  status=0
  (cd "$dir" && ctest --output-on-failure --rerun-failed) || status=$?
fi
done_at=$(date +%s)
echo "sanitize: $compiler, build $((built - start)) s, tests $((done_at - built)) s," \
  "$([[ $status == 0 ]] && echo passed || echo FAILED)" >&2
exit $status
