#!/usr/bin/env bash
# tests/run.sh refuses what it cannot do, before it installs or builds anything: a --tier
# or --label without a value, a tier tests/common/tiers.cmake does not define, --sanitize
# alone (it selects pass 2's build for --tier or --label); each exits 2 with a line that
# says why. Every tier of tiers.cmake is taken (run with --help after it: nothing runs).
#   run_usage.sh SOURCE_DIR
src=$1
fails=0
expect() {  # expect WHAT ARGS...: exit 2 and WHAT on stderr
  local what=$1 out rc
  shift
  out=$("$src/tests/run.sh" "$@" 2>&1 >/dev/null)
  rc=$?
  if [ $rc -eq 2 ] && [[ $out == *"$what"* ]]; then
    echo "ok:   run.sh $* -> exit 2, '$out'"
  else
    echo "FAIL: run.sh $* -> exit $rc, '$out' (expected exit 2 and '$what')"
    fails=$((fails + 1))
  fi
}
expect "--tier takes a value" --tier
expect "--label takes a value" --label
expect "--label takes a value" --label ""
expect "no tier 'quik'" --tier quik
expect "no tier 'slo'" --tier quick,slo
expect "--sanitize goes with --tier or --label" --sanitize
expect "--sanitize goes with --tier or --label" --full --sanitize
expect "unknown argument '--fast'" --fast
tiers=$(sed -n 's/^set(LAGSIM_TIERS \(.*\))$/\1/p' "$src/tests/common/tiers.cmake")
[ -n "$tiers" ] || { echo "FAIL: no LAGSIM_TIERS in tiers.cmake"; fails=$((fails + 1)); }
for t in $tiers; do
  if "$src/tests/run.sh" --tier "$t" --help >/dev/null 2>&1; then
    echo "ok:   --tier $t taken"
  else
    echo "FAIL: --tier $t refused"
    fails=$((fails + 1))
  fi
done
echo "run_usage: $fails failed"
[ $fails -eq 0 ]
