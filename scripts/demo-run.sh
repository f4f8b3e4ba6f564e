#!/usr/bin/env bash
# The demo itself, on an existing build (scripts/demo.sh installs and builds first; CTest runs this
# headless as demo.headless): starts gpubridged on the simulator and streams the demo scenes to it,
# and a second gpubridged serving the DMC-1 (--backend dmc1) with its example client's level
# streamed to it; into two gpubridge-view windows with a display, as PNG files without one.
# Usage: scripts/demo-run.sh [BUILD_DIR]   (default build; environment as in scripts/demo.sh)
# DEMO_BACKEND (default sim) is the daemon's backend: a board (icebreaker), or its emulation
# (emulated:icebreaker, any profile in configs/boards). On a board the daemon runs with --mirror and
# the demo ends by saying how many frames differed from the simulator. DEMO_DMC1=0 leaves the DMC-1
# out.
set -euo pipefail
cd "$(dirname "$0")/.."

bin=${1:-build}
out=${DEMO_OUT:-out/demo}
rundir=$(mktemp -d -t gpubridge-demo.XXXXXX)
sock="$rundir/gpubridge.sock"
dmc1_sock="$rundir/dmc1.sock"
dmc1=${DEMO_DMC1:-1}
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  wait 2>/dev/null || true
  rm -rf "$rundir"
}
trap cleanup EXIT

have_display=0
if [ -n "${DISPLAY:-}${WAYLAND_DISPLAY:-}" ]; then have_display=1; fi

backend=${DEMO_BACKEND:-sim}
daemon_args=(--listen "unix:$sock" --backend "$backend" --log-level warn)
mirror=0
if [ "$backend" != sim ]; then daemon_args+=(--mirror); mirror=1; fi
if [ "$have_display" = 0 ]; then
  rm -rf "$out"; mkdir -p "$out"
  daemon_args+=(--frames-dir "$out")
fi
"$bin/daemon/gpubridged" "${daemon_args[@]}" &
daemon=$!
pids+=($daemon)
# The DMC-1 (docs/dmc1.md), a second device behind its own daemon and socket.
if [ "$dmc1" = 1 ]; then
  dmc1_args=(--listen "unix:$dmc1_sock" --backend dmc1 --log-level warn)
  if [ "$have_display" = 0 ]; then mkdir -p "$out/dmc1"; dmc1_args+=(--frames-dir "$out/dmc1"); fi
  "$bin/daemon/gpubridged" "${dmc1_args[@]}" &
  dmc1_daemon=$!
  pids+=($dmc1_daemon)
fi
for _ in $(seq 100); do [ -S "$sock" ] && break; sleep 0.05; done
[ -S "$sock" ] || { echo "demo: gpubridged did not start (socket $sock missing)" >&2; exit 1; }
if [ "$mirror" = 1 ]; then
  echo "gpubridged is serving $backend at unix:$sock (the simulator mirrors it)"
else
  echo "gpubridged is serving the simulator at unix:$sock"
fi
if [ "$dmc1" = 1 ]; then
  for _ in $(seq 100); do [ -S "$dmc1_sock" ] && break; sleep 0.05; done
  [ -S "$dmc1_sock" ] || { echo "demo: gpubridged --backend dmc1 did not start (socket $dmc1_sock missing)" >&2; exit 1; }
  echo "gpubridged is serving the DMC-1 simulator at unix:$dmc1_sock"
fi
# Mirror mode: how many of the frames the board showed differed from the simulator's.
mirror_report() {
  [ "$mirror" = 1 ] || return 0
  "$bin/tools/gpubridge" --connect "unix:$sock" status | grep -A1 '^mirror:'
}

if [ "$have_display" = 1 ]; then
  "$bin/viewer/gpubridge-view" --connect "unix:$sock" --wait &
  viewer=$!
  pids+=($viewer)
  if [ "$dmc1" = 1 ]; then
    # The DMC-1 level goes round its camera path in a second window while the scenes play.
    "$bin/viewer/gpubridge-view" --connect "unix:$dmc1_sock" --wait &
    pids+=($!)
    "$bin/examples/dmc1/gpubridge-dmc1-demo" stream --connect "unix:$dmc1_sock" --loop --fps "${DEMO_FPS:-30}" > /dev/null &
    pids+=($!)
  fi
  "$bin/examples/gpubridge-demo" stream --connect "unix:$sock" --frames "${DEMO_FRAMES:-240}" --fps "${DEMO_FPS:-30}"
  mirror_report
  if [ "$dmc1" = 1 ]; then
    echo "demo: all scenes streamed (the DMC-1 level keeps going round); close the scenes' viewer window (or press Q) to finish"
  else
    echo "demo: all scenes streamed; close the viewer window (or press Q) to finish"
  fi
  wait "$viewer" || true
else
  "$bin/examples/gpubridge-demo" stream --connect "unix:$sock" --frames "${DEMO_FRAMES:-3}" --fps 0
  mirror_report
  if [ "$dmc1" = 1 ]; then
    # As many frames as each scene, spread round the level's camera path.
    dmc1_frames=${DEMO_FRAMES:-3}
    "$bin/examples/dmc1/gpubridge-dmc1-demo" stream --connect "unix:$dmc1_sock" --frames "$dmc1_frames" \
      --path-frames "$dmc1_frames" --fps 0
  fi
  # SIGTERM lets the daemons finish what they have in flight (every PNG is written) and exit.
  kill -TERM "$daemon"
  wait "$daemon" || { echo "demo: gpubridged did not exit cleanly" >&2; exit 1; }
  if [ "$dmc1" = 1 ]; then
    kill -TERM "$dmc1_daemon"
    wait "$dmc1_daemon" || { echo "demo: gpubridged --backend dmc1 did not exit cleanly" >&2; exit 1; }
  fi
  if compgen -G "$out/*.png" > /dev/null; then
    echo "No display: wrote these scanned-out frames (one PNG per swap, scenes in turn):"
    ls -1 "$out"/*.png | sed 's/^/  /'
  else
    # A board profile with "scanout": "crc" (or "off") reads back no pixels, only CRCs.
    echo "No display, and $backend reads back no pixels (its scanout is CRC only): no PNG frames to write"
  fi
  if [ "$dmc1" = 1 ]; then
    echo "The DMC-1 example level (gpubridge-dmc1-demo stream), as gpubridged --backend dmc1 scanned it out:"
    ls -1 "$out/dmc1"/*.png | sed 's/^/  /'
  fi
  board_option=""
  if [ "$mirror" = 1 ]; then board=${backend#emulated:}; board_option=" --board ${board%%\?*}"; fi
  echo "Every scene also renders in-process: $bin/examples/gpubridge-demo render$board_option --out $out/inprocess"
fi
