"""Finding libfriction: FRICTION_LIBRARY, the installation, a build tree, the
system's loader; a clear error that lists where it looked."""
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

from conftest import ROOT

from friction import _capi, _version


def test_the_environment_variable_alone(tmp_path):
    lib = tmp_path / "libfriction.so.0"
    lib.write_bytes(b"")
    assert _capi.library_candidates({"FRICTION_LIBRARY": str(lib)}) == [("FRICTION_LIBRARY", str(lib))]
    assert _capi.find_library({"FRICTION_LIBRARY": str(lib)}) == str(lib)
    with pytest.raises(_capi.LibraryNotFoundError) as caught:
        _capi.find_library({"FRICTION_LIBRARY": str(tmp_path / "nothing.so")})
    assert f"FRICTION_LIBRARY: {tmp_path / 'nothing.so'}" in str(caught.value)


def test_a_build_tree_above_the_package(tmp_path):
    package = tmp_path / "checkout" / "python" / "friction"
    package.mkdir(parents=True)
    build = tmp_path / "checkout" / "build"
    build.mkdir()
    (build / "libfriction.so.0").write_bytes(b"")
    assert _capi.find_library({}, package) == str(build / "libfriction.so.0")
    # the repository's own package finds the repository's build
    where = [path for what, path in _capi.library_candidates({}) if what == "a build tree"]
    assert str(ROOT / "build" / "libfriction.so.0") in where


def test_the_installation_first(tmp_path):
    prefix = tmp_path / "prefix"
    package = prefix / "share" / "friction" / "python" / "friction"
    package.mkdir(parents=True)
    (prefix / "lib").mkdir()
    (prefix / "lib" / "libfriction.so.0").write_bytes(b"")
    (prefix / "build").mkdir()   # a build tree further up loses to the installation
    (prefix / "build" / "libfriction.so.0").write_bytes(b"")
    (package / "_installed.py").write_text('LIBRARY_RELATIVE = "../../../../lib/libfriction.so.0"\n'
                                           f'LIBRARY_ABSOLUTE = "{prefix}/lib/libfriction.so.0"\n')
    assert Path(_capi.find_library({}, package)).resolve() == prefix / "lib" / "libfriction.so.0"
    # a copy of the package elsewhere (pip install from the installation) finds it by the absolute path
    copy = tmp_path / "venv" / "site-packages" / "friction"
    copy.mkdir(parents=True)
    shutil.copy(package / "_installed.py", copy)
    assert _capi.find_library({}, copy) == f"{prefix}/lib/libfriction.so.0"


def test_import_needs_no_library_and_the_error_lists_every_place():
    # outside the repository, whose build/ the package would find by walking up
    with tempfile.TemporaryDirectory() as folder:
        check_the_error_lists_every_place(Path(folder).resolve())


def check_the_error_lists_every_place(tmp_path):
    copy = tmp_path / "somewhere" / "friction"
    shutil.copytree(ROOT / "python" / "friction", copy, ignore=shutil.ignore_patterns("__pycache__"))
    env = {k: v for k, v in os.environ.items() if k not in ("FRICTION_LIBRARY", "LD_LIBRARY_PATH")}
    env["PYTHONPATH"] = str(copy.parent)
    code = ("import friction\n"
            "print(friction.__version__)\n"
            "data = friction.load(%r)\n"
            "try:\n"
            "    friction.library_version()\n"
            "except friction.LibraryNotFoundError as err:\n"
            "    print(err)\n") % str(ROOT / "docs" / "work_precision.h5")
    result = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=env, capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    lines = result.stdout.splitlines()
    assert lines[0] == _version.__version__
    assert "libfriction not found; set FRICTION_LIBRARY" in result.stdout
    assert f"a build tree: {copy / 'build' / 'libfriction.so.0'}" in result.stdout
    assert f"a build tree: {tmp_path / 'somewhere' / 'build' / 'libfriction.so.0'}" in result.stdout
    assert "the system's loader: libfriction.so.0" in result.stdout


def test_the_loaded_library(friction, library):
    assert Path(friction.library_path()) == Path(library).resolve()


def test_the_old_module_name_still_works(friction, library):
    sys.path.insert(0, str(ROOT / "scripts"))
    try:
        import friction_capi
        import friction_output
    finally:
        sys.path.remove(str(ROOT / "scripts"))
    assert friction_capi.Config is _capi.Config and friction_capi.run_job is _capi.run_job
    assert friction_capi.version() == friction.__version__
    assert friction_capi.library is _capi.library()
    assert friction_output.InputError is friction.FileError
