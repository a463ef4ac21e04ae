#!/usr/bin/env bash
# Installs the Debian packages lagsim needs (build, tests, peers for benchmarks, plots).
# Skips apt entirely when everything is already installed.
set -euo pipefail
pkgs=(build-essential cmake pkg-config clang libclang-rt-14-dev   # gcc pass; clang pass (sanitizers, libFuzzer)
      liblcm-dev liblcm-bin libglib2.0-dev libyaml-dev   # LCM (lcm.pc needs glib's dev package) and libyaml
      liblapacke-dev                                     # the example controllers' LQR design (LAPACK)
      python3                                            # the stdlib-only Python client and some tests
      lua5.2 liblcm-lua lua-posix                        # the Lua 5.2 clients (liblcm-lua is built for 5.2 only; lua-posix: their SIGINT, SIGTERM)
      libmujoco-dev libsundials-dev gnuplot-nox          # benchmark peers and plots
      liblcm-java libjchart2d-java default-jdk-headless  # the Java clients; lcm-spy with lagsim's types
      octave octave-control                              # the MATLAB/Octave clients (dlqr, lqr) and their tests
      libmicrohttpd-dev chromium fonts-dejavu-core       # lagsim-view; its browser test and screenshot
      curl                                               # the walkthrough (docs/clients.md) asks lagsim-view for its history
      iproute2 nftables                                  # two hosts on one machine: namespaces, veth, packet loss
      lintian systemd                                    # the Debian package: lintian, systemd-analyze, its unit run by systemd
      parallel slurm-client                              # lagsim-sweep shards: GNU parallel, sbatch (--test-only, no cluster)
      openssh-server openssh-client                      # ... and parallel --sshlogin, tested against sshd in namespaces
      universal-ctags)                                   # structure_function_length: each C function's first and last line
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi
echo "installing: ${missing[*]}"
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO=sudo
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
