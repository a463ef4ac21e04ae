#!/bin/bash
# Writes the scene fuzz target's inputs (tests/fuzz/scene/, see tests/fuzz/fuzz_scene.c
# for the format: the file, then one --set after each NUL byte).
#   corpus/   config/*.yaml and tests/scene/bad/*.yaml as they are, and a few of them
#           with --set overrides
#   crash/  small versions of files that once took minutes or gigabytes (kept for ever)
# Usage: tests/fuzz/scene/make_inputs.sh   (from anywhere; rewrites both directories)
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../../.." && pwd)
rm -rf "$here/corpus" "$here/crash"
mkdir -p "$here/corpus" "$here/crash"
for f in "$root"/config/*.yaml; do cp "$f" "$here/corpus/config-$(basename "$f")"; done
for f in "$root"/tests/scene/bad/*.yaml; do cp "$f" "$here/corpus/bad-$(basename "$f")"; done
with_sets() { # NAME FILE SET...
    local name=$1 file=$2; shift 2
    { cat "$file"; for s in "$@"; do printf '\0%s' "$s"; done; } > "$here/corpus/$name"
}
with_sets set-dopri5.bin "$root/config/dipc.yaml" integrator.method=dopri5 integrator.rtol=1e-6 integrator.max_steps=500
with_sets set-gauss4-lockstep.bin "$root/config/manipulator.yaml" integrator.method=gauss4 realtime.mode=lockstep "realtime.effort_limit={q1: 20, q2: 5}"
with_sets set-effects.bin "$root/config/manipulator.yaml" "effects={damping: {q1: 0.1}, friction: {q2: {static: 0.5, kinetic: 0.3}}, limits: {q2: {lower: 0.1, upper: 0.9, restitution: 0.5}}, actuator: {q1: {max: 5, lag: 0.01}}, noise: {seed: 3, q: {q1: 0.01}}}"
with_sets set-disturbance.bin "$root/config/dipc.yaml" "effects.disturbance=[{t: 0.005, joint: theta1, impulse: 0.01}, {t: 0.01, joint: theta0, force: 2, duration: 0.02}]"
with_sets set-stick-floor.bin "$root/config/stick.yaml" initial.qd=[0,-3] effects.floor.restitution=0.9 publish_hz=1000
with_sets set-url.bin "$root/config/dipc.yaml" lcm.allow_lan=true "lcm.url=udpm://239.255.76.67:7667?ttl=1&recv_buf_size=65536"
with_sets set-model-change.bin "$root/config/dipc.yaml" model=stick "parameters={m: 2}" initial.q=[0,1]
with_sets set-empty-file.bin /dev/null model=dipc
with_sets set-reference.bin "$root/config/dipc.yaml" "reference={theta0: {type: chirp, start: 0.5, amplitude: 0.1, frequency: 0.2, frequency_end: 3, duration: 4}, theta1: {type: square, frequency: 2, amplitude: 0.05}, theta2: {type: waypoints, points: [[0, 0], [1, 0.1], [2.5, -0.1]]}}" reference.theta0.amplitude=0.2 "reference.theta1={type: ramp, duration: 2}"

# A mapping of 5 000 keys: the quadratic duplicate-key check took 47 s at 100 000.
awk 'BEGIN { print "model: dipc"; for (i = 0; i < 5000; i++) printf "k%d: 1\n", i }' > "$here/crash/quadratic-duplicate-keys.yaml"
# initial.q with 20 000 items: 15 million took 1.76 GB before the error.
awk 'BEGIN { printf "model: dipc\ninitial:\n  q: [0"; for (i = 1; i < 20000; i++) printf ",0"; print "]" }' > "$here/crash/huge-initial-q.yaml"
# the same through a --set
{ printf 'model: dipc\n\0initial.q=[0'; awk 'BEGIN { for (i = 1; i < 20000; i++) printf ",0"; printf "]" }'; } > "$here/crash/huge-set-sequence.bin"
# more nodes than the limit, each mapping under its own
awk 'BEGIN { print "model: dipc"; for (m = 0; m < 6; m++) { printf "x%d:\n", m; for (i = 0; i < 1000; i++) printf "  k%d: 1\n", i } }' > "$here/crash/many-nodes.yaml"
# nesting far deeper than the limit, in flow and block style
awk 'BEGIN { printf "model: dipc\nx: "; for (i = 0; i < 2000; i++) printf "["; for (i = 0; i < 2000; i++) printf "]"; print "" }' > "$here/crash/deep-flow-nesting.yaml"
awk 'BEGIN { print "model: dipc"; s = ""; for (i = 0; i < 100; i++) { printf "%sk%d:\n", s, i; s = s "  " } }' > "$here/crash/deep-block-nesting.yaml"
# numbers the schema once read too freely
printf 'model: dipc\nintegrator: {dt: !!float 1e-3}\n' > "$here/crash/tag-float.yaml"
printf 'model: dipc\neffects:\n  disturbance:\n    - {t: 1e300, joint: theta0, force: 5, duration: 0.1}\n' > "$here/crash/disturbance-t-1e300.yaml"
printf 'model: dipc\nrealtime: {mode: fast}\npublish_hz: 1e-9\n' > "$here/crash/publish-hz-1e-9-fast.yaml"
