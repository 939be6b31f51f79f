#!/bin/bash
# ./run stops when the configure or the build fails: a copy of ./run in an empty folder, with a `cmake` on the
# PATH that fails, must exit non-zero and say so, for a failing configure and for a failing build.
set -uo pipefail
source_dir=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cp "$source_dir/run" "$work/run"
mkdir -p "$work/bin"
check() {  # STEP: the step the fake cmake fails at (configure or build)
  cat >"$work/bin/cmake" <<FAKE
#!/bin/bash
if [ "\$1" = "--build" ]; then
  [ "$1" = build ] && { echo "fake.cpp:1: error: a build that fails" >&2; exit 2; }
  exit 0
fi
[ "$1" = configure ] && { echo "CMake Error: a configure that fails" >&2; exit 1; }
exit 0
FAKE
  chmod +x "$work/bin/cmake"
  local output status
  output=$(cd "$work" && PATH="$work/bin:$PATH" ./run build 2>&1)
  status=$?
  if [ "$status" -eq 0 ]; then
    echo "FAIL: ./run build exited 0 although the $1 failed; it printed:"
    echo "$output"
    exit 1
  fi
  if ! grep -q "fails" <<<"$output"; then
    echo "FAIL: ./run build did not show the $1's errors; it printed:"
    echo "$output"
    exit 1
  fi
  echo "ok: a failing $1 stops ./run build (exit $status)"
}
check configure
check build
