#!/usr/bin/env python3
"""The library and the program configure and build with only what they link.

    build_without_tests.py --source DIR --workdir DIR --cmake CMAKE --generator NAME
        --make-program PROGRAM --fortran FC --c CC [--prefix-path PATH]

Configures the source tree with -DFRICTION_BUILD_TESTS=OFF in a scratch
build directory, with a PATH of symbolic links to every program of the
system's PATH except the test tools (ngspice, gnuplot, h5dump), builds it,
and checks: the build succeeds; `friction --version` runs; and the CMake
cache has no entry for a test tool (ngspice, gnuplot, h5dump, pFUnit,
Python), i.e. configuration did not even look for one.  It also builds the
program with -DFRICTION_STATIC_HDF5=OFF, the other way of linking it, and
checks that this program does load the shared HDF5 (`ldd`).  It compiles
the library once (about 20 s on two cores: label `slow`).
"""
import argparse
import os
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from helpers import fail, require  # noqa: E402

TEST_TOOLS = ("ngspice", "gnuplot", "h5dump")
# Cache entries a configuration that looked for a test tool leaves behind.
TEST_CACHE_ENTRIES = ("FRICTION_NGSPICE_EXECUTABLE", "FRICTION_GNUPLOT_EXECUTABLE", "FRICTION_H5DUMP_EXECUTABLE",
                      "PFUNIT_DIR", "Python3_EXECUTABLE")


def restricted_path(workdir):
    """A directory of links to the programs of PATH, the test tools left out."""
    bin_dir = os.path.join(workdir, "bin")
    os.makedirs(bin_dir)
    for directory in os.environ.get("PATH", "").split(os.pathsep):
        if not os.path.isdir(directory):
            continue
        for name in sorted(os.listdir(directory)):
            target = os.path.join(directory, name)
            link = os.path.join(bin_dir, name)
            if name.startswith(TEST_TOOLS) or os.path.lexists(link):
                continue
            if os.path.isfile(target) and os.access(target, os.X_OK):
                os.symlink(target, link)
    return bin_dir


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    for option in ("--source", "--workdir", "--cmake", "--generator", "--make-program", "--fortran", "--c"):
        parser.add_argument(option, required=True)
    args = parser.parse_args()
    shutil.rmtree(args.workdir, ignore_errors=True)
    os.makedirs(args.workdir)
    env = dict(os.environ, PATH=restricted_path(args.workdir))
    for tool in TEST_TOOLS:
        require(shutil.which(tool, path=env["PATH"]) is None, f"{tool} is not on the build's PATH")
    build = os.path.join(args.workdir, "build")

    def step(command):
        result = subprocess.run(command, env=env, capture_output=True, text=True, timeout=1800)
        if result.returncode != 0:
            fail(f"{' '.join(command)} exited {result.returncode}\n{result.stdout[-4000:]}\n{result.stderr[-4000:]}")
        return result

    step([args.cmake, "-S", args.source, "-B", build, "-G", args.generator,
          f"-DCMAKE_MAKE_PROGRAM={args.make_program}", f"-DCMAKE_Fortran_COMPILER={args.fortran}",
          f"-DCMAKE_C_COMPILER={args.c}", "-DCMAKE_BUILD_TYPE=Release", "-DFRICTION_BUILD_TESTS=OFF",
          "-DFRICTION_STATIC_HDF5=OFF"])
    with open(os.path.join(build, "CMakeCache.txt")) as handle:
        cache = handle.read()
    for entry in TEST_CACHE_ENTRIES:
        require(f"\n{entry}:" not in cache, f"configuration did not look for {entry}")
    step([args.cmake, "--build", build, "-j", "2"])
    version = step([os.path.join(build, "friction"), "--version"]).stdout
    require(version.startswith("friction "), f"the program built without tests runs: {version.strip()}")
    libraries = step(["ldd", os.path.join(build, "friction")]).stdout
    require("libhdf5" in libraries, "with FRICTION_STATIC_HDF5=OFF the program loads the shared HDF5")
    print("1 passed, 0 failed")


if __name__ == "__main__":
    main()
