"""The type stubs (puzzlecal/__init__.pyi) name every public function and
class the package exports, and every public member of those classes, so
that they cannot fall behind the module; help() on the calibrations says
what they take and give."""

import ast
import inspect
import pathlib
import pydoc

import puzzlecal

STUB = pathlib.Path(puzzlecal.__file__).with_name("__init__.pyi")


def stub_names():
    """Top-level names of the stub, and per class its members."""
    tree = ast.parse(STUB.read_text(encoding="utf-8"))
    names, members = set(), {}
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, ast.AnnAssign):
            names.add(node.target.id)
        if isinstance(node, ast.ClassDef):
            members[node.name] = {n.name for n in node.body
                                  if isinstance(n, ast.FunctionDef)}
    return names, members


def public_members(cls):
    return {name for name in vars(cls) if not name.startswith("_")}


def test_the_stub_is_installed_with_the_package():
    assert STUB.exists()
    assert STUB.with_name("py.typed").exists()


def test_the_stub_names_every_export():
    names, members = stub_names()
    exported = set(puzzlecal.__all__)
    compiled = {name for name in vars(puzzlecal._puzzlecal)
                if not name.startswith("_")}
    assert compiled <= exported, "exported by _puzzlecal, not by puzzlecal"
    assert exported - names == set(), "missing from __init__.pyi"
    assert names - exported == set(), "in __init__.pyi, not exported"
    for name in exported:
        assert hasattr(puzzlecal, name), name
        value = getattr(puzzlecal, name)
        if inspect.isclass(value):
            missing = public_members(value) - members[name]
            assert missing == set(), f"{name}: {sorted(missing)} not in stub"
            extra = members[name] - public_members(value) - {"__init__"}
            assert extra == set(), f"{name}: {sorted(extra)} only in stub"


def test_help_says_what_calibrations_take_and_give():
    text = pydoc.render_doc(puzzlecal.calibrate, renderer=pydoc.plaintext)
    for word in ("folder", "image_size", "model", "Calibration", "verdict"):
        assert word in text, word
    text = pydoc.render_doc(puzzlecal.calibrate_rig, renderer=pydoc.plaintext)
    for word in ("subfolder per camera", "match_by_order", "image_sizes",
                 "cam_from_rig", "RigVerdict", "ValueError"):
        assert word in text, word
    for cls in (puzzlecal.RigCalibration, puzzlecal.RigCamera):
        assert cls.__doc__
        text = pydoc.render_doc(cls, renderer=pydoc.plaintext)
        assert "cam_from_rig" in text or "rig_from_board" in text
