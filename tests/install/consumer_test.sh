#!/bin/bash
# Another project uses pdvo: installs the build into a temporary prefix (cmake --install), configures and builds
# tests/install/consumer against it with find_package(pdvo REQUIRED), and runs it.
# Usage: consumer_test.sh BUILD_DIR SOURCE_DIR [FLAGS]   (FLAGS: the sanitizer flags of a sanitized build, which
# its static libraries need at the consumer's compile and link)
set -euo pipefail
build=$1 source=$2 flags=${3:-}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cmake --install "$build" --prefix "$work/prefix" >"$work/install.log" || { cat "$work/install.log"; exit 1; }
cmake -S "$source/tests/install/consumer" -B "$work/consumer" -DCMAKE_PREFIX_PATH="$work/prefix" \
  -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS="$flags" \
  >"$work/configure.log" 2>&1 || { cat "$work/configure.log"; exit 1; }
cmake --build "$work/consumer" -j2 >"$work/build.log" 2>&1 || { cat "$work/build.log"; exit 1; }
"$work/consumer/pdvo_consumer"
