#!/bin/bash
# lagsimd's command line: --help documents every option and exits 0, --version exits 0,
# usage errors exit 2 with a message and run nothing. Usage: cli.sh LAGSIMD SCENE
set -u
lagsimd=$1 scene=$2
fail=0
help=$("$lagsimd" --help); rc=$?
if [ $rc -ne 0 ]; then echo "FAIL: --help exit $rc"; fail=1; fi
for opt in --config --set --duration --offline --csv --replay --quiet --help --version; do
    if [[ "$help" != *"$opt"* ]]; then echo "FAIL: --help does not mention $opt"; fail=1; fi
done
v=$("$lagsimd" --version); rc=$?
if [ $rc -ne 0 ] || [[ "$v" != "lagsimd "[0-9]* ]]; then echo "FAIL: --version ($rc): $v"; fail=1; fi

usage() { # usage EXPECTED_FRAGMENT ARGS...
    local want=$1; shift
    local out err rc
    # a bounded wait: an argument that is wrongly accepted may start a server
    err=$(timeout 10 "$lagsimd" "$@" 2>&1 >/dev/null); rc=$?
    out=$(timeout 10 "$lagsimd" "$@" 2>/dev/null)
    if [ $rc -ne 2 ]; then echo "FAIL: '$*' exit $rc, expected 2"; fail=1
    elif [[ "$err" != *"$want"* ]]; then echo "FAIL: '$*': '$err' lacks '$want'"; fail=1
    elif [ -n "$out" ]; then echo "FAIL: '$*' wrote to stdout"; fail=1
    else echo "ok: $* -> $want"; fi
}
usage "--config FILE is required" --offline --duration 1
usage "unknown option '--bogus'" --config "$scene" --bogus
usage "option --duration needs a value" --config "$scene" --duration
usage "--duration: expected a number of seconds from 0 to 1e9, got 'abc'" --config "$scene" --offline --duration abc
usage "--duration: expected a number of seconds from 0 to 1e9, got 'nan'" --config "$scene" --offline --duration nan
# durations whose tick count would overflow or lose its last digits, and numbers strtod
# takes but a scene would not
for d in 1e300 1e16 -1 0x10 inf 1e999 "5 " ""; do
    usage "--duration: expected a number of seconds from 0 to 1e9, got '$d'" --config "$scene" --offline --duration "$d"
    usage "--duration: expected a number of seconds from 0 to 1e9, got '$d'" --config "$scene" --duration "$d"
done
# the option at fault is named, also inside a cluster of short options
usage "unknown option '-z'" -zq --config "$scene"
usage "unknown option '-z'" -qz --config "$scene"
usage "unknown option '-z'" --config "$scene" -qz --offline
usage "option -c needs a value" -qc
usage "option --config needs a value" --conf
usage "ambiguous option '--c' (--config, --csv, --cost)" --c "$scene"
usage "option --help takes no value" --help=yes
usage "option --offline takes no value" --config "$scene" --offline=1 --duration 1
usage "unknown option '--bogus'" --config "$scene" --bogus=1
usage "--csv needs --offline" --config "$scene" --csv -
usage "--offline needs --duration" --config "$scene" --offline --csv -
usage "--offline and --replay exclude each other" --config "$scene" --offline --duration 1 --replay x.lcm
usage "unexpected argument 'extra'" --config "$scene" --offline --duration 1 extra
usage "--set x: expected key.path=value" --config "$scene" --offline --duration 1 --csv - --set x
usage "cannot open scene file" --config /nonexistent/scene.yaml --offline --duration 1 --csv -

# LCM_DEFAULT_URL gets the scene's checks when the scene has no lcm.url: a file:// URL
# would make LCM write a log there. Refused before anything runs; the file is not created.
victim=$(mktemp -u /tmp/lagsim-cli-XXXXXX)
err=$(LCM_DEFAULT_URL="file://$victim?mode=w" "$lagsimd" --config "$scene" --duration 0.05 -q 2>&1); rc=$?
if [ $rc -ne 2 ]; then echo "FAIL: LCM_DEFAULT_URL=file://: exit $rc, expected 2"; fail=1
elif [[ "$err" != *"LCM_DEFAULT_URL: LCM provider 'file://' is not accepted"* ]]; then
    echo "FAIL: LCM_DEFAULT_URL=file://: '$err'"; fail=1
elif [ -e "$victim" ]; then echo "FAIL: $victim was written"; fail=1
else echo "ok: LCM_DEFAULT_URL=file:// refused"; fi
rm -f "$victim"
exit $fail
