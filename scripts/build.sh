#!/usr/bin/env bash
# Configures and builds gpubridge in build/ (optimised -O2 without debug info, which halves the build
# time on small machines; pass -DCMAKE_BUILD_TYPE=RelWithDebInfo for a debuggable build). Warnings are
# errors.
# Usage: scripts/build.sh [extra cmake args...]
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${GPUBRIDGE_BUILD_DIR:-build}
JOBS=${JOBS:-$(nproc)}
cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_CXX_FLAGS_RELEASE="-O2 -DNDEBUG" -DCMAKE_C_FLAGS_RELEASE="-O2 -DNDEBUG" "$@" >/dev/null
cmake --build "$BUILD_DIR" -j "$JOBS"
