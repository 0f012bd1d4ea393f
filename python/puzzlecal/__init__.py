"""puzzlecal: camera calibration from photos of a PuzzleBoard or a checkerboard.

    import puzzlecal
    board = puzzlecal.Board.load("configs/boards/puzzleboard_23x16_30mm.yaml")
    result = puzzlecal.calibrate("photos/", board, model="auto")
    print(result.verdict.line())
    result.save("camera.yaml", format="opencv")

Images are numpy arrays (H x W grey or H x W x 3 BGR, as cv2 loads them);
points and pixels are N x 2 / N x 3 float64 arrays; ids N x 2 int. Errors are
ValueError with the messages the program prints.
"""

import json as _json
import os as _os

from ._puzzlecal import (  # noqa: F401  (the compiled part)
    MODELS,
    Board,
    Calibration,
    Camera,
    Detection,
    Options,
    Verdict,
    detect,
    detect_files,
    list_images,
    load_image,
)
from . import _puzzlecal

__all__ = [
    "MODELS", "Board", "Calibration", "Camera", "Detection", "Options",
    "Verdict", "calibrate", "detect", "detect_files", "list_images",
    "load_image", "options",
]


def options(settings=None, **sections):
    """The run options: the defaults, changed by an options file (a path),
    a dict of sections, or keyword sections, e.g.
    ``puzzlecal.options(calibration={"outlier_k": 4})``. The sections and
    field names are those of an options file (``puzzlecal options`` writes
    one with every default); unknown names are errors."""
    if settings is None:
        settings = {}
    if isinstance(settings, (str, _os.PathLike)):
        with open(settings, encoding="utf-8") as f:
            text, source = f.read(), str(settings)
        if sections:
            raise ValueError("options: give a file or keyword sections, not both")
        return _puzzlecal._parse_options(text, source)
    if not isinstance(settings, dict):
        raise ValueError("options: expected a path, a dict or keyword sections")
    merged = dict(settings)
    merged.update(sections)
    # JSON is YAML: the program's own reader checks every field.
    return _puzzlecal._parse_options(_json.dumps(merged), "options")


def calibrate(source, board, model="auto", image_size=None, options=None,
              threads=0):
    """Calibrates a camera and judges the result as ``puzzlecal calibrate``
    does.

    source: a folder or image file (str), a list of image files, a list of
        Detection (from detect / detect_files), or a list of (ids, corners)
        pairs (N x 2 int board ids, N x 2 float64 pixels; then image_size =
        (width, height) is required).
    board: a Board.
    model: one of puzzlecal.MODELS or "auto" (chosen on held-out views).
    options: puzzlecal.options(...) (default: the defaults).
    threads: workers for detection and calibration (0: all cores); the
        result does not depend on it.

    Returns a Calibration: camera, params_by_name, stddev_by_name,
    covariance, poses, residuals, inliers, rms_px, verdict, save(path,
    format).
    """
    if options is None:
        options = Options()
    if isinstance(source, (str, _os.PathLike)):
        source = list_images(str(source))
    source = list(source)
    if not source:
        raise ValueError("calibrate: no images or observations given")
    if all(isinstance(s, (str, _os.PathLike)) for s in source):
        source = detect_files([str(s) for s in source], board, threads, options)
    if all(isinstance(s, Detection) for s in source):
        return _puzzlecal._calibrate_detections(source, board, model, options,
                                                threads)
    if image_size is None:
        raise ValueError("calibrate: (ids, corners) observations need "
                         "image_size=(width, height)")
    return _puzzlecal._calibrate_observations(source, board,
                                              tuple(image_size), model,
                                              options, threads)
