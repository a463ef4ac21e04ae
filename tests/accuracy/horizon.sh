#!/bin/bash
# What accuracy cannot know, through lagsimd (the calibration itself: test_cost.c's
# horizon_* cases, against independent integrations):
#   1. integrator.error 1e-6 over integrator.horizon 100 s on the chaotic DIPC: a real-time
#      start is refused (exit 2) naming the horizon it can honour, H < 100 s; offline it
#      warns and chooses for H; given horizon H, it is honoured (no warning).
#   2. --cost of that scene: the header says every error is over H s, and the finest
#      settings are within the error there (not the references' own parting, which made
#      every row 176 to 408 rad when they were compared over 100 s).
#   3. --cost --plot of a scene that asks for no error: the gnuplot script (--plot FILE.gp)
#      draws no "error asked for", marks the scene's integrator and the setting that would
#      be chosen, each with its real-time factor, and a real-time axis; the table marks the
#      same rows, and the one that would be chosen is at least as accurate and no dearer.
#      With an error asked for, the line is there and the mark says "chosen". gnuplot draws
#      the script into a PNG.
# Usage: horizon.sh LAGSIMD CONFIG_DIR
set -u
lagsimd=$1 cfg=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail=0
ok() { echo "ok: $1"; }
bad() { echo "FAIL: $1"; fail=1; }
dipc=("$lagsimd" --config "$cfg/dipc.yaml" --set lcm.url=memq:// --set integrator.error=1e-6)

# 1. refused in real time, with the horizon it can honour
timeout 120 "${dipc[@]}" --set integrator.horizon=100 --set realtime.mode=realtime \
    --set realtime.start=running --duration 1 2> "$work/rt.err"
rc=$?
H=$(sed -n 's/.*ask for a horizon of at most \([0-9.e+-]*\) s.*/\1/p' "$work/rt.err")
echo "stderr: $(cat "$work/rt.err")"
[ $rc -eq 2 ] && grep -q "integrator.horizon 100 s cannot be honoured: the scene is predictable to 1e-06 for about $H s" "$work/rt.err" \
    && [ -n "$H" ] && awk -v h="$H" 'BEGIN { exit !(h > 0 && h < 100) }' \
    && ok "real time with horizon 100 s: refused (exit 2), honours $H s" \
    || bad "real time with horizon 100 s: exit $rc, horizon '$H'"
timeout 120 "${dipc[@]}" --set integrator.horizon=100 --offline --duration 0.1 \
    > /dev/null 2> "$work/off.err"
rc=$?
[ $rc -eq 0 ] && grep -q "warning: integrator.horizon 100 s cannot be honoured" "$work/off.err" \
    && grep -q "integrator.error 1e-06 over $H s: " "$work/off.err" \
    && ok "offline with horizon 100 s: a warning, chosen over $H s" \
    || bad "offline with horizon 100 s: exit $rc: $(cat "$work/off.err")"
if [ -n "$H" ]; then
  timeout 120 "${dipc[@]}" --set integrator.horizon="$H" --offline --duration 0.1 \
      > /dev/null 2> "$work/h.err"
  rc=$?
  [ $rc -eq 0 ] && ! grep -q "cannot be honoured" "$work/h.err" \
      && grep -q "integrator.error 1e-06 over $H s: " "$work/h.err" \
      && ok "horizon $H s: honoured" || bad "horizon $H s: exit $rc: $(cat "$work/h.err")"
fi

# 2. --cost over the horizon it can honour
timeout 120 "${dipc[@]}" --set integrator.horizon=100 --cost > "$work/cost.txt"
rc=$?
head -3 "$work/cost.txt"
# a row: the setting in 34 columns, then error, energy error, CPU s/sim-s, x real time
least=$(awk '/^(euler|semi-implicit-euler|rk4|dopri5|implicit-midpoint|gauss4) / {
               split(substr($0, 36), v, " "); if (v[1] == "-") next
               if (m == "" || v[1] + 0 < m) m = v[1] + 0 } END { print m }' "$work/cost.txt")
[ $rc -eq 0 ] && grep -q "every error below is over $H s" "$work/cost.txt" \
    && awk -v m="$least" 'BEGIN { exit !(m != "" && m <= 1e-6) }' \
    && ok "--cost at horizon 100 s: over $H s, the least error $least <= 1e-6" \
    || bad "--cost at horizon 100 s: exit $rc, least error '$least'"

# 3. --cost --plot without an error asked for, and with one
"$lagsimd" --config "$cfg/dipc.yaml" --cost --plot "$work/own.gp" > "$work/own.txt"
rc=$?
[ $rc -eq 0 ] && ok "--cost --plot FILE.gp: exit 0" || bad "--cost --plot FILE.gp: exit $rc"
own=$(grep -c "the scene's integrator$" "$work/own.txt")
would=$(grep -c "would be chosen" "$work/own.txt")
[ "$own" = 1 ] && [ "$would" = 1 ] && grep -q "^rk4 dt 0.001 s .*the scene's integrator$" "$work/own.txt" \
    && ok "the table marks the scene's integrator (rk4 dt 0.001 s) and one that would be chosen" \
    || bad "the table: $own rows of the scene's integrator, $would that would be chosen"
awk '{ split(substr($0, 36), v, " ") }
     /the scene.s integrator$/ { ce = v[1]; cc = v[3] }
     /would be chosen/ { we = v[1]; wc = v[3] }
     END { printf "error %g CPU %g against %g, %g", we, wc, ce, cc
           exit !(ce != "" && we != "" && we + 0 <= ce + 0 && wc + 0 <= cc + 0) }' \
    "$work/own.txt" > "$work/cmp.txt" \
    && ok "would be chosen: as accurate and no dearer ($(cat "$work/cmp.txt"))" \
    || bad "would be chosen against the scene's integrator: $(cat "$work/cmp.txt")"
! grep -q "error asked for" "$work/own.gp" && grep -q "title \"the scene's integrator: rk4 dt 0.001 s, .* x real time\"" "$work/own.gp" \
    && grep -q "title \"would be chosen: .* x real time\"" "$work/own.gp" && grep -q "^set x2tics" "$work/own.gp" \
    && ok "the plot: no 'error asked for', the scene's integrator and the setting that would be chosen marked with their real-time factors, a real-time axis" \
    || bad "the plot of a scene that asks for no error: $(grep -e "error asked" -e "^plot" "$work/own.gp")"
"${dipc[@]}" --cost --plot "$work/asked.gp" > /dev/null
grep -q "set label 'error asked for'" "$work/asked.gp" && grep -q "title \"chosen: " "$work/asked.gp" \
    && ! grep -q "the scene's integrator" "$work/asked.gp" \
    && ok "the plot with integrator.error: the error asked for and the chosen setting" \
    || bad "the plot with integrator.error: $(grep -e "error asked" -e "^plot" "$work/asked.gp")"
if command -v gnuplot > /dev/null; then
  (cd "$work" && gnuplot own.gp) && head -c 8 "$work/own.png" | od -An -c | grep -q "P   N   G" \
      && ok "gnuplot draws the script into own.png" || bad "gnuplot own.gp drew no PNG"
fi
exit $fail
