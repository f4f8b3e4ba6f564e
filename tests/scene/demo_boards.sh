#!/bin/sh
# The README's main job on every board profile (issue 22): scripts/demo-run.sh with
# DEMO_BACKEND=emulated:NAME for each spigpu board profile in configs/boards, headless. Every scene fits itself to
# the board's device (it says so), the daemon mirrors the board on the simulator, and not one frame
# of any scene differs; boards that read pixels back leave one decodable PNG per swap.
# Usage: demo_boards.sh SOURCE_DIR BUILD_DIR WORK_DIR
set -eu
src=$1 build=$2 work=$3
frames=2
scenes=$("$build/examples/gpubridge-demo" list | grep -c .)
[ "$scenes" -gt 0 ] || { echo "gpubridge-demo list printed no scenes"; exit 1; }
expected=$((frames * scenes))
rm -rf "$work" && mkdir -p "$work"
boards=0
# The spigpu boards, as `gpubridge boards` lists them (UART boards such as icebreaker-dmc1 run
# other devices and have no emulated SPI bridge).
spigpu_boards=$("$build/tools/gpubridge" boards | awk 'NR > 1 && $2 == "spigpu" { print $1 }')
for board in $spigpu_boards; do
  profile="$src/configs/boards/$board.json"
  log="$work/$board.log" out="$work/$board"
  # DEMO_DMC1=0: the DMC-1 part does not depend on the board (demo.headless runs it).
  env -u DISPLAY -u WAYLAND_DISPLAY DEMO_BACKEND="emulated:$board" DEMO_OUT="$out" DEMO_FRAMES=$frames DEMO_DMC1=0 \
    "$src/scripts/demo-run.sh" "$build" > "$log" 2>&1 || { cat "$log"; echo "$board: demo-run.sh failed"; exit 1; }
  fitted=$(grep -c " on $board: " "$log" || true)
  [ "$fitted" -eq "$scenes" ] || { cat "$log"; echo "$board: $fitted of $scenes scenes printed their fit"; exit 1; }
  grep -q "^mirror: *0 of $expected frame(s) differ from the simulator" "$log" ||
    { cat "$log"; echo "$board: expected 'mirror: 0 of $expected frame(s) differ'"; exit 1; }
  pngs=$(find "$out" -maxdepth 1 -name 'frame_*.png' | wc -l)
  if grep -q '"scanout": *"readback"' "$profile"; then
    [ "$pngs" -eq "$expected" ] || { cat "$log"; echo "$board: expected $expected PNG frames, found $pngs"; exit 1; }
    for f in "$out"/frame_*.png; do
      "$build/tools/gpubridge" compare "$f" "$f" > /dev/null || { echo "$board: $f does not decode as a PNG"; exit 1; }
    done
  fi
  echo "$board: $scenes scenes fitted, 0 of $expected frames differ, $pngs PNG frames"
  boards=$((boards + 1))
done
[ "$boards" -gt 0 ] || { echo "no board profiles in $src/configs/boards"; exit 1; }
echo "demo boards: every scene on $boards board profiles, 0 differing frames"
