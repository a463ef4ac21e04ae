#!/bin/bash
# Regenerates docs/eval_push.png (lagsim-eval's report of the cart-pole's `push` case) and
# docs/sweep_cartpole.png (a sweep of lqr_balance over the cart-pole's masses).
# Run from the source tree after building: docs/evaluation_figures.sh [BUILD_BIN]
set -euo pipefail
bin=${1:-build/bin}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$bin/lagsim-eval" --config config/cartpole.yaml --suite tests/eval/cartpole_cases.yaml \
    --controller "$bin/lqr_balance -q --prefix {prefix}" --case push --report "$tmp"
cp "$tmp/push.png" docs/eval_push.png
"$bin/lagsim-sweep" --config config/cartpole.yaml --duration 8 \
    --controller "$bin/lqr_balance -q --prefix {prefix}" \
    --vary 'parameters.m0=uniform(0.5,2)' --vary 'parameters.m1=uniform(0.05,0.3)' \
    --vary 'initial.q[1]=normal(0,0.05)' --runs 200 --seed 1 -j 2 \
    --require 'theta.settle<7' --csv "$tmp/sweep.csv" --plot "$tmp/sweep.png" || true
cp "$tmp/sweep.png" docs/sweep_cartpole.png
