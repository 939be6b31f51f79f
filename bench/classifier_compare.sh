#!/bin/bash
# The recogniser's learners side by side: RVM (the paper's, the default) against OpenCV ml's SVM, kNN and random
# trees, on the same training data as ./run model (40 synthetic streets and the TUM excerpt's planes from depth),
# the same features, draws and folds (pdvo train --classifier K --seed S --cv 3), for three training seeds. Each
# model is measured on validation streets (the only set a choice between learners may look at), on the held-out
# streets of ./run model (looking ahead, looking around) and on the Strecha facades (never seen), with the normals
# fused with the edges' vanishing direction (as used) and without (--no-fusion); then its training time, its time
# per 100x100 region on one core (recogniser_bench), its file size and its vectors (relevance or support vectors,
# stored samples, tree nodes; the committee's sum). Training runs two at a time (one per core), the speed is
# measured afterwards alone. Prints one table (mean and range over the seeds) and writes
# OUT/table.md. Runs kept in OUT/runs are not run again: remove OUT to start afresh. About 40 minutes.
#
# Usage: bench/classifier_compare.sh [OUT] [SEEDS]   default OUT out/classifier_compare, SEEDS "1 2 3"
set -euo pipefail
out=${1:-out/classifier_compare}
seeds=${2:-"1 2 3"}
pdvo=${PDVO:-build/apps/pdvo}
bench=${RECOGNISER_BENCH:-build/bench/recogniser_bench}
data=${PDVO_DATA:-../shared/data}
learners="rvm svm knn trees"
[ -x "$pdvo" ] && [ -x "$bench" ] || { echo "classifier_compare: $pdvo or $bench missing (./run bench)" >&2; exit 1; }
mkdir -p "$out/runs" "$out/streets"

# The streets: those of ./run model (training 401-440, held out 501-508 and 511-518) and validation streets
# 601-608 (ahead) and 611-618 (around), one frame per second of walking.
streets() {  # FRAMES LOOK_DEG SEED...
  local frames=$1 look=$2 s
  shift 2
  for s in "$@"; do
    [ -d "$out/streets/street_$s/annotations" ] && continue
    "$pdvo" synth -o "$out/streets/street_$s" -n "$frames" --seed "$s" --set walk.fps=1 \
      --set walk.look_deg="$look" -v warning
  done
}
streets 25 0 $(seq 401 420)
streets 25 60 $(seq 421 440)
streets 15 0 $(seq 501 508) $(seq 601 608)
streets 15 60 $(seq 511 518) $(seq 611 618)
train=("$out"/streets/street_4??/annotations)
if [ -d "$data/tum_rgbd_fr1_rpy_excerpt" ]; then
  [ -d "$out/streets/tum" ] || "$pdvo" annotate-depth -s "$data/tum_rgbd_fr1_rpy_excerpt" \
    -c config/cameras/tum_fr1.yaml -o "$out/streets/tum" -v warning
  train+=("$out/streets/tum")
fi
declare -A sets=(
  [validation_ahead]="$out/streets/street_60?/annotations" [validation_around]="$out/streets/street_61?/annotations"
  [heldout_ahead]="$out/streets/street_50?/annotations" [heldout_around]="$out/streets/street_51?/annotations"
  [strecha_entry]="$data/strecha_entry_p10/annotations" [strecha_herzjesu]="$data/strecha_herzjesu_p8/annotations")
set_names="validation_ahead validation_around heldout_ahead heldout_around strecha_entry strecha_herzjesu"

# One model per learner and seed, measured; two at a time (the machine's two cores).
run() {  # LEARNER SEED
  local k=$1 s=$2 dir="$out/runs/${1}_$2" name start
  [ -s "$dir/done" ] && return 0
  mkdir -p "$dir"
  start=$(date +%s.%N)
  "$pdvo" train -a "${train[@]}" -o "$dir/model.yml" --classifier "$k" --seed "$s" --cv 3 -v warning >"$dir/train.txt"
  awk -v end="$(date +%s.%N)" -v start="$start" 'BEGIN {print end - start}' >"$dir/train_seconds"
  for name in $set_names; do
    # shellcheck disable=SC2086
    ls -d ${sets[$name]} >/dev/null 2>&1 || continue
    # shellcheck disable=SC2086
    "$pdvo" evaluate -m "$dir/model.yml" -a ${sets[$name]} -v warning >"$dir/eval_$name.txt"
    # shellcheck disable=SC2086
    "$pdvo" evaluate -m "$dir/model.yml" -a ${sets[$name]} --no-fusion -v warning >"$dir/eval_${name}_nofusion.txt"
  done
  stat -c %s "$dir/model.yml" >"$dir/bytes"
  echo ok >"$dir/done"
}
echo "classifier_compare: learners $learners, seeds $seeds, in $out"
jobs_running=0
for s in $seeds; do
  for k in $learners; do
    run "$k" "$s" &
    jobs_running=$((jobs_running + 1))
    if [ "$jobs_running" -ge 2 ]; then wait -n; jobs_running=$((jobs_running - 1)); fi
  done
done
wait
# Speed, one model at a time on one core, with nothing else running.
for s in $seeds; do
  for k in $learners; do
    dir="$out/runs/${k}_$s"
    [ -s "$dir/region_us" ] && continue
    taskset -c 0 "$bench" --model="$dir/model.yml" --benchmark_filter=RecogniseRegion100 \
      --benchmark_format=csv 2>/dev/null | awk -F, '/RecogniseRegion100/ {print $3}' >"$dir/region_us"
  done
done

# The table: per learner, the mean over the seeds and, in brackets, the range.
summary() {  # LEARNER FIELD: one number per seed on a line
  local k=$1 field=$2 s dir
  for s in $seeds; do
    dir="$out/runs/${k}_$s"
    case "$field" in
      train_s) cat "$dir/train_seconds" ;;
      region_us) cat "$dir/region_us" ;;
      mb) awk '{printf "%.2f\n", $1 / 1e6}' "$dir/bytes" ;;
      vectors) sed -n 's/.*deg, [a-z ]* \([0-9/]*\) (.*/\1/p' "$dir/train.txt" | tr '/' '\n' | awk '{n += $1} END {print n}' ;;
      *:*)  # SET:acc|bal|auc|mean|median|mean_nf|median_nf
        local set=${field%%:*} what=${field#*:} file="$dir/eval_${field%%:*}.txt"
        [[ $what == *_nf ]] && file="$dir/eval_${set}_nofusion.txt"
        [ -f "$file" ] || { echo nan; continue; }
        case "${what%_nf}" in
          acc) sed -n 's/^accuracy \([0-9.]*\),.*/\1/p' "$file" ;;
          bal) sed -n 's/.*balanced accuracy \([0-9.]*\),.*/\1/p' "$file" ;;
          auc) [[ $set == strecha* ]] && continue  # planes only: no ROC
            sed -n 's/.*ROC AUC \([0-9.]*\).*/\1/p' "$file" ;;
          mean) sed -n 's/^normal error over .*: mean \([0-9.]*\),.*/\1/p' "$file" ;;
          median) sed -n 's/^normal error over .*median \([0-9.]*\),.*/\1/p' "$file" ;;
        esac ;;
    esac
  done | awk -v digits="${3:-3}" '{x[NR] = $1; s += $1; if (NR == 1 || $1 < lo) lo = $1; if (NR == 1 || $1 > hi) hi = $1}
    END {if (NR == 0) {print "-"; exit} f = "%." digits "f"; printf(f " (" f "-" f ")\n", s / NR, lo, hi)}'
}
{
  echo "| learner | set | accuracy | balanced accuracy | ROC AUC | normal mean / median (deg) | without fusion |"
  echo "| --- | --- | --- | --- | --- | --- | --- |"
  for k in $learners; do
    for name in $set_names; do
      [ -f "$out/runs/${k}_${seeds%% *}/eval_$name.txt" ] || continue
      echo "| $k | $name | $(summary "$k" "$name:acc") | $(summary "$k" "$name:bal") | $(summary "$k" "$name:auc") |" \
        "$(summary "$k" "$name:mean" 1) / $(summary "$k" "$name:median" 1) |" \
        "$(summary "$k" "$name:mean_nf" 1) / $(summary "$k" "$name:median_nf" 1) |"
    done
  done
  echo
  echo "| learner | training (s) | per 100x100 region, one core (us) | model file (MB) | vectors (committee's sum) |"
  echo "| --- | --- | --- | --- | --- |"
  for k in $learners; do
    echo "| $k | $(summary "$k" train_s 0) | $(summary "$k" region_us 0) | $(summary "$k" mb 2) | $(summary "$k" vectors 0) |"
  done
} | tee "$out/table.md"
echo "wrote $out/table.md"
