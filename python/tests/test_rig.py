"""Rig calibration from Python against the truth of a rendered stereo rig
(sim/'s StereoPinholeRig: two pinhole-radtan cameras 12 cm apart, turned 4
degrees towards each other, 16 frames at 640 x 480) and against the
program's own rig file."""

import gc
import pathlib
import shutil
import subprocess
import sys

import numpy as np
import pytest

import puzzlecal

# Tolerances against the render's truth. The rig's rotation sigma on this
# render is about 0.0022 degrees; the baseline's 0.005 mm.
MAX_ROTATION_ERROR_DEG = 0.01
MAX_BASELINE_ERROR = 1e-3  # of the baseline
MAX_TRANSLATION_ERROR_M = 1e-4
MAX_FOCAL_RELATIVE_ERROR = 5e-4
MAX_FRAME_ROTATION_ERROR_DEG = 0.02
MAX_FRAME_TRANSLATION_ERROR_M = 1e-3


def rotation_deg(a, b):
    """Angle of the rotation between a and b, degrees."""
    cosine = (np.trace(a.T @ b) - 1) / 2
    return float(np.degrees(np.arccos(np.clip(cosine, -1, 1))))


def write_board_file(board, path):
    path.write_text(f"type: {board.type}\ncols: {board.cols}\n"
                    f"rows: {board.rows}\n"
                    f"origin: [{board.origin[0]}, {board.origin[1]}]\n"
                    f"tile_size_m: {board.tile_size_m}\n")
    return path


@pytest.fixture(scope="module")
def rendered(tmp_path_factory):
    root = tmp_path_factory.mktemp("stereo")
    truth = puzzlecal.render_rig(str(root / "images"), "stereo-pinhole",
                                 (640, 480))
    board_file = write_board_file(truth["board"], root / "board.yaml")
    return root, truth, board_file


@pytest.fixture(scope="module")
def rig(rendered):
    root, truth, _ = rendered
    return puzzlecal.calibrate_rig(str(root / "images"), truth["board"],
                                   models="pinhole-radtan", threads=2)


def test_rig_meets_the_render_truth(rig, rendered):
    _, truth, _ = rendered
    assert rig.camera_names == ["cam0", "cam1"]
    assert len(rig.cameras) == len(truth["cameras"]) == 2
    for camera, true in zip(rig.cameras, truth["cameras"]):
        R, t = camera.cam_from_rig
        R_true, t_true = true["cam_from_rig"]
        assert R.shape == (3, 3) and t.shape == (3,)
        assert rotation_deg(R, R_true) < MAX_ROTATION_ERROR_DEG, camera.name
        assert np.linalg.norm(t - t_true) < MAX_TRANSLATION_ERROR_M
        baseline = np.linalg.norm(R_true.T @ t_true)
        assert camera.baseline_m == pytest.approx(
            baseline, abs=MAX_BASELINE_ERROR * 0.12)
        for k, name in enumerate(("fx", "fy")):
            assert camera.params_by_name[name] == pytest.approx(
                true["camera"].params[k], rel=MAX_FOCAL_RELATIVE_ERROR)
    # The relative pose of the pair: the second camera from the first.
    (R0, t0), (R1, t1) = (c.cam_from_rig for c in rig.cameras)
    R_rel, t_rel = R1 @ R0.T, t1 - R1 @ R0.T @ t0
    (T0, u0), (T1, u1) = (c["cam_from_rig"] for c in truth["cameras"])
    assert rotation_deg(R_rel, T1 @ T0.T) < MAX_ROTATION_ERROR_DEG
    assert np.linalg.norm(t_rel) == pytest.approx(
        np.linalg.norm(u1 - T1 @ T0.T @ u0), rel=MAX_BASELINE_ERROR)


def test_sigmas_are_those_of_the_covariance(rig):
    reference, second = rig.cameras
    assert reference.rotation_stddev_deg == 0
    np.testing.assert_array_equal(reference.cam_from_rig[0], np.eye(3))
    cov = second.extrinsics_covariance
    assert cov.shape == (6, 6)
    assert 0 < second.rotation_stddev_deg < MAX_ROTATION_ERROR_DEG
    # The sigma is that of the small rotation that perturbs R; the
    # covariance's is of the angle-axis vector: equal to first order.
    assert second.rotation_stddev_deg == pytest.approx(
        np.degrees(np.sqrt(np.trace(cov[:3, :3]))), rel=1e-3)
    np.testing.assert_allclose(second.translation_stddev_m,
                               np.sqrt(np.diag(cov)[3:]), rtol=1e-9)
    assert 0 < second.baseline_stddev_m < 1e-4
    assert all(s > 0 for s in second.stddev_by_name.values())


def test_frame_poses_meet_the_truth(rig, rendered):
    _, truth, _ = rendered
    assert len(rig.poses) == truth["num_frames"] == 16
    assert rig.num_frames_used == 16
    for pose, (R_true, t_true) in zip(rig.poses, truth["rig_from_board"]):
        R, t = pose
        assert rotation_deg(R, R_true) < MAX_FRAME_ROTATION_ERROR_DEG
        assert np.linalg.norm(t - t_true) < MAX_FRAME_TRANSLATION_ERROR_M


def test_residuals_rms_and_verdict(rig):
    for camera in rig.cameras:
        kept = [r[m] for r, m, used in zip(camera.residuals, camera.inliers,
                                           camera.frame_used) if used]
        kept = np.concatenate(kept)
        assert len(kept) == camera.num_corners_used
        assert camera.rms_px == pytest.approx(np.sqrt(np.mean(kept ** 2)),
                                              rel=1e-9)
        assert camera.rms_px < 0.1  # the render's corners: a few 0.01 px
        assert camera.verdict.kind == "good"
        assert camera.model_selection is None
        assert camera.evidence["halves"]["ok"]
    assert rig.verdict.kind == "good"
    assert rig.verdict.line().startswith("rig: verdict: good")
    assert rig.moved_frames == []
    np.testing.assert_array_equal(rig.shared_frames, [[16, 16], [16, 16]])
    assert rig.frame_names[0] == "frame_000.png"
    frame = rig.frames[0]
    assert [pathlib.Path(f).name for f in frame["files"]] == [
        "frame_000.png"] * 2
    assert frame["use"] == ["used", "used"]
    assert frame["compared"] and not frame["moved"]
    assert frame["transfer_px"] < 0.3
    assert "cam1" in rig.summary()


def test_auto_chooses_the_rendered_model_quietly(rendered, capfd):
    root, truth, _ = rendered
    # auto for the first camera, a model named for the second.
    result = puzzlecal.calibrate_rig(str(root / "images"), truth["board"],
                                     models=["auto", "pinhole-radtan"],
                                     threads=2)
    first, second = result.cameras
    assert first.model == truth["cameras"][0]["camera"].model
    assert "chosen: pinhole-radtan" in first.model_selection
    assert second.model_selection is None
    assert result.verdict.kind == "good"
    # The solver's warnings on the models tried stay out of the way.
    assert capfd.readouterr().err == ""


def test_saved_file_equals_the_programs(rig, rendered, program, tmp_path):
    root, _, board_file = rendered
    for fmt in ("puzzlecal", "opencv"):
        ours = tmp_path / f"python_{fmt}.yaml"
        theirs = tmp_path / f"program_{fmt}.yaml"
        assert rig.save(str(ours), format=fmt) == [str(ours)]
        subprocess.run([program, "calibrate-rig", "--images",
                        str(root / "images"), "--board", str(board_file),
                        "--model", "pinhole-radtan", "--format", fmt,
                        "--threads", "2", "--out", str(theirs), "--quiet"],
                       check=True, stdout=subprocess.DEVNULL)
        assert ours.read_text() == theirs.read_text(), fmt


def test_kalibr_holds_k3_fixed_as_the_program(rendered, program, tmp_path):
    # Kalibr's radtan has no k3: the calibration holds it at 0, as the
    # program's --format kalibr does, and the files agree.
    root, truth, board_file = rendered
    rig = puzzlecal.calibrate_rig(str(root / "images"), truth["board"],
                                  models="pinhole-radtan", format="kalibr")
    for camera in rig.cameras:
        assert camera.params_by_name["k3"] == 0
        assert camera.stddev_by_name["k3"] == 0
    ours, theirs = tmp_path / "python.yaml", tmp_path / "program.yaml"
    rig.save(str(ours))
    subprocess.run([program, "calibrate-rig", "--images", str(root / "images"),
                    "--board", str(board_file), "--model", "pinhole-radtan",
                    "--format", "kalibr", "--out", str(theirs), "--quiet"],
                   check=True, stdout=subprocess.DEVNULL)
    assert ours.read_text() == theirs.read_text()


def detections_as_observations(root, board):
    """Per camera, per frame (ids, corners) or None, from detect_files."""
    observations = []
    for camera in ("cam0", "cam1"):
        files = puzzlecal.list_images(str(root / "images" / camera))
        observations.append([(d.ids, d.corners) if d.usable else None
                             for d in puzzlecal.detect_files(files, board)])
    return observations


def test_observations_give_the_folders_result(rig, rendered):
    root, truth, _ = rendered
    board = truth["board"]
    observations = detections_as_observations(root, board)
    # A frame the second camera did not see.
    observations[1][3] = None
    result = puzzlecal.calibrate_rig(observations, board,
                                     models=["pinhole-radtan"] * 2,
                                     image_sizes=(640, 480),
                                     names=["left", "right"])
    assert result.camera_names == ["left", "right"]
    assert result.cameras[1].frame_used[3] is False
    assert result.frames[3]["use"][1].startswith("not used")
    R, _ = result.cameras[1].cam_from_rig
    assert rotation_deg(R, rig.cameras[1].cam_from_rig[0]) < 1e-3
    assert result.cameras[1].baseline_m == pytest.approx(
        rig.cameras[1].baseline_m, rel=1e-4)


def test_result_outlives_what_it_came_from(rendered):
    root, truth, board_file = rendered

    def make():
        board = puzzlecal.Board.load(str(board_file))
        # A list of camera folders ("cam0/" names its camera cam0).
        folders = [f"{root / 'images' / name}/" for name in ("cam0", "cam1")]
        return puzzlecal.calibrate_rig(folders, board,
                                       models="pinhole-radtan").cameras
    cameras = make()
    gc.collect()
    assert [c.name for c in cameras] == ["cam0", "cam1"]
    camera = cameras[1].camera
    R, _ = cameras[1].cam_from_rig
    verdict = cameras[1].verdict
    del cameras
    gc.collect()
    assert camera.params[0] == pytest.approx(
        truth["cameras"][1]["camera"].params[0], rel=MAX_FOCAL_RELATIVE_ERROR)
    assert rotation_deg(R, truth["cameras"][1]["cam_from_rig"][0]) < 0.01
    assert verdict.kind == "good"


def test_bad_input_is_refused_with_a_reason(rendered, tmp_path):
    root, truth, _ = rendered
    board = truth["board"]
    images = root / "images"
    missing = tmp_path / "no_such_camera"
    with pytest.raises(ValueError, match="no_such_camera"):
        puzzlecal.calibrate_rig([str(images / "cam0"), str(missing)], board,
                                models="pinhole-radtan")
    with pytest.raises(ValueError, match="not a folder"):
        puzzlecal.calibrate_rig(str(missing), board)
    one = tmp_path / "one_camera"
    shutil.copytree(images / "cam0", one / "cam0")
    with pytest.raises(ValueError, match="1 camera subfolder .*at least two"):
        puzzlecal.calibrate_rig(str(one), board)
    with pytest.raises(ValueError, match="3 models for 2 cameras"):
        puzzlecal.calibrate_rig(str(images), board,
                                models=["pinhole-radtan"] * 3)
    with pytest.raises(ValueError, match="unknown model 'pinhole'"):
        puzzlecal.calibrate_rig(str(images), board, models="pinhole")
    # Folders that share no file name, and pairing by order with counts
    # that differ: each message names the camera.
    renamed = tmp_path / "renamed"
    shutil.copytree(images, renamed)
    for path in (renamed / "cam1").iterdir():
        path.rename(path.with_name("right_" + path.name))
    with pytest.raises(ValueError, match="camera 'cam0' shares no frame"):
        puzzlecal.calibrate_rig(str(renamed), board, models="pinhole-radtan")
    (renamed / "cam1" / "right_frame_000.png").unlink()
    with pytest.raises(ValueError, match="camera 'cam1' has 15 images, "
                                         "camera 'cam0' 16"):
        puzzlecal.calibrate_rig(str(renamed), board, models="pinhole-radtan",
                                match_by_order=True)
    observations = detections_as_observations(root, board)
    with pytest.raises(ValueError, match="camera 'cam1': 15 frames, camera "
                                         "'cam0': 16"):
        puzzlecal.calibrate_rig([observations[0], observations[1][:-1]],
                                board, models="pinhole-radtan",
                                image_sizes=(640, 480))
    with pytest.raises(ValueError, match="image_sizes"):
        puzzlecal.calibrate_rig(observations, board, models="pinhole-radtan")
    with pytest.raises(ValueError, match="3 sizes for 2 cameras"):
        puzzlecal.calibrate_rig(observations, board, models="pinhole-radtan",
                                image_sizes=[(640, 480)] * 3)
    ids, corners = observations[1][0]
    bad = [observations[0], [(ids.astype(float), corners)]
           + observations[1][1:]]
    with pytest.raises(ValueError, match=r"observations\[1\]\[0\] ids: "
                                         "expected an N x 2 integer array"):
        puzzlecal.calibrate_rig(bad, board, models="pinhole-radtan",
                                image_sizes=(640, 480))
    bad[1][0] = (ids, np.zeros((len(ids), 3)))
    with pytest.raises(ValueError, match=r"corners: expected shape \(N, 2\), "
                                         r"got \(\d+, 3\)"):
        puzzlecal.calibrate_rig(bad, board, models="pinhole-radtan",
                                image_sizes=(640, 480))
    # Options by keyword reach the rig: the pair shares 16 frames.
    options = puzzlecal.options(rig={"min_shared_frames": 17})
    with pytest.raises(ValueError, match="camera 'cam1' shares no frame "
                                         "with any other camera"):
        puzzlecal.calibrate_rig(str(images), board, models="pinhole-radtan",
                                options=options)
    with pytest.raises(ValueError, match="unknown format 'yaml'"):
        puzzlecal.calibrate_rig(str(images), board, models="pinhole-radtan",
                                format="yaml")


def test_the_rig_example_runs(rendered, tmp_path):
    root, _, board_file = rendered
    example = (pathlib.Path(__file__).resolve().parents[2] / "examples" /
               "python" / "calibrate_rig.py")
    out = tmp_path / "rig.yaml"
    run = subprocess.run([sys.executable, str(example), str(root / "images"),
                          str(board_file), str(out), "pinhole-radtan"],
                         check=True, capture_output=True, text=True)
    assert "cam1: pinhole-radtan" in run.stdout
    assert "baseline 120.0" in run.stdout  # the render's 120.08 mm
    assert "rig: verdict: good" in run.stdout
    assert out.exists()


def test_same_focal_length_ties_every_camera(rendered):
    """One focal length per camera through the options, as --same-focal."""
    root, truth, _ = rendered
    board = truth["board"]
    result = puzzlecal.calibrate_rig(
        detections_as_observations(root, board), board,
        models=["pinhole-radtan"] * 2, image_sizes=(640, 480),
        options=puzzlecal.options(calibration={"same_focal_length": True}))
    for camera, true in zip(result.cameras, truth["cameras"]):
        params, sigma = camera.params_by_name, camera.stddev_by_name
        assert params["fx"] == params["fy"]
        assert sigma["fx"] == sigma["fy"] > 0
        assert params["fx"] == pytest.approx(true["camera"].params[0],
                                             rel=MAX_FOCAL_RELATIVE_ERROR)
