#!/usr/bin/env bash
# Long recording measurements, not run by CI (minutes, ~3 GB in build/test_tmp): issue 46's Livox
# CustomMsg recording at full length (20 poses held 6 s, ROS 1 bag and MCAP) through `import` and
# `watch`, with import's peak memory against a PointCloud2 recording of the same length.
#   scripts/long_recordings.sh [build dir]
set -euo pipefail
build="${1:-build}"
CALIBENCH_LONG=1 CALIBENCH_EXE="$build/calibench" \
  "$build/tests/test_e2e" --gtest_filter='RecordingImport.LongLivoxRecordingAsUsersRecordIt'
