#!/bin/bash
# The visual odometry's ATE over many synthetic streets: one street says little, since small changes of the
# options move a single street's ATE by half a point (docs/experiments/2026-11-odometry.md). Runs
# build/bench/vo_bench on each seed, two streets at a time (one per core), and prints each street's ATE (% of the
# path), the mean, the largest and how many are above the 1% target, and how often tracking was lost or uncertain.
# Usage: bench/vo_streets.sh FIRST_SEED LAST_SEED [option=value ...]   e.g. bench/vo_streets.sh 31 42 mode=idpp
# (seeds 31-42 are the streets the options were tuned on; 1-3 are the benchmark streets of ./run bench)
# FRAMES=N sets the streets' length (default 1000); synth=sim/config/driving.yaml drives them by car.
set -euo pipefail
if [ $# -lt 2 ]; then
  sed -n 's/^# \{0,1\}//p' "$0" | sed -n '2,8p'
  exit 2
fi
first=$1 last=$2
shift 2
bench=${VO_BENCH:-build/bench/vo_bench}
[ -x "$bench" ] || { echo "vo_streets: $bench not found (./run bench builds it)" >&2; exit 1; }
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
run() {  # core, seeds...
  local core=$1
  shift
  for seed in "$@"; do
    taskset -c "$core" "$bench" "${FRAMES:-1000}" "$seed" "${options[@]}" >"$out/$seed.txt"
  done
}
options=("$@")
seeds=($(seq "$first" "$last"))
odd=() even=()
for i in "${!seeds[@]}"; do
  if ((i % 2)); then odd+=("${seeds[$i]}"); else even+=("${seeds[$i]}"); fi
done
run 0 "${even[@]}" &
run 1 "${odd[@]}"
wait
for seed in "${seeds[@]}"; do
  ate=$(sed -n 's/.*m = \([0-9.]*\)% of the path.*/\1/p' "$out/$seed.txt")
  [ -n "$ate" ] || { echo "vo_streets: no ATE for seed $seed:" >&2; cat "$out/$seed.txt" >&2; exit 1; }
  doubt=$(sed -n 's/.*lost \([0-9]*\) times, \([0-9]*\) frames uncertain.*/\1 \2/p' "$out/$seed.txt")
  echo "$seed $ate $doubt"
done | awk -v opts="$*" '{ printf "seed %s: %s%%, lost %d, uncertain %d\n", $1, $2, $3, $4; sum += $2; n++;
    if ($2 > 1) above++; if ($2 > max) max = $2; lost += $3; uncertain += $4 }
  END { printf "mean %.2f%% over %d streets (max %.2f%%), %d above 1%%; lost %d times, %d frames uncertain [%s]\n",
    sum / n, n, max, above, lost, uncertain, opts }'
