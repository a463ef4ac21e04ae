#!/usr/bin/env bash
# Installs the Debian packages of one profile (as root or with sudo); skips apt entirely
# when they are all installed already.
#
#   .ci/install-deps.sh runtime   what the programs need: build lagsimd, the C controllers,
#                                 lagsim-view, lagsim-plot; run them (clients/demo.sh)
#   .ci/install-deps.sh tests     runtime + what the tests and benchmarks need; nothing that
#                                 starts a service (tests/run.sh installs this when missing)
#   .ci/install-deps.sh dev       tests + the packages that start a service or stand for one
#                                 (sshd, systemd): only when asked for, or in CI
#   .ci/install-deps.sh ci        what CI installs: dev (tests/run.sh under CI=true)
#   .ci/install-deps.sh --list P  prints profile P's packages, one a line, and installs nothing
#
# One table, a profile a row: a profile holds its own rows and those of the profiles before
# it (runtime < tests < service). The tests that need a "service" row skip (ctest: not run)
# without it and say so.
set -euo pipefail
table='
runtime build-essential       # the C compiler, make
runtime cmake
runtime pkg-config
runtime liblcm-dev            # LCM (lcm.pc needs glib'"'"'s dev package) ...
runtime liblcm-bin            # ... lcm-gen, lcm-logger, lcm-logplayer
runtime libglib2.0-dev
runtime libyaml-dev           # scenes
runtime liblapacke-dev        # the example controllers'"'"' LQR design (LAPACK)
runtime libmicrohttpd-dev     # lagsim-view
runtime python3               # the stdlib-only Python client
runtime gnuplot-nox           # lagsim-plot, lagsim-sweep --plot, lagsim-eval --report
runtime curl                  # the walkthrough (docs/clients.md) asks lagsim-view for its history
tests   clang                 # the sanitizer pass: clang, ASan+UBSan, libFuzzer
tests   libclang-rt-14-dev
tests   lua5.2                # the Lua 5.2 clients (liblcm-lua is built for 5.2 only)
tests   liblcm-lua
tests   liblua5.2-dev         # ... the client library'"'"'s Lua module (clients/lua/lagsim_client_lua.c)
tests   lua-posix             # ... their SIGINT, SIGTERM
tests   liblcm-java           # the Java clients; lcm-spy with lagsim'"'"'s types
tests   libjchart2d-java
tests   default-jdk-headless
tests   octave                # the MATLAB/Octave clients (dlqr, lqr) under GNU Octave
tests   octave-control
tests   chromium              # lagsim-view in a headless browser; its screenshot
tests   fonts-dejavu-core
tests   iproute2              # two hosts on one machine: namespaces, veth ...
tests   nftables              # ... and packet loss
tests   lintian               # the Debian package
tests   golang-go             # the Go controllers over the client library'"'"'s C ABI (cgo)
tests   abigail-tools         # the ABI check of the client library (abidw, abidiff: clients_abi)
tests   parallel              # lagsim-sweep shards under GNU parallel ...
tests   openssh-client        # ... and parallel --sshlogin
tests   libmujoco-dev         # benchmark peers
tests   libsundials-dev
tests   universal-ctags       # structure_function_length: each C function'"'"'s first and last line
tests   strace                # server_host_look: the waits of a starting daemon, counted
service openssh-server        # eval_lagsim_sweep_ssh: an sshd per namespace (the package starts one)
service systemd               # package_*: systemd-analyze; the unit run by systemd in a namespace
'

rank() {
  case $1 in
    runtime) echo 1 ;;
    tests) echo 2 ;;
    dev | ci | service) echo 3 ;;
    *) echo "usage: $0 [--list] runtime|tests|dev|ci" >&2; exit 2 ;;
  esac
}

list=0
if [ "${1:-}" = --list ]; then
  list=1
  shift
fi
# a profile to install or list (`service` is a kind of row of the table, not a profile)
case "$#:${1:-}" in
  1:runtime | 1:tests | 1:dev | 1:ci) ;;
  *) echo "usage: $0 [--list] runtime|tests|dev|ci" >&2; exit 2 ;;
esac
want=$(rank "$1")
pkgs=()
while read -r profile pkg _; do
  [ -n "$profile" ] || continue
  [ "$(rank "$profile")" -le "$want" ] && pkgs+=("$pkg")
done <<<"$table"
if [ $list -eq 1 ]; then
  printf '%s\n' "${pkgs[@]}"
  exit 0
fi

missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi
echo "installing ($1): ${missing[*]}"
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO=sudo
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
