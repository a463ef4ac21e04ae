#!/bin/bash
# Fast mode's CPU per state: lagsimd (the DIPC, 1000 states per sim second) runs fast for
# DURATION sim seconds with nobody listening; prints its user and system CPU seconds per
# 1000 states. Nothing is asserted: a figure for docs/network.md.
#   bench/net_fast_cpu.sh [LAGSIMD [DURATION]]    (default build/bin/lagsimd, 200)
set -eu
root=$(cd "$(dirname "$0")/.." && pwd)
lagsimd=${1:-$root/build/bin/lagsimd}
dur=${2:-200}
out=$(mktemp)
trap 'rm -f "$out"' EXIT
/usr/bin/time -f "%U %S %e" -o "$out" "$lagsimd" --config "$root/config/dipc.yaml" -q \
    --set realtime.mode=fast --set realtime.start=running --set publish_hz=1000 \
    --set realtime.command_timeout=100 --set lcm.prefix=FASTCPU$$ --duration "$dur" 2>/dev/null
read -r user sys wall <"$out"
states=$(awk -v d="$dur" 'BEGIN { printf "%d", d * 1000 + 1 }')
awk -v u="$user" -v s="$sys" -v w="$wall" -v n="$states" 'BEGIN {
    printf "%d states: user %.2f s, system %.2f s, wall %.2f s: %.1f us of CPU per state (%.0f %% of a core while it ran)\n",
        n, u, s, w, (u + s) / n * 1e6, (u + s) / w * 100 }'
