#!/bin/bash
# Runs per second of a 10 s DIPC LQR case (config/dipc.yaml, dipc_lqr, lockstep) on this
# machine, three ways, measured in the same run:
#   sweep    lagsim-sweep -j 2 over parameters.m1: one daemon and one controller per worker
#   restart  the same with --restart: a daemon and a controller started for every run
#   loop   a plain shell loop that starts lagsimd and dipc_lqr for every run, 2 at a time
#   bus    the bus's limit: bare LCM ping-pong round trips per second (lcm_pingpong) over
#          the 1001 round trips a 10 s run at 100 Hz needs
# usage: bench/sweep_rate.sh [BUILD_BIN] [RUNS]      (default build/bin, 40)
set -euo pipefail
bin=${1:-build/bin}
runs=${2:-40}
scene=config/dipc.yaml
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
now() { date +%s.%N; }

sweep() {
  "$bin/lagsim-sweep" --config "$scene" --controller "$bin/dipc_lqr -q --prefix {prefix}" \
      --duration 10 --vary 'parameters.m1=uniform(0.45,0.55)' --runs "$runs" --seed 1 -j 2 \
      --force "$@" >/dev/null || true
}
t0=$(now)
sweep --csv "$tmp/sweep.csv"
t1=$(now)
passed=$(awk -F, 'NR > 1 && $3 == 0' "$tmp/sweep.csv" | wc -l)
sweep --restart --csv "$tmp/restart.csv"
t1r=$(now)

one() { # run i: the controller, then lagsimd in lockstep with its own prefix and port
  local i=$1 p="LOOP$$_$1" port=$((30000 + 2 * ($$ % 5000) + 2 * ($1 % 2) * 5000))
  export LCM_DEFAULT_URL="udpm://239.255.76.67:$port?ttl=0"
  "$bin/dipc_lqr" -q --prefix "$p" >/dev/null 2>&1 &
  local c=$!
  "$bin/lagsimd" --config "$scene" --set realtime.mode=lockstep --set lcm.prefix="$p" \
      --set parameters.m1=0.5 --duration 10 -q >/dev/null 2>&1
  wait $c || true
}
export -f one
export bin scene
t2=$(now)
seq 1 "$runs" | xargs -P 2 -I{} bash -c 'one {}'
t3=$(now)
pp=$("$bin/lcm_pingpong" 20000 | awk '{print $(NF-2)}')
awk -v r="$runs" -v a="$t0" -v b="$t1" -v br="$t1r" -v c="$t2" -v d="$t3" -v pp="$pp" -v ok="$passed" 'BEGIN {
  printf "runs of 10 s DIPC LQR (lockstep, 100 Hz), %d each, 2 at a time\n", r
  printf "  lagsim-sweep -j 2        %6.2f runs/s  (%d of %d rows without failure)\n", r / (b - a), ok, r
  printf "  lagsim-sweep --restart   %6.2f runs/s\n", r / (br - b)
  printf "  plain loop, xargs -P 2   %6.2f runs/s\n", r / (d - c)
  printf "  bus limit (ping-pong)    %6.2f runs/s  (%d round trips/s / 1001, one process pair)\n", pp / 1001, pp
  printf "  1000 runs: sweep %.0f s, --restart %.0f s, loop %.0f s\n", 1000 * (b - a) / r, 1000 * (br - b) / r, 1000 * (d - c) / r
}'
