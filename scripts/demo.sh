#!/usr/bin/env bash
# Builds puzzlecal and calibrates the bundled sample set (testdata/sample:
# 16 renders of the 23x16 PuzzleBoard through a wide-angle pinhole lens, made
# by `puzzlecal render --scene testdata/sample_scene.yaml`), then prints the
# result next to the truth it was rendered with.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install_deps.sh
scripts/build.sh build Release
bin=./build/apps/puzzlecal
if [ ! -f testdata/sample/truth.yaml ]; then
  "$bin" render --scene testdata/sample_scene.yaml --out testdata/sample
fi
mkdir -p out/demo
"$bin" calibrate --images testdata/sample \
  --board configs/boards/puzzleboard_23x16_30mm.yaml \
  --model pinhole-radtan --out out/demo/camera.yaml --report out/demo/report
echo
"$bin" compare --camera out/demo/camera.yaml --truth testdata/sample/truth.yaml
"$bin" board --board configs/boards/puzzleboard_23x16_30mm.yaml --out out/demo/board.pdf
echo
echo "camera file: out/demo/camera.yaml, report: out/demo/report/summary.md, printable board: out/demo/board.pdf"
