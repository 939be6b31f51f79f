#!/bin/bash
# The visual odometry on the real excerpts in ../shared/data, in modes points and idpp, against the targets of
# docs/odometry.md: TUM fr1/rpy at 320x240 through pdvo vo's own reader and three input variants (grey before
# undistortion, bilinear resizing, working width 322) and the spread of their rotation error; KITTI 06 (all 51
# frames); TUM fr3 at 1 Hz, where every pose the odometry calls tracked must be within 10 degrees (the rest are
# flagged). Prints one row per run: ATE after Sim(3) alignment, rotation RMS, and the frames tracked, uncertain
# and lost. Needs build/apps/pdvo and build/bench/frame_variants (./run bench builds both).
# Usage: bench/vo_real.sh [DATA_DIR (default ../shared/data)] [option=value ...  (passed to pdvo vo as --set)]
set -euo pipefail
data=${1:-../shared/data}
[ $# -gt 0 ] && shift
pdvo=build/apps/pdvo variants=build/bench/frame_variants
for tool in $pdvo $variants; do
  [ -x "$tool" ] || { echo "vo_real: $tool not found (./run bench builds it)" >&2; exit 1; }
done
[ -d "$data/tum_rgbd_fr1_rpy_excerpt" ] || { echo "vo_real: no data at $data: nothing to measure" >&2; exit 1; }
sets=()
for option in "$@"; do sets+=(--set "$option"); done
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fr1=$data/tum_rgbd_fr1_rpy_excerpt kitti=$data/kitti_odometry_06_excerpt fr3=$data/tum_rgbd_fr3_long_office_1hz

# run NAME MODE SEQUENCE ATE_ARGS... -- VO_ARGS...: one row.
run() {
  local name=$1 mode=$2 sequence=$3
  shift 3
  local ate_args=()
  while [ "$1" != "--" ]; do ate_args+=("$1"); shift; done
  shift
  local out=$work/$name-$mode
  $pdvo vo -s "$sequence" -o "$out" --mode "$mode" -v warning "${sets[@]}" "$@" >"$out.log" 2>&1 \
    || { echo "vo_real: pdvo vo failed on $name ($mode):" >&2; cat "$out.log" >&2; exit 1; }
  $pdvo ate --est "$out/trajectory.txt" "${ate_args[@]}" -v warning >"$out.ate" 2>&1 \
    || { echo "vo_real: pdvo ate failed on $name ($mode):" >&2; cat "$out.ate" >&2; exit 1; }
  local health
  local count health=""
  for state in tracked uncertain lost; do  # stats.json has one line per frame; health is one of these per frame
    count=$({ grep -o "\"health\": *\"$state\"" "$out/stats.json" || true; } | wc -l)
    health+="${health:+, }$count $state"
  done
  awk -v name="$name" -v mode="$mode" -v health="$health" '
    /^ATE translation/ { t = $4 } /^ATE rotation/ { r = $4; rmax = $10 }
    /^trusted poses/ { sub(":", "", $5); trusted = sprintf(", trusted %s of %s, max rotation error %s deg", $3, $5, "RMAX") }
    END { sub("RMAX", rmax, trusted); printf "%-22s %-6s ATE %8.4f m  rotation %6.2f deg  %s%s\n", name, mode, t, r, health, trusted }' \
    "$out.ate" | tee -a "$work/rows"
}

for mode in points idpp; do
  gt=(--gt "$fr1/groundtruth.txt")
  run fr1 $mode "$fr1" "${gt[@]}" -- -c config/cameras/tum_fr1.yaml
  run fr1-width322 $mode "$fr1" "${gt[@]}" -- -c config/cameras/tum_fr1.yaml --set working_width=322
  for variant in grey=first resize=linear; do
    [ -d "$work/$variant" ] || $variants "$fr1" config/cameras/tum_fr1.yaml "$work/$variant" $variant
    run "fr1-${variant/=/-}" $mode "$work/$variant" "${gt[@]}" -- --set working_width=0
  done
  awk -v mode=$mode '$1 ~ /^fr1/ && $2 == mode { r = $7; if (n == 0 || r < lo) lo = r; if (n == 0 || r > hi) hi = r; n++ }
    END { printf "fr1 input variants     %-6s rotation spread %.2f deg (%.2f-%.2f)\n", mode, hi - lo, lo, hi }' "$work/rows"
  run kitti06 $mode "$kitti" --gt "$kitti/poses.txt" --format kitti --est-format tum --gt-times "$kitti/times.txt" --
  run fr3-1hz $mode "$fr3" --gt "$fr3/groundtruth.txt" --max-dt 0.1 --health "$work/fr3-1hz-$mode/stats.json" -- \
    -c config/cameras/tum_fr3.yaml
done
