#!/usr/bin/env bash
# scripts/fuzz.sh [SECONDS] [TARGET...]
# Fuzzes every loader (or the named targets) for SECONDS each (default 600) with libFuzzer, ASan
# and UBSan: builds the harnesses of tests/fuzz with clang 14 in build-fuzz/ (installing clang-14
# and libclang-rt-14-dev when missing), then runs each target on its own work corpus
# build-fuzz/corpus/<target>, seeded from tests/fuzz/corpus/<target>. Inputs that crash land in
# build-fuzz/findings/<target>/; copy each into tests/fuzz/corpus/<target>/ once fixed, so the
# test suite's replay keeps checking it. Prints executions, coverage and corpus size per target.
#   CALIBENCH_FUZZ_JOBS=N    targets fuzzed at once (default 1; each takes one core)
#   CALIBENCH_FUZZ_MERGE=1   merge (minimise) the new coverage back into tests/fuzz/corpus/
set -euo pipefail
cd "$(dirname "$0")/.."

seconds=${1:-600}
shift || true
bash scripts/install_deps.sh --fuzz

BUILD_DIR=build-fuzz
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  for folder in tests/fuzz/corpus/*/; do targets+=("$(basename "$folder")"); done
fi
CC=clang-14 CXX=clang++-14 cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCALIBENCH_FUZZ=ON >/dev/null
cmake --build "$BUILD_DIR" -j "${CALIBENCH_JOBS:-$(nproc)}" --target "${targets[@]/#/fuzz_}"

fuzz_one() {
  local target=$1 seconds=$2 build=$3
  local work="$build/corpus/$target" findings="$build/findings/$target"
  local log="$build/fuzz-$target.log" status=0
  mkdir -p "$work" "$findings"
  local started=$SECONDS
  # -rss_limit_mb: a loader that needs more than 2 GB for a file of a few KB is a finding (the
  # load limits must refuse it first). -timeout: 10 s for one input is a hang.
  "$build/tests/fuzz/fuzz_$target" -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=10 \
    -print_final_stats=1 -artifact_prefix="$findings/" "$work" "tests/fuzz/corpus/$target" \
    >"$log" 2>&1 || status=1
  local runs cov elapsed=$((SECONDS - started))
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo 0)
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | grep -o '[0-9]*' || echo 0)
  echo "fuzz $target: ${elapsed} s, $runs executions, coverage $cov edges," \
    "work corpus $(find "$work" -type f | wc -l) files," \
    "seed corpus $(find "tests/fuzz/corpus/$target" -type f | wc -l) files" \
    "$([ $status -eq 0 ] && echo "no finding" || echo "FINDING: see $log and $findings/")"
  if [ "${CALIBENCH_FUZZ_MERGE:-0}" = 1 ] && [ $status -eq 0 ]; then
    "$build/tests/fuzz/fuzz_$target" -merge=1 -rss_limit_mb=2048 -timeout=10 \
      "tests/fuzz/corpus/$target" "$work" >>"$log" 2>&1
  fi
  return $status
}
export -f fuzz_one

printf '%s\n' "${targets[@]}" |
  xargs -P "${CALIBENCH_FUZZ_JOBS:-1}" -I{} bash -c 'fuzz_one "$@"' _ {} "$seconds" "$BUILD_DIR"
