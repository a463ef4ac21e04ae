#!/bin/bash
# A controller's states under a command flood, with commands on the state URL's port (as
# when one port carried everything) and on the command URL's (port + 1, as now).
# lagsimd runs the DIPC in real time at 1000 states a second; a C subscriber to
# <PREFIX>_STATE on the state URL (net_flood listen) counts what it gets for 4 s while
# net_flood floods valid, empty commands for 3 s:
#   none     no flood
#   shared   the flood on the state port: every socket of that port (the controller's,
#            lcm-logger's, the view's) receives it, as it did with one port; the daemon
#            does not, so the old layout was if anything worse
#   separate the same flood on the command port: only the daemon's socket receives it
# Prints one line per layout and run. Nothing is asserted: figures for docs/network.md.
#   bench/net_flood.sh [BUILD_DIR [RUNS]]      (default build, 3)
set -u
root=$(cd "$(dirname "$0")/.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
runs=${2:-3}
port=$((20000 + $$ % 20000))
url="udpm://239.255.76.67:$port?ttl=0"
curl="udpm://239.255.76.67:$((port + 1))?ttl=0"
prefix=FLOOD$$
"$build/bin/lagsimd" --config "$root/config/dipc.yaml" -q --set "lcm.url=$url" \
    --set lcm.prefix=$prefix --set realtime.start=running --set publish_hz=1000 \
    --set realtime.command_timeout=1000 2>/dev/null &
d=$!
trap 'kill $d 2>/dev/null' EXIT
sleep 1.5
for r in $(seq "$runs"); do
    for layout in none shared separate; do
        "$build/bin/net_flood" listen "$url" $prefix 4 >/tmp/net_flood_$$.out &
        l=$!
        sleep 0.5
        case $layout in
        shared) f=$("$build/bin/net_flood" flood "$url" ${prefix}_COMMAND 3) ;;
        separate) f=$("$build/bin/net_flood" flood "$curl" ${prefix}_COMMAND 3) ;;
        none) sleep 3; f="flood: none" ;;
        esac
        wait $l
        printf "run %d %-8s %s; %s\n" "$r" "$layout" "$(cat /tmp/net_flood_$$.out)" "$f"
    done
done
rm -f /tmp/net_flood_$$.out
