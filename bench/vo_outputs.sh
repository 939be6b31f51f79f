#!/bin/bash
# The visual odometry's outputs on a fixed set of inputs, recorded by one pdvo binary and compared with those of
# another: for changes that must not alter what the odometry computes (a restructuring), or to see what a change
# alters. The inputs: the three benchmark streets (pdvo synth, seeds 1-3, 1000 frames, rendered once into
# WORK/streets), and, when ../shared/data is beside the project, the TUM fr1/rpy and KITTI 06 excerpts; each in
# both modes (points, idpp).
#
# Usage: bench/vo_outputs.sh record PDVO WORK OUT    runs PDVO vo on every input, writes OUT/<input>_<mode>/
#        bench/vo_outputs.sh compare A B             compares two records: trajectory.txt byte for byte, and
#                                                    stats.json without its times (seconds, fps, ...), its
#                                                    resident memory and the keys listed in NEW_KEYS (keys the
#                                                    newer record adds, e.g. NEW_KEYS="update"); exit 1 if any
#                                                    differ
# e.g. bench/vo_outputs.sh record /tmp/pdvo_before out/vo_outputs out/vo_outputs/before
set -euo pipefail
usage() { sed -n 's/^# \{0,1\}//p' "$0" | sed -n '2,13p'; exit 2; }
[ $# -ge 1 ] || usage
data=${PDVO_DATA:-../shared/data}

record() {
  local pdvo=$1 work=$2 out=$3 seed mode
  [ -x "$pdvo" ] || { echo "vo_outputs: $pdvo is not an executable" >&2; exit 1; }
  mkdir -p "$work/streets" "$out"
  local inputs=()
  for seed in 1 2 3; do
    local street="$work/streets/street_$seed"
    if [ ! -f "$street/groundtruth.txt" ]; then
      echo "vo_outputs: rendering benchmark street $seed (1000 frames)"
      "$pdvo" synth --out "$street" --seed "$seed" --frames 1000 -v warning
    fi
    inputs+=("street_$seed=$street=")
  done
  if [ -d "$data/tum_rgbd_fr1_rpy_excerpt" ]; then
    inputs+=("tum_fr1_rpy=$data/tum_rgbd_fr1_rpy_excerpt=config/cameras/tum_fr1.yaml")
  else
    echo "vo_outputs: $data/tum_rgbd_fr1_rpy_excerpt not found, skipped" >&2
  fi
  if [ -d "$data/kitti_odometry_06_excerpt" ]; then
    inputs+=("kitti_06=$data/kitti_odometry_06_excerpt=")
  else
    echo "vo_outputs: $data/kitti_odometry_06_excerpt not found, skipped" >&2
  fi
  local input name sequence camera
  for input in "${inputs[@]}"; do
    IFS='=' read -r name sequence camera <<<"$input"
    for mode in points idpp; do
      local args=(vo -s "$sequence" -o "$out/${name}_$mode" --mode "$mode" -v warning)
      [ -n "$camera" ] && args+=(-c "$camera")
      echo "vo_outputs: $name, $mode"
      "$pdvo" "${args[@]}" >/dev/null
    done
  done
}

# stats.json without its times, resident memory and the named new keys, and without the commas these leave.
stats_without_times() {
  local keys="seconds|tracking_seconds|fps|resident_mib|detector_seconds|latency_seconds|detector_wait_seconds"
  [ -n "${NEW_KEYS:-}" ] && keys="$keys|${NEW_KEYS// /|}"
  sed -E "s/\"($keys)\": ?(\"[^\"]*\"|[-+0-9.eE]+|true|false|null),?//g; s/,([]}])/\1/g; s/,$//" "$1"
}

compare() {
  local a=$1 b=$2 run differ=0 runs=0
  for run in "$a"/*/; do
    run=$(basename "$run")
    runs=$((runs + 1))
    if [ ! -d "$b/$run" ]; then
      echo "$run: missing in $b"
      differ=1
      continue
    fi
    local verdict="same"
    cmp -s "$a/$run/trajectory.txt" "$b/$run/trajectory.txt" || verdict="trajectory.txt differs"
    if ! cmp -s <(stats_without_times "$a/$run/stats.json") <(stats_without_times "$b/$run/stats.json"); then
      verdict="$verdict; stats.json differs"
      [ "$verdict" = "same; stats.json differs" ] && verdict="stats.json differs"
    fi
    [ "$verdict" = "same" ] || differ=1
    echo "$run: $verdict"
  done
  [ "$runs" -gt 0 ] || { echo "vo_outputs: no runs in $a" >&2; exit 1; }
  if [ "$differ" -eq 0 ]; then echo "all $runs runs the same"; else echo "some runs differ"; fi
  return "$differ"
}

case $1 in
  record) [ $# -eq 4 ] || usage; record "$2" "$3" "$4" ;;
  compare) [ $# -eq 3 ] || usage; compare "$2" "$3" ;;
  *) usage ;;
esac
