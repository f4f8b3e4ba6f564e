#!/usr/bin/env bash
# find_package(gpubridge) as a third party uses it: install the build tree into a scratch prefix, build
# tests/package/consumer against that prefix only, start the *installed* gpubridged on the simulator and
# run the consumer against it.
set -euo pipefail
build_dir=$1 source_dir=$2
work=$(mktemp -d)
daemon_pid=
cleanup() {
  [ -n "$daemon_pid" ] && kill "$daemon_pid" 2>/dev/null && wait "$daemon_pid" 2>/dev/null
  rm -rf "$work"
}
trap cleanup EXIT

cmake --install "$build_dir" --prefix "$work/prefix" >/dev/null
test -f "$work/prefix/lib/cmake/gpubridge/gpubridgeConfig.cmake" ||
  test -n "$(find "$work/prefix" -name gpubridgeConfig.cmake)" || { echo "no gpubridgeConfig.cmake installed"; exit 1; }

cmake -S "$source_dir/tests/package/consumer" -B "$work/consumer" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$work/prefix" -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF >"$work/configure.log" 2>&1 ||
  { cat "$work/configure.log"; exit 1; }
cmake --build "$work/consumer" >"$work/build.log" 2>&1 || { cat "$work/build.log"; exit 1; }

socket="$work/gpubridge.sock"
"$work/prefix/sbin/gpubridged" --listen "unix:$socket" --backend sim >"$work/daemon.log" 2>&1 &
daemon_pid=$!
for _ in $(seq 100); do [ -S "$socket" ] && break; sleep 0.05; done
[ -S "$socket" ] || { echo "installed gpubridged did not create $socket"; cat "$work/daemon.log"; exit 1; }

"$work/consumer/consumer" "unix:$socket"
