#!/usr/bin/env python3
"""A property-based fuzzing suite of the `friction` program (docs/reliability.md),
with Hypothesis.  It generates namelists (valid ones with
random physical values, and broken ones), XYZ nets with random defects, and
output faults, runs the program on each and asserts the contract:

  * the exit code is one of the documented ones, 0 2 3 4 5 6 (never a
    signal, never another code);
  * a failure says so in one clear message: exactly one line
    `friction: error: ...` (usage errors: one `friction: ...` line);
  * never a runtime abort: no "Fortran runtime error", "Error allocating",
    backtrace or signal report on stderr;
  * an existing file is never damaged: every file present before a run is
    byte for byte the same after it, except an output replaced on purpose
    (--force on a regular file);
  * nothing is left behind: no temporary files (*.tmp*), no output after a
    failure;
  * an output holds no non-finite value (none of these inputs asks for one),
    and its datasets have the shapes the input asks for.

    fuzz_test.py --binary BIN --mpiexec MPIEXEC --inputs DIR --workdir DIR CLASS [--examples N] [--long]

CLASS is one of the classes below, or `all`.  The ordinary suite runs each
class with its fixed budget and a derandomized (fixed) seed; --long (or
FRICTION_FUZZ_EXAMPLES=N) runs N examples per class with fresh random seeds:
scripts/fuzz.  A summary line per class gives the cases tried and the exit
codes seen.
"""
import argparse
import collections
import hashlib
import json
import math
import os
import shutil
import stat
import subprocess
import sys
import time

import h5py
import numpy as np
from hypothesis import HealthCheck, example, given, settings, strategies as st

ABORTS = ("Fortran runtime error", "Error allocating", "Backtrace", "Segmentation fault", "SIGSEGV",
          "infinite loop closing library",
          "Error termination", "Program received signal", "HDF5-DIAG")
DOCUMENTED = {0, 2, 3, 4, 5, 6}
# Every generated run is bounded: a stiff or slow random case ends with exit 4.
BOUNDS = "&integrator max_wall_time = 3.0, max_steps = 400000 /\n"
SINGLETON = {"OMPI_MCA_ess_singleton_isolated": "1"}


class Contract:
    """Runs the program in a fresh directory and checks the contract."""

    def __init__(self, args, name):
        self.args = args
        self.name = name
        self.count = 0
        self.codes = collections.Counter()
        self.seconds = 0.0

    def fresh(self):
        self.count += 1
        directory = os.path.join(self.args.workdir, f"{self.name}-{self.count}")
        unmount_if_mounted(os.path.join(directory, "small"))
        shutil.rmtree(directory, ignore_errors=True)
        os.makedirs(directory)
        return directory

    def run(self, directory, arguments, ranks=None, stdin=None, replaced=(), output=None, shapes=None,
            allowed=DOCUMENTED, timeout=120, env=None, binary=None):
        """Run `friction --quiet ARGUMENTS` in directory and check the
        contract; `replaced` may change (the output with --force), `output`
        is checked when the run succeeds; returns the completed process."""
        before = snapshot(directory)
        cmd = [binary or self.args.binary, "--quiet", *arguments]
        extra = dict(env or {})
        env = dict(os.environ)
        env.update(extra)
        if ranks is None:
            env.update(SINGLETON)
        else:
            cmd = [self.args.mpiexec, "-n", str(ranks), *[item for name in extra for item in ("-x", name)], *cmd]
        start = time.monotonic()
        try:
            result = subprocess.run(cmd, cwd=directory, capture_output=True, env=env, timeout=timeout,
                                    input=stdin)
        except subprocess.TimeoutExpired:
            raise AssertionError(f"{cmd}: no answer in {timeout} s (a hang)")
        self.seconds += time.monotonic() - start
        stderr = result.stderr.decode("utf-8", "replace")
        code = result.returncode
        self.codes[code] += 1
        where = f"{' '.join(cmd)} in {directory}:\n{stderr}"
        assert code >= 0, f"killed by signal {-code}: {where}"
        assert code in DOCUMENTED, f"exit {code}, not a documented code: {where}"
        assert code in allowed, f"exit {code}, expected one of {sorted(allowed)}: {where}"
        for word in ABORTS:
            assert word not in stderr, f"runtime abort ({word!r}): {where}"
        if code not in (0, 6):
            prefix = "friction:" if code == 2 else "friction: error:"
            lines = [line for line in stderr.splitlines() if line.startswith(prefix)]
            assert len(lines) == 1, f"expected one {prefix!r} message: {where}"
        after = snapshot(directory)
        for name, digest in before.items():
            if name in replaced and code == 0:
                continue
            assert after.get(name) == digest, f"existing file {name} was damaged or removed: {where}"
        left = [name for name in after if ".tmp" in name]
        assert not left, f"temporary files left: {left}: {where}"
        if output is not None:
            path = os.path.join(directory, output)
            if code == 0:
                check_output(path, shapes, where)
            elif output not in before:
                assert not os.path.exists(path), f"a failed run left its output {output}: {where}"
        return result

    def summary(self):
        codes = ", ".join(f"exit {code}: {n}" for code, n in sorted(self.codes.items()))
        return f"{self.name}: {self.count} cases, {codes}; {self.seconds:.1f} s in the program"


def snapshot(directory):
    """Digest of every regular file under directory (links and other kinds
    by what they are)."""
    found = {}
    for root, dirs, files in os.walk(directory):
        for name in files + dirs:
            full = os.path.join(root, name)
            relative = os.path.relpath(full, directory)
            mode = os.lstat(full).st_mode
            if stat.S_ISLNK(mode):
                found[relative] = "link:" + os.readlink(full)
            elif stat.S_ISREG(mode):
                with open(full, "rb") as handle:
                    found[relative] = hashlib.sha256(handle.read()).hexdigest()
            elif not stat.S_ISDIR(mode):
                found[relative] = f"kind:{stat.S_IFMT(mode)}"
    return found


def check_output(path, shapes, where):
    """Every number finite; the datasets the input asks for, with their shapes."""
    assert os.path.isfile(path), f"exit 0 but no output {path}: {where}"
    with h5py.File(path, "r") as handle:
        datasets = []
        handle.visititems(lambda name, item: datasets.append(name) if isinstance(item, h5py.Dataset) else None)
        assert datasets, f"no datasets in {path}: {where}"
        for name in datasets:
            data = handle[name][()]
            if np.issubdtype(np.asarray(data).dtype, np.floating):
                data = np.asarray(data)
                bad = ~np.isfinite(data) & ~stated_nonfinite(handle, name, data)
                assert not np.any(bad), f"/{name} has non-finite values the contract does not state: {where}"
            # Not absurd either: a lateral force of 1e6 nN is no friction force
            # (rtol = atol = 1e300 once gave 1e181 nN with exit 0).
            if name.startswith("afm/") and name.split("/")[-1] in ("fx", "fy", "fz", "f_along", "f_across"):
                assert np.all(np.abs(data) < 1e6), f"/{name} holds absurd forces (max {np.max(np.abs(data))}): {where}"
        for name, shape in (shapes or {}).items():
            assert name in handle, f"/{name} missing: {where}"
            assert handle[name].shape == shape, f"/{name} has shape {handle[name].shape}, not {shape}: {where}"


def stated_nonfinite(handle, name, data):
    """The non-finite values docs/reliability.md's contract states, as a mask
    of data: a standard error (*_sem) is NaN from one realization; a
    Lyapunov or Floquet exponent is -inf for the direction the stick
    collapses (a multiplier of 0); a continuation's period and largest
    modulus are NaN where no orbit was found (the machine's multipliers
    too), and the machine's equilibrium's growth where it has none, as a
    machine or brake sweep's orbit results are at its points without one."""
    leaf = name.split("/")[-1]
    if leaf.endswith("_sem") and "afm" in handle and int(handle["afm"].attrs.get("realizations", 2)) == 1:
        return np.isnan(data)
    if name.startswith(("brake/", "machine/")) and ("exponents" in leaf):
        return np.isneginf(data)
    if name.startswith("brake/orbit/branch/") and leaf in ("period", "max_modulus"):
        found = handle["brake/orbit/branch/found"][()].astype(bool)
        return np.isnan(data) & ~found
    if name.startswith("machine/orbit/branch/") and leaf in ("period", "max_modulus", "floquet_multipliers_real",
                                                           "floquet_multipliers_imag"):
        found = handle["machine/orbit/branch/found"][()].astype(bool)
        return np.isnan(data) & ~found.reshape((-1,) + (1,) * (data.ndim - 1))
    if name == "machine/orbit/branch/growth" and "machine/orbit/equilibrium" not in handle:
        # A machine on a moving support has no equilibrium: its growth is NaN at every point.
        return np.isnan(data)
    if name.startswith("sweep/orbit_") and leaf != "orbit_found" and handle.attrs.get("sweep_scene") in (
            b"machine", "machine", b"brake", "brake"):
        found = handle["sweep/orbit_found"][()].astype(bool)
        return np.isnan(data) & ~found
    return np.zeros(data.shape, bool)


def unmount_if_mounted(directory):
    if os.path.ismount(directory):
        subprocess.run(["umount", directory], capture_output=True)


def number(value):
    """A real as namelist text that reads back to the same double."""
    return repr(float(value))


def log_uniform(low, high):
    return st.floats(math.log10(low), math.log10(high)).map(lambda e: 10.0 ** e)


# ---- class 1: valid maps with random physical values ----

VALID_AFM = st.fixed_dictionaries({
    "potential": st.sampled_from(["naf", "hopg"]),
    "v0": st.floats(0.0, 2.0),
    "kx": st.floats(0.5, 50.0), "ky": st.floats(0.5, 50.0),
    "mass": log_uniform(1e-9, 1e-7),
    "cx": log_uniform(1e-4, 1e-2), "cy": log_uniform(1e-4, 1e-2),
    "velocity": log_uniform(10.0, 5000.0),
    "angle": st.floats(-90.0, 90.0), "length": st.floats(0.5, 20.0), "width": st.floats(0.0, 10.0),
    "lead_in": st.floats(0.0, 3.0),
    "nx": st.integers(2, 24), "ny": st.integers(1, 3), "retrace": st.booleans(),
    "model": st.sampled_from(["inertial", "overdamped", "quasistatic"]),
    "method": st.sampled_from(["auto", "rkf45", "rk8pd", "rkck", "msbdf", "rk4imp"]),
    "rtol": log_uniform(1e-8, 1e-2), "atol": log_uniform(1e-8, 1e-3),
})


def afm_text(p):
    return (f"&surface potential = '{p['potential']}', v0 = {number(p['v0'])} /\n"
            f"&tip model = '{p['model']}', mass = {number(p['mass'])}, kx = {number(p['kx'])}, "
            f"ky = {number(p['ky'])}, cx = {number(p['cx'])}, cy = {number(p['cy'])} /\n"
            f"&scan velocity = {number(p['velocity'])}, length = {number(p['length'])}, "
            f"width = {number(p['width'])}, angle = {number(p['angle'])}, lead_in = {number(p['lead_in'])},\n"
            f"  nx = {p['nx']}, ny = {p['ny']}, retrace = {'.true.' if p['retrace'] else '.false.'} /\n"
            f"&integrator method = '{p['method']}', rtol = {number(p['rtol'])}, atol = {number(p['atol'])},"
            f" max_wall_time = 3.0, max_steps = 400000 /\n")


def afm_shapes(p):
    shapes = {"afm/support_x": (p["nx"],), "afm/support_y": (p["ny"],), "afm/trace/fx": (p["ny"], p["nx"])}
    if p["retrace"]:
        shapes["afm/retrace/fx"] = (p["ny"], p["nx"])
        shapes["afm/friction"] = (p["ny"],)
    return shapes


def valid_afm(contract, p):
    directory = contract.fresh()
    with open(os.path.join(directory, "run.nml"), "w") as handle:
        handle.write(afm_text(p))
    contract.run(directory, ["-o", "out.h5", os.path.join(contract.args.inputs, f"{p['potential']}.nml"),
                             "run.nml"], output="out.h5", shapes=afm_shapes(p), allowed={0, 4})


# ---- class 2: valid brake runs ----

VALID_BRAKE = st.fixed_dictionaries({
    "model": st.sampled_from(["switched", "regularized"]),
    "mu": st.floats(0.05, 0.55), "mu_s": st.floats(0.56, 0.9),
    "v_dr_prime": st.floats(-0.01, 0.0),
    "t_end": st.floats(0.5, 60.0), "dt_out": st.floats(0.05, 1.0),
    "x0": st.floats(-0.01, 0.01), "w0": st.floats(-0.01, 0.01),
    "method": st.sampled_from(["auto", "rk8pd", "rkf45", "msbdf"]),
})


def valid_brake(contract, p):
    directory = contract.fresh()
    with open(os.path.join(directory, "run.nml"), "w") as handle:
        handle.write(f"&brake model = '{p['model']}', mu = {number(p['mu'])}, mu_s = {number(p['mu_s'])},"
                     f" v_dr_prime = {number(p['v_dr_prime'])}, t_start = 0.0, t_end = {number(p['t_end'])},"
                     f" dt_out = {number(p['dt_out'])}, x0 = {number(p['x0'])}, w0 = {number(p['w0'])} /\n"
                     "&analysis spectrum = .false., poincare = .false., lyapunov = .false., rosenstein = .false.,"
                     " lyapunov_spectrum = .false., orbit = .false. /\n"
                     f"&integrator method = '{p['method']}', max_wall_time = 3.0 /\n")
    contract.run(directory, ["-o", "out.h5", os.path.join(contract.args.inputs, "brake.nml"), "run.nml"],
                 output="out.h5", allowed={0, 4})


# ---- class 3: broken values ----

VARIABLES = [("tip", "mass", "r"), ("tip", "kx", "r"), ("tip", "cx", "r"), ("scan", "velocity", "r"),
             ("scan", "length", "r"), ("scan", "angle", "r"), ("scan", "nx", "i"), ("scan", "ny", "i"),
             ("surface", "v0", "r"), ("surface", "potential", "c"), ("integrator", "rtol", "r"),
             ("integrator", "atol", "r"), ("integrator", "method", "c"), ("integrator", "h_min", "r"),
             ("scan", "retrace", "l"), ("tip", "model", "c")]
# Values every variable of the kind must refuse (exit 3).
ALWAYS_BAD = {
    "r": ["abc", "'1.0'", ".true.", "1e400", "-1e400", "1e-400", "nan", "inf", "1.0.0", "--1", "1e", "0x10",
          "'unclosed", "1,2,3,4,5", "1.0d+999", "3*"],
    "i": ["abc", "1.5", "1e3", "2147483648", "99999999999999999999", "'4'", "-", "4 5", ".false."],
    "c": ["rkf45", "'nonesuch'", "'unclosed", "1.0", "'a' 'b'", "'\u00e9\udcff'"],
    "l": ["maybe", "1", "'t'", "yes"],
}
# Values that may or may not be valid for the variable: any documented
# outcome, but no abort and a finite output when it runs.
MAYBE = ["0", "-1", "-0.5", "1e30", "1e-30", "", "2", "1e-12", "4.9e-324", "1.7976931348623157e308"]


def broken_value(contract, case):
    (group, name, kind), bad, value = case
    directory = contract.fresh()
    small = "&scan nx = 8, ny = 2 /\n" + BOUNDS
    with open(os.path.join(directory, "small.nml"), "w") as handle:
        handle.write(small)
    text = f"&{group} {name} = {value} /\n"
    with open(os.path.join(directory, "bad.nml"), "w", errors="surrogateescape") as handle:
        handle.write(text)
    result = contract.run(directory, ["-o", "out.h5", os.path.join(contract.args.inputs, "naf.nml"), "small.nml",
                                      "bad.nml"], output="out.h5", allowed={3} if bad else {0, 3, 4}, timeout=180)
    if result.returncode == 3:
        stderr = result.stderr.decode("utf-8", "replace")
        assert "bad.nml" in stderr or bad is False, f"the message does not name bad.nml: {stderr}"


BROKEN_VALUES = st.sampled_from(VARIABLES).flatmap(
    lambda variable: st.one_of(
        st.tuples(st.just(variable), st.just(True), st.sampled_from(ALWAYS_BAD[variable[2]])),
        st.tuples(st.just(variable), st.just(False), st.sampled_from(MAYBE))))


# ---- class 4: broken structure: mutated files, garbage, long lines, missing groups ----

BASE = ("&surface potential = 'naf', v0 = 1.0 /\n&tip mass = 1.0e-8, kx = 10.0, ky = 10.0 /\n"
        "&scan nx = 8, ny = 2, velocity = 400.0 /\n")


@st.composite
def mutated(draw):
    text = bytearray((BASE + BOUNDS).encode())
    kind = draw(st.sampled_from(["delete", "insert", "replace", "truncate", "long-line", "garbage", "drop-group",
                                 "duplicate-line", "no-newline"]))
    if kind == "delete":
        at = draw(st.integers(0, len(text) - 1))
        del text[at:at + draw(st.integers(1, 5))]
    elif kind == "insert":
        at = draw(st.integers(0, len(text)))
        text[at:at] = draw(st.binary(min_size=1, max_size=6))
    elif kind == "replace":
        at = draw(st.integers(0, len(text) - 1))
        text[at] = draw(st.integers(0, 255))
    elif kind == "truncate":
        text = text[:draw(st.integers(0, len(text)))]
    elif kind == "long-line":
        at = draw(st.sampled_from([i for i, c in enumerate(text) if c == ord(",")]))
        text[at + 1:at + 1] = b" " * draw(st.integers(1000, 200000))
    elif kind == "garbage":
        text = bytearray(draw(st.binary(min_size=0, max_size=3000)))
    elif kind == "drop-group":
        lines = bytes(text).split(b"\n")
        del lines[draw(st.integers(0, len(lines) - 1))]
        text = bytearray(b"\n".join(lines))
    elif kind == "duplicate-line":
        lines = bytes(text).split(b"\n")
        k = draw(st.integers(0, len(lines) - 1))
        lines.insert(k, lines[k])
        text = bytearray(b"\n".join(lines))
    else:
        text = bytearray(bytes(text).rstrip(b"\n"))
    return kind, bytes(text)


def broken_structure(contract, case):
    kind, text = case
    directory = contract.fresh()
    with open(os.path.join(directory, "run.nml"), "wb") as handle:
        handle.write(text)
    # The shipped NaF file first: what the mutated file leaves unset keeps its value.
    contract.run(directory, ["-o", "out.h5", os.path.join(contract.args.inputs, "naf.nml"), "run.nml"],
                 output="out.h5", allowed={0, 3, 4}, timeout=180)


# ---- class 5: XYZ nets with random defects ----

@st.composite
def nets(draw):
    side = draw(st.integers(1, 7))
    a = draw(st.floats(0.3, 4.0))
    jitter = draw(st.floats(0.0, 0.3))
    atoms = []
    for i in range(side):
        for j in range(side):
            dx, dy = draw(st.tuples(st.floats(-jitter, jitter), st.floats(-jitter, jitter)))
            atoms.append(["C", (i - (side - 1) / 2) * a + dx, (j - (side - 1) / 2) * a + dy, 0.0])
    defects = draw(st.lists(st.sampled_from(["duplicate", "far", "nan", "count-high", "count-low", "species",
                                            "field", "vacancy", "raised", "none"]), max_size=3))
    lines = [f"{s} {x!r} {y!r} {z!r}" for s, x, y, z in atoms]
    count = len(lines)
    for defect in defects:
        if defect == "duplicate":
            lines.append(lines[draw(st.integers(0, len(lines) - 1))])
            count += 1
        elif defect == "far":
            lines.append(f"C {draw(st.sampled_from([1e5, -1e6, 3e7]))!r} {draw(st.floats(-1e6, 1e6))!r} 0.0")
            count += 1
        elif defect == "nan":
            lines[draw(st.integers(0, len(lines) - 1))] = "C nan 0.0 0.0"
        elif defect == "count-high":
            count += draw(st.integers(1, 5))
        elif defect == "count-low":
            count = max(1, count - draw(st.integers(1, 3)))
        elif defect == "species":
            lines[draw(st.integers(0, len(lines) - 1))] = "Au 0.0 0.0 0.0"
        elif defect == "field":
            lines[draw(st.integers(0, len(lines) - 1))] = "C 1.0 two 0.0"
        elif defect == "vacancy":
            k = draw(st.integers(0, len(lines) - 1))
            lines[k] = "X" + lines[k][1:]
        elif defect == "raised":
            lines.append(f"C 0.3 0.2 {draw(st.floats(0.5, 5.0))!r}")
            count += 1
    parameters = {
        "sigma": draw(st.sampled_from([0.01, 0.5, 2.4945, 4.0])),
        "support_z": draw(st.sampled_from([-6.0, -1.0, 0.0, -30.0, -1e6])),
        "cutoff": draw(st.sampled_from([0.0, 0.0, 8.0, 1000.0])),
    }
    return f"{count}\nfuzzed net\n" + "\n".join(lines) + "\n", defects, parameters


def xyz_net(contract, case):
    text, defects, p = case
    directory = contract.fresh()
    with open(os.path.join(directory, "net.xyz"), "w") as handle:
        handle.write(text)
    cutoff = f", cutoff = {number(p['cutoff'])}" if p["cutoff"] > 0 else ""
    if p["cutoff"] and p["cutoff"] < p["sigma"]:
        cutoff = ""
    with open(os.path.join(directory, "run.nml"), "w") as handle:
        handle.write(f"&surface net = 'file', net_file = 'net.xyz', sigma = {number(p['sigma'])}{cutoff} /\n"
                     f"&tip support_z = {number(p['support_z'])} /\n"
                     "&scan nx = 6, ny = 2, length = 1.0, width = 1.0, origin_x = 0.1, origin_y = 0.1 /\n" + BOUNDS)
    result = contract.run(directory, ["-o", "out.h5", os.path.join(contract.args.inputs, "graphite.nml"),
                                      "run.nml"], output="out.h5", allowed={0, 3, 4}, timeout=180)
    if result.returncode == 0:
        with h5py.File(os.path.join(directory, "out.h5"), "r") as handle:
            atoms = handle["surface/atoms"][()]
            tip = np.concatenate([handle["afm/trace/tip_z"][()].ravel(), handle["afm/retrace/tip_z"][()].ravel()])
            # The tip stays above the layer (never through it: docs/reliability.md).
            assert np.all(tip > atoms[:, 2].min()), f"the tip went below the atoms: {directory}"
            assert not any(d in defects for d in ("duplicate", "nan", "species", "field", "count-high")), \
                f"a net with {defects} was accepted: {directory}"


# ---- class 6: output faults ----

FAULTS = ["existing", "existing-force", "symlink", "symlink-force", "dangling-symlink", "fifo", "directory",
          "missing-directory", "input-as-output", "empty-name", "readonly", "full", "device", "two-ranks-full"]


def output_fault(contract, case):
    fault, nx, ny = case
    directory = contract.fresh()
    naf = os.path.join(contract.args.inputs, "naf.nml")
    with open(os.path.join(directory, "small.nml"), "w") as handle:
        handle.write(f"&scan nx = {nx}, ny = {ny} /\n" + BOUNDS)
    shapes = {"afm/trace/fx": (ny, nx)}
    run = contract.run
    if fault in ("existing", "existing-force"):
        with open(os.path.join(directory, "out.h5"), "w") as handle:
            handle.write("someone's data")
        force = ["-f"] if fault == "existing-force" else []
        result = run(directory, [*force, "-o", "out.h5", naf, "small.nml"], output="out.h5", shapes=shapes,
                     replaced={"out.h5"} if force else (), allowed={0} if force else {3})
    elif fault in ("symlink", "symlink-force", "dangling-symlink"):
        with open(os.path.join(directory, "target.h5"), "w") as handle:
            handle.write("the target")
        os.symlink("target.h5" if fault != "dangling-symlink" else "nowhere.h5", os.path.join(directory, "out.h5"))
        force = ["-f"] if fault == "symlink-force" else []
        run(directory, [*force, "-o", "out.h5", naf, "small.nml"], allowed={3})
        assert not os.path.exists(os.path.join(directory, "nowhere.h5"))
    elif fault in ("fifo", "device"):
        target = os.path.join(directory, "out.h5")
        if fault == "fifo":
            os.mkfifo(target)
        else:
            try:
                os.mknod(target, 0o666 | stat.S_IFCHR, os.makedev(1, 3))
            except OSError:
                os.mkfifo(target)
        run(directory, ["-f", "-o", "out.h5", naf, "small.nml"], allowed={3}, timeout=60)
    elif fault == "directory":
        os.mkdir(os.path.join(directory, "out.h5"))
        run(directory, ["-f", "-o", "out.h5", naf, "small.nml"], allowed={3})
    elif fault == "missing-directory":
        run(directory, ["-o", "no/such/out.h5", naf, "small.nml"], allowed={5})
    elif fault == "input-as-output":
        run(directory, ["-f", "-o", "small.nml", naf, "small.nml"], allowed={3})
    elif fault == "empty-name":
        run(directory, ["-o", "", naf, "small.nml"], allowed={2})
    elif fault in ("readonly", "full", "two-ranks-full"):
        small = os.path.join(directory, "small")
        os.mkdir(small)
        size = {"readonly": "1m", "full": "64k", "two-ranks-full": "3m"}[fault]
        mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", small],
                                 capture_output=True).returncode == 0
        if not mounted:   # (not root: the fault cannot be made here; an ordinary run instead)
            run(directory, ["-o", "out.h5", naf, "small.nml"], output="out.h5", shapes=shapes, allowed={0, 4})
            return
        try:
            with open(os.path.join(small, "existing.h5"), "w") as handle:
                handle.write("keep")
            if fault == "readonly":
                subprocess.run(["mount", "-o", "remount,ro", small], check=True, capture_output=True)
                allowed = {5}
            else:
                allowed = {0, 5}
            with open(os.path.join(directory, "big.nml"), "w") as handle:
                handle.write(f"&scan nx = {nx * 200}, ny = {ny * 4} /\n" + BOUNDS)
            run(directory, ["-o", "small/out.h5", naf, "big.nml"], ranks=2 if fault == "two-ranks-full" else None,
                output="small/out.h5", shapes={"afm/trace/fx": (ny * 4, nx * 200)}, allowed=allowed)
        finally:
            unmount_if_mounted(small)


OUTPUT_FAULTS = st.tuples(st.sampled_from(FAULTS), st.integers(2, 20), st.integers(1, 3))


# ---- class 7: the C API in a host process: values by name, a line into short arrays ----

CAPI_NAMES = ["tip.nonesuch", "nogroup.mass", "", "tip.", ".mass", "tip.mass(2)", "scan.nx(0)", "brake.mu",
              "surface.lattice(99)", "tip" + "." * 300, "tip.mass\udcff"]
CAPI_STATUSES = {0, 1, 2, 3, 4}   # friction.h: OK, ERROR_INPUT, ERROR_NUMERICAL, ERROR_IO, ERROR_INTERNAL


@st.composite
def capi_cases(draw):
    """1 to 3 values set by name (a known variable with a value it must
    refuse or may take, or a name that does not exist), then one line into
    arrays of nx + change elements (change < 0: too short)."""
    sets = []
    for _ in range(draw(st.integers(1, 3))):
        if draw(st.integers(0, 4)) == 0:
            sets.append((draw(st.sampled_from(CAPI_NAMES)), "1.0", "unknown"))
        else:
            (group, name, kind), bad, value = draw(BROKEN_VALUES)
            sets.append((f"{group}.{name}", value, "bad" if bad else "maybe"))
    return {"sets": sets, "line_length_change": draw(st.sampled_from([0, 0, -1, -7, 5]))}


def capi_values(contract, case):
    directory = contract.fresh()
    files = [os.path.join(contract.args.inputs, "naf.nml"), os.path.join(directory, "small.nml")]
    with open(files[1], "w") as handle:
        handle.write("&scan nx = 8, ny = 2 /\n" + BOUNDS)
    job = {"scene": "afm", "files": files, "sets": [[name, value] for name, value, _ in case["sets"]],
           "line_length_change": case["line_length_change"]}
    env = dict(os.environ, FRICTION_LIBRARY=contract.args.library)
    cmd = [sys.executable, os.path.join(os.path.dirname(os.path.abspath(__file__)), "fuzz_capi_host.py"),
           os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "python")]
    start = time.monotonic()
    try:
        result = subprocess.run(cmd, input=json.dumps(job, ensure_ascii=True).encode(), capture_output=True,
                                env=env, cwd=directory, timeout=180)
    except subprocess.TimeoutExpired:
        raise AssertionError(f"C API case {job}: no answer in 180 s (a hang)")
    contract.seconds += time.monotonic() - start
    stderr = result.stderr.decode("utf-8", "replace")
    where = f"C API case {job}:\n{stderr}"
    contract.codes[result.returncode] += 1
    assert result.returncode >= 0, f"the host was killed by signal {-result.returncode}: {where}"
    assert result.returncode == 0, f"the host ended with {result.returncode}: {where}"
    for word in ABORTS:
        assert word not in stderr, f"runtime abort ({word!r}): {where}"
    report = json.loads(result.stdout)
    last = {name: k for k, (name, _, _) in enumerate(case["sets"])}
    for k, ((name, value, kind), (status, message)) in enumerate(zip(case["sets"], report["sets"])):
        assert status in CAPI_STATUSES, f"set {name} = {value!r}: status {status}: {where}"
        if kind == "unknown":
            assert status == 1, f"set of the unknown name {name!r} was not refused (status {status}): {where}"
        if kind == "bad" and status == 0 and last[name] == k:
            # Refused by the checks when not by the set: a value the text
            # reads as (an unknown method, say) but the scene cannot take.
            assert report["check"][0] == 1, f"set {name} = {value!r} was taken and passed the checks: {where}"
            message = report["check"][1]
            status = 1
        if status != 0:
            assert message.strip(), f"set {name} = {value!r}: refused without a message: {where}"
            if kind == "bad" and last[name] == k and len(case["sets"]) == 1:
                assert name.split(".")[1] in message, f"the message does not name {name}: {message}"
    for stage in ("check", "line", "compute"):
        if report[stage] is not None:
            assert report[stage][0] in CAPI_STATUSES, f"{stage}: status {report[stage][0]}: {where}"
            if report[stage][0] != 0:
                assert report[stage][1].strip(), f"{stage}: refused without a message: {where}"
    assert report["guard_intact"], f"friction_afm_line wrote past the {report.get('line_n')} elements given: {where}"
    if report["line"] is not None and report["line_n"] < report["nx"]:
        assert report["line"][0] == 1, f"arrays of {report['line_n']} for nx = {report['nx']} accepted: {where}"
    assert report["finite"], f"a computed array holds non-finite values: {where}"


# ---- the classes, their strategies and budgets (cases in the ordinary suite) ----

# ---- class 8: the newer groups: &thermal, the orbit and its continuation, sweeps over them, map checkpoints ----

@st.composite
def newer_cases(draw):
    kind = draw(st.sampled_from(["thermal", "orbit", "sweep-thermal", "sweep-orbit", "map-checkpoint"]))
    p = {"kind": kind}
    if kind in ("thermal", "sweep-thermal"):
        p["model"] = draw(st.sampled_from(["langevin", "kramers"]))
        # Both models over the whole range, into the refusal above 1e5 K: every run ends by
        # max_wall_time (3 s in BOUNDS) or is refused.
        p["temperature"] = draw(log_uniform(1e-6, 1e6))
        p["realizations"] = draw(st.integers(1, 3))
        p["seed"] = draw(st.integers(1, 2**40))
        p["nx"], p["ny"] = draw(st.integers(2, 12)), draw(st.integers(1, 2))
        p["velocity"] = draw(log_uniform(0.1, 1e4))
        p["time_step"] = draw(st.sampled_from([0.0, 0.0, 1e-9, 1e-7, 1e-30, 1.0]))
    if kind in ("orbit", "sweep-orbit"):
        p["t_end"] = draw(st.floats(150.0, 400.0))
        p["mu"] = draw(st.floats(0.3, 0.55))
        p["variable"] = draw(st.sampled_from(["mu", "mu_s", "xi", "kappa", "v_dr_prime", "nonesuch"]))
        p["end"] = draw(st.floats(-0.5, 1.0))
        p["points"] = draw(st.sampled_from([2, 3, 5, 0, 1, 2147483647]))
        p["iterations"] = draw(st.sampled_from([1, 5, 30]))
        p["spectrum"] = draw(st.booleans())
        p["renormalise"] = draw(st.sampled_from([0.1, 0.5, 2.0, 1e-13, 1e-300]))
    if kind.startswith("sweep"):
        p["count"] = draw(st.integers(1, 3))
    if kind == "map-checkpoint":
        p["nx"], p["ny"] = draw(st.integers(2, 24)), draw(st.integers(2, 9))
        p["stop_after"] = draw(st.integers(1, 9))
        p["ranks"] = draw(st.sampled_from([None, None, 2]))
        p["thermal"] = draw(st.booleans())
    return p


def thermal_text(p):
    return (f"&scan nx = {p['nx']}, ny = {p['ny']}, velocity = {number(p['velocity'])} /\n"
            f"&thermal model = '{p['model']}', temperature = {number(p['temperature'])},"
            f" realizations = {p['realizations']}, seed = {p['seed']},"
            f" time_step = {number(p['time_step'] if p['model'] == 'langevin' else 0.0)} /\n" + BOUNDS)


def orbit_text(p):
    return (f"&brake mu = {number(p['mu'])}, t_end = {number(p['t_end'])}, dt_out = 0.1 /\n"
            "&analysis spectrum = .false., poincare = .false., rosenstein = .false., lyapunov = .false.,"
            f" lyapunov_spectrum = {'.true.' if p['spectrum'] else '.false.'},"
            f" lyapunov_spectrum_renormalise = {number(p['renormalise'])}, lyapunov_spectrum_transient = 50.0,"
            f" orbit = .true., orbit_max_iterations = {p['iterations']}, continuation = '{p['variable']}',"
            f" continuation_end = {number(p['end'])}, continuation_points = {p['points']} /\n"
            "&integrator max_wall_time = 3.0 /\n")


def swept(contract, directory, files):
    """A sweep: exit 4 when every point failed still writes the file, with
    each point's reason (docs/sweeps.md), which is checked as a success's."""
    result = contract.run(directory, ["-o", "out.h5", *files], allowed={0, 3, 4}, timeout=90)
    path = os.path.join(directory, "out.h5")
    if result.returncode == 4 and os.path.exists(path):
        stderr = result.stderr.decode("utf-8", "replace")
        assert "every one of the" in stderr, f"exit 4 left a file but not for failed points: {stderr}"
    if result.returncode in (0, 4) and os.path.exists(path):
        check_output(path, None, f"the sweep in {directory}")
    elif result.returncode != 0:
        assert not os.path.exists(path), f"a failed sweep left its output: {directory}"


def newer_groups(contract, p):
    directory = contract.fresh()
    inputs = contract.args.inputs
    kind = p["kind"]

    def write(name, text):
        with open(os.path.join(directory, name), "w") as handle:
            handle.write(text)

    if kind == "thermal":
        write("run.nml", thermal_text(p))
        contract.run(directory, ["-o", "out.h5", os.path.join(inputs, "naf_thermal_temperature.nml"), "run.nml"],
                     output="out.h5", allowed={0, 3, 4}, timeout=60)
    elif kind == "orbit":
        write("run.nml", orbit_text(p))
        contract.run(directory, ["-o", "out.h5", os.path.join(inputs, "brake.nml"), "run.nml"], output="out.h5",
                     allowed={0, 3, 4}, timeout=60)
    elif kind == "sweep-thermal":
        values = ", ".join(number(p["temperature"] * (k + 1)) for k in range(p["count"]))
        write("run.nml", thermal_text(p) + f"&sweep sweep_variable = 'thermal.temperature', sweep_values = {values} /\n")
        swept(contract, directory, [os.path.join(inputs, "naf_thermal_temperature.nml"), "run.nml"])
    elif kind == "sweep-orbit":
        text = orbit_text(p).replace(f" continuation = '{p['variable']}',", " continuation = '',")
        write("run.nml", text + "&sweep sweep_variable = 'brake.mu', sweep_spacing = 'linear', sweep_from = 0.35,"
              f" sweep_to = 0.5, sweep_count = {p['count']} /\n")
        swept(contract, directory, [os.path.join(inputs, "brake.nml"), "run.nml"])
    else:
        text = f"&scan nx = {p['nx']}, ny = {p['ny']}, checkpoint_interval = 0.0 /\n" + BOUNDS
        if p["thermal"]:
            text += "&thermal temperature = 300.0, realizations = 2, seed = 5 /\n"
        write("run.nml", text)
        files = [os.path.join(inputs, "naf.nml"), "run.nml"]
        # (The test build of the program stops on cue, as SIGTERM after that many lines would.)
        stop = contract.args.stop_binary
        stopped = contract.run(directory, ["-o", "out.h5", *files], ranks=p["ranks"], allowed={0, 6}, timeout=90,
                               env={"FRICTION_TEST_STOP_AFTER": str(p["stop_after"])} if stop else None,
                               binary=stop)
        kept = [f for f in os.listdir(directory) if f.startswith("out.h5.line-")]
        assert stopped.returncode == 0 or (kept and not os.path.exists(os.path.join(directory, "out.h5"))), \
            f"a stopped map: exit {stopped.returncode}, checkpoints {kept}"
        if stopped.returncode == 0:
            return   # every line done before the stop: nothing to resume
        contract.run(directory, ["--resume", "-o", "out.h5", *files], ranks=p["ranks"], output="out.h5",
                     allowed={0}, timeout=90, replaced=tuple(kept))
        left = [f for f in os.listdir(directory) if ".ckpt" in f]
        assert not left, f"checkpoints left after --resume: {left}"


# ---- class 9: the friction laws (docs/laws.md): the machine and the brake with &law, every law and tool ----

LAW_NAMES = ["coulomb", "arctan", "stribeck", "karnopp", "dahl", "lugre", "elastoplastic", "rate_state", "gms",
             "table"]


@st.composite
def law_values(draw, model, force):
    """A law's &law values over wide ranges (force: the scale of its force
    levels, N on the machine, m on the nondimensional brake); mostly within
    the law's checks, at times across them (a refusal is then the answer)."""
    p = {"model": f"'{model}'"}
    fc = force * draw(st.floats(0.0, 3.0))
    fs = fc * draw(st.floats(1.0, 3.0)) + force * draw(st.sampled_from([0.0, 0.01]))
    if model in ("coulomb", "arctan"):
        p["mu"] = draw(st.floats(0.0, 2.0)) * force
    if model == "coulomb":
        p["mu_s"] = p["mu"] * draw(st.floats(1.0, 2.0))
    if model == "arctan":
        p["epsilon"], p["delta"] = draw(log_uniform(1.0, 1e9)), draw(st.floats(0.0, 10.0))
    if model in ("stribeck", "karnopp", "lugre", "elastoplastic", "gms", "dahl"):
        p["fc"] = fc
    if model in ("stribeck", "karnopp", "lugre", "elastoplastic", "gms"):
        p["fs"], p["vs"], p["exponent"] = fs, draw(log_uniform(1e-7, 1.0)), draw(st.floats(0.3, 4.0))
    if model in ("coulomb", "stribeck", "karnopp", "lugre", "elastoplastic", "gms"):
        p["sigma2"] = 0.0 if draw(st.booleans()) else draw(log_uniform(1e-4, 10.0))
    if model == "karnopp":
        p["dv"] = draw(log_uniform(1e-8, 1e-1))
    if model in ("dahl", "lugre", "elastoplastic"):
        p["sigma0"] = draw(log_uniform(1.0, 1e9)) * force
    if model in ("lugre", "elastoplastic"):
        p["sigma1"] = draw(log_uniform(1e-3, 1e5)) * force
    if model == "dahl":
        p["alpha"] = draw(st.floats(1.0, 4.0))
    if model == "elastoplastic":
        p["z_ba"] = draw(st.floats(0.0, 0.99)) * fc / p["sigma0"]
    if model == "rate_state":
        p["mu0"], p["a"], p["b"] = draw(st.floats(0.05, 1.0)), draw(log_uniform(1e-4, 0.1)), draw(log_uniform(1e-4, 0.1))
        p["dc"], p["v0"] = draw(log_uniform(1e-8, 1e-2)), draw(log_uniform(1e-9, 1.0))
        p["evolution"] = draw(st.sampled_from(["'aging'", "'slip'"]))
    if model == "gms":
        n = draw(st.integers(1, 8))
        weights = [draw(st.floats(0.05, 1.0)) for _ in range(n)]
        p["elements"] = str(n)
        p["element_stiffness"] = ", ".join(number(draw(log_uniform(1.0, 1e8)) * force) for _ in range(n))
        p["element_weight"] = ", ".join(number(w / sum(weights)) for w in weights)
        p["attraction"] = draw(log_uniform(1e-2, 1e4))
    if model == "table":
        p["table_file"] = "'table.txt'"
        p["scale"] = draw(log_uniform(1e-3, 1e3))
        p["extrapolation"] = draw(st.sampled_from(["'constant'", "'logarithmic'"]))
    return p


def law_text(values):
    return "&law " + ",\n  ".join(f"{name} = {value if isinstance(value, str) else number(value)}"
                                   for name, value in values.items()) + " /\n"


@st.composite
def table_rows(draw, force):
    """A valid table: strictly increasing positive velocities, forces >= 0."""
    n = draw(st.integers(2, 12))
    start = draw(st.floats(-9.0, 1.0))
    steps = [draw(st.floats(0.01, 2.0)) for _ in range(n)]
    rows, e = [], start
    for step in steps:
        rows.append((10.0 ** e, force * draw(st.floats(0.0, 3.0))))
        e += step
    return rows


def rows_text(rows):
    return "# v (m/s)  F (N)\n" + "".join(f"{v!r} {f!r}\n" for v, f in rows)


# Tools of the machine's and the brake's &analysis; continuation variables of each.
LAW_TOOLS = ["none", "spectrum", "poincare", "lyapunov", "lyapunov_spectrum", "orbit", "continuation", "sweep"]
MACHINE_CONTINUATION = ["belt_velocity", "stiffness", "damping", "normal", "mass", "load_velocity",
                        "support_amplitude", "support_frequency", "nonesuch"]
BRAKE_CONTINUATION = ["xi", "kappa", "v_dr_prime", "mu", "fs", "fc", "vs", "sigma0", "sigma1", "dc", "a", "b",
                      "dv", "attraction", "epsilon", "scale", "nonesuch"]
# Values a law's check must refuse, by variable (the law that reads it).
LAW_BAD = {
    "sigma0": ("lugre", ["-1.0", "0.0", "nan", "inf", "-inf", "1e400"]),
    "fs": ("stribeck", ["0.5", "-1.0", "nan"]),        # fc = 1: F_s < F_c
    "vs": ("lugre", ["0.0", "-1e-3", "nan", "-inf"]),
    "dc": ("rate_state", ["0.0", "-1e-5", "nan", "inf"]),
    "a": ("rate_state", ["-0.01", "nan"]),
    "mu_s": ("coulomb", ["0.1", "nan"]),               # mu = 0.3: mu_s < mu
    "mu": ("arctan", ["-1.0", "nan", "inf"]),
    "epsilon": ("arctan", ["0.0", "-1.0", "nan", "inf"]),
    "dv": ("karnopp", ["0.0", "-1e-4", "nan"]),
    "alpha": ("dahl", ["0.5", "-1.0", "nan"]),
    "z_ba": ("elastoplastic", ["1e-3", "-1e-6", "nan"]),  # F_c/sigma0 = 1e-5
    "sigma1": ("elastoplastic", ["-1.0", "nan", "inf"]),
    "exponent": ("stribeck", ["0.0", "-2.0", "nan"]),
    "sigma2": ("karnopp", ["-0.4", "nan", "inf"]),
    "elements": ("gms", ["0", "9", "-1", "2147483647"]),
    "element_stiffness": ("gms", ["-4.0e4", "0.0", "nan", "inf"]),
    "element_weight": ("gms", ["0.0", "-0.1", "nan", "2.0"]),
    "attraction": ("gms", ["0.0", "-20.0", "nan", "inf"]),
    "scale": ("table", ["-1.0", "nan", "inf"]),
    "extrapolation": ("table", ["'nonesuch'", "''"]),
    "evolution": ("rate_state", ["'nonesuch'", "''"]),
    "model": ("coulomb", ["'nonesuch'", "''", "' '", "1.0"]),
    "table_file": ("table", ["''"]),
}
MACHINE_BAD = {"stiffness": ["-2.0", "nan", "inf", "1e400"], "mass": ["0.0", "-1.0", "nan"],
               "normal": ["-1.0", "nan", "inf"], "damping": ["-0.1", "nan"], "dt_out": ["0.0", "-0.01", "nan", "1e-300"],
               "t_end": ["-1.0", "nan", "inf"], "belt_velocity": ["nan", "inf", "1e400"],
               "support_amplitude": ["-1.0", "nan"], "event_tolerance": ["0.0", "-1.0", "nan"],
               "stick_velocity": ["0.0", "nan"]}
LAW_MAYBE = ["1e300", "1e-300", "4.9e-324", "1.7976931348623157e308", "1e30", "1e-30", "0.0"]
# Broken tables: each must be refused (exit 3), the message naming the table's file.
TABLE_DEFECTS = ["decreasing", "repeated", "nan", "inf", "one-row", "empty", "missing", "one-column", "three-columns",
                 "text", "negative-force", "zero-velocity", "directory", "h5-no-dataset", "h5-other-sweep",
                 "h5-one-point", "h5-garbage"]


@st.composite
def law_cases(draw):
    kind = draw(st.sampled_from(["machine", "machine", "brake", "broken-law", "broken-machine", "maybe",
                                 "broken-table"]))
    p = {"kind": kind}
    if kind in ("machine", "brake"):
        model = draw(st.sampled_from(LAW_NAMES))
        force = 1.0 if kind == "machine" else 0.01
        p["law"] = draw(law_values(model, force))
        if model == "table":
            p["rows"] = draw(table_rows(force))
        p["tool"] = draw(st.sampled_from(LAW_TOOLS))
        # ('auto' is the brake's choice; the machine refuses it, so rarely there.)
        methods = ["auto", "auto", "rodas4", "rk8pd", "rkf45", "msbdf", "bsimp"] if kind == "brake" else \
            ["rodas4", "rodas4", "rodas4", "rk8pd", "rkf45", "msbdf", "bsimp", "auto"]
        p["method"] = draw(st.sampled_from(methods))
        p["rtol"] = draw(log_uniform(1e-11, 1e-3))
        p["end_factor"] = draw(st.floats(0.5, 2.0))
        p["window"] = draw(st.floats(0.0, 0.9))
        p["points"] = draw(st.sampled_from([2, 3, 2, 1, 0]))
        p["count"] = draw(st.integers(1, 3))
        if kind == "machine":
            p["mechanism"] = draw(st.sampled_from(["belt", "slider", "support"]))
            p["machine"] = {
                "mass": draw(log_uniform(1e-3, 1e3)), "stiffness": draw(log_uniform(1e-2, 1e5)),
                "damping": draw(st.sampled_from([0.0, 0.0, 0.1, 10.0])), "normal": draw(log_uniform(1e-2, 1e2)),
                "belt_velocity": draw(st.sampled_from([-1.0, 1.0])) * draw(log_uniform(1e-7, 10.0)),
                "v0": draw(st.floats(-1.0, 1.0)), "x0": draw(st.floats(-1e-2, 1e-2)),
                "t_end": draw(st.floats(0.5, 60.0)), "dt_out": draw(log_uniform(1e-3, 1.0)),
                "steady_start": draw(st.booleans())}
            if p["mechanism"] == "slider":
                p["machine"]["belt_velocity"] = 0.0
                p["machine"]["load_velocity"] = draw(log_uniform(1e-7, 1.0))
            elif p["mechanism"] == "support":
                p["machine"]["support_amplitude"] = draw(log_uniform(1e-6, 1e-1))
                p["machine"]["support_frequency"] = draw(log_uniform(1e-2, 1e2))
            p["variable"] = draw(st.sampled_from(MACHINE_CONTINUATION))
        else:
            p["brake"] = {"v_dr_prime": -draw(log_uniform(1e-5, 1e-1)), "t_end": draw(st.floats(5.0, 400.0)),
                          "dt_out": draw(st.sampled_from([0.05, 0.1, 1.0])), "units": "'nondimensional'"}
            p["variable"] = draw(st.sampled_from(BRAKE_CONTINUATION))
    elif kind == "broken-law":
        p["variable"] = draw(st.sampled_from(sorted(LAW_BAD)))
        p["value"] = draw(st.sampled_from(LAW_BAD[p["variable"]][1]))
        p["scene"] = draw(st.sampled_from(["machine", "brake"]))
    elif kind == "broken-machine":
        p["variable"] = draw(st.sampled_from(sorted(MACHINE_BAD)))
        p["value"] = draw(st.sampled_from(MACHINE_BAD[p["variable"]]))
        p["model"] = draw(st.sampled_from(LAW_NAMES[:-1]))
    elif kind == "maybe":
        model = draw(st.sampled_from(LAW_NAMES[:-1]))
        names = [name for name in draw(law_values(model, 1.0)) if name not in ("model", "evolution", "elements",
                                                                                   "extrapolation", "table_file")]
        p["model"], p["variable"] = model, draw(st.sampled_from(names))
        p["value"] = draw(st.sampled_from(LAW_MAYBE + ["-" + v for v in LAW_MAYBE[:4]]))
        p["scene"] = draw(st.sampled_from(["machine", "brake"]))
    else:
        p["defect"] = draw(st.sampled_from(TABLE_DEFECTS))
        p["rows"] = draw(table_rows(1.0))
        p["scene"] = draw(st.sampled_from(["machine", "brake"]))
    return p


def machine_law_text(p):
    if p["kind"] == "machine":
        head = "&job scene = 'machine' /\n&machine " + ", ".join(
            f"{name} = {('.true.' if value else '.false.') if isinstance(value, bool) else number(value)}"
            for name, value in p["machine"].items()) + " /\n"
        variable, value = p["variable"], p["machine"].get(p["variable"], 1.0)
        sweep = f"&sweep sweep_variable = 'machine.stiffness', sweep_spacing = 'linear'," \
                f" sweep_from = {number(p['machine']['stiffness'])}," \
                f" sweep_to = {number(p['machine']['stiffness'] * p['end_factor'])}, sweep_count = {p['count']} /\n"
    else:
        head = "&job scene = 'brake' /\n&brake model = 'law', " + ", ".join(
            f"{name} = {value if isinstance(value, str) else number(value)}" for name, value in p["brake"].items()) \
            + " /\n"
        variable = p["variable"]
        value = p["law"].get(variable, p["brake"].get(variable, 1.0))
        value = value if isinstance(value, float) else 1.0
        sweep = f"&sweep sweep_variable = 'brake.v_dr_prime', sweep_spacing = 'linear'," \
                f" sweep_from = {number(p['brake']['v_dr_prime'])}," \
                f" sweep_to = {number(p['brake']['v_dr_prime'] * p['end_factor'])}, sweep_count = {p['count']} /\n"
    tool = p["tool"]
    flags = {name: tool == name for name in ("spectrum", "poincare", "lyapunov", "lyapunov_spectrum")}
    flags["orbit"] = tool in ("orbit", "continuation", "sweep")
    analysis = "&analysis " + ", ".join(f"{name} = {'.true.' if on else '.false.'}" for name, on in flags.items())
    analysis += ", rosenstein = .false., orbit_max_iterations = 8"
    # The windows and transients within the run, so that the tools run (a window past t_end is refused).
    span = p["machine"]["t_end"] if p["kind"] == "machine" else p["brake"]["t_end"]
    start = p["window"] * span
    analysis += (f",\n  window_start = {number(start)}, window_end = {number(span)},"
                 f" lyapunov_transient = {number(start)}, lyapunov_spectrum_transient = {number(start)},"
                 f" lyapunov_renormalise = {number(span / 20.0)}, lyapunov_spectrum_renormalise = {number(span / 20.0)},"
                 f" orbit_transient = {number(start)}")
    if tool == "continuation":
        analysis += (f", continuation = '{variable}', continuation_end = {number(value * p['end_factor'])},"
                     f" continuation_points = {p['points']}")
    else:
        analysis += ", continuation = ''"
    text = head + law_text(p["law"]) + analysis + " /\n"
    text += (f"&integrator method = '{p['method']}', rtol = {number(p['rtol'])}, max_wall_time = 3.0,"
             " max_steps = 400000 /\n")
    return text + (sweep if tool == "sweep" else "")


def write_file(directory, name, text):
    with open(os.path.join(directory, name), "w") as handle:
        handle.write(text)


def broken_table(directory, defect, rows):
    """Writes the broken table; returns its file name."""
    if defect.startswith("h5-"):
        with h5py.File(os.path.join(directory, "table.h5"), "w") as handle:
            if defect == "h5-no-dataset":
                handle.create_group("sweep")
            elif defect == "h5-garbage":
                handle.create_dataset("something", data=np.arange(3.0))
            else:
                n = 1 if defect == "h5-one-point" else len(rows)
                sweep = handle.create_group("sweep")
                sweep.create_dataset("values", data=np.array([v for v, _ in rows[:n]]))
                sweep.create_dataset("mean_friction", data=np.array([f for _, f in rows[:n]]))
                sweep.create_dataset("status", data=np.ones(n, dtype=np.int32))
                handle.attrs["sweep_variable"] = "scan.temperature" if defect == "h5-other-sweep" else "scan.velocity"
        return "table.h5"
    if defect == "missing":
        return "nowhere.txt"
    if defect == "directory":
        os.mkdir(os.path.join(directory, "table.txt"))
        return "table.txt"
    rows = list(rows)
    text = None
    if defect == "decreasing":
        rows[-1] = (rows[0][0] / 2.0, rows[-1][1])
    elif defect == "repeated":
        rows.append(rows[-1])
    elif defect in ("nan", "inf"):
        rows[len(rows) // 2] = (rows[len(rows) // 2][0], float(defect))
    elif defect == "one-row":
        rows = rows[:1]
    elif defect == "empty":
        text = "# no rows\n\n"
    elif defect == "one-column":
        text = rows_text(rows) + f"{rows[-1][0] * 10.0!r}\n"
    elif defect == "three-columns":
        text = "".join(f"{v!r} {f!r} 1.0\n" for v, f in rows)
    elif defect == "text":
        text = rows_text(rows) + "1.0e3 many\n"
    elif defect == "negative-force":
        rows[0] = (rows[0][0], -1.0)
    elif defect == "zero-velocity":
        rows[0] = (0.0, rows[0][1])
    write_file(directory, "table.txt", text if text is not None else rows_text(rows))
    return "table.txt"


def refused_naming(result, *words):
    """A refusal (exit 3) whose one message names each of words (one of a tuple)."""
    stderr = result.stderr.decode("utf-8", "replace")
    message = [line for line in stderr.splitlines() if line.startswith("friction: error:")][0]
    for word in words:
        options = word if isinstance(word, tuple) else (word,)
        assert any(option in message for option in options), f"the message does not name {word}: {message}"


def laws(contract, p):
    directory = contract.fresh()
    inputs = contract.args.inputs
    kind = p["kind"]
    if kind in ("machine", "brake"):
        if p["law"]["model"] == "'table'":
            write_file(directory, "table.txt", rows_text(p["rows"]))
        write_file(directory, "run.nml", machine_law_text(p))
        if p["tool"] == "sweep":
            swept(contract, directory, ["run.nml"])
        else:
            result = contract.run(directory, ["-o", "out.h5", "run.nml"], output="out.h5", allowed={0, 3, 4},
                                  timeout=90)
            if result.returncode == 3:
                # A value the file leaves at its default is refused as "(default): &group: ...", or at the line of
                # the variable it conflicts with when the file set that one (docs/input.md).
                refused_naming(result, ("run.nml:", "(default): &"))
        return
    scene = p.get("scene", "machine")
    base = os.path.join(inputs, "machine_lugre.nml" if scene == "machine" else "brake_lugre.nml")
    if kind == "broken-table":
        name = broken_table(directory, p["defect"], p["rows"])
        write_file(directory, "bad.nml", f"&law model = 'table', table_file = '{name}' /\n" + BOUNDS)
        result = contract.run(directory, ["-o", "out.h5", base, "bad.nml"], output="out.h5", allowed={3})
        refused_naming(result, name)
        return
    if kind == "broken-machine":
        law = f"&law model = '{p['model']}' /\n"
        write_file(directory, "bad.nml", f"&machine {p['variable']} = {p['value']} /\n" + law + BOUNDS)
        result = contract.run(directory, ["-o", "out.h5", os.path.join(inputs, "machine_lugre.nml"), "bad.nml"],
                              output="out.h5", allowed={3})
        refused_naming(result, "bad.nml:1", "&machine", p["variable"])
        return
    model = LAW_BAD[p["variable"]][0] if kind == "broken-law" else p["model"]
    values = {"model": f"'{model}'"}
    if model == "stribeck":
        values["fc"] = "1.0"
    if model == "table":
        write_file(directory, "table.txt", rows_text([(1e-6, 1.5), (1e-3, 1.2), (1.0, 1.0)]))
        if p["variable"] != "table_file":
            values["table_file"] = "'table.txt'"
    values[p["variable"]] = p["value"]
    lines = [f"{name} = {value}" for name, value in values.items()]
    write_file(directory, "bad.nml", "&law\n" + "\n".join(lines) + "\n/\n" + BOUNDS)
    result = contract.run(directory, ["-o", "out.h5", base, "bad.nml"], output="out.h5",
                          allowed={3} if kind == "broken-law" else {0, 3, 4}, timeout=90)
    if result.returncode == 3:
        line = 2 + list(values).index(p["variable"])
        names = (p["variable"], "fc") if p["variable"] == "fs" else (p["variable"], "mu") \
            if p["variable"] == "mu_s" else (p["variable"], "fc", "sigma0") if p["variable"] == "z_ba" else \
            p["variable"]
        if kind == "maybe":
            # A doubtful value may break a check against another variable, set in the base file or left at
            # its default: the message names where that one was set.
            refused_naming(result, (".nml:", "(default): &"))
            return
        refused_naming(result, "bad.nml", "&law", names)
        if p["variable"] not in ("fs", "mu_s", "z_ba"):
            refused_naming(result, f"bad.nml:{line}")


# ---- the law on its own through the C API: histories with wild values ----

@st.composite
def law_history_cases(draw):
    model = draw(st.sampled_from(LAW_NAMES))
    sets = {}
    if draw(st.booleans()):
        sets = {name: value for name, value in draw(law_values(model, 1.0)).items()
                if name not in ("model", "table_file")}
        sets = {name: value if isinstance(value, str) else float(value) for name, value in sets.items()}
    if draw(st.integers(0, 3)) == 0:
        variable = draw(st.sampled_from(sorted(LAW_BAD)))
        sets[variable] = draw(st.sampled_from(LAW_BAD[variable][1] + [float("nan"), float("inf"), -1e300]))
    n = draw(st.sampled_from([0, 1, 2, 3, 50, 400]))
    t = draw(st.sampled_from(["increasing", "increasing", "decreasing", "repeated", "nan", "huge", "tiny"]))
    u = draw(st.sampled_from(["sine", "sine", "ramp", "nan", "inf", "huge", "tiny", "zero", "step"]))
    return {"model": model, "sets": sets, "n": n, "t": t, "u": u,
            "amplitude": draw(log_uniform(1e-9, 1e3)),
            "normal": draw(st.sampled_from([1.0, 0.0, 1e6, -1.0, float("nan"), float("inf"), 1e-300])),
            "displacement": draw(st.sampled_from([0, 0, 1, 2, -1])),
            "u_change": draw(st.sampled_from([0, 0, 0, -1, 5])),
            "states_change": draw(st.sampled_from([0, 0, -1, 3, None])),
            "table": draw(st.sampled_from(["table.txt", "table.txt", "nowhere.txt", "decreasing.txt"]))}


def law_capi(contract, cases):
    """1 to 4 histories in one host process (its start, the package's import, is most of a case's time)."""
    directory = contract.fresh()
    rows = [(1e-6, 1.5), (1e-3, 1.2), (1.0, 1.0)]
    write_file(directory, "table.txt", rows_text(rows))
    write_file(directory, "decreasing.txt", rows_text(rows[::-1]))
    env = dict(os.environ, FRICTION_LIBRARY=contract.args.library)
    here = os.path.dirname(os.path.abspath(__file__))
    cmd = [sys.executable, os.path.join(here, "fuzz_law_host.py"), os.path.join(os.path.dirname(here), "python")]
    job = json.dumps(cases, allow_nan=True)
    start = time.monotonic()
    try:
        result = subprocess.run(cmd, input=job.encode(), capture_output=True, env=env, cwd=directory, timeout=120)
    except subprocess.TimeoutExpired:
        raise AssertionError(f"law histories {job}: no answer in 120 s (a hang)")
    contract.seconds += time.monotonic() - start
    stderr = result.stderr.decode("utf-8", "replace")
    where = f"law histories {job}:\n{stderr}"
    contract.codes[result.returncode] += 1
    assert result.returncode >= 0, f"the host was killed by signal {-result.returncode}: {where}"
    assert result.returncode == 0, f"the host ended with {result.returncode}: {where}"
    for word in ABORTS:
        assert word not in stderr, f"runtime abort ({word!r}): {where}"
    for case, report in zip(cases, json.loads(result.stdout)):
        where = f"law history {json.dumps(case, allow_nan=True)}:\n{stderr}"
        for stage in ("new", "sets", "check", "history"):
            for status, message in report[stage]:
                assert status in CAPI_STATUSES, f"{stage}: status {status}: {where}"
                if status != 0:
                    assert message.strip(), f"{stage}: refused without a message: {where}"
        if len(case["sets"]) == 1 and report["sets"] and report["sets"][0][0] == 0 and report["check"] \
                and report["check"][0][0] != 0:
            name = next(iter(case["sets"]))
            assert name in report["check"][0][1], f"the check does not name {name}: {report['check'][0][1]}"
        assert report["guard_intact"], f"friction_law_history wrote past its arrays: {where}"
        if report["history"]:
            status = report["history"][0][0]
            if status == 1:
                assert report["untouched"], f"a refused history wrote into the caller's arrays: {where}"
            if status == 0:
                assert report["finite"], f"a history holds non-finite values: {where}"
                assert report["valid"], f"a history was computed from invalid arguments: {where}"
            for status, message in report["history"][1:]:
                assert status != 0, f"Law.history took arrays of different lengths: {where}"


CLASSES = {
    "valid-afm": (VALID_AFM, valid_afm, 25),
    "valid-brake": (VALID_BRAKE, valid_brake, 15),
    "broken-values": (BROKEN_VALUES, broken_value, 30),
    "broken-structure": (mutated(), broken_structure, 25),
    "xyz-nets": (nets(), xyz_net, 15),
    "output-faults": (OUTPUT_FAULTS, output_fault, 15),
    "capi-values": (capi_cases(), capi_values, 15),
    "newer-groups": (newer_cases(), newer_groups, 20),
    "laws": (law_cases(), laws, 40),
    "law-capi": (st.lists(law_history_cases(), min_size=1, max_size=4), law_capi, 5),
}


def xyz_example(defect, sigma=2.4945, support_z=-6.0):
    """A 4 x 4 net with one defect, as nets() makes it."""
    atoms = [f"C {(i - 1.5) * 2.46!r} {(j - 1.5) * 2.46!r} 0.0" for i in range(4) for j in range(4)]
    count = len(atoms)
    if defect == "duplicate":
        atoms.append(atoms[5])
        count += 1
    elif defect == "far":
        atoms.append("C 1000000.0 -1000000.0 0.0")
        count += 1
    elif defect == "nan":
        atoms[3] = "C nan 0.0 0.0"
    elif defect == "count-high":
        count += 2
    elif defect == "species":
        atoms[2] = "Au 0.0 0.0 0.0"
    elif defect == "one":
        atoms, count = ["C 3.0 3.0 0.0"], 1
    parameters = {"sigma": sigma, "support_z": support_z, "cutoff": 0.0}
    return (f"{count}\nexample\n" + "\n".join(atoms) + "\n", [defect], parameters)


# Cases every run of the suite tries, before the generated ones: each
# defect of issue 15 that the class covers, at least once.
EXAMPLES = {
    "broken-values": [(("tip", "mass", "r"), True, "1e400"), (("scan", "velocity", "r"), True, "-1e400"),
                      (("surface", "v0", "r"), True, "1e-400"), (("tip", "kx", "r"), True, "1.0d+999"),
                      (("scan", "nx", "i"), True, "2147483648"), (("integrator", "rtol", "r"), False, "1e300"),
                      (("integrator", "atol", "r"), False, "1.7976931348623157e308"),
                      (("integrator", "h_min", "r"), False, "1e-2"),
                      (("surface", "potential", "c"), True, "'\u00e9\udcff'")],
    "broken-structure": [("long-line", (BASE.replace("nx = 8,", "nx = 8," + " " * 5000) + BOUNDS).encode()),
                         ("garbage", bytes(range(256)) * 4), ("no-newline", (BASE + BOUNDS).rstrip("\n").encode())],
    "xyz-nets": [xyz_example(defect) for defect in ("duplicate", "far", "nan", "count-high", "species", "one")]
                + [xyz_example("none", sigma=0.01), xyz_example("none", support_z=-1e6)],
    "output-faults": [(fault, 4, 2) for fault in FAULTS],
    "newer-groups": [
        {"kind": "thermal", "model": "langevin", "temperature": 1e300, "realizations": 1, "seed": 1, "nx": 4, "ny": 1,
         "velocity": 100.0, "time_step": 0.0},
        {"kind": "orbit", "t_end": 400.0, "mu": 0.5, "variable": "mu", "end": 0.5, "points": 2147483647,
         "iterations": 30, "spectrum": False, "renormalise": 1.0},
        {"kind": "orbit", "t_end": 200.0, "mu": 0.5, "variable": "mu", "end": 0.45, "points": 3, "iterations": 30,
         "spectrum": True, "renormalise": 1e-300},
        {"kind": "map-checkpoint", "nx": 8, "ny": 5, "stop_after": 1, "ranks": 2, "thermal": True}],
    # The violations the class found first: 'auto' on the machine, a spectrum's window past a short run, a
    # negative normal load in a law history.
    "laws": [
        {"kind": "machine", "law": {"model": "'coulomb'", "mu": 0.0, "mu_s": 0.0, "sigma2": 1.0}, "tool": tool,
         "method": method, "rtol": 1e-3, "end_factor": 1.0, "window": window, "points": 2, "count": 1,
         "mechanism": "belt", "variable": "belt_velocity",
         "machine": {"mass": 1.0, "stiffness": 1.0, "damping": 0.0, "normal": 1.0, "belt_velocity": -1.0, "v0": 0.0,
                     "x0": 0.0, "t_end": 1.0, "dt_out": 1.0, "steady_start": False}}
        for tool, method, window in (("none", "auto", 0.0), ("spectrum", "rodas4", 0.5),
                                     ("continuation", "rodas4", 0.0))],
    "law-capi": [[{"model": "coulomb", "sets": {}, "n": 1, "t": "increasing", "u": "sine", "amplitude": 1.0,
                   "normal": -1.0, "displacement": 0, "u_change": 0, "states_change": 0, "table": "table.txt"}]],
    "capi-values": [{"sets": [("tip.mass", "1e400", "bad")], "line_length_change": -1},
                    {"sets": [("surface.potential", "'\u00e9\udcff'", "bad")], "line_length_change": 0},
                    {"sets": [("tip.nonesuch", "1.0", "unknown")], "line_length_change": -7}],
}


def run_class(args, name, examples, derandomize):
    strategy, check, _ = CLASSES[name]
    contract = Contract(args, name)

    def property_holds(case):
        check(contract, case)

    for case in reversed(EXAMPLES.get(name, [])):
        property_holds = example(case)(property_holds)
    property_holds = settings(max_examples=examples, derandomize=derandomize, deadline=None, database=None,
                              suppress_health_check=list(HealthCheck), print_blob=True)(given(strategy)(property_holds))
    property_holds()
    return contract


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--binary", required=True)
    parser.add_argument("--stop-binary", default=None,
                        help="the program with a reporter that stops on cue (FRICTION_TEST_STOP_AFTER), for the "
                             "map checkpoints of newer-groups; without it those maps run uninterrupted")
    parser.add_argument("--mpiexec", required=True)
    parser.add_argument("--inputs", required=True)
    parser.add_argument("--library", default=None, help="libfriction, for the C API class")
    parser.add_argument("--workdir", required=True)
    parser.add_argument("--examples", type=int, default=None, help="cases per class (default: its budget)")
    parser.add_argument("--long", action="store_true", help="a long run: fresh random seeds, 10x the budget")
    parser.add_argument("classes", nargs="+", choices=sorted(CLASSES) + ["all"])
    args = parser.parse_args()
    # (Absolute: the cases run in directories of their own, and a relative
    # path, as scripts/fuzz gives, would name nothing there.)
    args.binary = os.path.abspath(args.binary)
    if args.stop_binary:
        args.stop_binary = os.path.abspath(args.stop_binary)
    args.inputs = os.path.abspath(args.inputs)
    args.workdir = os.path.abspath(args.workdir)
    if {"capi-values", "law-capi", "all"} & set(args.classes):
        if not args.library:
            parser.error("the classes capi-values and law-capi need --library")
        args.library = os.path.abspath(args.library)
    names = sorted(CLASSES) if "all" in args.classes else args.classes
    from_environment = os.environ.get("FRICTION_FUZZ_EXAMPLES")
    long_run = args.long or bool(from_environment)
    shutil.rmtree(args.workdir, ignore_errors=True)
    os.makedirs(args.workdir)
    start = time.monotonic()
    total = 0
    for name in names:
        examples = args.examples or (int(from_environment) if from_environment else None) or \
            CLASSES[name][2] * (10 if args.long else 1)
        contract = run_class(args, name, examples, derandomize=not long_run)
        total += contract.count
        print(contract.summary())
        if not long_run:
            shutil.rmtree(args.workdir, ignore_errors=True)
            os.makedirs(args.workdir)
    print(f"fuzz: {total} cases in {len(names)} classes, {time.monotonic() - start:.1f} s; "
          "crashes 0, contract violations 0")


if __name__ == "__main__":
    main()
