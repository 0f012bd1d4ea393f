import numpy as np
import pytest

import puzzlecal
from conftest import BOARD_FILE


def test_load_board_file():
    board = puzzlecal.Board.load(str(BOARD_FILE))
    assert board.type == "puzzleboard"
    assert (board.cols, board.rows) == (23, 16)
    assert board.origin == (50, 100)
    assert board.tile_size_m == pytest.approx(0.03)
    assert board.num_corners == 23 * 16


def test_missing_board_file_names_the_file(tmp_path):
    path = tmp_path / "missing.yaml"
    with pytest.raises(ValueError, match="missing.yaml"):
        puzzlecal.Board.load(str(path))


def test_wrong_board_file_names_the_field(tmp_path):
    path = tmp_path / "board.yaml"
    path.write_text("type: puzzleboard\ncols: 1\nrows: 8\ntile_size_m: 0.02\n")
    with pytest.raises(ValueError, match="cols"):
        puzzlecal.Board.load(str(path))


def test_made_boards_and_their_points():
    board = puzzlecal.Board.puzzleboard(5, 4, 0.02, origin=(10, 20))
    ids = board.ids()
    assert ids.shape == (20, 2) and ids.dtype.kind == "i"
    assert tuple(ids[0]) == (10, 20) and tuple(ids[-1]) == (14, 23)
    points = board.points(ids)
    assert points.shape == (20, 3)
    np.testing.assert_allclose(points[:, :2], ids * 0.02)
    np.testing.assert_array_equal(points[:, 2], 0)
    checker = puzzlecal.Board.checkerboard(11, 8, 0.025)
    assert checker.type == "checkerboard" and checker.origin == (0, 0)
    with pytest.raises(ValueError, match="cols and rows"):
        puzzlecal.Board.puzzleboard(1, 4, 0.02)
    with pytest.raises(ValueError, match="origin"):
        puzzlecal.Board.puzzleboard(5, 4, 0.02, origin=(600, 0))
    with pytest.raises(ValueError, match="integer"):
        board.points(np.zeros((3, 2), dtype=float))
    with pytest.raises(ValueError, match=r"shape \(N, 2\)"):
        board.points(np.zeros((3, 3), dtype=int))


def test_rendered_page_has_the_printed_size():
    board = puzzlecal.Board.puzzleboard(5, 4, 0.02)
    page = board.render(dpi=254)  # 10 pixels per millimetre
    assert page.dtype == np.uint8
    # A PuzzleBoard page is cols x rows tiles: 100 mm x 80 mm.
    assert page.shape == (800, 1000)
    assert page.min() < 50 and page.max() > 200
    checker = puzzlecal.Board.checkerboard(5, 4, 0.02).render(dpi=254)
    # A checkerboard page has a whole tile of border: (cols + 1) x (rows + 1).
    assert checker.shape == (1000, 1200)
