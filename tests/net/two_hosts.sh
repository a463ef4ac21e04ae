#!/bin/bash
# Two hosts on one machine: two network namespaces joined by a veth pair, each with a
# multicast route on its end, lagsimd in one ("A") and a controller, lcm-logger or a peer
# in the other ("B"), over LCM udpm with ttl=1, with nftables dropping packets where a
# case asks for loss. Needs root (ip netns, nft); anywhere it cannot make namespaces it
# says why and exits 77, which ctest reports as skipped.
#
#   two_hosts.sh CASE BUILD_DIR SOURCE_DIR
#   CASE: host_local      the default scene (lcm.allow_lan false) accepts 0 of a peer's
#                         commands and control requests; with allow_lan it accepts them;
#                         with the route 224.0.0.0/4 dev lo it accepts this host's
#
# Every run names its namespaces and veth ends after its PID and removes them in a trap.
set -u
case_name=${1:?usage: two_hosts.sh CASE BUILD_DIR SOURCE_DIR}
build=$(cd "${2:?build dir}" && pwd)
src=$(cd "${3:?source dir}" && pwd)
lagsimd=$build/bin/lagsimd
types=$build/python
netpeer="python3 $src/tests/net/netpeer.py"
config=$src/config/dipc.yaml

skip() { echo "SKIPPED: $*"; exit 77; }
[ "$(id -u)" = 0 ] || skip "needs root (network namespaces, nftables)"
command -v ip >/dev/null || skip "no 'ip' command (iproute2)"
command -v nft >/dev/null || skip "no 'nft' command (apt-get install nftables)"
command -v lcm-logger >/dev/null || skip "no lcm-logger (liblcm-bin)"

id=$$
nsA=lagsimA$id nsB=lagsimB$id vA=lsa$id vB=lsb$id
work=$(mktemp -d /tmp/lagsim_two_hosts_XXXXXX)
pids=()
cleanup() {
    for p in "${pids[@]}"; do kill -9 "$p" 2>/dev/null; done
    ip netns del "$nsA" 2>/dev/null
    ip netns del "$nsB" 2>/dev/null
    ip link del "$vA" 2>/dev/null
    rm -rf "$work"
}
trap cleanup EXIT
trap 'exit 1' INT TERM

ip netns add "$nsA" 2>/dev/null || skip "cannot create a network namespace here"
ip netns add "$nsB" || skip "cannot create a second network namespace"
ip link add "$vA" type veth peer name "$vB" || skip "cannot create a veth pair"
ip link set "$vA" netns "$nsA"
ip link set "$vB" netns "$nsB"
ip -n "$nsA" addr add 10.77.0.1/24 dev "$vA"
ip -n "$nsB" addr add 10.77.0.2/24 dev "$vB"
for ns in "$nsA" "$nsB"; do ip -n "$ns" link set lo up; done
ip -n "$nsA" link set "$vA" up
ip -n "$nsB" link set "$vB" up
ip -n "$nsA" route add 224.0.0.0/4 dev "$vA"
ip -n "$nsB" route add 224.0.0.0/4 dev "$vB"
# commands in a namespace (not shell functions: `$inA cmd &` must give cmd's own PID)
inA="ip netns exec $nsA"
inB="ip netns exec $nsB"

fail=0
check() { # check CONDITION-TEXT RESULT(0 = true)
    if [ "$2" = 0 ]; then echo "ok: $1"; else echo "FAIL: $1"; fail=1; fi
}
# jq-less reading of netpeer.py's JSON summary
field() { python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print(eval(sys.argv[2]))" "$1" "$2"; }

# A lagsimd in A with a logger in A on its state URL; a peer in B sends commands and
# STATUS requests with ttl=1 to both ports of the URL (the command URL, and the state URL
# where a daemon with one port listened); the daemon's final status says what it
# accepted.
host_local_run() { # allow_lan ttl tag [local]: with "local", a sender in A as well
    local lan=$1 ttl=$2 tag=$3 also_local=${4:-} prefix=HL$id
    local url="udpm://239.255.76.67:7667?ttl=$ttl"
    $inA lcm-logger -q -f --lcm-url "$url" "$work/$tag.lcm" & pids+=($!); local logger=$!
    sleep 0.5
    $inA "$lagsimd" --config "$config" --set lcm.prefix=$prefix --set lcm.allow_lan=$lan \
        --set "lcm.url=$url" --set realtime.command_timeout=100 -q \
        2>"$work/$tag.err" & pids+=($!); local d=$!
    sleep 1
    for port in 7668 7667; do
        $inB $netpeer send --raw --types "$types" --url "udpm://239.255.76.67:$port?ttl=1" \
            --prefix $prefix --commands 20 --controls 5 --interval 0.02
    done
    if [ -n "$also_local" ]; then
        $inA $netpeer send --types "$types" --url "$url" --prefix $prefix --commands 20 \
            --controls 0 --interval 0.02
    fi
    sleep 0.5
    kill -TERM $d; wait $d; local rc=$?
    sleep 0.3
    kill -INT $logger; wait $logger 2>/dev/null
    cat "$work/$tag.err"
    $netpeer summary --types "$types" --prefix $prefix "$work/$tag.lcm" >"$work/$tag.json"
    accepted=$(field "$work/$tag.json" "d['status']['commands_accepted']")
    states=$(field "$work/$tag.json" "d['states']")
    echo "$tag: lagsimd exit $rc, $states states, commands accepted: $accepted"
    [ $rc = 0 ]
}

case_host_local() {
    host_local_run false 0 local
    check "lagsimd ran (host-local default)" $?
    check "the default scene accepts 0 of the peer's commands (got $accepted)" \
        $([ "$accepted" = 0 ]; echo $?)
    grep -q "listening on $vA for commands and control from this host only" "$work/local.err"
    check "the start line names the interface ($vA) and says 'this host only'" $?
    host_local_run true 1 lan
    check "lagsimd ran (lcm.allow_lan: true, ttl=1)" $?
    check "with lcm.allow_lan the peer's 20 commands on the command URL are accepted (got $accepted)" \
        $([ "$accepted" = 20 ]; echo $?)
    grep -q "from the network (lcm.allow_lan: true" "$work/lan.err"
    check "the start line announces the network" $?
    # the loopback route: multicast stays on lo; the filter keeps what arrives on lo
    ip -n "$nsA" route replace 224.0.0.0/4 dev lo
    host_local_run false 0 loroute local
    check "lagsimd ran (route 224.0.0.0/4 dev lo)" $?
    check "with the loopback route, this host's 20 commands are accepted and the peer's none (got $accepted)" \
        $([ "$accepted" = 20 ]; echo $?)
    grep -q "listening on lo for commands" "$work/loroute.err"
    check "the start line says lo" $?
    ip -n "$nsA" route replace 224.0.0.0/4 dev "$vA"
}

case "$case_name" in
host_local) case_host_local ;;
*) echo "unknown case $case_name"; exit 2 ;;
esac
[ $fail = 0 ] && echo "two_hosts $case_name: ok" || echo "two_hosts $case_name: FAILED"
exit $fail
