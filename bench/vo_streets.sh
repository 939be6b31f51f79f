#!/bin/bash
# The visual odometry's ATE over many synthetic streets: one street says little, since small changes of the
# options move a single street's ATE by half a point (docs/experiments/2026-11-odometry.md). Runs
# build/bench/vo_bench on each seed, two streets at a time (one per core), and prints each street's ATE (% of the
# path), the mean, the largest and how many are above the 1% target, and how often tracking was lost or uncertain;
# in modes with planes also the planes a run, points per plane and purity (means over the runs with planes).
# Usage: bench/vo_streets.sh FIRST_SEED LAST_SEED [option=value ...]   e.g. bench/vo_streets.sh 31 42 mode=idpp
# (seeds 31-42 are the streets the options were tuned on; 1-3 are the benchmark streets of ./run bench)
# FRAMES=N sets the streets' length (default 1000); synth=sim/config/driving.yaml drives them by car.
# SIGMAS="0.49 0.5 0.51" runs each street once per search.pixel_sigma listed (an ensemble: a single run per street
# cannot show a change of the 24-street mean under about 0.1%, docs/developing.md) and averages per street first.
set -euo pipefail
if [ $# -lt 2 ]; then
  sed -n 's/^# \{0,1\}//p' "$0" | sed -n '2,10p'
  exit 2
fi
first=$1 last=$2
shift 2
bench=${VO_BENCH:-build/bench/vo_bench}
[ -x "$bench" ] || { echo "vo_streets: $bench not found (./run bench builds it)" >&2; exit 1; }
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
sigmas=(${SIGMAS:-})
run() {  # core, seeds...
  local core=$1 sigma
  shift
  for seed in "$@"; do
    if [ ${#sigmas[@]} -eq 0 ]; then
      taskset -c "$core" "$bench" "${FRAMES:-1000}" "$seed" "${options[@]}" >"$out/$seed-default.txt"
    fi
    for sigma in "${sigmas[@]}"; do
      taskset -c "$core" "$bench" "${FRAMES:-1000}" "$seed" "${options[@]}" search.pixel_sigma="$sigma" \
        >"$out/$seed-$sigma.txt"
    done
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
  for run in "$out/$seed"-*.txt; do
    ate=$(sed -n 's/^result .* ate_percent=\([0-9.]*\) .*/\1/p' "$run")
    [ -n "$ate" ] || { echo "vo_streets: no ATE in $(basename "$run" .txt):" >&2; cat "$run" >&2; exit 1; }
    doubt=$(sed -n 's/.*lost \([0-9]*\) times, \([0-9]*\) frames uncertain.*/\1 \2/p' "$run")
    planes=$(sed -n 's/^result .* planes=\([0-9]*\) points_per_plane=\([0-9.]*\) .* purity=\([0-9.]*\) .*/\1 \2 \3/p' "$run")
    echo "$seed $ate $doubt ${planes:-0 0 0}"
  done
done | awk -v opts="$*" -v runs="${#sigmas[@]}" '
  { if (!($1 in ate)) order[++n] = $1; ate[$1] += $2; k[$1]++; lost += $3; uncertain += $4
    runs_all++; planes += $5; if ($5 > 0) { with_planes++; per_plane += $6; purity += $7 } }
  END {
    for (i = 1; i <= n; i++) {
      s = order[i]; m = ate[s] / k[s]
      printf "seed %s: %.4f%%%s\n", s, m, (k[s] > 1 ? sprintf(" (mean of %d runs)", k[s]) : "")
      sum += m; sq += m * m; if (m > 1) above++; if (m > max) max = m
    }
    mean = sum / n; var = sq / n - mean * mean; se = n > 1 && var > 0 ? sqrt(var / (n - 1)) : 0
    printf "mean %.3f%% over %d streets%s (max %.2f%%, standard error over the streets %.3f%%), %d above 1%%; lost %d times, %d frames uncertain%s [%s]\n",
      mean, n, (runs > 0 ? sprintf(", %d runs each", runs) : ""), max, se, above, lost, uncertain,
      (runs > 1 ? " (summed over all runs)" : ""), opts
    if (planes > 0)
      printf "planes %.2f a run, %.2f points per plane and purity %.3f over the %d runs with planes\n",
        planes / runs_all, per_plane / with_planes, purity / with_planes, with_planes }'
