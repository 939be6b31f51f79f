#!/bin/bash
# The visual odometry's ATE over many synthetic streets: one street says little, since small changes of the
# options move a single street's ATE by half a point (docs/experiments/2026-11-odometry.md). Runs
# build/bench/vo_bench on each seed, two streets at a time (one per core), and prints each street's ATE (% of the
# path), the mean and how many are above the 1% target.
# Usage: bench/vo_streets.sh FIRST_SEED LAST_SEED [option=value ...]   e.g. bench/vo_streets.sh 31 42 mode=idpp
# (seeds 31-42 are the streets the options were tuned on; 1-3 are the benchmark streets of ./run bench)
set -euo pipefail
if [ $# -lt 2 ]; then
  sed -n 's/^# \{0,1\}//p' "$0" | sed -n '2,7p'
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
    taskset -c "$core" "$bench" 1000 "$seed" "${options[@]}" >"$out/$seed.txt"
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
  echo "$seed $ate"
done | awk -v opts="$*" '{ printf "seed %s: %s%%\n", $1, $2; sum += $2; n++; if ($2 > 1) above++ }
  END { printf "mean %.2f%% over %d streets, %d above 1%% [%s]\n", sum / n, n, above, opts }'
