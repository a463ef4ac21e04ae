#!/bin/sh
# Work-precision benchmark: builds lagsim_bench with -O2 in build-bench, runs
# the whole sweep (a few minutes on 2 cores), writes docs/bench_wp.csv,
# docs/bench_energy_long.csv, the plots docs/bench_*.png and the printed tables
# bench/results/report.md.
#
#   bench/run.sh                  # run (peers built when their packages are installed)
#   bench/run.sh --install-peers  # first apt-get install MuJoCo 2.2.2, SUNDIALS 6.4, gnuplot
set -eu
cd "$(dirname "$0")/.."
BUILD=${BUILD:-build-bench}
if [ "${1:-}" = "--install-peers" ]; then
    apt-get install -y libmujoco-dev libsundials-dev gnuplot-nox
fi
cmake -S . -B "$BUILD" -DCMAKE_BUILD_TYPE=Release -DCMAKE_C_FLAGS_RELEASE="-O2 -DNDEBUG" >/dev/null
cmake --build "$BUILD" -j2 --target lagsim_bench
mkdir -p docs bench/results
"$BUILD/bin/lagsim_bench" --out docs --reps 3 | tee bench/results/report.md
if command -v gnuplot >/dev/null 2>&1; then
    gnuplot -e "outdir='docs'" bench/plot.gp
    echo "plots: docs/bench_wp_*.png docs/bench_energy_long.png"
else
    echo "gnuplot not found: no plots (apt-get install gnuplot-nox)"
fi
