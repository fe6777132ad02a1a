#!/usr/bin/env bash
# `pip install` of the Python package from a clone into a fresh virtual
# environment; the installed package then works from any folder with no
# environment variable.
#
#   python_install_test.sh PYTHON PACKAGE_DIR WORK LIBRARY VERSION
#
# Offline: the environment sees the system's site-packages (numpy, h5py,
# matplotlib, setuptools) and pip neither fetches a build backend
# (--no-build-isolation) nor dependencies (--no-deps), nor asks an index
# (--no-index).  pip builds in the source folder (build/, *.egg-info), so it
# installs from a clone made of a copy of PACKAGE_DIR as WORK/clone/python,
# the repository's CMakeLists.txt beside it, and WORK/clone/build a link to
# the build directory of LIBRARY: the layout of a clone after scripts/build.
# Then, from WORK/elsewhere, with FRICTION_LIBRARY, PYTHONPATH and
# LD_LIBRARY_PATH unset: `import friction` prints VERSION, the module is the
# environment's copy, the library loaded is the clone's build (recorded in
# the wheel by setup.py), a line runs through the C API, and the console
# command friction-plot-afm plots a map.
set -euo pipefail
python=$1 package=$2 work=$3 library=$4 version=$5

rm -rf "$work"
mkdir -p "$work/clone" "$work/elsewhere"
cp -r "$package" "$work/clone/python"
rm -rf "$work/clone/python/build" "$work/clone/python/"*.egg-info "$work/clone/python/tests"
cp "$package/../CMakeLists.txt" "$work/clone/CMakeLists.txt"
ln -s "$(cd "$(dirname "$library")" && pwd)" "$work/clone/build"
"$python" -m venv --system-site-packages "$work/venv"
venv_python=$work/venv/bin/python
# Offline, setuptools builds the wheel itself from 70.1 on, with the wheel package before.
if ! "$venv_python" -c "
import setuptools, sys
major, minor = (int(p) for p in setuptools.__version__.split('.')[:2])
sys.exit(0 if (major, minor) >= (70, 1) else __import__('importlib').util.find_spec('wheel') is None)"; then
  echo "FAILED: setuptools $("$venv_python" -c 'import setuptools; print(setuptools.__version__)') without the" \
       "wheel package cannot build offline: run scripts/install-deps (python3 -m pip install wheel)" >&2
  exit 1
fi
"$venv_python" -m pip install --quiet --no-input --no-index --no-deps --no-build-isolation "$work/clone/python"

cd "$work/elsewhere"
unset FRICTION_LIBRARY PYTHONPATH LD_LIBRARY_PATH
printed=$("$venv_python" -c "import friction; print(friction.__version__)")
echo "import friction; print(friction.__version__): $printed"
if [[ $printed != "$version" ]]; then
  echo "FAILED: the installed package says '$printed', the project's version is $version" >&2
  exit 1
fi
"$venv_python" - "$work/venv" "$version" "$work/clone/build" <<'PY'
import sys
from pathlib import Path

import friction

venv, version, build = Path(sys.argv[1]).resolve(), sys.argv[2], Path(sys.argv[3])
where = Path(friction.__file__).resolve()
assert venv in where.parents, f"imported {where}, not the environment's copy under {venv}"
assert friction.library_version() == version, friction.library_version()
loaded = Path(friction.library_path())
assert loaded.resolve().parent == build.resolve(), f"loaded {loaded}, not the library of the clone's build {build}"
x, fx, fy = friction.afm_line(values={"scan.nx": 32})
assert x.size == fx.size == 32 and abs(fx).max() > 0.1
print(f"ok: friction {friction.__version__} from {where.parent}, library {loaded}, "
      f"a NaF line of {x.size} samples, max |Fx| = {abs(fx).max():.3f} nN")
PY
# The console command: a small map through the package's job (Open MPI, which
# the library may start, refuses root without these), then its picture.
OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 "$venv_python" -c "
import friction
friction.Config('afm', values={'scan.nx': 16, 'scan.ny': 4}).run('small.h5', force=True, progress=False)"
"$work/venv/bin/friction-plot-afm" small.h5 -o plots
test -s plots/small_maps.png
"$work/venv/bin/friction-plot-afm" --help | grep -q "usage: friction-plot-afm"
echo "ok: friction-plot-afm drew plots/small_maps.png"
