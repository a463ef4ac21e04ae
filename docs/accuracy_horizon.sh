#!/bin/bash
# Redraws docs/accuracy_horizon.png: how far the setting chosen for integrator.error = 1e-6
# (horizon 1 s) drifts from the exact solution past its horizon, on the DIPC released near
# upright (chaotic) and on the manipulator (not chaotic), over 10 s. The exact solution
# is taken as Gauss-Legendre at dt = period / 1024.
# usage: docs/accuracy_horizon.sh [BUILD_DIR]   (from the project's root)
set -euo pipefail
build=${1:-build}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for scene in dipc manipulator; do
  sets=$("$build/bin/lagsimd" --config "config/$scene.yaml" --set integrator.error=1e-6 \
         --offline --duration 0 2>&1 | grep -o -- "--set integrator\.[a-z]*=[^ ]*" | tr '\n' ' ')
  # shellcheck disable=SC2086
  "$build/bin/lagsimd" -q --config "config/$scene.yaml" $sets --offline --duration 10 --csv "$work/$scene.csv"
  "$build/bin/lagsimd" -q --config "config/$scene.yaml" --set integrator.method=gauss4 \
      --set integrator.dt=9.765625e-06 --offline --duration 10 --csv "$work/$scene-ref.csv"
  n=$(head -1 "$work/$scene.csv" | tr ',' '\n' | grep -vc "_dot\|^t$\|energy")
  paste -d, "$work/$scene.csv" "$work/$scene-ref.csv" | awk -F, -v n="$n" -v w=$(( $(head -1 "$work/$scene.csv" | tr ',' '\n' | wc -l) )) \
    'NR > 1 { m = 0; for (i = 2; i <= n + 1; i++) { e = $i - $(i + w); if (e < 0) e = -e; if (e > m) m = e }
              printf "%s %.6g\n", $1, (m > 1e-16 ? m : 1e-16) }' > "$work/$scene.dat"
done
gnuplot <<GP
set terminal pngcairo size 900,500 enhanced font "DejaVu Sans,11"
set output "docs/accuracy_horizon.png"
set logscale y
set format y "10^{%L}"
set grid
set key left top
set xlabel "sim time (s)"
set ylabel "max |q - q_{exact}| (m or rad)"
set title "The setting chosen for integrator.error = 1e-6 over a 1 s horizon, run for 10 s"
set arrow from 1, graph 0 to 1, graph 1 nohead dt 2 lc rgb "gray40"
set label "horizon" at 1.1, graph 0.05 tc rgb "gray40"
set arrow from graph 0, first 1e-6 to graph 1, first 1e-6 nohead dt 2 lc rgb "red"
set label "error asked for" at graph 0.75, first 1e-6 offset 0,0.6 tc rgb "red"
plot "$work/dipc.dat" using 1:2 with lines lw 2 title "DIPC released near upright (chaotic)", \
     "$work/manipulator.dat" using 1:2 with lines lw 2 title "manipulator"
GP
echo "wrote docs/accuracy_horizon.png"
