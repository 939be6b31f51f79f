#!/bin/bash
# The C++ sources are formatted as .clang-format says: lists the files clang-format would change, exit 1 if any.
# Usage: format_test.sh SOURCE_DIR
set -euo pipefail
cd "$1"
command -v clang-format >/dev/null || { echo "format_test: clang-format is not installed (./run installs it)"; exit 1; }
bad=()
while IFS= read -r f; do
  clang-format --style=file --dry-run --Werror "$f" >/dev/null 2>&1 || bad+=("$f")
done < <(git ls-files '*.cpp' '*.h')
if [ ${#bad[@]} -gt 0 ]; then
  echo "format_test: not formatted (clang-format -i --style=file FILE):"
  printf '  %s\n' "${bad[@]}"
  exit 1
fi
echo "format_test: every C++ file as .clang-format says"
