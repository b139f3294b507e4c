#!/usr/bin/env bash
# The workbench's CPU time while idle: opens a dataset in a window under Xvfb, lets it load, then
# reads its /proc/<pid>/stat (user + system ticks) at the start and the end of an idle period in
# which nobody touches it. Prints the CPU used as a share of one core.
#
#   scripts/idle_cpu.sh [dataset.json] [idle seconds, default 60] [load seconds, default 20]
#
# Needs xvfb-run (apt-get install xvfb xauth) and a built build/calibench.
set -euo pipefail
cd "$(dirname "$0")/.."
dataset=${1:-build/demo/dataset.json}
idle_s=${2:-60}
load_s=${3:-20}
exe=${CALIBENCH_EXE:-build/calibench}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
xvfb-run -a -s '-screen 0 1600x900x24' sh -c \
  "'$exe' gui --dataset '$dataset' --size 1600x900 --quit-after-seconds $((load_s + idle_s + 5)) \
     > '$work/log' 2>&1 & echo \$! > '$work/pid'; wait" &
runner=$!
for _ in $(seq 50); do [[ -s $work/pid ]] && break; sleep 0.1; done
pid=$(cat "$work/pid")
ticks() { awk '{print $14 + $15}' "/proc/$pid/stat"; }
sleep "$load_s"
start=$(ticks)
sleep "$idle_s"
end=$(ticks)
hz=$(getconf CLK_TCK)
wait "$runner" || true
awk -v t=$((end - start)) -v hz="$hz" -v s="$idle_s" 'BEGIN {
  printf "idle workbench: %.2f s of CPU in %d s = %.2f %% of one core\n", t / hz, s, 100 * t / hz / s }'
tail -1 "$work/log"
