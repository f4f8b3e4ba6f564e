#!/usr/bin/env bash
# The README's main command: installs dependencies, builds, starts gpubridged on the simulator and
# streams the demo scenes to it, and a second gpubridged serving the DMC-1 with its example level.
# With a display, two gpubridge-view windows show them as they animate (close the scenes' window or
# press Q in it to finish); without one, a few frames of every scene and of the level are written as
# PNG files and their paths printed.
# Environment: GPUBRIDGE_SKIP_DEPS=1 skips the package install; DEMO_FRAMES (default 240 with a
# display, 3 without) frames per scene; DEMO_FPS (default 30); DEMO_OUT (default out/demo);
# DEMO_BACKEND (default sim): a board profile (emulated:icebreaker without the board), mirrored;
# DEMO_DMC1=0 leaves the DMC-1 out.
set -euo pipefail
cd "$(dirname "$0")/.."

if [ "${GPUBRIDGE_SKIP_DEPS:-0}" != 1 ]; then ./scripts/install-deps.sh; fi
./scripts/build.sh

exec ./scripts/demo-run.sh "${GPUBRIDGE_BUILD_DIR:-build}"
