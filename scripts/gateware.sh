#!/usr/bin/env bash
# Board bitstreams and their figures (docs/gateware.md "Boards"): yosys -> nextpnr-ice40 -> icepack for
# the iCEBreaker (build/gateware/boards/icebreaker.bin, what `gpubridge flash --board icebreaker` writes),
# yosys synth_ecp5 for the ULX3S (nextpnr-ecp5 -> ecppack -> ulx3s.bit when both are on PATH).
# Usage: scripts/gateware.sh [--board icebreaker|ulx3s|all] [--seeds N] [--abc9] [--no-video] [--json FILE]
# Exit 1 when a design does not fit its part or misses its clock (the message names the resource),
# 2 when a tool is missing or fails.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
out="${GPUBRIDGE_BUILD_DIR:-$root/build}/gateware/boards"
for arg in "$@"; do
  if [ "$arg" = "--help" ] || [ "$arg" = "-h" ]; then exec python3 "$root/gateware/boards/build.py" --help; fi
done
exec python3 "$root/gateware/boards/build.py" --out "$out" "$@"
