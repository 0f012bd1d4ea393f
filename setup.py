"""pip install of the Python package `puzzlecal`, offline, with Debian's
setuptools and pybind11 (no download):

    python3 -m venv --system-site-packages .venv
    .venv/bin/pip install --no-build-isolation .

The module is built by the project's own CMake (the libraries it links,
Release, no tests or benchmarks) in build-python/, then packaged with
python/puzzlecal/*.py and the type stubs (*.pyi, py.typed)."""

import os
import pathlib
import shutil
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = pathlib.Path(__file__).resolve().parent


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        build_dir = ROOT / "build-python"
        configure = [
            "cmake", "-S", str(ROOT), "-B", str(build_dir),
            "-DCMAKE_BUILD_TYPE=Release", "-DPUZZLECAL_BUILD_TESTS=OFF",
            "-DPUZZLECAL_BUILD_BENCH=OFF", "-DPUZZLECAL_BUILD_PYTHON=ON",
            f"-DPython3_EXECUTABLE={sys.executable}",
        ]
        if shutil.which("ninja"):
            configure += ["-G", "Ninja"]
        subprocess.run(configure, check=True)
        subprocess.run(["cmake", "--build", str(build_dir), "--target",
                        "_puzzlecal", "--parallel", str(os.cpu_count() or 1)],
                       check=True)
        built = next((build_dir / "python" / "puzzlecal").glob("_puzzlecal*.so"))
        target = pathlib.Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(built, target)


setup(
    name="puzzlecal",
    version="0.1.0",
    description="Camera calibration from photos of a PuzzleBoard or a "
                "checkerboard",
    packages=["puzzlecal"],
    package_dir={"puzzlecal": "python/puzzlecal"},
    package_data={"puzzlecal": ["*.pyi", "py.typed"]},
    ext_modules=[Extension("puzzlecal._puzzlecal", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    python_requires=">=3.9",
    install_requires=["numpy"],
)
