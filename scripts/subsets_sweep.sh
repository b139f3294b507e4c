#!/usr/bin/env bash
# σ honesty on every simulated range-sensor kind: `calibench evaluate --subsets` (first k and random
# subsets of 4-30 pairs) on a 32-pair simulated set per kind and seed, against the all-pairs result
# and the ground truth. A sweep, not a CI test: ~15 s per kind and seed on 2 cores.
#   scripts/subsets_sweep.sh [--seeds N] [--out DIR] [--calibench PATH] [--kinds a,b,...]
set -euo pipefail
seeds=3
out=/tmp/calibench-subsets
calibench=build/calibench
only=""
while [[ $# -gt 0 ]]; do
  case "$1" in
    --seeds) seeds="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --calibench) calibench="$2"; shift 2 ;;
    --kinds) only=",$2,"; shift 2 ;;
    *) echo "usage: $0 [--seeds N] [--out DIR] [--calibench PATH] [--kinds a,b,...]" >&2; exit 2 ;;
  esac
done
mkdir -p "$out"
# kind label : simulate flags
kinds=(
  "vlp16:--lidar vlp16"
  "os0-128:--lidar os0-128"
  "swept-2d:--lidar swept-2d"
  "swept-2d-viewpoints:--lidar swept-2d --lidar-viewpoints"
  "nodding-2d:--lidar nodding-2d"
  "segments:--lidar vlp16 --board-only-clouds"
  "mid40-frame:--lidar mid40 --lidar-frame 0.1"
  "mid40-hold:--lidar mid40 --lidar-frame 1"
  "avia-frame:--lidar avia --lidar-frame 0.1"
  "avia-hold:--lidar avia --lidar-frame 1"
  "mid360-frame:--lidar mid360 --lidar-frame 0.1"
  "mid360-hold:--lidar mid360 --lidar-frame 1"
)
printf "| kind | seed | within 3σ of all pairs | within 3σ of the truth |\n|---|---|---|---|\n"
total=0; truth_total=0; cases_total=0
for entry in "${kinds[@]}"; do
  label="${entry%%:*}"; flags="${entry#*:}"
  [[ -z "$only" || "$only" == *",$label,"* ]] || continue
  for seed in $(seq 1 "$seeds"); do
    dir="$out/$label-$seed"
    # shellcheck disable=SC2086
    "$calibench" simulate -o "$dir" $flags --pairs 32 --seed "$seed" --no-lidar-seeds >/dev/null 2>&1
    table="$dir/subsets.md"
    if ! "$calibench" evaluate --subsets -d "$dir" --table "$table" >/dev/null 2>"$dir/subsets.log"; then
      printf "| %s | %s | failed: %s | |\n" "$label" "$seed" "$(tail -1 "$dir/subsets.log")"
      continue
    fi
    all=$(grep -o 'all-pairs result: [0-9]* of [0-9]*' "$table" | grep -o '[0-9]* of [0-9]*')
    truth=$(grep -o 'ground truth: [0-9]* of [0-9]*' "$table" | grep -o '[0-9]* of [0-9]*')
    printf "| %s | %s | %s | %s |\n" "$label" "$seed" "$all" "$truth"
    total=$((total + ${all%% *})); truth_total=$((truth_total + ${truth%% *}))
    cases_total=$((cases_total + ${all##* }))
  done
done
printf "\nall kinds: %d of %d within 3σ of the all-pairs result, %d of %d of the truth\n" \
  "$total" "$cases_total" "$truth_total" "$cases_total"
