#!/usr/bin/env bash
# Builds puzzlecal and runs the whole test suite.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install_deps.sh
scripts/build.sh build Release
(cd build && ctest --output-on-failure --parallel "$(nproc)")
