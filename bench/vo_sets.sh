#!/bin/bash
# Every set a change to the odometry is judged on, with the same options for all: the walking streets never used
# for tuning (101-124, ensembles of three runs a street), the driving streets (201-224, 600 frames), the streets round
# a block (401-424, 600 frames, each starting in a corner), the driving streets through KITTI's camera (301-312, 200
# frames), each summarised per mode as vo_streets.sh does, and the real excerpts (vo_real_ensemble.sh's means). A
# change that gains on one set and loses on another shows here at once (docs/developing.md). About 30 minutes for
# the three modes on two cores.
# Usage: bench/vo_sets.sh [option=value ...]   e.g. bench/vo_sets.sh features.max_misses=5
# MODES="points idpp" runs fewer modes (default: points idpp pdvo); SETS="walking loop" fewer sets (default: walking
# driving loop kitti_view real; the real excerpts always run the three modes).
set -euo pipefail
if [ "${1:-}" = "-h" ] || [ "${1:-}" = "--help" ]; then
  sed -n 's/^# \{0,1\}//p' "$0" | sed -n '2,10p'
  exit 0
fi
here=$(dirname "$0")
read -ra modes <<<"${MODES:-points idpp pdvo}"
read -ra sets <<<"${SETS:-walking driving loop kitti_view real}"

streets() {  # NAME FRAMES FIRST LAST SYNTH SIGMAS, then the options: vo_streets.sh's summary per mode
  local name=$1 frames=$2 first=$3 last=$4 synth=$5 sigmas=$6 mode
  shift 6
  for mode in "${modes[@]}"; do
    FRAMES=$frames SIGMAS=$sigmas "$here/vo_streets.sh" "$first" "$last" ${synth:+synth=$synth} mode="$mode" "$@" |
      sed -n -e "s/^mean /$name $first-$last, $mode: mean /p" -e "s/^planes /$name $first-$last, $mode: planes /p"
  done
}
for set in "${sets[@]}"; do
  case $set in
    walking) streets walking 1000 101 124 "" "0.49 0.5 0.51" "$@" ;;
    driving) streets driving 600 201 224 sim/config/driving.yaml "" "$@" ;;
    loop) streets "round a block" 600 401 424 sim/config/loop.yaml "" "$@" ;;
    kitti_view) streets "KITTI view" 200 301 312 sim/config/driving_kitti.yaml "" "$@" ;;
    real) "$here/vo_real_ensemble.sh" "${PDVO_DATA:-../shared/data}" "$@" | grep '^mean' ;;
    *) echo "vo_sets: unknown set $set (walking, driving, loop, kitti_view, real)" >&2; exit 2 ;;
  esac
done
