#!/usr/bin/env bash
# The README's main command: installs dependencies, builds, starts gpubridged on the simulator and
# streams the demo scenes to it. With a display, gpubridge-view shows them as they animate (close
# the window or press Q to finish); without one, a few frames of every scene are written as PNG
# files and their paths printed.
# Environment: GPUBRIDGE_SKIP_DEPS=1 skips the package install; DEMO_FRAMES (default 240 with a
# display, 3 without) frames per scene; DEMO_FPS (default 30); DEMO_OUT (default out/demo).
set -euo pipefail
cd "$(dirname "$0")/.."

if [ "${GPUBRIDGE_SKIP_DEPS:-0}" != 1 ]; then ./scripts/install-deps.sh; fi
./scripts/build.sh

bin=build
out=${DEMO_OUT:-out/demo}
rundir=$(mktemp -d -t gpubridge-demo.XXXXXX)
sock="$rundir/gpubridge.sock"
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  wait 2>/dev/null || true
  rm -rf "$rundir"
}
trap cleanup EXIT

have_display=0
if [ -n "${DISPLAY:-}${WAYLAND_DISPLAY:-}" ]; then have_display=1; fi

daemon_args=(--listen "unix:$sock" --backend sim --log-level warn)
if [ "$have_display" = 0 ]; then
  rm -rf "$out"; mkdir -p "$out"
  daemon_args+=(--frames-dir "$out")
fi
"$bin/daemon/gpubridged" "${daemon_args[@]}" &
pids+=($!)
for _ in $(seq 100); do [ -S "$sock" ] && break; sleep 0.05; done
[ -S "$sock" ] || { echo "demo: gpubridged did not start (socket $sock missing)" >&2; exit 1; }
echo "gpubridged is serving the simulator at unix:$sock"

if [ "$have_display" = 1 ]; then
  "$bin/viewer/gpubridge-view" --connect "unix:$sock" --wait &
  viewer=$!
  pids+=($viewer)
  "$bin/examples/gpubridge-demo" stream --connect "unix:$sock" --frames "${DEMO_FRAMES:-240}" --fps "${DEMO_FPS:-30}"
  echo "demo: all scenes streamed; close the viewer window (or press Q) to finish"
  wait "$viewer" || true
else
  "$bin/examples/gpubridge-demo" stream --connect "unix:$sock" --frames "${DEMO_FRAMES:-3}" --fps 0
  sleep 0.5
  echo "No display: wrote these scanned-out frames (one PNG per swap, scenes in turn):"
  ls -1 "$out"/*.png | sed 's/^/  /'
  echo "Every scene also renders in-process: $bin/examples/gpubridge-demo render --out $out/inprocess"
fi
