#!/usr/bin/env bash
# The main job: installs what it needs, builds, then runs lagsimd on config/dipc.yaml in
# real time with dipc_lqr balancing the double inverted pendulum; lagsimd's live status
# line (sim time, real-time factor, overruns, energy) shows in this terminal, and
# lagsim-view serves a live view to browsers (its address is printed).
# Ctrl-C stops both. Extra arguments go to lagsimd, e.g.
#   clients/demo.sh --duration 30 --set realtime.rate=0.5
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
"$root/.ci/install-deps.sh" runtime  # the programs' packages only: no test tool, no service
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)" --target lagsimd dipc_lqr lagsim-view >/dev/null

# The controller first: it waits for the daemon's scene description, designs its LQR
# gains from it, then answers every state. Its output goes to a log, shown at the end, so
# that lagsimd's live status line stays readable.
log=build/dipc_lqr.log
build/bin/dipc_lqr -q >"$log" 2>&1 &
lqr=$!
# The live view in a browser (this machine only); its address is printed below.
build/bin/lagsim-view --prefix DIPC --port "${LAGSIM_VIEW_PORT:-8765}" -q >build/lagsim-view.log 2>&1 &
view=$!
finish() {
    kill -INT "$lqr" 2>/dev/null || true
    kill -TERM "$view" 2>/dev/null || true
    wait "$lqr" 2>/dev/null || true
    wait "$view" 2>/dev/null || true
    printf '\n--- dipc_lqr (%s) ---\n' "$log"
    cat "$log"
}
trap finish EXIT
trap 'exit 0' INT TERM
# its address line, or its end (at most 10 s: a loaded machine starts it late)
for _ in $(seq 100); do
    grep -q 'http://' build/lagsim-view.log && break
    kill -0 "$view" 2>/dev/null || break
    sleep 0.1
done
if addr=$(grep -o 'http://[^ ]*' build/lagsim-view.log); then
    echo "lagsim-view: open $addr in a browser to watch the DIPC" >&2
else
    echo "lagsim-view did not start (port ${LAGSIM_VIEW_PORT:-8765} taken? set LAGSIM_VIEW_PORT):" >&2
    cat build/lagsim-view.log >&2
fi
echo "lagsimd: DIPC in real time, balanced by dipc_lqr (pid $lqr); Ctrl-C to stop" >&2
build/bin/lagsimd --config config/dipc.yaml "$@"
