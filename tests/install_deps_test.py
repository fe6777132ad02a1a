#!/usr/bin/env python3
"""scripts/install-deps on a system without dpkg: it installs nothing, prints
what the build needs (the compilers, CMake, GSL, FFTW, an MPI with mpi_f08,
parallel HDF5, and what the tests add) and exits 1.

    install_deps_test.py --script scripts/install-deps --workdir DIR

The system is simulated by a PATH holding links to only the programs the
script runs before its dpkg check (bash, id, cat, env), so dpkg-query is
not found.
"""
import argparse
import os
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from helpers import fail, require  # noqa: E402

NEEDED = ["Fortran 2008 compiler", "C compiler", "CMake >= 3.20", "pkg-config", "GSL", "FFTW 3",
          "mpi_f08", "parallel HDF5", "pFUnit 4.14", "ngspice", "gnuplot", "h5dump", "h5py"]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--script", required=True)
    parser.add_argument("--workdir", required=True)
    args = parser.parse_args()
    shutil.rmtree(args.workdir, ignore_errors=True)
    bin_dir = os.path.join(args.workdir, "bin")
    os.makedirs(bin_dir)
    for tool in ("bash", "id", "cat", "env"):
        os.symlink(shutil.which(tool), os.path.join(bin_dir, tool))
    require(shutil.which("dpkg-query", path=bin_dir) is None, "dpkg-query is not on the script's PATH")
    result = subprocess.run([os.path.join(bin_dir, "bash"), args.script], env={"PATH": bin_dir},
                            capture_output=True, text=True, timeout=60)
    require(result.returncode == 1, f"install-deps exits 1 without dpkg (got {result.returncode})")
    for word in NEEDED:
        if word not in result.stderr:
            fail(f"the list of what is needed lacks {word!r}:\n{result.stderr}")
    require("nothing installed" in result.stderr, "it says it installed nothing")
    print("1 passed, 0 failed")


if __name__ == "__main__":
    main()
