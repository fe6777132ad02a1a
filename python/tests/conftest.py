"""Fixtures of the package's tests: the program, the library, and the files
the program writes for them (once per session, in a temporary folder).

Run from the repository (CTest's python-package test does):
    FRICTION_LIBRARY=build/libfriction.so.0 python3 -m pytest python/tests -q
FRICTION_PROGRAM names the program (default: build/friction).
"""
import os
import sys
from pathlib import Path

import pytest

TESTS = Path(__file__).resolve().parent
ROOT = TESTS.parent.parent
sys.path.insert(0, str(ROOT / "tests"))   # helpers.py, check_png.py
sys.path.insert(0, str(ROOT / "python"))  # the package under test, before any installed copy

import helpers  # noqa: E402

helpers.raise_on_failure()
# friction.run initialises MPI in this process: Open MPI must be allowed to run as root here too.
for _name, _value in helpers.MPI_ENV.items():
    os.environ.setdefault(_name, _value)

INPUTS = ROOT / "inputs"
DATA = ROOT / "tests" / "data"


def interrupted(caught):
    """The call's FrictionError (status 5, stopped on request) behind the
    exception (KeyboardInterrupt) raised after it."""
    context = caught.value.__context__
    assert isinstance(context, Exception) and getattr(context, "status", None) == 5, repr(context)
    return context


def sigint_at_report(number):
    """(reports, progress): a progress callback that keeps its (message,
    fraction) reports and sends this process SIGINT at report `number`, as
    Ctrl-C would during a job or computation."""
    import signal
    reports = []

    def progress(message, fraction):
        reports.append((message, fraction))
        if len(reports) == number:
            signal.raise_signal(signal.SIGINT)

    return reports, progress


@pytest.fixture(scope="session")
def stop_program():
    """The test build of the program that stops a job on cue (FRICTION_TEST_STOP_AFTER)."""
    path = Path(os.environ.get("FRICTION_STOP_PROGRAM", ROOT / "build" / "tests" / "friction_stop_after"))
    if not path.is_file():
        pytest.fail(f"no program at {path}: build the tests first (scripts/test) or set FRICTION_STOP_PROGRAM")
    return path


@pytest.fixture(scope="session")
def program():
    path = Path(os.environ.get("FRICTION_PROGRAM", ROOT / "build" / "friction"))
    if not path.is_file():
        pytest.fail(f"no program at {path}: build first (scripts/build) or set FRICTION_PROGRAM")
    return path


@pytest.fixture(scope="session")
def library():
    path = Path(os.environ.get("FRICTION_LIBRARY", ROOT / "build" / "libfriction.so.0"))
    if not path.is_file():
        pytest.fail(f"no library at {path}: build first (scripts/build) or set FRICTION_LIBRARY")
    os.environ["FRICTION_LIBRARY"] = str(path)
    return path


@pytest.fixture(scope="session")
def friction(library):
    import friction as package
    return package


@pytest.fixture(scope="session")
def files(tmp_path_factory, program):
    """Writes the program's output for one input (files + overrides) once: files(name, [paths], text)."""
    folder = tmp_path_factory.mktemp("program")
    made = {}

    def make(name, inputs, override=""):
        if name not in made:
            paths = [str(p) for p in inputs]
            if override:
                extra = folder / f"{name}_override.nml"
                extra.write_text(override)
                paths.append(str(extra))
            out = folder / f"{name}.h5"
            helpers.run([program, "--quiet", "--force", "-o", out, *paths], cwd=folder)
            made[name] = out
        return made[name]
    return make


@pytest.fixture(scope="session")
def naf_map(files):
    """A NaF map, 10 lines of 40 samples, trace and retrace (tests/data/small.nml)."""
    return files("naf_small", [INPUTS / "naf.nml", DATA / "small.nml"])


@pytest.fixture(scope="session")
def brake_run(files):
    """The paper's brake over tau in [0, 300], with its diagnostics (tests/data/brake_short.nml)."""
    return files("brake_short", [INPUTS / "brake.nml", DATA / "brake_short.nml"])


@pytest.fixture(scope="session")
def brake_sweep(files):
    """A brake sweep of 6 points over v'_dr (tests/data/sweep_small.nml)."""
    return files("sweep_small", [INPUTS / "brake_sweep.nml", DATA / "sweep_small.nml"])


@pytest.fixture(scope="session")
def brake_atlas(files):
    """A brake sweep over a 3 x 4 grid of mu and a log-spaced (negative) v'_dr."""
    return files("brake_atlas_small", [INPUTS / "brake_sweep.nml", DATA / "sweep_small.nml"],
                 "&sweep sweep_variable = 'brake.mu', sweep_spacing = 'linear', sweep_from = 0.3, sweep_to = 0.5,"
                 " sweep_count = 3, sweep_variable2 = 'brake.v_dr_prime', sweep_spacing2 = 'log',"
                 " sweep_from2 = -0.004, sweep_to2 = -0.0005, sweep_count2 = 4 /\n")


@pytest.fixture(scope="session")
def afm_sweep(files):
    """An AFM sweep over a 5 x 2 grid of V0 and the velocity (tests/data/afm_sweep_small.nml)."""
    return files("afm_sweep_small", [INPUTS / "afm_sweep.nml", DATA / "afm_sweep_small.nml"])


@pytest.fixture(scope="session")
def machine_sweep(files):
    """A machine sweep of 4 belt velocities, the Stribeck law with orbits (tests/data/machine_sweep_small.nml)."""
    return files("machine_sweep_small", [INPUTS / "machine_stribeck_orbit.nml", DATA / "machine_sweep_small.nml"])


@pytest.fixture(scope="session")
def graphite_map(files):
    """A tiny graphite map under a Lennard-Jones tip, with its net (tests/data/graphite_small.nml)."""
    return files("graphite_small", [INPUTS / "graphite.nml", DATA / "graphite_small.nml"])
