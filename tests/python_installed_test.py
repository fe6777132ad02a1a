#!/usr/bin/env python3
"""The Python package of `cmake --install` finds the installed library by itself.

    python_installed_test.py PREFIX VERSION

With neither FRICTION_LIBRARY nor LD_LIBRARY_PATH set and the working
directory outside the repository: PREFIX/share/friction/python on the path,
`import friction` loads PREFIX/lib*/libfriction.so.0 (recorded by the
install in friction/_installed.py); the installed scripts (which find the
package beside them) plot a map and fit a line.
"""
import os
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from helpers import fail, mpi_env, require  # noqa: E402

prefix, version = Path(sys.argv[1]).resolve(), sys.argv[2]
package_dir = prefix / "share" / "friction" / "python"
require((package_dir / "friction" / "_installed.py").is_file(), "the install wrote friction/_installed.py")
env = mpi_env({"PYTHONPATH": str(package_dir)})
code = ("import friction\n"
        "print(friction.__version__, friction.library_version(), friction.library_path(), friction.__file__)\n")
result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, cwd=os.getcwd())
if result.returncode != 0:
    fail(f"import friction from {package_dir}: {result.stderr}")
package_version, library_version, library, module = result.stdout.split()
require(package_version == version and library_version == version, f"versions {package_version}, {library_version}")
require(Path(library).resolve().parent.parent == prefix, f"the installed library is loaded: {library}")
require(Path(module).resolve().is_relative_to(package_dir), f"the installed package is imported: {module}")

scripts = prefix / "share" / "friction" / "scripts"
fit = subprocess.run([sys.executable, scripts / "fit_example.py", "--check"], capture_output=True, text=True,
                     env=mpi_env(), cwd=os.getcwd())
require(fit.returncode == 0 and "fitted 0.8013 eV" in fit.stdout, "the installed fit_example.py --check")
Path("small.nml").write_text("&scan nx = 16, ny = 4 /\n")
run = subprocess.run([prefix / "bin" / "friction", "-q", "-f", "-o", "installed.h5",
                      prefix / "share" / "friction" / "inputs" / "naf.nml", "small.nml"],
                     capture_output=True, text=True, env=mpi_env())
if run.returncode != 0:
    fail(f"the installed program: {run.stderr}")
plot = subprocess.run([sys.executable, scripts / "plot_afm.py", "installed.h5", "-o", "installed-plots"],
                      capture_output=True, text=True, env=mpi_env())
require(plot.returncode == 0 and (Path("installed-plots") / "installed_maps.png").is_file(),
        "the installed plot_afm.py " + plot.stderr)
print("PASS")
