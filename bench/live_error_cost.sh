#!/bin/sh
# What the live error estimate costs: lagsimd in fast mode on config/dipc.yaml (100 Hz,
# the DIPC falling and tumbling), SIM seconds of sim time, CPU time of the whole process
# (user + system, the least of REPS runs, alternated) per control period, with the shadow
# run every N = 1, 20, 50 periods (integrator.estimate_every = N) and without it (0), for rk4 at the
# scene's dt (1 ms, 10 ticks a period) and dopri5 at tolerance 1e-8 (one tick a period);
# and the loop's own step time (status step_time_mean_us of the last status), which the
# shadow, run after the state is published, does not add to.
# usage: bench/live_error_cost.sh [BUILD_DIR] [REPS] [SIM]  (defaults: build 5 2000)
set -eu
cd "$(dirname "$0")/.."
B=${1:-build}/bin
REPS=${2:-5}
SIM=${3:-2000}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
P=LIVECOST$$
periods=$((SIM * 100))

cpu() { # $1 = estimate_every, $2.. = integrator settings; prints CPU seconds
    every=$1
    shift
    /usr/bin/time -f "%U %S" -o "$tmp/t" "$B/lagsimd" --config config/dipc.yaml -q \
        --set lcm.prefix=$P --set lcm.url=memq:// --set realtime.mode=fast \
        --set realtime.start=running --set integrator.estimate_every="$every" "$@" \
        --duration "$SIM" >/dev/null 2>&1
    awk '{ printf "%.4f\n", $1 + $2 }' "$tmp/t"
}
best() { awk -v a="$1" -v b="$2" 'BEGIN { print (b < a) ? b : a }'; }

echo "## the live error estimate: CPU per control period (config/dipc.yaml, $periods periods, least of $REPS runs)"
echo
echo "| method | estimate_every | CPU us / period | vs off |"
echo "|---|---|---|---|"
for method in rk4 dopri5; do
    if [ $method = rk4 ]; then set -- --set integrator.method=rk4 --set integrator.dt=0.001
    else set -- --set integrator.method=dopri5 --set integrator.dt=0.01 \
        --set integrator.rtol=1e-8 --set integrator.atol=1e-8; fi
    off=1e9; e1=1e9; e20=1e9; e50=1e9
    i=0
    while [ $i -lt "$REPS" ]; do
        off=$(best $off "$(cpu 0 "$@")")
        e1=$(best $e1 "$(cpu 1 "$@")")
        e20=$(best $e20 "$(cpu 20 "$@")")
        e50=$(best $e50 "$(cpu 50 "$@")")
        i=$((i + 1))
    done
    for row in "0 $off" "1 $e1" "20 $e20" "50 $e50"; do
        set -- $row
        awk -v m=$method -v n="$1" -v c="$2" -v o="$off" -v p=$periods \
            'BEGIN { printf "| %s | %s | %.2f | %s |\n", m, n == 0 ? "0 (off)" : n,
                     c / p * 1e6, n == 0 ? "1" : sprintf("%.3f", c / o) }'
    done
done

# 2. instructions per control period (callgrind: repeatable on a shared machine), from
#    the difference between runs of 40 s and 20 s of sim time (2000 periods), so that the
#    start (scene, LCM) cancels out
instr() { # $1 = estimate_every, $2 = duration, $3.. = settings
    every=$1 dur=$2
    shift 2
    valgrind --tool=callgrind --callgrind-out-file="$tmp/cg" "$B/lagsimd" --config config/dipc.yaml -q \
        --set lcm.prefix=$P --set lcm.url=memq:// --set realtime.mode=fast \
        --set realtime.start=running --set integrator.estimate_every="$every" "$@" \
        --duration "$dur" >/dev/null 2>&1
    callgrind_annotate "$tmp/cg" 2>/dev/null | awk '/PROGRAM TOTALS/ { gsub(",", "", $1); print $1; exit }'
}
if command -v valgrind >/dev/null && command -v callgrind_annotate >/dev/null; then
    echo
    echo "| method | estimate_every | instructions / period | vs off |"
    echo "|---|---|---|---|"
    for method in rk4 dopri5; do
        if [ $method = rk4 ]; then set -- --set integrator.method=rk4 --set integrator.dt=0.001
        else set -- --set integrator.method=dopri5 --set integrator.dt=0.01 \
            --set integrator.rtol=1e-8 --set integrator.atol=1e-8; fi
        off=""
        for every in 0 1 20 50; do
            a=$(instr $every 40 "$@")
            b=$(instr $every 20 "$@")
            per=$(awk -v a="$a" -v b="$b" 'BEGIN { printf "%.0f", (a - b) / 2000 }')
            [ -n "$off" ] || off=$per
            awk -v m=$method -v n=$every -v p="$per" -v o="$off" \
                'BEGIN { printf "| %s | %s | %d | %.3f |\n", m, n == 0 ? "0 (off)" : n, p, p / o }'
        done
    done
fi
