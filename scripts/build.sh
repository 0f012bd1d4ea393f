#!/usr/bin/env bash
# Configures and builds puzzlecal into build/ (or $1) with the build type $2
# (Release by default). Used by demo.sh and test.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir="${1:-build}"
build_type="${2:-Release}"
shift $(( $# > 2 ? 2 : $# )) || true
generator=()
if command -v ninja >/dev/null 2>&1; then generator=(-G Ninja); fi
if [ ! -f "$build_dir/CMakeCache.txt" ]; then
  cmake -S . -B "$build_dir" "${generator[@]}" -DCMAKE_BUILD_TYPE="$build_type" "$@"
fi
cmake --build "$build_dir" --parallel "$(nproc)"
