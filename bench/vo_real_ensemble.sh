#!/bin/bash
# The odometry (modes points, idpp and pdvo) on the real excerpts (TUM fr1/rpy at 320x240, KITTI 06) as means
# over an ensemble of runs whose measurement noise (search.pixel_sigma) is moved by up to 8% around its default: a
# single run of these short sequences moves by half a degree with any small change of the options
# (docs/experiments/2026-12-05-waiting-points.md), so that comparing two settings by one run each says little.
# Prints one row per run and the means per mode (ATE after Sim(3), rotation RMS; the largest fr1 rotation error of
# the ensemble in brackets). About a minute.
# Usage: bench/vo_real_ensemble.sh [DATA_DIR (default ../shared/data)] [option=value ...  (passed as --set)]
# e.g.   bench/vo_real_ensemble.sh ../shared/data features.max_waiting=80
set -euo pipefail
data=${1:-../shared/data}
[ $# -gt 0 ] && shift
pdvo=build/apps/pdvo
[ -x "$pdvo" ] || { echo "vo_real_ensemble: $pdvo not found (./run build builds it)" >&2; exit 1; }
fr1=$data/tum_rgbd_fr1_rpy_excerpt kitti=$data/kitti_odometry_06_excerpt
[ -d "$fr1" ] && [ -d "$kitti" ] || { echo "vo_real_ensemble: no data at $data: nothing to measure" >&2; exit 1; }
sets=()
for option in "$@"; do sets+=(--set "$option"); done
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# ate OUT ATE_ARGS...: "translation rotation" of the run in OUT.
ate() {
  local out=$1
  shift
  $pdvo ate --est "$out/trajectory.txt" "$@" -v warning 2>/dev/null |
    awk '/^ATE translation/ { t = $4 } /^ATE rotation/ { r = $4 } END { print t, r }'
}
for mode in points idpp pdvo; do
  for sigma in 0.46 0.48 0.49 0.50 0.51 0.52 0.54; do
    options=(--mode "$mode" -v error --set search.pixel_sigma=$sigma "${sets[@]}")
    $pdvo vo -s "$fr1" -o "$work/fr1" -c config/cameras/tum_fr1.yaml "${options[@]}" >/dev/null ||
      { echo "vo_real_ensemble: pdvo vo failed on fr1 ($mode, pixel_sigma $sigma)" >&2; exit 1; }
    $pdvo vo -s "$kitti" -o "$work/kitti" "${options[@]}" >/dev/null ||
      { echo "vo_real_ensemble: pdvo vo failed on KITTI 06 ($mode, pixel_sigma $sigma)" >&2; exit 1; }
    echo "$mode $sigma $(ate "$work/fr1" --gt "$fr1/groundtruth.txt") $(ate "$work/kitti" --gt "$kitti/poses.txt" \
      --format kitti --est-format tum --gt-times "$kitti/times.txt")"
  done
done | awk '{ printf "%-6s pixel_sigma %s  fr1 %.4f m %5.2f deg  kitti06 %.3f m %.2f deg\n", $1, $2, $3, $4, $5, $6
              n[$1]++; ft[$1] += $3; fr[$1] += $4; kt[$1] += $5; kr[$1] += $6; if ($4 > fmax[$1]) fmax[$1] = $4 }
        END { for (m in n) printf "mean   %-6s fr1 %.4f m %.2f deg (largest %.2f)  kitti06 %.3f m %.2f deg  (%d runs)\n",
                m, ft[m] / n[m], fr[m] / n[m], fmax[m], kt[m] / n[m], kr[m] / n[m], n[m] }'
