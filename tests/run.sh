#!/usr/bin/env bash
# The test command: installs what it needs, then runs two passes and reports both.
#   1. gcc, warnings as errors, optimized: every test.
#   2. clang, warnings as errors, AddressSanitizer + UndefinedBehaviorSanitizer (with
#      float-cast-overflow) + libFuzzer: every test except those labelled "slow" (they
#      pace in wall-clock time), every kept fuzz input, and each fuzz target for
#      LAGSIM_FUZZ_SECONDS (default 20).
# The second pass runs even when the first failed; the exit status is non-zero when
# either failed, after both summaries.
# usage: tests/run.sh            (from anywhere)
#   LAGSIM_SKIP_SANITIZE=1  first pass only
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
"$root/.ci/install-deps.sh" || exit 1
jobs=$(nproc)
summaries=()
failed=0

# run_pass NAME BUILD_DIR "CTEST ARGS" CMAKE ARGS...
run_pass() {
  local name=$1 dir=$2 ctest_args=$3
  shift 3
  local log="$root/$dir/ctest.log" result
  echo "==== $name"
  if ! cmake -S . -B "$dir" "$@" >/dev/null || ! cmake --build "$dir" -j"$jobs"; then
    summaries+=("$name: BUILD FAILED")
    failed=1
    return
  fi
  # shellcheck disable=SC2086
  (cd "$dir" && ctest --output-on-failure -j"$jobs" $ctest_args) 2>&1 | tee "$log"
  if [ "${PIPESTATUS[0]}" -eq 0 ]; then
    result=$(grep -E "tests passed" "$log" | tail -1)
    summaries+=("$name: $result")
  else
    failed=1
    result=$(grep -E "tests passed|tests failed" "$log" | tail -1)
    summaries+=("$name: ${result:-ctest failed}"$'\n'"$(sed -n '/The following tests FAILED/,$p' "$log" | grep -E '^\s+[0-9]+ - ')")
  fi
}

run_pass "pass 1 (gcc -Werror)" build "--timeout 300" \
  -DCMAKE_C_COMPILER=gcc -DCMAKE_BUILD_TYPE=RelWithDebInfo -DLAGSIM_WERROR=ON

if [ "${LAGSIM_SKIP_SANITIZE:-0}" != 1 ]; then
  export ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1
  run_pass "pass 2 (clang ASan+UBSan+libFuzzer)" build-asan "--timeout 600 -LE slow" \
    -DCMAKE_C_COMPILER=clang -DCMAKE_BUILD_TYPE=Debug -DLAGSIM_WERROR=ON \
    -DLAGSIM_SANITIZE=ON -DLAGSIM_FUZZ=ON -DLAGSIM_BENCH=OFF
fi

echo "==== summary"
for s in "${summaries[@]}"; do echo "$s"; done
exit $failed
