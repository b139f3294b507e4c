#!/usr/bin/env bash
# The two README commands in one script:
#   scripts/bootstrap.sh          install dependencies, build, run the demo
#   scripts/bootstrap.sh --test   the same, then the whole test suite
set -euo pipefail
cd "$(dirname "$0")/.."

run_tests=0
[ "${1:-}" = "--test" ] && run_tests=1

bash scripts/install_deps.sh

BUILD_DIR=${CALIBENCH_BUILD_DIR:-build}
JOBS=${CALIBENCH_JOBS:-$(nproc)}
# Unity builds: the fresh build about 0.6x the time (CMakeLists.txt says why they are off otherwise).
cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCALIBENCH_UNITY_BUILD=ON
# The demo needs the executable, the Python module and its files, the man page and completion;
# the test suites and benchmarks (most of a fresh build) only with --test.
if [ $run_tests -eq 1 ]; then
  cmake --build "$BUILD_DIR" -j "$JOBS"
else
  cmake --build "$BUILD_DIR" -j "$JOBS" --target calibench calibench_python calibench_python_files \
    calibench_docs
fi

# The main job: the demo (simulate, calibrate, print the result and its error), then the
# workbench on it when there is a display, or its views rendered to PNG when there is none.
# With --test the window never opens: the test suite must not wait for it.
demo_flags=()
[ $run_tests -eq 1 ] && demo_flags+=(--no-gui)
"$BUILD_DIR/calibench" demo --out "$BUILD_DIR/demo" "${demo_flags[@]}"
# The same result from the Python module built beside it (python/, README "Python").
PYTHONPATH="$BUILD_DIR/python" /usr/bin/python3 -c \
  "import calibench; print('from Python:', calibench.load_result('$BUILD_DIR/demo/result.json'))"

if [ $run_tests -eq 1 ]; then
  ctest --test-dir "$BUILD_DIR" --output-on-failure -j "$JOBS" --timeout 900
  # The sanitizers, routinely: the core and workbench tests again under ASan + UBSan
  # (scripts/sanitize.sh --ci, in build-asan/; the whole suite and valgrind: scripts/sanitize.sh).
  bash scripts/sanitize.sh --ci
fi
