#!/bin/sh
# The README's main job without a display (scripts/demo-run.sh on this build): every demo scene
# streams through a real gpubridged, and every swap leaves a PNG that decodes; the DMC-1 example
# level streams through a second gpubridged (--backend dmc1), and its first frame, the chip's first
# after reset, is the committed golden examples/dmc1/golden/level-00.png.
# Usage: demo_headless.sh SOURCE_DIR BUILD_DIR WORK_DIR
set -eu
src=$1 build=$2 work=$3
frames=2
# One PNG per swap: every scene the demo lists, `frames` times.
scenes=$("$build/examples/gpubridge-demo" list | grep -c .)
[ "$scenes" -gt 0 ] || { echo "gpubridge-demo list printed no scenes"; exit 1; }
rm -rf "$work" && mkdir -p "$work"
env -u DISPLAY -u WAYLAND_DISPLAY DEMO_OUT="$work/out" DEMO_FRAMES=$frames \
  "$src/scripts/demo-run.sh" "$build" > "$work/log" 2>&1 || { cat "$work/log"; echo "demo-run.sh failed"; exit 1; }
cat "$work/log"
count=$(ls "$work/out"/frame_*.png | wc -l)
[ "$count" -eq $((frames * scenes)) ] || { echo "expected $((frames * scenes)) PNG frames, found $count"; exit 1; }
for f in "$work/out"/frame_*.png; do
  grep -q "  $f\$" "$work/log" || { echo "$f was written but not listed"; exit 1; }
  "$build/tools/gpubridge" compare "$f" "$f" > /dev/null || { echo "$f does not decode as a PNG"; exit 1; }
done
dmc1=$(ls "$work/out/dmc1"/frame_*.png | wc -l)
[ "$dmc1" -eq $frames ] || { echo "expected $frames DMC-1 PNG frames, found $dmc1"; exit 1; }
for f in "$work/out/dmc1"/frame_*.png; do
  grep -q "  $f\$" "$work/log" || { echo "$f was written but not listed"; exit 1; }
done
"$build/tools/gpubridge" compare "$src/examples/dmc1/golden/level-00.png" "$work/out/dmc1/frame_000000.png" --tolerance 0 ||
  { echo "the DMC-1 level's first frame is not examples/dmc1/golden/level-00.png"; exit 1; }
echo "demo headless: $count frames written, listed and decodable; $dmc1 DMC-1 frames, the first its golden"
