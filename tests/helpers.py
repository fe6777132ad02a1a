"""What the Python tests share: the Open MPI environment, running a command
(the program, a script) and failing with its output, and the friction
package of this repository.

    sys.path.insert(0, str(Path(__file__).resolve().parent))   # tests/
    from helpers import fail, mpi_env, run, friction_package, file_contents

The standalone test programs (cli_test.py, capi_test.py, ...) report a
failure with fail(), which prints "FAILED: ..." and exits 1; pytest tests
(python/tests) use run() with expect=..., whose failure raises
TestFailure (an AssertionError) with the command's output.
"""
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
INPUTS = ROOT / "inputs"
SCRIPTS = ROOT / "scripts"
PACKAGE = ROOT / "python"

# Open MPI refuses to run as root (as in containers and CI) unless told it may.
MPI_ENV = {"OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1"}


class TestFailure(AssertionError):
    """A command that did not do what the test expected."""

    __test__ = False   # not a pytest test class


_exit_on_failure = True


def raise_on_failure():
    """From now on fail() raises TestFailure instead of exiting (for pytest)."""
    global _exit_on_failure
    _exit_on_failure = False


def fail(message):
    """The test failed: print "FAILED: message" and exit 1 (or raise TestFailure under pytest)."""
    if not _exit_on_failure:
        raise TestFailure(message)
    print("FAILED: " + message, flush=True)
    sys.exit(1)


def require(condition, message):
    """fail(message) unless condition; print "ok: message" when it holds."""
    if not condition:
        fail(message)
    print("ok: " + message)


def mpi_env(extra=None, base=None):
    """The environment for the program and mpiexec: `base` (default: this
    process's) with Open MPI allowed to run as root, and `extra` over it."""
    env = dict(os.environ if base is None else base)
    for name, value in MPI_ENV.items():
        env.setdefault(name, value)
    env.update(extra or {})
    return env


def run(command, cwd=None, expect=0, env=None, extra_env=None, timeout=600, echo=False):
    """Run a command (a list; Paths are fine) with mpi_env(extra_env, env) and
    return the CompletedProcess (text).  expect: the exit code required
    (None: any); otherwise fail() with the command, its code and output.
    echo: print the command and its output."""
    command = [str(c) for c in command]
    result = subprocess.run(command, cwd=cwd, capture_output=True, text=True, env=mpi_env(extra_env, env),
                            timeout=timeout)
    if echo:
        print("$ " + " ".join(command))
        print(result.stdout + result.stderr)
    if expect is not None and result.returncode != expect:
        fail(f"{' '.join(command)} exited {result.returncode}, expected {expect}\n"
             f"stdout: {result.stdout}\nstderr: {result.stderr}")
    return result


def friction_package(library=None):
    """The repository's friction package (python/friction), imported; with
    `library`, the libfriction it loads (FRICTION_LIBRARY)."""
    if library:
        os.environ["FRICTION_LIBRARY"] = str(library)
    if str(PACKAGE) not in sys.path:
        sys.path.insert(0, str(PACKAGE))
    import friction
    return friction


# Attributes that differ between two runs of the same input.
TIMINGS = {"wall_time", "compute_time", "check_compute_time", "created"}


def attribute_value(f, value):
    """An attribute's value, comparable between files: the object references
    of the dimension scales (DIMENSION_LIST, REFERENCE_LIST) become the
    paths they point to, which two files of the same results share."""
    import h5py
    import numpy as np

    def name(ref):
        return f[ref].name if ref else ""

    if isinstance(value, np.ndarray) and value.dtype.names:          # REFERENCE_LIST: (dataset, axis)
        return tuple((name(row[0]), int(row[1])) for row in value)
    if isinstance(value, np.ndarray) and value.dtype == object:      # DIMENSION_LIST: refs per axis
        flat = [tuple(name(r) for r in np.ravel(axis)) if isinstance(axis, np.ndarray)
                else name(axis) if isinstance(axis, h5py.Reference) else axis for axis in value.ravel()]
        if any(isinstance(x, tuple) for x in flat) or any(isinstance(v, h5py.Reference) for v in value.ravel()):
            return tuple(flat)
    return value


#: Datasets a file holds as an axis for netCDF readers, not as a result: the
#: events' numbers 1 to n (a computation in memory has no such array).
AXES_ONLY = {"events/event"}


def group_datasets(path, group):
    """The results under a group of an HDF5 file, by name relative to it
    ("x", "events/t"), without the AXES_ONLY datasets: what a computation in
    memory (the C API's friction_compute, Config.compute) returns."""
    import h5py

    found = {}
    with h5py.File(path, "r") as f:
        f[group].visititems(lambda name, item: found.__setitem__(name, item[()])
                            if isinstance(item, h5py.Dataset) and name not in AXES_ONLY else None)
    return found


def file_contents(path, ignore=TIMINGS):
    """Every dataset and attribute of an HDF5 file by name ("group/name",
    "group/name@attribute"), but the attributes in `ignore` (the timings):
    two files that hold the same results compare equal as dicts of arrays."""
    import h5py

    contents = {}

    def visit(name, item):
        if isinstance(item, h5py.Dataset):
            contents[name] = item[()]
        for key, value in item.attrs.items():
            if key not in ignore:
                contents[f"{name}@{key}"] = attribute_value(f, value)

    with h5py.File(path, "r") as f:
        for key, value in f.attrs.items():
            if key not in ignore:
                contents[f"/@{key}"] = value
        f.visititems(visit)
    return contents
