"""Capture advice from Python: Calibration.advise on a deficient start (four
of the sample photos) against the program's `puzzlecal advise` on the same
photos (the same poses, to the digits advice.yaml prints), and its poses
against the calibrated camera."""

import shutil
import subprocess

import numpy as np
import pytest
import yaml

import puzzlecal
from conftest import BOARD_FILE, SAMPLE


@pytest.fixture(scope="module")
def start(tmp_path_factory):
    folder = tmp_path_factory.mktemp("start")
    for name in ("sample_view_000.png", "sample_view_001.png",
                 "sample_view_002.png", "sample_view_003.png"):
        shutil.copy(SAMPLE / name, folder / name)
    return folder


@pytest.fixture(scope="module")
def board():
    return puzzlecal.Board.load(str(BOARD_FILE))


@pytest.fixture(scope="module")
def advice(start, board):
    calibration = puzzlecal.calibrate(str(start), board,
                                      model="pinhole-radtan", threads=2)
    assert calibration.verdict.kind == "insufficient-data"
    return calibration, calibration.advise(count=2, threads=2)


def test_advice_poses_put_the_board_where_said(advice, board):
    calibration, result = advice
    assert len(result["views"]) == 2
    origin = np.array(board.origin, dtype=float)
    centre = np.array([(origin[0] + (board.cols - 1) / 2) * board.tile_size_m,
                       (origin[1] + (board.rows - 1) / 2) * board.tile_size_m,
                       0.0])
    worst = result["uncertainty_now"]["worst_px"]
    for view in result["views"]:
        R, t = view["R"], view["t"]
        np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-12)
        assert np.linalg.det(R) == pytest.approx(1.0)
        pixel = calibration.camera.project((R @ centre + t).reshape(1, 3))
        np.testing.assert_allclose(pixel[0], view["centre_px"], atol=1e-6)
        assert view["words"].startswith("board about ")
        assert view["outline_px"].shape[1] == 2
        assert view["picture"].dtype == np.uint8
        assert view["picture"].shape[1:] == (1200, 3)
        assert view["expected_after"]["worst_px"] < worst
        worst = view["expected_after"]["worst_px"]
    assert result["photos_to_target"] is None or \
        result["photos_to_target"] >= result["views_taken"]


def test_advice_equals_the_programs(advice, start, program, tmp_path):
    _, result = advice
    out = tmp_path / "advice"
    subprocess.run([program, "advise", "--images", str(start), "--board",
                    str(BOARD_FILE), "--out", str(out), "--model",
                    "pinhole-radtan", "--count", "2", "--threads", "2"],
                   check=True, capture_output=True)
    with open(out / "advice.yaml", encoding="utf-8") as f:
        written = yaml.safe_load(f)
    assert written["photos_to_target"] == result["photos_to_target"]
    for mine, theirs in zip(result["views"], written["views"]):
        assert mine["words"] == theirs["words"]
        np.testing.assert_array_equal(
            mine["R"], np.array(theirs["cam_from_board"]["R"]))
        np.testing.assert_array_equal(
            mine["t"], np.array(theirs["cam_from_board"]["t"]))


def test_bad_count_is_refused(advice):
    calibration, _ = advice
    with pytest.raises(ValueError, match="count must be >= 1"):
        calibration.advise(count=0)


def test_advice_on_a_splined_camera_keeps_the_prior_the_options_give(
        start, board, program, tmp_path):
    """A splined camera's advice holds the knots no corner saw with the
    smoothness prior its calibration had: the one the options give (as
    `puzzlecal advise --options` does), not the default."""
    stiff = {"spline_prior": {"smoothness_weight": 10.0, "zero_weight": 1.0}}
    options = puzzlecal.options(calibration=stiff)
    calibration = puzzlecal.calibrate(str(start), board,
                                      model="kannala-brandt-splined",
                                      options=options, threads=2)
    mine = calibration.advise(count=1, options=options, threads=2)
    default = calibration.advise(count=1, threads=2)
    # A stiffer prior holds the unseen knots tighter: less uncertainty now.
    assert mine["uncertainty_now"]["worst_px"] < \
        0.9 * default["uncertainty_now"]["worst_px"]
    options_file = tmp_path / "options.yaml"
    options_file.write_text(yaml.safe_dump({"calibration": stiff}),
                            encoding="utf-8")
    out = tmp_path / "advice"
    subprocess.run([program, "advise", "--images", str(start), "--board",
                    str(BOARD_FILE), "--out", str(out), "--model",
                    "kannala-brandt-splined", "--options", str(options_file),
                    "--count", "1", "--threads", "2"],
                   check=True, capture_output=True)
    with open(out / "advice.yaml", encoding="utf-8") as f:
        written = yaml.safe_load(f)
    assert written["views"][0]["words"] == mine["views"][0]["words"]
    assert written["views"][0]["expected_after"]["worst_px"] == \
        pytest.approx(mine["views"][0]["expected_after"]["worst_px"],
                      rel=1e-9)


def test_predict_with_the_advised_poses_gives_the_advices_expectation(advice):
    """Calibration.predict scores poses the way the advice scores its
    candidates: the advised poses give the advice's expectation after its
    last view, no pose gives the uncertainty now, and the taken views'
    own poses taken once more at least double the information (the
    uncertainty falls by sqrt(2) or more): a predicted view counts every
    board corner its pose puts in the image, the calibration only those
    detected and kept; but less than triple it."""
    calibration, result = advice
    poses = [(view["R"], view["t"]) for view in result["views"]]
    expected = result["views"][-1]["expected_after"]
    predicted = calibration.predict(poses)
    for key in ("worst_px", "median_px", "worst_band_median_px"):
        assert predicted[key] == pytest.approx(expected[key], rel=1e-9)
    now = calibration.predict([])
    assert now["worst_px"] == pytest.approx(
        result["uncertainty_now"]["worst_px"], rel=1e-9)
    used = [pose for pose, kept in zip(calibration.poses,
                                       calibration.view_used) if kept]
    again = calibration.predict(used)
    ratio = now["median_px"] / again["median_px"]
    assert np.sqrt(2) * 0.98 < ratio < np.sqrt(3)


def test_predict_refuses_a_matrix_that_is_no_rotation(advice):
    calibration, result = advice
    t = result["views"][0]["t"]
    with pytest.raises(ValueError, match="R is not a rotation"):
        calibration.predict([(2 * np.eye(3), t)])
    with pytest.raises(ValueError, match="R must be 3 x 3"):
        calibration.predict([(np.eye(3)[:2], t)])
