#!/usr/bin/env python3
"""Python's overhead on detect(): the wall time of puzzlecal.detect() on a
1600x1200 photo against the time the C++ library spent inside it
(Detection.seconds, measured by the pipeline itself). Prints JSON.

    PYTHONPATH=build/python python3 python/bench/bench_detect.py [IMAGE]

Without IMAGE a 1600x1200 view is rendered first with the program
(PUZZLECAL_PROGRAM, default build/apps/puzzlecal)."""

import json
import os
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

import puzzlecal

ROOT = pathlib.Path(__file__).resolve().parents[2]


def photo():
    if len(sys.argv) > 1:
        return sys.argv[1]
    program = os.environ.get("PUZZLECAL_PROGRAM",
                             str(ROOT / "build" / "apps" / "puzzlecal"))
    out = pathlib.Path(tempfile.mkdtemp()) / "render"
    subprocess.run([program, "render", "--scene", "wide_pinhole", "--size",
                    "1600x1200", "--out", str(out)], check=True,
                   stdout=subprocess.DEVNULL)
    return sorted(out.glob("*.png"))[0]


def main():
    board = puzzlecal.Board.load(
        str(ROOT / "configs" / "boards" / "puzzleboard_23x16_30mm.yaml"))
    path = photo()
    image = puzzlecal.load_image(str(path))
    wall, inside = [], []
    for _ in range(3):  # warm-up
        puzzlecal.detect(image, board)
    for _ in range(30):
        start = time.perf_counter()
        detection = puzzlecal.detect(image, board)
        wall.append(time.perf_counter() - start)
        inside.append(detection.seconds)
    wall_ms = statistics.median(wall) * 1e3
    inside_ms = statistics.median(inside) * 1e3
    print(json.dumps({
        "image": f"{image.shape[1]}x{image.shape[0]}",
        "ids": int(len(detection.ids)),
        "python_detect_ms_median": round(wall_ms, 3),
        "cpp_inside_ms_median": round(inside_ms, 3),
        "overhead_ms": round(wall_ms - inside_ms, 3),
        "overhead_percent": round(100 * (wall_ms - inside_ms) / inside_ms, 2),
        "runs": len(wall),
    }, indent=2))


if __name__ == "__main__":
    main()
