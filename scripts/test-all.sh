#!/usr/bin/env bash
# Every test: install what is needed, build, run the whole suite (unit, CLI, install, Blender
# oracle), then build again with AddressSanitizer + UBSan and run the suite once more.
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/deps.sh
install_deps test
jobs="$(nproc)"

cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build
ctest --test-dir build --output-on-failure -j "$jobs"

cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSGBAKE_SANITIZE=ON -DSGBAKE_BUILD_BENCH=OFF
cmake --build build-asan
# Full malloc stacks so that tests/lsan.supp can name the third-party library that leaks.
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:fast_unwind_on_malloc=0 \
LSAN_OPTIONS="suppressions=$PWD/tests/lsan.supp" \
UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build-asan --output-on-failure -j "$jobs" -LE install
