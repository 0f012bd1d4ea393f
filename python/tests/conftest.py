"""Shared truth for the Python package's tests: the bundled sample set
(testdata/sample: renders with exact corners, ids and intrinsics in
truth.yaml) and the program itself (PUZZLECAL_PROGRAM) for cross-checks."""

import os
import pathlib

import numpy as np
import pytest
import yaml

ROOT = pathlib.Path(__file__).resolve().parents[2]
SAMPLE = ROOT / "testdata" / "sample"
BOARD_FILE = ROOT / "configs" / "boards" / "puzzleboard_23x16_30mm.yaml"


@pytest.fixture(scope="session")
def truth():
    with open(SAMPLE / "truth.yaml", encoding="utf-8") as f:
        return yaml.safe_load(f)


def truth_view(truth, index, hidden=False):
    """(file, R, t, ids N x 2, corners N x 2) of a view's visible corners
    (with `hidden`, also those covered or outside the image that project)."""
    view = truth["views"][index]
    rows = np.array(view["corners"], dtype=float)
    visible = np.isfinite(rows[:, 0]) & ((rows[:, 4] == 1) | hidden)
    rows = rows[visible]
    R = np.array(view["cam_from_board"]["rotation"]).reshape(3, 3)
    t = np.array(view["cam_from_board"]["translation"])
    return (SAMPLE / view["file"], R, t, rows[:, 2:4].astype(int),
            rows[:, 0:2])


@pytest.fixture(scope="session")
def program():
    path = os.environ.get("PUZZLECAL_PROGRAM")
    if not path:
        candidate = ROOT / "build" / "apps" / "puzzlecal"
        path = str(candidate) if candidate.exists() else None
    if not path:
        pytest.fail("PUZZLECAL_PROGRAM is not set and build/apps/puzzlecal "
                    "does not exist")
    return path
