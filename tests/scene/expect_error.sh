#!/bin/bash
# A scene that must be refused before anything runs: exit code 2, the expected message on
# stderr, nothing on stdout.
#
#   expect_error.sh LAGSIMD FIXTURE.yaml
#       expectations from the fixture's own comments:
#         "# expect-at: L:C"   the message starts with "FIXTURE.yaml:L:C: "
#         "# expect: TEXT"     TEXT appears in the message (repeatable)
#   expect_error.sh LAGSIMD CONFIG.yaml --expect TEXT [--expect TEXT ...] -- [lagsimd args]
#       for --set and command-line cases
set -u
lagsimd=$1 config=$2
shift 2
prefix="" expects=() args=()
if [ $# -eq 0 ]; then
    at=$(sed -n 's/^# expect-at: //p' "$config")
    [ -n "$at" ] && prefix="$config:$at: "
    while IFS= read -r line; do expects+=("$line"); done < <(sed -n 's/^# expect: //p' "$config")
else
    while [ $# -gt 0 ]; do
        case $1 in
        --expect) expects+=("$2"); shift 2 ;;
        --) shift; args=("$@"); break ;;
        *) echo "expect_error.sh: bad argument $1" >&2; exit 2 ;;
        esac
    done
fi
if [ ${#expects[@]} -eq 0 ] && [ -z "$prefix" ]; then
    echo "FAIL: no expectations given for $config" >&2
    exit 1
fi

out=$(mktemp) err=$(mktemp)
trap 'rm -f "$out" "$err"' EXIT
# --offline --csv -: if the scene were wrongly accepted, CSV rows would appear on stdout
"$lagsimd" --config "$config" --offline --duration 0.05 --csv - "${args[@]}" >"$out" 2>"$err"
rc=$?
fail=0
if [ $rc -ne 2 ]; then echo "FAIL: exit code $rc, expected 2"; fail=1; fi
if [ -s "$out" ]; then echo "FAIL: something ran (stdout not empty)"; fail=1; fi
msg=$(cat "$err")
if [ -n "$prefix" ] && [[ "$msg" != "$prefix"* ]]; then
    echo "FAIL: message does not start with '$prefix'"; fail=1
fi
for e in "${expects[@]}"; do
    if [[ "$msg" != *"$e"* ]]; then echo "FAIL: message lacks '$e'"; fail=1; fi
done
if [ $(printf '%s\n' "$msg" | wc -l) -ne 1 ]; then
    echo "FAIL: expected exactly one line on stderr"; fail=1
fi
echo "stderr: $msg"
exit $fail
