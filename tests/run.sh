#!/usr/bin/env bash
# The test command: installs what it needs, builds with warnings as errors, runs every
# test; then builds with AddressSanitizer + UndefinedBehaviorSanitizer and runs the tests
# again (except those labelled "slow", which pace in wall-clock time).
# usage: tests/run.sh            (from anywhere)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
"$root/.ci/install-deps.sh"
jobs=$(nproc)

cmake -S . -B build -DCMAKE_BUILD_TYPE=RelWithDebInfo -DLAGSIM_WERROR=ON >/dev/null
cmake --build build -j"$jobs"
(cd build && ctest --output-on-failure -j"$jobs" --timeout 300)

if [ "${LAGSIM_SKIP_SANITIZE:-0}" != 1 ]; then
  cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=Debug -DLAGSIM_WERROR=ON -DLAGSIM_SANITIZE=ON \
        -DLAGSIM_BENCH=OFF >/dev/null
  cmake --build build-asan -j"$jobs"
  (cd build-asan && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
     ctest --output-on-failure -j"$jobs" --timeout 600 -LE slow)
fi
