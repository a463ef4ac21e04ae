#!/bin/bash
# The same scene run twice gives a bit-identical CSV, for every integrator of the core's
# table (lagsimd --list methods: a method added there is run here with no edit); different
# methods give different CSVs (so --set integrator.method did take effect).
# Usage: determinism.sh LAGSIMD SCENE
set -u
lagsimd=$1 scene=$2
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
fail=0
methods=$("$lagsimd" --list methods) || { echo "FAIL: lagsimd --list methods: exit $?"; exit 1; }
count=$(echo "$methods" | wc -w)
[ "$count" -ge 2 ] || { echo "FAIL: lagsimd --list methods gave $count methods"; exit 1; }
for m in $methods; do
    for run in 1 2; do
        "$lagsimd" -q --config "$scene" --offline --duration 2 --set integrator.method=$m \
            --csv "$tmp/$m.$run.csv" || { echo "FAIL: $m run $run exit $?"; fail=1; }
    done
    rows=$(($(wc -l < "$tmp/$m.1.csv") - 1))
    if [ $rows -ne 201 ]; then echo "FAIL: $m: $rows rows, expected 201"; fail=1; fi
    if cmp -s "$tmp/$m.1.csv" "$tmp/$m.2.csv"; then
        echo "ok: $m bit-identical ($(md5sum < "$tmp/$m.1.csv" | cut -c1-12))"
    else
        echo "FAIL: $m runs differ"; fail=1
    fi
done
n=$(md5sum "$tmp"/*.1.csv | cut -d' ' -f1 | sort -u | wc -l)
if [ "$n" -ne "$count" ]; then echo "FAIL: only $n distinct CSVs for $count methods"; fail=1; fi
exit $fail
