#!/usr/bin/env bash
# `pip install` of the Python package into a fresh virtual environment.
#
#   python_install_test.sh PYTHON PACKAGE_DIR WORK LIBRARY VERSION
#
# Offline: the environment sees the system's site-packages (numpy, h5py,
# matplotlib, setuptools) and pip neither fetches a build backend
# (--no-build-isolation) nor dependencies (--no-deps), nor asks an index
# (--no-index).  pip builds in the source folder (build/, *.egg-info), so it
# installs from a copy of PACKAGE_DIR.  Then, from outside the repository:
# `import friction` prints VERSION, the module is the environment's copy,
# and with FRICTION_LIBRARY=LIBRARY it runs a line through the C API.
set -euo pipefail
python=$1 package=$2 work=$3 library=$4 version=$5

rm -rf "$work"
mkdir -p "$work"
cp -r "$package" "$work/source"
rm -rf "$work/source/build" "$work/source/"*.egg-info "$work/source/tests"
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
"$venv_python" -m pip install --quiet --no-input --no-index --no-deps --no-build-isolation "$work/source"

cd "$work"
unset FRICTION_LIBRARY PYTHONPATH
printed=$("$venv_python" -c "import friction; print(friction.__version__)")
echo "import friction; print(friction.__version__): $printed"
if [[ $printed != "$version" ]]; then
  echo "FAILED: the installed package says '$printed', the project's version is $version" >&2
  exit 1
fi
FRICTION_LIBRARY=$library "$venv_python" - "$work/venv" "$version" <<'PY'
import sys
from pathlib import Path

import friction

venv, version = Path(sys.argv[1]).resolve(), sys.argv[2]
where = Path(friction.__file__).resolve()
assert venv in where.parents, f"imported {where}, not the environment's copy under {venv}"
assert friction.library_version() == version, friction.library_version()
x, fx, fy = friction.afm_line(values={"scan.nx": 32})
assert x.size == fx.size == 32 and abs(fx).max() > 0.1
print(f"ok: friction {friction.__version__} from {where.parent}, library {friction.library_path()}, "
      f"a NaF line of {x.size} samples, max |Fx| = {abs(fx).max():.3f} nN")
PY
