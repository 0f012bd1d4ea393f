"""puzzlecal: camera calibration from photos of a PuzzleBoard or a checkerboard.

    import puzzlecal
    board = puzzlecal.Board.load("configs/boards/puzzleboard_23x16_30mm.yaml")
    result = puzzlecal.calibrate("photos/", board, model="auto")
    print(result.verdict.line())
    result.save("camera.yaml", format="opencv")
    rig = puzzlecal.calibrate_rig("rig_photos/", board, models="auto")
    print(rig.verdict.line(), rig.cameras[1].cam_from_rig)

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
    RigCalibration,
    RigCamera,
    RigVerdict,
    Verdict,
    detect,
    detect_files,
    list_images,
    load_image,
    render_rig,
)
from . import _puzzlecal

__all__ = [
    "MODELS", "Board", "Calibration", "Camera", "Detection", "Options",
    "RigCalibration", "RigCamera", "RigVerdict", "Verdict", "calibrate",
    "calibrate_rig", "detect", "detect_files", "list_images", "load_image",
    "options", "render_rig",
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
    options: puzzlecal.options(...) (default: the defaults); parameters
        held at their start: ``calibration={"fixed_params": ["k3"]}``, a
        known start: ``calibration={"initial_params": [...]}`` (the model's
        order), as ``puzzlecal calibrate --fix`` and ``--initial``.
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


def calibrate_rig(source, board, models="auto", image_sizes=None, names=None,
                  match_by_order=False, format="puzzlecal", options=None,
                  threads=0):
    """Calibrates a rig of cameras and judges it as ``puzzlecal
    calibrate-rig`` does.

    source: one of
        - a folder (str) holding one subfolder per camera, as
          ``calibrate-rig --images`` takes (sorted by name; the first camera
          is the rig frame);
        - a list of camera folders, one per camera (the first is the rig
          frame);
        - a list, per camera, of per-frame observations: each frame an
          (ids, corners) pair (N x 2 int board ids, N x 2 float64 pixels) or
          None where the camera did not see the board; every camera lists
          the same frames. image_sizes is then required.
        The same file name in different camera folders is the same instant
        (match_by_order=True pairs the n-th image of every folder instead).
    board: a Board.
    models: one model name (puzzlecal.MODELS) or "auto" for all cameras, or
        a list with one per camera; "auto" chooses a camera's model on its
        held-out views.
    image_sizes: with observations, (width, height) for all cameras or a
        list with one per camera.
    names: camera names (default: the folders' names, or cam0, cam1, ...).
    format: the rig file format the result is meant for (puzzlecal, opencv,
        ros, kalibr): a parameter the format cannot hold is held fixed, as
        the program's --format does; save() writes it by default.
    options: puzzlecal.options(...) (sections rig, rig_evidence,
        calibration, evidence, verdict, model_selection, detection ones).
    threads: workers (0: all cores); the result does not depend on it.

    Returns a RigCalibration: cameras (RigCamera: camera, cam_from_rig (R, t)
    with rotation_stddev_deg / translation_stddev_m, baseline_m with its
    sigma, residuals, rms_px, its own verdict), poses (rig_from_board per
    frame), rms_px, verdict (RigVerdict: kind, reason, next_step), frames
    (per frame: files, use, transfer error, epipolar error, moved), summary(),
    save(path, format). Raises ValueError with the program's message (naming
    the camera, folder or file) when the input is refused or the rig cannot
    be calibrated.
    """
    if options is None:
        options = Options()
    if isinstance(models, str):
        models = [models]
    models = list(models)
    if names is not None:
        names = [str(n) for n in names]
    if isinstance(source, (str, _os.PathLike)):
        folders = _puzzlecal._rig_camera_folders(str(source))
        return _puzzlecal._calibrate_rig_folders(
            folders, names or [], board, models, bool(match_by_order), format,
            options, threads)
    source = list(source)
    if not source:
        raise ValueError("calibrate_rig: no cameras given")
    if all(isinstance(s, (str, _os.PathLike)) for s in source):
        return _puzzlecal._calibrate_rig_folders(
            [str(s) for s in source], names or [], board, models,
            bool(match_by_order), format, options, threads)
    if image_sizes is None:
        raise ValueError("calibrate_rig: observations need image_sizes="
                         "(width, height) or one per camera")
    if (len(image_sizes) == 2
            and all(isinstance(v, int) for v in image_sizes)):
        image_sizes = [tuple(image_sizes)]
    return _puzzlecal._calibrate_rig_observations(
        source, names or [], [tuple(s) for s in image_sizes], board, models,
        format, options, threads)
