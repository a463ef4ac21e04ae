#!/bin/bash
# A lab host: N DIPC plants at 100 Hz, a dipc_lqr each on the same host, for SECONDS of
# sim time; first all N in one lagsimd (--plants DIR --port-base P), then N separate
# lagsimd, in the same run. For each: overruns (from each plant's final status), period
# error p50/p99/max (from the states' utime intervals, read by bench/lab_probe.c without
# LCM threads), CPU per plant-period of the daemon(s) and of the controllers (user +
# system, /usr/bin/time), the daemons' memory (the sum of each one's largest resident
# set, /usr/bin/time's %M), the load average before and after. A benchmark, not a test:
# nothing is asserted (docs/benchmarks.md, "A lab host").
#
#   bench/lab_host.sh [-n N] [-s SECONDS] [-b BUILD] [-p PORT_BASE] [-m host|separate|both]
#                     [-N NICE]
#
# -N: the daemons' nice value in both configurations (below 0 needs root, as the unit's
# Nice= has; default 0).
#
# Ports PORT_BASE - 2 .. PORT_BASE + 2N - 1 (default 30000; refused if any is bound: the
# pair below the base is the host's directory, LCM_DEFAULT_URL of its run), group of
# LCM_DEFAULT_URL (default 239.255.76.67), ttl 0. Every process it starts ends with it.
set -u
root=$(cd "$(dirname "$0")/.." && pwd)
n=100 secs=60 build=$root/build base=30000 modes=both nice=0
while getopts "n:s:b:p:m:N:" o; do
    case $o in
    n) n=$OPTARG ;; s) secs=$OPTARG ;; b) build=$OPTARG ;; p) base=$OPTARG ;; m) modes=$OPTARG ;;
    N) nice=$OPTARG ;;
    *) sed -n '2,20p' "$0"; exit 2 ;;
    esac
done
[ "$modes" = both ] && modes="host separate"
bin=$build/bin
group=239.255.76.67
if [ -n "${LCM_DEFAULT_URL:-}" ]; then
    g=$(sed -n 's|^udpm://\([0-9.]*\).*|\1|p' <<<"$LCM_DEFAULT_URL")
    [ -n "$g" ] && group=$g
fi
for f in lagsimd dipc_lqr lab_probe; do
    [ -x "$bin/$f" ] || { echo "lab_host: $bin/$f missing (build first)" >&2; exit 2; }
done
[ -x /usr/bin/time ] || { echo "lab_host: needs /usr/bin/time (apt-get install time)" >&2; exit 2; }
# no socket of this host on the ports (another bench or plant would mix in); the pair below
# the base is the host's directory (LCM_DEFAULT_URL of its run)
for ((p = base - 2; p < base + 2 * n; p++)); do
    if awk -v p="$(printf '%04X' "$p")" 'NR > 1 && $2 ~ ":"p"$" { f = 1 } END { exit !f }' \
        /proc/net/udp; then
        echo "lab_host: port $p is bound already: give another -p" >&2
        exit 2
    fi
done
work=$(mktemp -d)
pids=()
cleanup() {
    # /usr/bin/time does not pass a signal on: its child first, then it
    for p in "${pids[@]}"; do kill $(pgrep -P "$p") "$p" 2>/dev/null; done
    wait 2>/dev/null
    rm -rf "$work"
}
trap cleanup EXIT
trap 'exit 130' INT TERM
mkdir -p "$work/lab"
for ((i = 0; i < n; i++)); do cp "$root/config/dipc.yaml" "$work/lab/$(printf 'p%03d' "$i").yaml"; done

# Sums the user + system CPU seconds of the /usr/bin/time files given.
cpu_of() { cat "$@" 2>/dev/null | awk '{ s += $2 + $3 } END { printf "%.3f", s }'; }
# Sums the largest resident sets (KiB, the 4th field of the daemons' files), in MB.
mem_of() { cat "$@" 2>/dev/null | awk '{ s += $4 } END { printf "%.1f", s / 1024 }'; }

# One configuration: the probe, the controllers, the daemon(s); a line of figures.
run_mode() {
    local mode=$1 d=$work/$1
    mkdir -p "$d"
    local load0
    load0=$(cut -d' ' -f1-3 /proc/loadavg)
    "$bin/lab_probe" "$group" "$base" "$n" "$secs" 10000 >"$d/probe.out" &
    local probe=$!
    pids=("$probe")
    for ((i = 0; i < n; i++)); do
        local pre url
        pre=$(printf 'P%03d' "$i")
        url="udpm://$group:$((base + 2 * i))?ttl=0"
        /usr/bin/time -f '%e %U %S' -o "$d/ctl.$i" "$bin/dipc_lqr" -q --prefix "$pre" --url "$url" \
            --timeout 60 >/dev/null 2>&1 &
        pids+=($!)
    done
    if [ "$mode" = host ]; then
        LCM_DEFAULT_URL="udpm://$group:$((base - 2))?ttl=0" /usr/bin/time -f '%e %U %S %M' -o "$d/d.0" \
            nice -n "$nice" "$bin/lagsimd" --plants "$work/lab" --port-base "$base" --duration "$secs" -q \
            2>"$d/daemon.err" &
        pids+=($!)
    else
        for ((i = 0; i < n; i++)); do
            /usr/bin/time -f '%e %U %S %M' -o "$d/d.$i" nice -n "$nice" "$bin/lagsimd" --config \
                "$work/lab/$(printf 'p%03d' "$i").yaml" --set "lcm.prefix=$(printf 'P%03d' "$i")" \
                --set "lcm.url=udpm://$group:$((base + 2 * i))?ttl=0" --duration "$secs" -q \
                2>>"$d/daemon.err" &
            pids+=($!)
        done
    fi
    wait "${pids[@]}" 2>/dev/null
    pids=()
    local load1 dcpu ccpu periods
    load1=$(cut -d' ' -f1-3 /proc/loadavg)
    dcpu=$(cpu_of "$d"/d.*)
    ccpu=$(cpu_of "$d"/ctl.*)
    periods=$(awk -v n="$n" -v s="$secs" 'BEGIN { printf "%d", n * s * 100 }')
    printf '%-8s N=%d %s; daemon CPU %s s = %.1f us per plant-period, memory %s MB; controllers %s s = %.1f us; load %s -> %s\n' \
        "$mode" "$n" "$(cat "$d/probe.out")" "$dcpu" "$(awk -v c="$dcpu" -v p="$periods" 'BEGIN { print c / p * 1e6 }')" \
        "$(mem_of "$d"/d.*)" "$ccpu" "$(awk -v c="$ccpu" -v p="$periods" 'BEGIN { print c / p * 1e6 }')" "$load0" "$load1"
    grep -v -e 'listening on' -e 'event start' -e 'plants starting' -e "host's directory" "$d/daemon.err" | head -5
}

echo "lab_host: $n DIPC plants at 100 Hz, a dipc_lqr each, $secs s, daemons at nice $nice; $(nproc) cores; $(date -u '+%Y-%m-%d %H:%M UTC')"
for m in $modes; do run_mode "$m"; done
