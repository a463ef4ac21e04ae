#!/bin/bash
# --set overrides: they take effect (checked against energies computed here, independently,
# from the models' T and U (docs/models.md)), the last one wins, they are validated like the file and their
# errors name the --set. Usage: set_overrides.sh LAGSIMD CONFIG_DIR EXPECT_ERROR_SH
set -u
lagsimd=$1 cfg=$2 expect=$3
fail=0
ok() { echo "ok: $1"; }
bad() { echo "FAIL: $1"; fail=1; }

# Energy (field 8 of the t = 0 row) of config/dipc.yaml under extra --set arguments.
energy0() { "$lagsimd" -q --config "$cfg/dipc.yaml" --offline --duration 0 --csv - "$@" | sed -n 2p | cut -d, -f8; }
# |a - b| <= 1e-12 (|a| + |b|) + 1e-15
close() { awk -v a="$1" -v b="$2" 'BEGIN { d = a - b; if (d < 0) d = -d; s = (a < 0 ? -a : a) + (b < 0 ? -b : b); exit !(d <= 1e-12 * s + 1e-15) }'; }

# Parameters given by --set, both as a whole mapping and key by key (the later wins).
P=(--set "parameters={m0: 2, m1: 0.3, m2: 0.6, l1: 0.6, l2: 0.8, I2: 0.05, g: 9.7, h0: 0.3}"
   --set parameters.m1=0.4)
m0=2 m1=0.4 m2=0.6 l1=0.6 l2=0.8 I2=0.05 g=9.7
E_rest=$(energy0 "${P[@]}" --set "initial={q: [0, 0, 0], qd: [0, 0, 0]}")

# 1. potential: U(0, a, b) - U(0, 0, 0) = g [m1 l1/2 (cos a - 1) + m2 (l1 (cos a - 1) + l2/2 (cos b - 1))]
a=0.5 b=-0.3
E=$(energy0 "${P[@]}" --set "initial.q=[0, $a, $b]" --set "initial.qd=[0,0,0]")
want=$(awk -v g=$g -v m1=$m1 -v m2=$m2 -v l1=$l1 -v l2=$l2 -v a=$a -v b=$b \
    'BEGIN { printf "%.17g", g * (m1 * l1 / 2 * (cos(a) - 1) + m2 * (l1 * (cos(a) - 1) + l2 / 2 * (cos(b) - 1))) }')
got=$(awk -v x="$E" -v y="$E_rest" 'BEGIN { printf "%.17g", x - y }')
if close "$got" "$want"; then ok "dU = $got (want $want)"; else bad "dU = $got, want $want"; fi

# 2. cart velocity v at q = 0: T = 1/2 (m0 + m1 + m2) v^2
v=1.5
E=$(energy0 "${P[@]}" --set "initial={q: [0, 0, 0], qd: [$v, 0, 0]}")
want=$(awk -v m0=$m0 -v m1=$m1 -v m2=$m2 -v v=$v 'BEGIN { printf "%.17g", 0.5 * (m0 + m1 + m2) * v * v }')
got=$(awk -v x="$E" -v y="$E_rest" 'BEGIN { printf "%.17g", x - y }')
if close "$got" "$want"; then ok "T(cart) = $got (want $want)"; else bad "T(cart) = $got, want $want"; fi

# 3. lower rod spinning at w, q = 0: T = 1/2 (m1 (l1/2)^2 + I1 + m2 l1^2) w^2 with the
#    uniform-rod default I1 = m1 l1^2 / 12 computed from the overridden m1, l1
w=2
E=$(energy0 "${P[@]}" --set "initial={q: [0, 0, 0], qd: [0, $w, 0]}")
want=$(awk -v m1=$m1 -v m2=$m2 -v l1=$l1 -v w=$w \
    'BEGIN { printf "%.17g", 0.5 * (m1 * l1 * l1 / 4 + m1 * l1 * l1 / 12 + m2 * l1 * l1) * w * w }')
got=$(awk -v x="$E" -v y="$E_rest" 'BEGIN { printf "%.17g", x - y }')
if close "$got" "$want"; then ok "T(rod 1) = $got (want $want)"; else bad "T(rod 1) = $got, want $want"; fi

# 4. upper rod spinning at w: T = 1/2 (m2 (l2/2)^2 + I2) w^2 with I2 as given
E=$(energy0 "${P[@]}" --set "initial={q: [0, 0, 0], qd: [0, 0, $w]}")
want=$(awk -v m2=$m2 -v l2=$l2 -v I2=$I2 -v w=$w 'BEGIN { printf "%.17g", 0.5 * (m2 * l2 * l2 / 4 + I2) * w * w }')
got=$(awk -v x="$E" -v y="$E_rest" 'BEGIN { printf "%.17g", x - y }')
if close "$got" "$want"; then ok "T(rod 2) = $got (want $want)"; else bad "T(rod 2) = $got, want $want"; fi

# 5. the last --set of a key wins; initial.q reaches the first row exactly
rows=$("$lagsimd" -q --config "$cfg/dipc.yaml" --offline --duration 1 --csv - \
       --set publish_hz=50 --set publish_hz=20 | wc -l)
if [ "$rows" -eq 22 ]; then ok "last --set wins (20 Hz: 21 rows)"; else bad "$rows lines, expected 22"; fi
row=$("$lagsimd" -q --config "$cfg/dipc.yaml" --offline --duration 0 --csv - --set "initial.q=[0,0.2,-0.1]" | sed -n 2p | cut -d, -f2-4)
if [ "$row" = "0,0.2,-0.1" ]; then ok "initial.q override"; else bad "first row q = $row"; fi

# 6. a key of a section the file does not have
if "$lagsimd" -q --config "$cfg/stick.yaml" --offline --duration 0 --set realtime.mode=lockstep \
       --set "lcm.url=udpm://239.255.76.67:7667?ttl=0" > /dev/null; then
    ok "new section by --set accepted"
else bad "--set realtime.mode=lockstep on stick.yaml refused"; fi

# 6b. accepted transports and their options; ttl above 0 only when the scene says so
for u in "" "memq://" "udpm://" "udpm://239.255.76.67" "udpm://224.0.0.251:1?recv_buf_size=4096" \
         "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=2097152"; do
    if "$lagsimd" -q --config "$cfg/dipc.yaml" --offline --duration 0 --set "lcm.url='$u'" > /dev/null; then
        ok "lcm.url '$u' accepted"
    else bad "lcm.url '$u' refused"; fi
done
if "$lagsimd" -q --config "$cfg/dipc.yaml" --offline --duration 0 --set lcm.allow_lan=true \
       --set "lcm.url=udpm://239.255.76.67:7667?ttl=1" > /dev/null; then
    ok "ttl=1 with lcm.allow_lan: true accepted"
else bad "ttl=1 with lcm.allow_lan: true refused"; fi
if "$lagsimd" -q --config "$cfg/dipc.yaml" --offline --duration 0 \
       --set "realtime.effort_limit={theta0: 250}" > /dev/null; then
    ok "realtime.effort_limit on the actuated joint accepted"
else bad "realtime.effort_limit on the actuated joint refused"; fi

# 7. errors name the --set; a file node keeps its file position after grafting
e() { "$expect" "$lagsimd" "$cfg/dipc.yaml" "$@" || fail=1; }
e --expect "--set integrator.dt: expected a finite number > 0 (s), got -1" -- --set integrator.dt=-1
e --expect "--set integrator.dt: missing value: expected a number" -- --set integrator.dt=
e --expect "--set integrator: integrator.dt: expected a finite number > 0 (s), got -1" -- --set "integrator={dt: -1}"
e --expect "--set integrator.method: unknown method 'no such method'" -- --set "integrator.method=no such method"
e --expect "--set initial.q: expected a sequence of 3 numbers (theta0, theta1, theta2) for model dipc, got 2" -- --set "initial.q=[0,0.1]"
e --expect "--set parameters.m9: unknown parameter 'm9' for model dipc" -- --set parameters.m9=1
e --expect "--set parameters.m0: expected a number > 0 (kg), got -1.5" -- --set parameters.m0=-1.5
e --expect "--set publish_hz: expected a finite number, got .inf" -- --set publish_hz=.inf
e --expect "--set realtime.mode: unknown mode 'slow'" -- --set realtime.mode=slow
e --expect "--set lcm.prefix: YAML syntax error" -- --set "lcm.prefix=[a"
e --expect "--set integrator..dt: empty key in the dotted path" -- --set integrator..dt=1
e --expect "--set effects.damping: expected a mapping of joints (theta0, theta1, theta2), got a scalar" -- --set effects.damping=1
e --expect "--set effects.no such effect: unknown effect 'no such effect' in effects" -- --set "effects.no such effect=1"
e --expect "--set lcm.url: ttl=1 sends every message beyond this host" -- --set "lcm.url=udpm://239.255.76.67:7667?ttl=1"
e --expect "--set lcm.url: udpm option 'ttl' given twice" -- --set lcm.allow_lan=true --set "lcm.url=udpm://239.255.76.67?ttl=0&ttl=1"
e --expect "--set lcm.url: memq:// takes no address or options" -- --set "lcm.url=memq://x"
e --expect "--set lcm.url: expected ttl=<integer>" -- --set "lcm.url=udpm://239.255.76.67?ttl=010"
e --expect "--set lcm.url: expected udpm://GROUP:PORT with GROUP a dotted IPv4 multicast address" -- --set "lcm.url=udpm://239.255.076.67"
# what a message quotes is escaped: always one line
e --expect "--set lcm.pre\\nfix: unknown key 'pre\\nfix' in lcm" -- --set $'lcm.pre\nfix=AB'
e --expect "lcm.prefix: expected a channel prefix of [A-Za-z0-9_], got 'A\\tB'" -- --set $'lcm.prefix="A\tB"'
e --expect "--set realtime.effort_limit: unknown joint 'x' in realtime.effort_limit for model dipc" -- --set "realtime.effort_limit={x: 1}"
qline=$(grep -n '^  q:' "$cfg/dipc.yaml" | cut -d: -f1)   # "  q: [...]": the sequence starts at column 6
m0line=$(grep -n '^  m0:' "$cfg/dipc.yaml" | cut -d: -f1) # "  m0: ...": the key at column 3
e --expect "$cfg/dipc.yaml:$m0line:3: unknown parameter 'm0' for model stick" -- --set model=stick
e --expect "$cfg/dipc.yaml:$qline:6: initial.q: expected a sequence of 2 numbers (x, phi) for model stick, got 3" \
  -- --set model=stick --set "parameters={m: 1}"
e --expect "--set initial.q.x: cannot set a key inside 'initial.q', which is a sequence at $cfg/dipc.yaml:$qline:6" -- --set initial.q.x=1
e --expect "--set initial.x.y: cannot set a key inside 'initial.x': it was set to a scalar by initial.x=..., not a mapping (set 'initial.x' to a mapping, e.g. initial.x={}, first)" -- --set initial.x=5 --set initial.x.y=1
# nothing (null) below a key is an empty mapping: a key set inside it starts one
if "$lagsimd" -q --config "$cfg/dipc.yaml" --offline --duration 0 --set effects=null \
       --set effects.damping.theta1=0.1 >/dev/null; then
    ok "effects=null, then effects.damping.theta1"
else
    bad "effects=null, then effects.damping.theta1: refused"
fi
exit $fail

