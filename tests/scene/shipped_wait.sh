#!/bin/bash
# Every shipped scene waits at t = 0 for the first command (docs/scenes.md): each
# config/*.yaml, found in the directory at run time (a new scene is checked too), is run
# by lagsimd in real time with no controller for 2 s with --duration 0.3. A scene that
# waits says so in its start event and is still at t = 0 when SIGINT stops it; one that
# runs reaches its --duration ("duration reached"). Usage: shipped_wait.sh LAGSIMD CONFIG_DIR
set -u
lagsimd=$1 dir=$2
fail=0 n=0
# a port pair of this script's own (tests/common/lcm_port.py), held while it runs
coproc PORTHOLD { python3 "$(dirname "$0")/../common/lcm_port.py" --hold; }
read -r port <&"${PORTHOLD[0]}"
for f in "$dir"/*.yaml; do
    name=$(basename "$f" .yaml)
    n=$((n + 1))
    err=$(timeout -s INT 2 "$lagsimd" --config "$f" --duration 0.3 \
          --set "lcm.prefix=SHIP${n}_$$" --set "lcm.url=udpm://239.255.76.67:$port?ttl=0" 2>&1 >/dev/null)
    if [[ "$err" != *"waiting at t = 0 for the first command"* ]]; then
        echo "FAIL: $name: its start event does not say it waits for the first command:"
        echo "$err" | head -5
        fail=1
    elif [[ "$err" == *"duration reached"* ]] || [[ "$err" != *"SIGINT"* ]]; then
        echo "FAIL: $name ran without a command:"
        echo "$err" | tail -5
        fail=1
    else
        echo "ok: $name waits at t = 0 for the first command"
    fi
done
if [ $n -lt 4 ]; then echo "FAIL: only $n scenes in $dir"; fail=1; fi
exit $fail
