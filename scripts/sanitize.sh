#!/usr/bin/env bash
# scripts/sanitize.sh [ctest arguments...]
# The whole test suite under AddressSanitizer + UndefinedBehaviorSanitizer (any finding stops the
# test that hit it: -fno-sanitize-recover), then `calibench calibrate` on the demo under valgrind
# (--error-exitcode=1). Builds in build-asan/ (sanitizers) and uses build/ for the valgrind run.
# Leaks inside the GL drivers and X libraries the workbench tests load are not ours; they are
# listed in tests/sanitizers/lsan.supp.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh --sanitize

JOBS=${CALIBENCH_JOBS:-$(nproc)}
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCALIBENCH_SANITIZE=address,undefined -DCALIBENCH_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build build-asan -j "$JOBS"

supp="$PWD/tests/sanitizers"
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:detect_stack_use_after_return=0"
export LSAN_OPTIONS="suppressions=$supp/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:suppressions=$supp/ubsan.supp"
ctest --test-dir build-asan --output-on-failure -j "$JOBS" --timeout 1800 "$@"

# valgrind: the release build, as users run it, on the demo dataset.
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j "$JOBS" --target calibench
[ -f build/demo/dataset.json ] || build/calibench simulate --preset demo --out build/demo >/dev/null
valgrind --error-exitcode=1 --errors-for-leak-kinds=definite --leak-check=full \
  --suppressions="$supp/valgrind.supp" \
  build/calibench calibrate --dataset build/demo --out build/demo/valgrind-result.json --threads 2
echo "sanitize: the test suite passed under ASan + UBSan; valgrind found no error in calibrate"
