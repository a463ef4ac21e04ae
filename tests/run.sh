#!/usr/bin/env bash
# The test command. Installs what the tests need when it is missing (.ci/install-deps.sh
# tests; under CI=true, ci), builds, runs ctest, and prints a summary per pass.
#
#   tests/run.sh                the quick tier (a developer's loop): gcc -Werror Release
#                               build, every test of the tier quick (docs/testing.md, "Tiers")
#   tests/run.sh --full         what CI runs (.ci/run), in two passes:
#                                1. gcc, -Werror, Release (build/): every test;
#                                2. clang, -Werror, -O1, ASan + UBSan (float-cast-overflow
#                                   too) + libFuzzer (build-asan/): every test but the tier slow
#                                   (no bench or package test is made there), and each
#                                   fuzz target for LAGSIM_FUZZ_SECONDS (default 25).
#   tests/run.sh --tier T,...   those tiers of pass 1 (e.g. --tier quick,wallclock)
#   tests/run.sh --label L      ctest -L L in pass 1 (a regular expression, as ctest takes it)
#   tests/run.sh --sanitize ... pass 2's build instead of pass 1's (with --tier or --label)
#
# A pass is one ctest, -j (100 x cores): each test takes its tier's share of a core
# (PROCESSORS, tests/common/tiers.cmake's LAGSIM_TIER_RUN), so many tests that wait run
# beside few that compute. Every pass runs even when one before failed; the exit status is
# non-zero when any failed, after every summary.
#   LAGSIM_SKIP_SANITIZE=1   --full without pass 2
#   LAGSIM_TEST_CORES=N      the cores a pass plans for (default: nproc)
#   LAGSIM_FUZZ_SECONDS=S    each fuzz target's time in pass 2 (kept in build-asan/'s cache)
# A pass's whole ctest output: BUILD_DIR/ctest.log (the summary names it); one test by
# name: cd build && ctest -R '^NAME$' --output-on-failure.
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root" || exit 2

mode=quick
select=""
sanitize=0
usage() { echo "tests/run.sh: $* (--help)" >&2; exit 2; }
# the tiers: tests/common/tiers.cmake's LAGSIM_TIERS
tiers=$(sed -n 's/^set(LAGSIM_TIERS \(.*\))$/\1/p' "$root/tests/common/tiers.cmake")
while [ $# -gt 0 ]; do
  case $1 in
    --full) mode=full ;;
    --quick) mode=quick ;;
    --tier | --label)
      [ $# -ge 2 ] && [ -n "$2" ] || usage "$1 takes a value"
      mode=some
      if [ "$1" = --tier ]; then
        for t in ${2//,/ }; do
          [[ " $tiers " == *" $t "* ]] || usage "no tier '$t': the tiers are $tiers"
        done
        select="^(${2//,/|})\$"
      else
        select=$2
      fi
      shift ;;
    --sanitize) sanitize=1 ;;
    -h | --help) sed -n '2,/^set -uo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    *) usage "unknown argument '$1'" ;;
  esac
  shift
done
[ $sanitize -eq 0 ] || [ $mode = some ] || usage "--sanitize goes with --tier or --label"

"$root/.ci/install-deps.sh" "$([ "${CI:-}" = true ] && echo ci || echo tests)" || exit 1
cores=$(nproc)
plan=${LAGSIM_TEST_CORES:-$cores}
case $plan in
  '' | *[!0-9]* | 0*) echo "tests/run.sh: LAGSIM_TEST_CORES='$plan': expected a whole number of cores, 1 or more" >&2
                      exit 2 ;;
esac
jobs=$((100 * plan))  # hundredths of a core (PROCESSORS)
summaries=()
failed=0
total_passed=0
total_failed=0

# build DIR CMAKE ARGS...: configures and builds DIR (-j cores); its status in DIR/build.rc
# and its seconds in DIR/build.s
build() {
  local dir=$1 t0=$SECONDS rc=0
  shift
  mkdir -p "$dir"
  echo "(configuring $dir: cmake's output in $dir/configure.log; then building it)"
  cmake -S . -B "$dir" "$@" >"$dir/configure.log" 2>&1 && cmake --build "$dir" -j"$cores" ||
    { rc=1; tail -30 "$dir/configure.log"; }
  echo $rc >"$dir/build.rc"
  echo $((SECONDS - t0)) >"$dir/build.s"
  return $rc
}

# build_behind DIR CMAKE ARGS...: the next pass's build, started now at a low priority
# (nice 10) beside this pass's tests, its output in DIR/build.log: it takes the CPU the
# tests leave, and a test that waits on the wall clock holds beside busy processes anyway
# (as it must on a loaded machine). wait_built DIR waits for it.
build_behind() {
  local dir=$1
  mkdir -p "$dir"
  rm -f "$dir/build.rc"
  (nice -n 10 bash -c "$(declare -f build); cores=$cores; build \"\$@\"" build "$@" \
     >"$dir/build.log" 2>&1) &
}
wait_built() {
  local dir=$1
  while [ ! -f "$dir/build.rc" ]; do
    sleep 1
  done
  [ "$(cat "$dir/build.rc")" = 0 ] || { tail -50 "$dir/build.log"; return 1; }
}

# run_pass NAME BUILD_DIR TIMEOUT SELECT EXCLUDE BUILT CMAKE ARGS...
#   SELECT: a label regex the tests must match ("" all); EXCLUDE: tiers left out ("" none);
#   TIMEOUT "-": build only; BUILT "behind": built by build_behind (waited for here), else
#   built here. One ctest, its output shown as it runs and kept in BUILD_DIR/ctest.log.
run_pass() {
  local name=$1 dir=$2 timeout=$3 sel=$4 excl=$5 built=$6
  shift 6
  local start=$SECONDS result rc=0
  echo "==== $name"
  local ok=0
  if [ "$built" = behind ]; then
    wait_built "$dir" || ok=1
    echo "(built beside the pass before: $(cat "$dir/build.s" 2>/dev/null) s; $dir/build.log)"
  else
    build "$dir" "$@" || ok=1
  fi
  if [ $ok -ne 0 ]; then
    summaries+=("$name: BUILD FAILED")
    failed=1
    return
  fi
  if [ "$timeout" = - ]; then
    summaries+=("$name: built, warning-free ($(cat "$dir/build.s") s of build)")
    return
  fi
  # --no-tests=error: a selection that matches no test fails, it does not pass
  local args=(--output-on-failure --no-tests=error -j"$jobs" --timeout "$timeout")
  [ -n "$sel" ] && args+=(-L "$sel")
  [ -n "$excl" ] && args+=(-LE "^(${excl// /|})\$")
  (cd "$dir" && ctest "${args[@]}") 2>&1 | tee "$root/$dir/ctest.log"
  rc=${PIPESTATUS[0]}
  local log="$root/$dir/ctest.log" counts
  counts=$(sed -n 's/.*tests passed, \([0-9]*\) tests\{0,1\} failed out of \([0-9]*\).*/\1 \2/p' "$log" | tail -1)
  if [ -n "$counts" ]; then
    total_failed=$((total_failed + ${counts% *}))
    total_passed=$((total_passed + ${counts#* } - ${counts% *}))
  fi
  if [ "$rc" -eq 0 ]; then
    result=$(grep -E "tests passed" "$log" | tail -1)
    summaries+=("$name: $result ($(sed -n 's/^Total Test time (real) = *//p' "$log"); $dir/ctest.log)")
  else
    failed=1
    result=$(grep -E "tests passed|tests failed" "$log" | tail -1)
    summaries+=("$name: ${result:-ctest failed} ($dir/ctest.log)"$'\n'"$(sed -n '/The following tests FAILED/,$p' "$log" | grep -E '^\s+[0-9]+ - ')")
  fi
  summaries+=("$name: $((SECONDS - start)) s")
}

# Release: what the package ships (-O3, NDEBUG), and the optimizer's warnings that -O2
# does not find (a format truncation gcc sees only when a helper is inlined)
gcc_args=(-DCMAKE_C_COMPILER=gcc -DCMAKE_BUILD_TYPE=Release -DLAGSIM_WERROR=ON)
# -O1 with the sanitizers (as AddressSanitizer's documentation advises): the same checks,
# its physics tests 2.1 to 2.3 times as fast as at -O0 (test_hard chaos 20.7 s -> 9.1 s,
# test_accuracy_cost dipc_1e-04 11.5 s -> 5.5 s); assertions stay (no NDEBUG)
asan_args=(-DCMAKE_C_COMPILER=clang -DCMAKE_BUILD_TYPE=Debug "-DCMAKE_C_FLAGS_DEBUG=-g -O1"
           -DLAGSIM_WERROR=ON -DLAGSIM_SANITIZE=ON -DLAGSIM_FUZZ=ON -DLAGSIM_BENCH=OFF
           ${LAGSIM_FUZZ_SECONDS:+-DLAGSIM_FUZZ_SECONDS=$LAGSIM_FUZZ_SECONDS})
asan_env() { export ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1; }

case $mode in
  quick)
    run_pass "quick tier (gcc -Werror Release)" build 300 "^quick\$" "" here "${gcc_args[@]}" ;;
  some)
    if [ $sanitize -eq 1 ]; then
      asan_env
      run_pass "clang ASan+UBSan+libFuzzer: $select" build-asan 600 "$select" "" here "${asan_args[@]}"
    else
      run_pass "gcc -Werror Release: $select" build 300 "$select" "" here "${gcc_args[@]}"
    fi ;;
  full)
    # pass 1's build first; pass 2's behind pass 1's tests, at a low priority
    echo "==== pass 1's build"
    build build "${gcc_args[@]}"
    rm -f build-asan/build.rc
    [ "${LAGSIM_SKIP_SANITIZE:-0}" != 1 ] && build_behind build-asan "${asan_args[@]}"
    run_pass "pass 1 (gcc -Werror Release)" build 300 "" "" here "${gcc_args[@]}"
    if [ "${LAGSIM_SKIP_SANITIZE:-0}" != 1 ]; then
      asan_env
      run_pass "pass 2 (clang ASan+UBSan+libFuzzer)" build-asan 600 "" "slow" behind
    fi ;;
esac

echo "==== summary"
for s in "${summaries[@]}"; do echo "$s"; done
echo "tests: $total_passed passed, $total_failed failed"
exit $failed
