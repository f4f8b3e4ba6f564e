#!/usr/bin/env bash
# The README's test command: installs dependencies, builds, and runs every test.
#  1. gcc build of everything + the whole CTest suite (unit, end-to-end daemon/viewer/USB-model tests).
#  2. clang build with AddressSanitizer + UndefinedBehaviorSanitizer of the protocol, simulator, accuracy
#     and DMC-1 suites, which run again under the sanitizers, plus a short smoke run of every libFuzzer
#     target.
# Long fuzz runs are not part of this; see "Testing" in README.md.
set -euo pipefail
cd "$(dirname "$0")/.."
start=$(date +%s)

if [ "${GPUBRIDGE_SKIP_DEPS:-0}" != 1 ]; then ./scripts/install-deps.sh; fi

echo "== build (gcc) =="
./scripts/build.sh
echo "== tests (gcc build) =="
ctest --test-dir build --output-on-failure -j "$(nproc)" --timeout 300

echo "== sanitizer build (clang, ASan + UBSan) =="
SAN_DIR=build-san
# -O1 with line tables: fast to build, readable sanitizer stacks, assertions on.
cmake -S . -B "$SAN_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_CXX_FLAGS_RELEASE="-O1 -gline-tables-only" -DCMAKE_C_FLAGS_RELEASE="-O1 -gline-tables-only" \
  -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ \
  -DGPUBRIDGE_SANITIZE=ON -DGPUBRIDGE_FUZZ=ON -DGPUBRIDGE_BUILD_BENCH=OFF >/dev/null
# Only the suites that decode untrusted input or do the arithmetic are rebuilt and rerun under the
# sanitizers: every test executable of tests/protocol, tests/sim, tests/accuracy and tests/dmc1, plus
# the fuzzers.
san_dirs=()
for d in tests/protocol tests/sim tests/accuracy tests/dmc1 tests/fuzz; do
  [ -f "$d/CMakeLists.txt" ] && san_dirs+=("$d/all")
done
cmake --build "$SAN_DIR" -j "$(nproc)" --target "${san_dirs[@]}"
echo "== tests (sanitizer build) =="
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 ASAN_OPTIONS=detect_leaks=1
passed=0
for d in tests/protocol tests/sim tests/accuracy tests/dmc1; do
  [ -d "$SAN_DIR/$d" ] || continue
  while IFS= read -r exe; do
    echo "-- $exe"
    "$exe" --gtest_brief=1
    passed=$((passed + 1))
  done < <(find "$SAN_DIR/$d" -maxdepth 1 -type f -executable -name '*test*' | sort)
done
echo "sanitizer suites: $passed executables passed"
if [ -x scripts/fuzz-smoke.sh ]; then
  echo "== fuzz smoke (libFuzzer + ASan + UBSan) =="
  GPUBRIDGE_FUZZ_BUILD_DIR="$SAN_DIR" ./scripts/fuzz-smoke.sh "${GPUBRIDGE_FUZZ_SECONDS:-5}"
fi

echo "== done in $(( $(date +%s) - start )) s =="
