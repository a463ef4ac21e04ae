#!/bin/bash
# Offline CSV format: header, row count, time grid, full precision, file == stdout, and
# the shipped scenes run. Usage: offline_csv.sh LAGSIMD CONFIG_DIR
set -u
lagsimd=$1 cfg=$2
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
fail=0
check() { if ! eval "$2"; then echo "FAIL: $1"; fail=1; else echo "ok: $1"; fi; }

# DIPC, 1 s at 100 Hz: header + 101 rows (t = 0, 0.01, ..., 1)
"$lagsimd" -q --config "$cfg/dipc.yaml" --offline --duration 1 --csv - > "$tmp/a.csv"
check "dipc exit 0" "[ $? -eq 0 ]"
check "dipc header" '[ "$(head -1 "$tmp/a.csv")" = "t,theta0,theta1,theta2,theta0_dot,theta1_dot,theta2_dot,energy" ]'
check "101 rows for 1 s at 100 Hz" '[ $(($(wc -l < "$tmp/a.csv") - 1)) -eq 101 ]'
check "8 fields on every row" '[ -z "$(awk -F, "NF != 8" "$tmp/a.csv")" ]'
# t of row k is the sim time tick * dt = (10 k) * 0.001, exactly (independent of printing)
check "time grid t_k = (10 k) * 0.001 exactly, ends at 1" \
    '[ -z "$(awk -F, "NR > 1 { k = NR - 2; if (\$1 + 0 != (10 * k) * 0.001) print }" "$tmp/a.csv")" ] && [ "$(tail -1 "$tmp/a.csv" | cut -d, -f1)" = 1 ]'
# first row: the scene's initial state, as the scene writes it (the shortest decimal that
# reads back to the double: 0.05, not %.17g's 0.050000000000000003)
check "row t=0 is config/dipc.yaml's q = [0, 0.05, -0.03], qd = 0" \
    '[ "$(sed -n 2p "$tmp/a.csv" | cut -d, -f1-7)" = "0,0,0.05,-0.03,0,0,0" ]'
# every number is the shortest that reads back: with one significant digit less, printf's
# %g gives another double (Python's float reads them)
shortest() {
    python3 - "$1" <<'PY'
import re, sys
bad = 0
for line in open(sys.argv[1]).read().splitlines()[1:]:
    for f in line.split(","):
        x = float(f)
        k = len(re.sub(r"^0+|0+$", "", re.sub(r"[^0-9]", "", f.split("e")[0])))
        if k > 1 and float("%.*g" % (k - 1, x)) == x:
            bad += 1
sys.exit(1 if bad else 0)
PY
}
check "every number the shortest decimal that reads back" 'shortest "$tmp/a.csv"'

# --csv PATH writes what --csv - writes
"$lagsimd" -q --config "$cfg/dipc.yaml" --offline --duration 1 --csv "$tmp/b.csv"
check "--csv PATH identical to --csv -" 'cmp -s "$tmp/a.csv" "$tmp/b.csv"'

# duration 0: header and the t = 0 row only; 0.5 s at 20 Hz: 11 rows
"$lagsimd" -q --config "$cfg/dipc.yaml" --offline --duration 0 --csv "$tmp/c.csv"
check "duration 0 -> 1 row" '[ $(wc -l < "$tmp/c.csv") -eq 2 ]'
"$lagsimd" -q --config "$cfg/dipc.yaml" --offline --duration 0.5 --set publish_hz=20 --csv "$tmp/d.csv"
check "0.5 s at 20 Hz -> 11 rows" '[ $(wc -l < "$tmp/d.csv") -eq 12 ]'

# the stick (its floor lets it fly: a third joint h, the lower end's height): header, and
# x stays exactly 0 (no horizontal force, released from rest), h stays 0 (it never lifts off)
"$lagsimd" -q --config "$cfg/stick.yaml" --offline --duration 0.4 --csv "$tmp/s.csv"
check "stick exit 0" "[ $? -eq 0 ]"
check "stick header" '[ "$(head -1 "$tmp/s.csv")" = "t,x,phi,h,x_dot,phi_dot,h_dot,energy" ]'
check "stick 41 rows" '[ $(($(wc -l < "$tmp/s.csv") - 1)) -eq 41 ]'
check "stick x, x_dot, h, h_dot stay exactly 0" \
    '[ -z "$(awk -F, "NR > 1 && (\$2 != 0 || \$5 != 0 || \$4 != 0 || \$7 != 0)" "$tmp/s.csv")" ]'
check "stick falls: phi decreases from 1.2" \
    '[ "$(awk -F, "NR == 2 { a = \$3 } END { print (a == 1.2 && \$3 < a) ? \"y\" : \"n\" }" "$tmp/s.csv")" = y ]'
# spun up from the floor it flies: h > 0 on some rows, never below the floor, and the run
# ends lying on it; on a floor it may not leave, the same scene is a fault (exit 1)
"$lagsimd" --config "$cfg/stick.yaml" --offline --duration 3 --set initial.qd=[0.4,12] \
    --csv "$tmp/t.csv" 2> "$tmp/t.err"
check "thrown stick exit 0" "[ $? -eq 0 ]"
check "thrown stick flies (h > 0.5 m on some row)" '[ -n "$(awk -F, "NR > 1 && \$4 > 0.5" "$tmp/t.csv")" ]'
check "thrown stick: h >= 0 on every row" '[ -z "$(awk -F, "NR > 1 && \$4 < 0" "$tmp/t.csv")" ]'
check "thrown stick: liftoff and landing events" \
    'grep -q "event liftoff" "$tmp/t.err" && grep -q "event landing" "$tmp/t.err"'
check "thrown stick lies still at 3 s (h, phi_dot, h_dot 0)" \
    '[ "$(tail -1 "$tmp/t.csv" | cut -d, -f4,6,7)" = "0,0,0" ]'
"$lagsimd" -q --config "$cfg/stick.yaml" --offline --duration 3 --set initial.qd=[0.4,12] \
    --set effects.floor.flight=false --csv "$tmp/u.csv" 2> "$tmp/u.err"
check "flight: false: lift-off is a fault (exit 1)" "[ $? -eq 1 ] && grep -qi \"lifted off\" \"$tmp/u.err\""

"$lagsimd" -q --config "$cfg/manipulator.yaml" --offline --duration 1 --csv "$tmp/m.csv"
check "manipulator exit 0" "[ $? -eq 0 ]"
check "manipulator header (the scene's reference after energy)" '[ "$(head -1 "$tmp/m.csv")" = "t,q1,q2,q1_dot,q2_dot,energy,q1_ref,q1_ref_dot,q1_ref_ddot,q2_ref,q2_ref_dot,q2_ref_ddot" ]'
check "manipulator row t=0: q = [0, 0.5], qd = 0" '[ "$(sed -n 2p "$tmp/m.csv" | cut -d, -f1-5)" = "0,0,0.5,0,0" ]'

# A numeric fault stops the run with exit 1 and a message; the rows so far stay, and
# none of them is past the fault: the DIPC falls until |theta| > explode_limit = 0.5.
"$lagsimd" -q --config "$cfg/dipc.yaml" --offline --duration 10 --set explode_limit=0.5 \
    --csv "$tmp/f.csv" 2> "$tmp/f.err"
rc=$?
check "fault: exit 1" "[ $rc -eq 1 ]"
check "fault: message on stderr" 'grep -q "numeric fault at t = .*explode_limit" "$tmp/f.err"'
check "fault: rows so far kept (more than 1, fewer than 1001)" \
    'n=$(($(wc -l < "$tmp/f.csv") - 1)); [ $n -gt 1 ] && [ $n -lt 1001 ]'
check "fault: every kept row within explode_limit" \
    '[ -z "$(awk -F, "NR > 1 { for (i = 2; i <= 7; i++) if (\$i > 0.5 || \$i < -0.5) print }" "$tmp/f.csv")" ]'
exit $fail
