#!/bin/bash
# For every shipped scene (config/*.yaml, listed now) and an error of 1e-4, 1e-6 and 1e-9:
# `lagsimd --offline` with only `--set integrator.error=E` stays within E of an
# independent reference over the horizon (1 s): Gauss-Legendre at dt = period / 1024, run
# by lagsimd with that method named (its own error over 1 s is below 1e-12 on these
# scenes). Columns 2 .. nq+1 of the CSVs are the joints' q.
# Usage: accuracy_all.sh LAGSIMD CONFIG_DIR
set -u
lagsimd=$1 cfg=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail=0
for scene in "$cfg"/*.yaml; do
  name=$(basename "$scene" .yaml)
  hz=$(awk '/^publish_hz:/ { print $2 }' "$scene")
  hz=${hz:-100}  # the loader's default
  ref_dt=$(awk -v hz="$hz" 'BEGIN { printf "%.17g", 1 / hz / 1024 }')
  "$lagsimd" -q --config "$scene" --set integrator.method=gauss4 --set "integrator.dt=$ref_dt" \
      --offline --duration 1 --csv "$work/$name-ref.csv" || { echo "FAIL: $name: reference run"; fail=1; continue; }
  nq=$(head -1 "$work/$name-ref.csv" | tr ',' '\n' | grep -vc "_dot$\|_ddot$\|^t$\|^energy$\|_ref$")
  for E in 1e-4 1e-6 1e-9; do
    if ! "$lagsimd" -q --config "$scene" --set "integrator.error=$E" --offline --duration 1 \
         --csv "$work/$name-$E.csv" 2> "$work/err"; then
      echo "FAIL: $name, E = $E: $(cat "$work/err")"; fail=1; continue
    fi
    d=$(paste -d, "$work/$name-$E.csv" "$work/$name-ref.csv" | awk -F, -v nq="$nq" \
        -v w="$(head -1 "$work/$name-ref.csv" | tr ',' '\n' | wc -l)" \
        'NR > 1 { for (i = 2; i <= nq + 1; i++) { e = $i - $(i + w); if (e < 0) e = -e; if (e > m) m = e } }
         END { printf "%.3g", m }')
    if awk -v d="$d" -v e="$E" 'BEGIN { exit !(d <= e) }'; then
      echo "ok: $name, integrator.error = $E: max |q - q_ref| = $d over 1 s"
    else
      echo "FAIL: $name, integrator.error = $E: max |q - q_ref| = $d"; fail=1
    fi
  done
done
exit $fail
