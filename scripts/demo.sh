#!/usr/bin/env bash
# Builds puzzlecal and runs the main job on the bundled sample set.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install_deps.sh
scripts/build.sh build Release
mkdir -p out/demo
./build/apps/puzzlecal board --board configs/boards/puzzleboard_11x8_60mm.yaml --out out/demo/board.svg
./build/apps/puzzlecal render --scene configs/scenes/wide_pinhole.yaml --out out/demo/wide_pinhole
