#!/bin/sh
# What `lagsimd --log` costs per control period, as ratios against the same run without
# it, measured in the same invocation:
#   1. fast mode, the DIPC at publish_hz 1000 (one rk4 tick per period: the period is as
#      short as lagsimd makes it, so the log's share is the largest), N periods: wall time
#      per period (fastest of REPS runs each, alternated), and CPU time per period of the
#      whole process (the loop and, with --log, the writer thread);
#   2. the loop thread's instructions per period (callgrind, repeatable on a shared
#      machine): what the log adds to the period itself; the writer thread's apart;
#   3. lockstep with dipc_lqr (a controller answering every state over LCM): control
#      cycles per second.
# usage: bench/log_cost.sh [BUILD_DIR] [REPS]      (BUILD_DIR default: build)
set -eu
cd "$(dirname "$0")/.."
B=${1:-build}/bin
REPS=${2:-5}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
P=LOGCOST$$
SECONDS_SIM=100            # fast mode: 100 000 periods at 1000 Hz
run_fast() { # $1 = extra args; prints "wall_s cpu_s"
    /usr/bin/time -f "%e %U %S" -o "$tmp/t" "$B/lagsimd" --config config/dipc.yaml -q \
        --set lcm.prefix=$P --set realtime.mode=fast --set realtime.start=running --set publish_hz=1000 \
        --duration $SECONDS_SIM $1 >/dev/null 2>&1
    awk '{ printf "%s %.3f\n", $1, $2 + $3 }' "$tmp/t"
}
best_wall_off=1e9; best_wall_on=1e9; best_cpu_off=1e9; best_cpu_on=1e9
i=0
while [ $i -lt "$REPS" ]; do
    set -- $(run_fast "")
    best_wall_off=$(awk -v a="$best_wall_off" -v b="$1" 'BEGIN { print (b < a) ? b : a }')
    best_cpu_off=$(awk -v a="$best_cpu_off" -v b="$2" 'BEGIN { print (b < a) ? b : a }')
    set -- $(run_fast "--log $tmp/run.lcm --force")
    best_wall_on=$(awk -v a="$best_wall_on" -v b="$1" 'BEGIN { print (b < a) ? b : a }')
    best_cpu_on=$(awk -v a="$best_cpu_on" -v b="$2" 'BEGIN { print (b < a) ? b : a }')
    i=$((i + 1))
done
bytes=$(stat -c %s "$tmp/run.lcm")
periods=$((SECONDS_SIM * 1000))
echo "## lagsimd --log: cost per control period"
echo
echo "fast mode, DIPC rk4, dt 1 ms, publish_hz 1000 (1 tick per period), $periods periods,"
echo "fastest of $REPS runs each; the log: $bytes bytes, $(awk -v b="$bytes" -v p="$periods" 'BEGIN { printf "%.0f", b / p }') bytes per period"
echo
echo "| per period | without --log | with --log | ratio |"
echo "|---|---:|---:|---:|"
awk -v a="$best_wall_off" -v b="$best_wall_on" -v p="$periods" \
    'BEGIN { printf "| wall time (us) | %.2f | %.2f | %.3f |\n", a / p * 1e6, b / p * 1e6, b / a }'
awk -v a="$best_cpu_off" -v b="$best_cpu_on" -v p="$periods" \
    'BEGIN { printf "| CPU time, all threads (us) | %.2f | %.2f | %.3f |\n", a / p * 1e6, b / p * 1e6, b / a }'

# 2. instructions per period, per thread (callgrind), 10 s of sim time: at publish_hz 1000
#    (1 tick per period) and at the shipped scene's 100 Hz (10 ticks per period)
if command -v valgrind >/dev/null 2>&1; then
    cg() { # $1 = out prefix, $2 = publish_hz, $3 = extra args
        valgrind --tool=callgrind --separate-threads=yes --callgrind-out-file="$tmp/$1" \
            "$B/lagsimd" --config config/dipc.yaml -q --set lcm.prefix=$P \
            --set realtime.mode=fast --set realtime.start=running --set publish_hz=$2 --duration 10 $3 >/dev/null 2>&1
    }
    total() { callgrind_annotate "$1" 2>/dev/null | awk '/PROGRAM TOTALS/ { gsub(",", "", $1); print $1; exit }'; }
    for hz in 1000 100; do
        rm -f "$tmp"/off-* "$tmp"/on-*
        cg off $hz ""
        cg on $hz "--log $tmp/cg.lcm --force"
        loop_off=$(total "$tmp/off-01")
        loop_on=$(total "$tmp/on-01")
        writer=0
        for f in "$tmp"/on-0[2-9]; do
            [ -e "$f" ] || continue
            # the writer thread: the one that ran rt_log.c's writer()
            if callgrind_annotate "$f" 2>/dev/null | grep -q "rt_log.c:writer \["; then writer=$(total "$f"); fi
        done
        awk -v a="$loop_off" -v b="$loop_on" -v w="$writer" -v n=$((hz * 10)) -v hz=$hz 'BEGIN {
            printf "| loop thread at %d Hz, instructions | %.0f | %.0f | %.3f |\n", hz, a / n, b / n, b / a
            printf "| writer thread at %d Hz, instructions | | %.0f | |\n", hz, w / n }'
    done
fi

# 3. lockstep with a controller over LCM
lock() { # $1 = extra args; prints cycles per second
    "$B/dipc_lqr" -q --prefix $P >/dev/null 2>&1 &
    lqr=$!
    sleep 0.3
    /usr/bin/time -f "%e" -o "$tmp/t" "$B/lagsimd" --config config/dipc.yaml -q \
        --set lcm.prefix=$P --set realtime.mode=lockstep --duration 60 $1 >/dev/null 2>&1
    wait $lqr || true
    awk '{ printf "%.0f\n", 6000 / $1 }' "$tmp/t"
}
best_off=0; best_on=0
i=0
while [ $i -lt "$REPS" ]; do
    c=$(lock ""); [ "$c" -gt "$best_off" ] && best_off=$c
    c=$(lock "--log $tmp/lock.lcm --force"); [ "$c" -gt "$best_on" ] && best_on=$c
    i=$((i + 1))
done
echo
echo "lockstep with dipc_lqr over LCM, 6000 control cycles, best of $REPS runs each"
echo
echo "| | without --log | with --log | ratio |"
echo "|---|---:|---:|---:|"
awk -v a="$best_off" -v b="$best_on" 'BEGIN { printf "| control cycles per second | %d | %d | %.3f |\n", a, b, b / a }'
