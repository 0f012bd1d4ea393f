import numpy as np
import pytest

import puzzlecal
from conftest import BOARD_FILE, SAMPLE, truth_view


@pytest.fixture(scope="module")
def board():
    return puzzlecal.Board.load(str(BOARD_FILE))


def match_truth(detection, ids, corners):
    """Largest distance (px) of detected corners from their true position,
    and how many of the detected ids the truth holds."""
    truth = {tuple(i): c for i, c in zip(ids, corners)}
    errors = [np.linalg.norm(c - truth[tuple(i)])
              for i, c in zip(detection.ids, detection.corners)
              if tuple(i) in truth]
    return max(errors), len(errors)


def test_detect_an_array_against_the_truth(board, truth):
    # Every projectable corner: the detector may find one the truth marks
    # covered (an occluder's edge) or just outside the image.
    path, _, _, ids, corners = truth_view(truth, 0, hidden=True)
    image = puzzlecal.load_image(str(path))
    assert image.dtype == np.uint8 and image.shape == (600, 800)
    detection = puzzlecal.detect(image, board)
    assert detection.usable and detection.decoded
    assert detection.outcome == "usable"
    assert detection.ids.shape == detection.corners.shape
    assert len(detection.ids) >= 44
    worst, matched = match_truth(detection, ids, corners)
    assert matched == len(detection.ids)  # every id is a true one
    assert worst < 0.5  # the worst of 350, near an occluder or the border
    assert detection.all_corners.shape[0] >= len(detection.ids)


def test_colour_and_16_bit_arrays_give_the_same_corners(board, truth):
    path = truth_view(truth, 1)[0]
    grey = puzzlecal.load_image(str(path))
    reference = puzzlecal.detect(grey, board)
    bgr = np.ascontiguousarray(np.stack([grey] * 3, axis=-1))
    bgra = np.ascontiguousarray(np.dstack([bgr, np.full_like(grey, 255)]))
    for image in (bgr, bgra):
        detection = puzzlecal.detect(image, board)
        np.testing.assert_array_equal(detection.ids, reference.ids)
        np.testing.assert_allclose(detection.corners, reference.corners,
                                   atol=1e-9)
    # 16-bit images are scaled by their own maximum, as the program reads
    # 16-bit files: the same as the 8-bit image stretched to full scale.
    wide = grey.astype(np.uint16) * 257
    stretched = np.round(grey * (255.0 / grey.max())).astype(np.uint8)
    expected = puzzlecal.detect(stretched, board)
    detection = puzzlecal.detect(wide, board)
    np.testing.assert_array_equal(detection.ids, expected.ids)
    np.testing.assert_allclose(detection.corners, expected.corners, atol=1e-9)


def test_wrong_images_are_refused_with_a_reason(board):
    with pytest.raises(ValueError, match="dtype int32"):
        puzzlecal.detect(np.zeros((10, 10), dtype=np.int32), board)
    with pytest.raises(ValueError, match=r"shape \(10, 10, 2\)"):
        puzzlecal.detect(np.zeros((10, 10, 2), dtype=np.uint8), board)
    with pytest.raises(ValueError, match="numpy array"):
        puzzlecal.detect([[0, 1], [1, 0]], board)
    with pytest.raises(ValueError, match="missing.png"):
        puzzlecal.load_image(str(SAMPLE / "missing.png"))


def test_without_a_board_labels_are_relative(truth):
    image = puzzlecal.load_image(str(truth_view(truth, 0)[0]))
    detection = puzzlecal.detect(image)
    assert not detection.decoded
    assert len(detection.ids) == 0
    assert detection.num_components >= 1
    assert len(detection.all_corners) >= 44


def test_files_in_parallel_equal_one_by_one(board):
    files = puzzlecal.list_images(str(SAMPLE))
    assert len(files) == 16
    one = puzzlecal.detect_files(files, board, threads=1)
    three = puzzlecal.detect_files(files + [str(SAMPLE / "truth.yaml")],
                                   board, threads=3)
    assert three[-1].outcome == "unreadable" and "truth.yaml" in three[-1].reason
    for a, b in zip(one, three):
        assert a.file == b.file and a.outcome == b.outcome
        np.testing.assert_array_equal(a.ids, b.ids)
        np.testing.assert_array_equal(a.corners, b.corners)
    assert sum(d.usable for d in one) >= 14
