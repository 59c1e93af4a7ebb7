#!/usr/bin/env bash
# Set up, build, and run the whole test suite (GoogleTest suites and the CLI end-to-end
# test, through CTest).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cd build
ctest --output-on-failure -j "$(nproc)" "$@"
