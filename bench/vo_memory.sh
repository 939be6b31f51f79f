#!/bin/bash
# The odometry's memory over a long sequence: a synthetic street of FRAMES frames (default 10,000, rendered once
# into WORK/street, about 2.4 GB) through `pdvo vo` in each mode; prints the resident memory after frames 1,000
# and 9,000 (stats.json's frames[].resident_mib) and fails if they differ by more than 5 MiB in any mode.
#
# Usage: bench/vo_memory.sh [WORK] [FRAMES]     (default: out/vo_memory 10000)
set -euo pipefail
cd "$(dirname "$0")/.."
work=${1:-out/vo_memory} frames=${2:-10000} pdvo=build/apps/pdvo
[ -x "$pdvo" ] || { echo "vo_memory: build first (./run build)" >&2; exit 1; }
early=$((frames / 10 - 1)) late=$((frames * 9 / 10 - 1))
if [ ! -f "$work/street/groundtruth.txt" ] || [ "$(wc -l <"$work/street/rgb.txt")" -lt "$frames" ]; then
  echo "vo_memory: rendering a street of $frames frames into $work/street"
  "$pdvo" synth -o "$work/street" -n "$frames" --seed 7 -v warning
fi
status=0
printf '%-6s %8s %14s %14s %10s\n' mode frames "MiB at $((early + 1))" "MiB at $((late + 1))" growth
for mode in idpp pdvo; do
  "$pdvo" vo -s "$work/street" -o "$work/vo_$mode" --mode "$mode" -v warning >/dev/null
  a=$(sed -n "$((early + 5))p" "$work/vo_$mode/stats.json" | grep -oE '"resident_mib":[0-9.eE+-]+' | cut -d: -f2)
  b=$(sed -n "$((late + 5))p" "$work/vo_$mode/stats.json" | grep -oE '"resident_mib":[0-9.eE+-]+' | cut -d: -f2)
  growth=$(awk -v a="$a" -v b="$b" 'BEGIN { printf "%.2f", b - a }')
  printf '%-6s %8s %14.1f %14.1f %10s\n' "$mode" "$frames" "$a" "$b" "$growth"
  awk -v g="$growth" 'BEGIN { exit !(g <= 5) }' || status=1
done
[ "$status" -eq 0 ] || echo "vo_memory: memory grew by more than 5 MiB between the two frames"
exit "$status"
