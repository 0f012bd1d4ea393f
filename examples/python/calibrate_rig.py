#!/usr/bin/env python3
"""Calibrates a rig (one photo subfolder per camera; the same file name in
every subfolder is the same instant), prints each camera's place in the rig
with its sigma and the rig's verdict, and writes the rig file.

    PYTHONPATH=build/python python3 examples/python/calibrate_rig.py \
        RIG_FOLDER BOARD.yaml out/rig.yaml [MODEL ...]

Without a rig at hand, puzzlecal.render_rig("rig/") renders one with its
truth (the board: its "board" entry)."""

import sys

import numpy as np

import puzzlecal


def main(images, board_file, out, models):
    board = puzzlecal.Board.load(board_file)
    rig = puzzlecal.calibrate_rig(images, board, models=models or "auto")
    for camera in rig.cameras:
        R, t = camera.cam_from_rig
        angle = np.degrees(np.arccos(np.clip((np.trace(R) - 1) / 2, -1, 1)))
        print(f"{camera.name}: {camera.model}, RMS {camera.rms_px:.3f} px, "
              f"turned {angle:.3f} +- {camera.rotation_stddev_deg:.3f} deg, "
              f"baseline {camera.baseline_m * 1000:.3f} +- "
              f"{camera.baseline_stddev_m * 1000:.3f} mm")
        print("  " + camera.verdict.line())
    print(rig.verdict.line())
    for path in rig.save(out):
        print("wrote", path)


if __name__ == "__main__":
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4:])
