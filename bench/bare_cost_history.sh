#!/bin/sh
# Does the bare model (no effects) cost what it did before the effects existed?
# Builds bench/bare_tick.c against the core of REV (default e5ed52d, the core before
# effects) and against the working tree, counts instructions per rk4 tick with callgrind
# (repeatable on a shared machine, unlike wall time) and prints both per model. Built as
# the release build is (-O2 -DNDEBUG: the core's internal asserts are off).
# usage: bench/bare_cost_history.sh [REV]
set -eu
cd "$(dirname "$0")/.."
rev=${1:-e5ed52d}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
git archive "$rev" server/core server/include | tar -x -C "$tmp"
build() { # $1 = tree, $2 = output
    gcc -O2 -DNDEBUG -std=c11 -D_GNU_SOURCE -I"$1/server/include" -I"$1/server/core" \
        bench/bare_tick.c "$1"/server/core/*.c -lm -o "$2"
}
build "$tmp" "$tmp/old"
build . "$tmp/new"
printf '| model | instructions per tick at %s | now | ratio |\n|---|---:|---:|---:|\n' "$rev"
for m in stick manipulator dipc; do
    for v in old new; do
        valgrind --tool=callgrind --callgrind-out-file="$tmp/cg.$v" "$tmp/$v" $m >/dev/null 2>&1
        eval "n_$v=\$(callgrind_annotate \"$tmp/cg.$v\" | awk '/PROGRAM TOTALS/ {gsub(\",\",\"\",\$1); print \$1}')"
    done
    awk -v m=$m -v a="$n_old" -v b="$n_new" 'BEGIN { printf "| %s | %.0f | %.0f | %.2f |\n", m, a/20000, b/20000, b/a }'
done
