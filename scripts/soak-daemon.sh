#!/usr/bin/env bash
# Hostile soak of gpubridged (issue 14; docs/daemon.md "Hostile soak"): every hostile client scenario
# at once beside a good client whose screenshots must equal `gpubridge render`, with RSS, descriptors
# and SIGTERM checked. Not part of scripts/test.sh: it runs for minutes. Builds what it needs in the
# existing build directory (scripts/build.sh first).
# Usage: scripts/soak-daemon.sh [--minutes N] [--trace TRACE]   (default 10 minutes, tests/daemon/data/triangle.trace)
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${GPUBRIDGE_BUILD_DIR:-build}
if [[ ! -f "$BUILD_DIR/build.ninja" ]]; then
  echo "soak-daemon.sh: no build in $BUILD_DIR; run scripts/build.sh first (or set GPUBRIDGE_BUILD_DIR)" >&2
  exit 2
fi
if ! out=$(cmake --build "$BUILD_DIR" --target daemon_soak 2>&1); then
  echo "$out" >&2
  echo "soak-daemon.sh: building daemon_soak failed" >&2
  exit 2
fi
minutes=10
trace=tests/daemon/data/triangle.trace
while [[ $# -gt 0 ]]; do
  case "$1" in
    --minutes) minutes=$2; shift 2 ;;
    --trace) trace=$2; shift 2 ;;
    -h|--help) sed -n '2,6p' "$0"; exit 0 ;;
    *) echo "soak-daemon.sh: unknown argument $1 (use --minutes N, --trace TRACE)" >&2; exit 2 ;;
  esac
done
exec "$BUILD_DIR/tests/daemon/daemon_soak" --minutes "$minutes" --trace "$trace"
