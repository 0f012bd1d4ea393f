import gc
import subprocess

import numpy as np
import pytest

import puzzlecal
from conftest import BOARD_FILE, SAMPLE, truth_view


@pytest.fixture(scope="module")
def board():
    return puzzlecal.Board.load(str(BOARD_FILE))


@pytest.fixture(scope="module")
def radtan(board):
    return puzzlecal.calibrate(str(SAMPLE), board, model="pinhole-radtan",
                               threads=2)


def test_calibration_meets_the_truth(radtan, truth):
    true = dict(zip(truth["camera"]["param_names"], truth["camera"]["params"]))
    params = radtan.params_by_name
    assert radtan.model == "pinhole-radtan"
    assert list(params) == ["fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2",
                            "k3"]
    for name in ("fx", "fy"):
        assert params[name] == pytest.approx(true[name], rel=2e-3)
    for name in ("cx", "cy"):
        assert params[name] == pytest.approx(true[name], abs=1.5)
    sigma = radtan.stddev_by_name
    assert all(s > 0 for s in sigma.values())
    cov = radtan.covariance
    assert cov.shape == (9, 9)
    np.testing.assert_allclose(np.sqrt(np.diag(cov)), list(sigma.values()),
                               rtol=1e-9)
    assert 0 < radtan.rms_px < 0.5
    assert radtan.verdict.kind in ("good", "model-error", "bad-detections",
                                   "insufficient-data")
    assert radtan.verdict.line().startswith("verdict: ")
    assert radtan.model_selection is None
    evidence = radtan.evidence
    sigma_map = evidence["uncertainty"]["sigma_px"]
    step = evidence["uncertainty"]["step_px"]
    # A grid over the image: (rows - 1) * step spans its height.
    assert sigma_map.ndim == 2 and step > 0
    assert abs((sigma_map.shape[0] - 1) * step - 600) <= step
    assert abs((sigma_map.shape[1] - 1) * step - 800) <= step
    assert np.nanmax(sigma_map) > 0
    assert evidence["halves"]["ok"]
    assert evidence["halves"]["difference_px"].shape == sigma_map.shape
    assert sum(b["count"] for b in evidence["residuals_by_angle"]) > 100


def test_poses_residuals_and_inliers(radtan, truth):
    names = radtan.view_names
    assert len(names) == len(radtan.poses) == len(radtan.residuals)
    _, R_true, t_true, _, _ = truth_view(truth, 0)
    R, t = radtan.poses[names.index("sample_view_000.png")]
    assert R.shape == (3, 3) and t.shape == (3,)
    np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-9)
    angle = np.degrees(np.arccos(np.clip((np.trace(R.T @ R_true) - 1) / 2,
                                         -1, 1)))
    assert angle < 0.3
    np.testing.assert_allclose(t, t_true, atol=0.01)
    for used, residuals, inliers in zip(radtan.view_used, radtan.residuals,
                                        radtan.inliers):
        if not used:
            continue
        assert residuals.shape == (len(inliers), 2)
        assert inliers.dtype == bool and inliers.mean() > 0.9


def test_saved_file_equals_the_programs(radtan, program, tmp_path):
    for fmt in ("puzzlecal", "opencv"):
        ours = tmp_path / f"python_{fmt}.yaml"
        theirs = tmp_path / f"program_{fmt}.yaml"
        radtan.save(str(ours), format=fmt)
        subprocess.run([program, "calibrate", "--images", str(SAMPLE),
                        "--board", str(BOARD_FILE), "--model",
                        "pinhole-radtan", "--format", fmt, "--threads", "2",
                        "--out", str(theirs), "--quiet"], check=True)
        assert ours.read_text() == theirs.read_text(), fmt


def test_observations_from_the_truth(board, truth):
    observations = [truth_view(truth, v)[3:5]
                    for v in range(len(truth["views"]))]
    result = puzzlecal.calibrate(observations, board, model="pinhole-radtan",
                                 image_size=(800, 600))
    true = truth["camera"]["params"]
    # Exact corners: the truth within a small fraction of a pixel.
    np.testing.assert_allclose(result.camera.params[:4], true[:4], atol=0.05)
    assert result.rms_px < 1e-3
    assert result.view_names[0] == "view_0"


def test_auto_chooses_and_says_why(board):
    detections = puzzlecal.detect_files(puzzlecal.list_images(str(SAMPLE)),
                                        board)
    result = puzzlecal.calibrate(detections, board, model="auto")
    assert result.model in puzzlecal.MODELS
    assert "held-out" in result.model_selection or result.model_selection


def test_result_outlives_what_it_came_from(truth):
    def make():
        board = puzzlecal.Board.load(str(BOARD_FILE))
        observations = [truth_view(truth, v)[3:5] for v in range(6)]
        return puzzlecal.calibrate(observations, board, model="pinhole-radtan",
                                   image_size=(800, 600))
    result = make()
    gc.collect()
    camera = result.camera
    del result
    gc.collect()
    assert camera.params[0] == pytest.approx(400, rel=1e-3)


def test_bad_calls_are_refused_with_a_reason(board, truth):
    ids, corners = truth_view(truth, 0)[3:5]
    with pytest.raises(ValueError, match="image_size"):
        puzzlecal.calibrate([(ids, corners)], board)
    with pytest.raises(ValueError, match="integer"):
        puzzlecal.calibrate([(ids.astype(float), corners)], board,
                            image_size=(800, 600))
    with pytest.raises(ValueError, match="ids but"):
        puzzlecal.calibrate([(ids, corners[:-1])], board,
                            image_size=(800, 600))
    with pytest.raises(ValueError, match="unknown model 'pinhole'"):
        puzzlecal.calibrate([(ids, corners)] * 5, board, model="pinhole",
                            image_size=(800, 600))
    with pytest.raises(ValueError, match="not on the board"):
        puzzlecal.calibrate([(ids - 100, corners)], board,
                            image_size=(800, 600))
    with pytest.raises(ValueError, match="no images"):
        puzzlecal.calibrate([], board)


def test_options_by_keyword(board, tmp_path):
    options = puzzlecal.options(calibration={"outlier_k": 4})
    assert "outlier_k: 4" in options.yaml()
    with pytest.raises(ValueError, match="bogus"):
        puzzlecal.options(calibration={"bogus": 1})
    path = tmp_path / "options.yaml"
    path.write_text(options.yaml())
    assert puzzlecal.options(str(path)).yaml() == options.yaml()


def test_fixed_parameters_and_a_known_start(board, radtan):
    # The options file's calibration.fixed_params and initial_params, as
    # `puzzlecal calibrate --fix` and `--initial` use them.
    held = puzzlecal.calibrate(
        str(SAMPLE), board, model="pinhole-radtan", threads=2,
        options=puzzlecal.options(calibration={
            "fixed_params": ["k3", "p1", "p2"]}))
    for name in ("k3", "p1", "p2"):
        assert held.params_by_name[name] == 0.0
        assert held.stddev_by_name[name] == 0.0
    assert held.stddev_by_name["k1"] > 0
    start = [radtan.params_by_name[n] for n in
             ("fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3")]
    known = puzzlecal.calibrate(
        str(SAMPLE), board, model="pinhole-radtan", threads=2,
        options=puzzlecal.options(calibration={
            "initial_params": start, "fixed_params": ["fx", "fy"]}))
    assert known.params_by_name["fx"] == start[0]
    assert known.params_by_name["fy"] == start[1]
    with pytest.raises(ValueError, match="not a parameter of pinhole-radtan"):
        puzzlecal.calibrate(
            str(SAMPLE), board, model="pinhole-radtan", threads=2,
            options=puzzlecal.options(calibration={"fixed_params": ["k9"]}))


def test_same_focal_length_by_keyword(board):
    """One focal length through the options, as --same-focal does."""
    result = puzzlecal.calibrate(
        str(SAMPLE), board, model="pinhole-radtan", threads=2,
        options=puzzlecal.options(calibration={"same_focal_length": True}))
    params = result.params_by_name
    assert params["fx"] == params["fy"]
    sigma = result.stddev_by_name
    assert sigma["fx"] == sigma["fy"] > 0
