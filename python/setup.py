"""The build step pyproject.toml cannot state: record in the wheel where the
library of the repository this package is installed from will be.

pip builds the package in its own folder (python/ of a clone), so the
repository's build/libfriction.so.0 is ../build/ from here.  The wheel
carries friction/_built.py with that absolute path, whether or not the
library is built yet, so `pip install ./python` before or after
scripts/build both work, and a rebuild needs no reinstall.  When the
package is not installed from a clone (no ../CMakeLists.txt beside it, as
for the copy cmake --install makes, which records its own library in
friction/_installed.py), nothing is recorded.  FRICTION_BUILD_DIR at install
time names another build directory.  The wheel also carries the project's
input files (../inputs, as friction/inputs: friction.input_file finds them).
"""
import os
import shutil
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

HERE = Path(__file__).resolve().parent
SONAME = "libfriction.so.0"


class BuildPyRecordingLibrary(build_py):
    def run(self):
        super().run()
        inputs = HERE.parent / "inputs"
        if inputs.is_dir():
            shutil.copytree(inputs, Path(self.build_lib) / "friction" / "inputs", dirs_exist_ok=True)
        build_dir = os.environ.get("FRICTION_BUILD_DIR")
        if build_dir:
            library = Path(build_dir).resolve() / SONAME
        elif (HERE.parent / "CMakeLists.txt").is_file():
            library = HERE.parent / "build" / SONAME
        else:
            return
        record = Path(self.build_lib) / "friction" / "_built.py"
        record.write_text(
            '"""Written by setup.py when the package was built: the library of the build it came from."""\n'
            f"LIBRARY = {str(library)!r}\n")


setup(cmdclass={"build_py": BuildPyRecordingLibrary})
