import numpy as np
import pytest

import puzzlecal

RADTAN = [820.0, 818.5, 642.3, 477.1, -0.28, 0.09, 6e-4, -4e-4, -0.012]
FISHEYE = [495.0, 494.2, 801.7, 598.4, 0.02, -0.005, 0.001, -0.0002]


def test_projection_of_a_plain_pinhole():
    camera = puzzlecal.Camera("pinhole-radtan", [500, 510, 320, 240] + [0] * 5,
                              640, 480)
    points = np.array([[0.1, -0.2, 2.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]])
    pixels = camera.project(points)
    np.testing.assert_allclose(pixels[0], [320 + 25, 240 - 51])
    np.testing.assert_allclose(pixels[1], [320, 240])
    assert np.isnan(pixels[2]).all()  # behind a pinhole camera


@pytest.mark.parametrize("model,params", [("pinhole-radtan", RADTAN),
                                          ("kannala-brandt", FISHEYE)])
def test_unproject_inverts_project(model, params):
    camera = puzzlecal.Camera(model, params, 1280, 960)
    rng = np.random.default_rng(1)
    directions = rng.normal(size=(50, 3)) * [0.3, 0.3, 0] + [0, 0, 1]
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    rays = camera.unproject(camera.project(directions * 3.0))
    np.testing.assert_allclose(rays, directions, atol=1e-7)


def test_noncentral_rays_start_off_the_origin():
    camera = puzzlecal.Camera("kannala-brandt-noncentral",
                              FISHEYE + [0.95e-3, 0.31e-3], 1600, 1200)
    assert not camera.central
    origins, directions = camera.unproject_rays(np.array([[1500.0, 600.0]]))
    assert origins[0, 2] != 0
    np.testing.assert_allclose(np.linalg.norm(directions, axis=1), 1)


@pytest.mark.parametrize("fmt", ["puzzlecal", "opencv", "ros", "kalibr"])
def test_every_format_reads_back(fmt, tmp_path):
    params = RADTAN[:8] + [0.0]  # kalibr's radtan has no k3
    camera = puzzlecal.Camera("pinhole-radtan", params, 1280, 960)
    path = tmp_path / f"{fmt}.yaml"
    camera.save(str(path), format=fmt)
    loaded = puzzlecal.Camera.load(str(path))
    assert loaded.model == "pinhole-radtan"
    assert (loaded.width, loaded.height) == (1280, 960)
    np.testing.assert_allclose(loaded.params, params, rtol=1e-12)


def test_undistortion_maps_follow_the_model():
    camera = puzzlecal.Camera("pinhole-radtan", RADTAN, 1280, 960)
    map_x, map_y, target = camera.undistort_maps(alpha=0.0)
    assert map_x.dtype == np.float32 and map_x.shape == (960, 1280)
    assert target.model == "pinhole-radtan" and not any(target.params[4:])
    fx, fy, cx, cy = target.params[:4]
    for u, v in [(100, 80), (640, 480), (1200, 900)]:
        ray = [(u - cx) / fx, (v - cy) / fy, 1.0]
        expected = camera.project(np.array([ray]))[0]
        np.testing.assert_allclose([map_x[v, u], map_y[v, u]], expected,
                                   atol=2e-3)


def test_bad_cameras_are_refused():
    with pytest.raises(ValueError, match="9 parameters, got 4"):
        puzzlecal.Camera("pinhole-radtan", [1, 2, 3, 4], 640, 480)
    with pytest.raises(ValueError, match="unknown model"):
        puzzlecal.Camera("pinhole", RADTAN, 640, 480)
    with pytest.raises(ValueError, match="unknown format"):
        puzzlecal.Camera("pinhole-radtan", RADTAN, 64, 48).save("x.yaml", "xml")
    with pytest.raises(ValueError, match=r"shape \(N, 3\)"):
        puzzlecal.Camera("pinhole-radtan", RADTAN, 64, 48).project(
            np.zeros((4, 2)))
