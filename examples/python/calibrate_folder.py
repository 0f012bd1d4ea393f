#!/usr/bin/env python3
"""Calibrates a folder of photos with puzzlecal, undistorts one photo with
OpenCV from the written camera file, and plots the residuals.

    PYTHONPATH=build/python python3 examples/python/calibrate_folder.py \
        testdata/sample configs/boards/puzzleboard_23x16_30mm.yaml out/python

cv2 (python3-opencv) and matplotlib (python3-matplotlib) are needed for the
second and third steps only."""

import pathlib
import sys

import numpy as np

import puzzlecal


def main(images, board_file, out):
    out = pathlib.Path(out)
    out.mkdir(parents=True, exist_ok=True)
    board = puzzlecal.Board.load(board_file)
    result = puzzlecal.calibrate(images, board, model="auto")
    print(result.model_selection)
    print(result.verdict.line())
    for name, value in result.params_by_name.items():
        print(f"  {name} = {value:.6g} +- {result.stddev_by_name[name]:.2g}")
    note = result.save(str(out / "camera.yaml"), format="opencv")
    if note:
        print("note:", note)

    try:
        import cv2
    except ImportError:
        print("cv2 not installed: skipping the undistortion")
    else:
        fs = cv2.FileStorage(str(out / "camera.yaml"), cv2.FILE_STORAGE_READ)
        K = fs.getNode("camera_matrix").mat()
        D = fs.getNode("distortion_coefficients").mat()
        photo = cv2.imread(puzzlecal.list_images(images)[0])
        if result.camera.model.startswith("pinhole"):
            undistorted = cv2.undistort(photo, K, D)
        else:  # kannala-brandt: OpenCV's fisheye module
            undistorted = cv2.fisheye.undistortImage(photo, K, D, Knew=K)
        cv2.imwrite(str(out / "undistorted.png"), undistorted)
        # puzzlecal's own maps, for any model (cv2.remap):
        map_x, map_y, target = result.camera.undistort_maps()
        cv2.imwrite(str(out / "undistorted_puzzlecal.png"),
                    cv2.remap(photo, map_x, map_y, cv2.INTER_LINEAR))

    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib not installed: skipping the residual plot")
        return
    residuals = np.concatenate([r[m] for r, m in zip(result.residuals,
                                                     result.inliers)
                                if len(r)])
    plt.figure(figsize=(5, 5))
    plt.scatter(residuals[:, 0], residuals[:, 1], s=2)
    plt.gca().set_aspect("equal")
    plt.xlabel("x residual (px)")
    plt.ylabel("y residual (px)")
    plt.title(f"{result.model}: RMS {result.rms_px:.3f} px")
    plt.savefig(out / "residuals.png", dpi=120)
    print("wrote", out / "camera.yaml", "and the pictures beside it")


if __name__ == "__main__":
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    main(*sys.argv[1:])
