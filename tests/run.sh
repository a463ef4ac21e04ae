#!/usr/bin/env bash
# The test command. Installs what the tests need when it is missing (.ci/install-deps.sh
# tests; under CI=true, ci), builds, runs ctest, and prints a summary per pass.
#
#   tests/run.sh                the quick tier (a developer's loop): gcc -Werror build,
#                               every test of the tier quick (docs/testing.md, "Tiers")
#   tests/run.sh --full         what CI runs (.ci/run), in three passes:
#                                1. gcc, -Werror, optimized (build/): every test;
#                                2. clang, -Werror, ASan + UBSan (with float-cast-overflow)
#                                   + libFuzzer (build-asan/): every test but the tier slow
#                                   (no bench or package test is made there), and each
#                                   fuzz target for LAGSIM_FUZZ_SECONDS (default 20);
#                                3. gcc, -Werror, Release (build-release/): built, not run.
#   tests/run.sh --tier T,...   those tiers of pass 1 (e.g. --tier quick,wallclock)
#   tests/run.sh --label L      ctest -L L in pass 1 (a regular expression, as ctest takes it)
#   tests/run.sh --sanitize ... pass 2's build instead of pass 1's (with --tier or --label)
#
# Inside a pass ctest runs 3 x cores tests at once, but the tiers that compute take a slot
# of a "cpu" pool of one slot per core (tests/common/tiers.cmake): the tests that mostly
# wait run beside them. Every pass runs even when one before failed; the exit status is
# non-zero when any failed, after every summary.
#   LAGSIM_SKIP_SANITIZE=1   --full without pass 2
#   LAGSIM_JOBS=N            ctest -j N (default 3 x cores); LAGSIM_CPUS=N the pool's slots
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root" || exit 2

mode=quick
select=()
sanitize=0
while [ $# -gt 0 ]; do
  case $1 in
    --full) mode=full ;;
    --quick) mode=quick ;;
    --tier) mode=some; shift; select=(-L "^(${1//,/|})\$") ;;
    --label) mode=some; shift; select=(-L "$1") ;;
    --sanitize) sanitize=1 ;;
    -h | --help) sed -n '2,/^set -uo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    *) echo "tests/run.sh: unknown argument '$1' (--help)" >&2; exit 2 ;;
  esac
  shift
done

"$root/.ci/install-deps.sh" "$([ "${CI:-}" = true ] && echo ci || echo tests)" || exit 1
cores=$(nproc)
cpus=${LAGSIM_CPUS:-$cores}
jobs=${LAGSIM_JOBS:-$((3 * cores))}
summaries=()
failed=0

# run_pass NAME BUILD_DIR "CTEST ARGS" CMAKE ARGS...   (CTEST ARGS "-" : build only)
run_pass() {
  local name=$1 dir=$2 ctest_args=$3
  shift 3
  local log="$root/$dir/ctest.log" result start=$SECONDS
  echo "==== $name"
  if ! cmake -S . -B "$dir" "$@" >/dev/null || ! cmake --build "$dir" -j"$cores"; then
    summaries+=("$name: BUILD FAILED")
    failed=1
    return
  fi
  if [ "$ctest_args" = - ]; then
    summaries+=("$name: built, warning-free ($((SECONDS - start)) s)")
    return
  fi
  printf '{"version": {"major": 1, "minor": 0}, "local": [{"cpu": [{"id": "0", "slots": %d}]}]}\n' \
    "$cpus" >"$root/$dir/resources.json"
  # shellcheck disable=SC2086
  (cd "$dir" && ctest --output-on-failure -j"$jobs" --resource-spec-file resources.json \
     $ctest_args) 2>&1 | tee "$log"
  if [ "${PIPESTATUS[0]}" -eq 0 ]; then
    result=$(grep -E "tests passed" "$log" | tail -1)
    summaries+=("$name: $result ($((SECONDS - start)) s)")
  else
    failed=1
    result=$(grep -E "tests passed|tests failed" "$log" | tail -1)
    summaries+=("$name: ${result:-ctest failed} ($((SECONDS - start)) s)"$'\n'"$(sed -n '/The following tests FAILED/,$p' "$log" | grep -E '^\s+[0-9]+ - ')")
  fi
}

gcc_args=(-DCMAKE_C_COMPILER=gcc -DCMAKE_BUILD_TYPE=RelWithDebInfo -DLAGSIM_WERROR=ON)
asan_args=(-DCMAKE_C_COMPILER=clang -DCMAKE_BUILD_TYPE=Debug -DLAGSIM_WERROR=ON
           -DLAGSIM_SANITIZE=ON -DLAGSIM_FUZZ=ON -DLAGSIM_BENCH=OFF)
asan_env() { export ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1; }

case $mode in
  quick)
    run_pass "quick tier (gcc -Werror)" build "--timeout 300 -L ^quick\$" "${gcc_args[@]}" ;;
  some)
    if [ $sanitize -eq 1 ]; then
      asan_env
      run_pass "clang ASan+UBSan+libFuzzer: ${select[*]}" build-asan "--timeout 600 ${select[*]}" \
        "${asan_args[@]}"
    else
      run_pass "gcc -Werror: ${select[*]}" build "--timeout 300 ${select[*]}" "${gcc_args[@]}"
    fi ;;
  full)
    run_pass "pass 1 (gcc -Werror)" build "--timeout 300" "${gcc_args[@]}"
    if [ "${LAGSIM_SKIP_SANITIZE:-0}" != 1 ]; then
      asan_env
      run_pass "pass 2 (clang ASan+UBSan+libFuzzer)" build-asan \
        "--timeout 600 -LE ^slow\$" "${asan_args[@]}"
    fi
    run_pass "pass 3 (gcc -Werror Release, build only)" build-release - \
      -DCMAKE_C_COMPILER=gcc -DCMAKE_BUILD_TYPE=Release -DLAGSIM_WERROR=ON ;;
esac

echo "==== summary"
for s in "${summaries[@]}"; do echo "$s"; done
exit $failed
