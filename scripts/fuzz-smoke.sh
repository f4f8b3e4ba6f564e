#!/usr/bin/env bash
# Short libFuzzer runs of every fuzz target under ASan+UBSan: the protocol message parser, binary and
# text traces, the daemon session dispatch, scene files (parse + build), the daemon config, board
# profiles, PNG decoding, the four USB-SPI bridge drivers fed scripted USB replies, and the DMC-1
# stream files and UART link (with the simulator behind them).
#   scripts/fuzz-smoke.sh [seconds-per-target]   (default 20; scripts/test.sh passes 10)
# Configures build-fuzz/ with clang++ (-DGPUBRIDGE_FUZZ=ON -DGPUBRIDGE_SANITIZE=ON), builds only the
# fuzz targets, runs each from its seed corpus (tests/fuzz/corpus/<target>/, copied so the repo is
# not modified) and exits non-zero if any run finds a crash, leak, UB or failed property.
# Crash inputs are left in build-fuzz/fuzz-artifacts/. Seeds: python3 tests/fuzz/make_corpus.py.
set -euo pipefail

seconds="${1:-20}"
if ! [[ "$seconds" =~ ^[0-9]+$ ]] || [ "$seconds" -lt 1 ]; then
  echo "fuzz-smoke: seconds must be a positive integer, got '$seconds'" >&2
  exit 2
fi
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${GPUBRIDGE_FUZZ_BUILD_DIR:-$root/build-fuzz}"
cxx="${CXX_FUZZ:-$(command -v clang++ || command -v clang++-14 || true)}"
cc="${CC_FUZZ:-$(command -v clang || command -v clang-14 || true)}"
if [ -z "$cxx" ] || [ -z "$cc" ]; then
  echo "fuzz-smoke: clang/clang++ not found; install clang (scripts/install-deps.sh) to run the fuzzers" >&2
  exit 2
fi

generator=()
command -v ninja >/dev/null && generator=(-G Ninja)
# Reuse a build directory that is already configured for fuzzing (scripts/test.sh passes its
# sanitizer build); configure a fresh one otherwise.
if ! grep -q '^GPUBRIDGE_FUZZ:BOOL=ON' "$build/CMakeCache.txt" 2>/dev/null; then
  cmake -S "$root" -B "$build" "${generator[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_C_COMPILER="$cc" -DCMAKE_CXX_COMPILER="$cxx" \
    -DGPUBRIDGE_FUZZ=ON -DGPUBRIDGE_SANITIZE=ON -DGPUBRIDGE_BUILD_BENCH=OFF >/dev/null
fi
cmake --build "$build" --target fuzz_targets daemon_session_fuzz -j"$(nproc)"

artifacts="$build/fuzz-artifacts"
mkdir -p "$artifacts"
declare -A max_len=([message_parser]=65536 [binary_trace]=65536 [text_trace]=16384 [daemon_session]=65536
                    [scene]=32768 [daemon_config]=8192 [board_profile]=8192 [png]=16384 [usb_bridges]=4096
                    [dmc1_stream]=16384 [dmc1_link]=8192)
declare -A binary=([message_parser]=tests/fuzz/fuzz_message_parser [binary_trace]=tests/fuzz/fuzz_binary_trace
                   [text_trace]=tests/fuzz/fuzz_text_trace [daemon_session]=tests/daemon/daemon_session_fuzz)
declare -A corpus=([message_parser]=message_parser [binary_trace]=binary_trace [text_trace]=text_trace
                   [daemon_session]=message_parser)
targets=(message_parser binary_trace text_trace daemon_session)
# The newer targets exist when their library is in the tree (tests/fuzz/CMakeLists.txt).
for target in scene daemon_config board_profile png usb_bridges dmc1_stream dmc1_link; do
  if [ -x "$build/tests/fuzz/fuzz_$target" ]; then
    targets+=("$target")
    binary[$target]=tests/fuzz/fuzz_$target
    corpus[$target]=$target
  fi
done
status=0
for target in "${targets[@]}"; do
  work="$build/fuzz-corpus/$target"
  mkdir -p "$work"
  cp -n "$root/tests/fuzz/corpus/${corpus[$target]}/"* "$work/" 2>/dev/null || true
  log="$build/fuzz-$target.log"
  echo "fuzz-smoke: $target for ${seconds}s"
  if ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
      "$build/${binary[$target]}" -max_total_time="$seconds" -rss_limit_mb=2048 \
      -max_len="${max_len[$target]}" -timeout=10 -print_final_stats=1 \
      -artifact_prefix="$artifacts/$target-" "$work" >"$log" 2>&1; then
    execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo 0)
    rate=$(grep -o 'stat::average_exec_per_sec: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo 0)
    cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 || true)
    echo "fuzz-smoke: $target ok: $execs runs, $rate exec/s, $cov"
  else
    echo "fuzz-smoke: $target FAILED; log $log, inputs in $artifacts:" >&2
    grep -E 'ERROR|runtime error|fuzz property failed|SUMMARY' "$log" | head -20 >&2 || tail -20 "$log" >&2
    status=1
  fi
done
exit $status
