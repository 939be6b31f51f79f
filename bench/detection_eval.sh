#!/bin/bash
# The plane detector scored on held-out data: synthetic streets never used in training or tuning (seeds 501-508
# looking ahead, 511-518 looking around; 15 frames each at one frame a second, as ./run model renders them), and
# the real sets of ../shared/data with reference annotations (Strecha, KITTI, TUM). One line per set: plane pixel
# F1, false plane area, non-plane F1, plane recall within 30 / 10 degrees, median normal error of matched
# planes, spurious planes per image, covering, the reference planes merged into larger detected planes (and onto
# what, mostly: planes of their orientation / planes at another angle / non-plane / unannotated pixels), ms per
# image.
# With --validation, only the validation streets instead (seeds 601-603 ahead, 604-606 around, scored as one set:
# where detector options are chosen, apart from the held-out ones).
# Usage: bench/detection_eval.sh WORK [--validation] [--set key=value ...]   (detector options, e.g. --set mrf_planes=false)
# e.g. bench/detection_eval.sh out/detection_eval
set -euo pipefail
if [ $# -lt 1 ]; then
  sed -n 's/^# \{0,1\}//p' "$0" | sed -n '2,11p'
  exit 2
fi
work=$1
shift
pdvo=${PDVO:-build/apps/pdvo}
data=${PDVO_DATA:-../shared/data}
[ -x "$pdvo" ] || { echo "detection_eval: $pdvo not found (./run build)" >&2; exit 1; }
mkdir -p "$work/streets"
run=$(mktemp -d)
trap 'rm -rf "$run"' EXIT
render() {  # LOOK_DEG SEED...
  local look=$1 s
  shift
  for s in "$@"; do
    [ -f "$work/streets/street_$s/groundtruth.txt" ] && continue
    "$pdvo" synth -o "$work/streets/street_$s" -n 15 --seed "$s" --set walk.fps=1 --set walk.look_deg="$look" -v warning
  done
}
validation=false
if [ "${1:-}" = --validation ]; then
  validation=true
  shift
fi
# Every reference folder of a set is detected; the set is scored over all its folders at once.
score() {  # NAME FOLDER...
  local name=$1 folder k=0
  shift
  local pairs=()
  for folder in "$@"; do
    [ -d "$folder" ] || continue
    k=$((k + 1))
    "$pdvo" detect -a "$folder" -o "$run/$k" -v warning "${options[@]}" >>"$run/log"
    pairs+=(-r "$folder" -e "$run/$k")
  done
  if [ "$k" -eq 0 ]; then
    echo "$name: not found, skipped"
    return
  fi
  local ms
  ms=$(sed -n 's/.* \([0-9.]*\) ms per image.*/\1/p' "$run/log" | awk '{ s += $1; n++ } END { printf "%.0f", s / n }')
  "$pdvo" evaluate-detection "${pairs[@]}" | awk -v name="$name" -v ms="$ms" '
    /images/ { images = $1 }
    /^  plane pixels/ { f1 = $8; false_area = $12 }
    /^  non-plane pixels/ { nf1 = $8 }
    /^  plane recall/ { r30 = $3; r10 = $7; refs = $12; spurious = $15 }
    /normal error/ { normal = $6 }
    /segmentation/ { covering = $11 }
    /^  not matched/ { why = $3 " merged (" }
    /^  merged, onto/ { why = why $7 "/" $12 "/" $14 "/" $17 ")" }
    END { printf "%-27s %4d images  plane F1 %s  false area %s  non-plane F1 %s  recall 30/10 %s/%s (of %s)  " \
          "normal %s deg  spurious %.1f  covering %s  %s  %s ms\n", name, images, f1, false_area, nf1, r30, r10, refs,
          normal, spurious / images, covering, why, ms }' | tr -d ',;'
  rm -rf "$run"/* 
}
options=("$@")
if $validation; then
  render 0 601 602 603
  render 60 604 605 606
  score "validation streets" "$work"/streets/street_60[1-6]/annotations
  exit 0
fi
render 0 $(seq 501 508)
render 60 $(seq 511 518)
streets_ahead=() streets_around=()
for s in $(seq 501 508); do streets_ahead+=("$work/streets/street_$s/annotations"); done
for s in $(seq 511 518); do streets_around+=("$work/streets/street_$s/annotations"); done
score "held-out streets, ahead" "${streets_ahead[@]}"
score "held-out streets, around" "${streets_around[@]}"
score "Strecha entry_p10" "$data/strecha_entry_p10/annotations"
score "Strecha herzjesu_p8" "$data/strecha_herzjesu_p8/annotations"
score "KITTI (object, raw, stereo)" "$data/kitti_object_lidar_a/annotations" \
  "$data/kitti_raw_2011_09_26_traffic_lidar/annotations" "$data/kitti_stereo2015_000046/annotations"
score "TUM fr1/rpy (indoor)" "$data/tum_rgbd_fr1_rpy_excerpt/annotations"
