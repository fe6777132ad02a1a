#!/usr/bin/env python3
"""The slow regime of the thermal scene and the overdamped tip at T = 0, one case per CTest test.

    thermal_slow_test.py --binary BIN --inputs DIR --workdir DIR CASE

Cases:
  kramers-hang       the reduced model on a one-dimensional row (NaF with ay = 1000 A,
                     ax = 2.46 A, one realization, one line) ends, with its result, well
                     within max_wall_time; it used to search the same lost saddle forever
  kramers-wall-time  a reduced-model run of ~10 minutes (thermolubric, 1e-7 A/s) stops at
                     max_wall_time with exit code 4 and a message naming it
  kramers-stop       SIGTERM ends a single-line reduced-model run within the line (exit 6)
  kramers-cost       the up-front cost estimate warns about that run, and not about a
                     cheap one
  row                the one-dimensional row surface against NaF on its row of minima, and
                     its reduced model against its Langevin tip at 300 K
  overdamped-slips   the overdamped tip at T = 0 on a stiff 1-D row: each stepper at its
                     default tolerances either gives the friction of a tight reference or
                     stops with the premature-slip error

Each asserts on exit codes, messages and file contents; the times asserted are bounds a
hang or an unbounded loop would exceed by far (minutes against seconds), not speed targets.
"""
import argparse
import os
import shutil
import signal
import subprocess
import sys
import time

import h5py
import numpy as np


def fail(message):
    print("FAIL: " + message)
    sys.exit(1)


def write(args, name, text):
    path = os.path.join(args.workdir, name)
    with open(path, "w") as handle:
        handle.write(text)
    return path


def run(args, *rest, expect=0, timeout=600):
    cmd = [args.binary, *rest]
    start = time.monotonic()
    done = subprocess.run(cmd, cwd=args.workdir, capture_output=True, text=True, timeout=timeout)
    elapsed = time.monotonic() - start
    if done.returncode != expect:
        fail(f"{' '.join(cmd)} exited {done.returncode}, expected {expect}: {done.stderr}")
    return done.stderr, elapsed


# The reproduction: the paper's NaF tip without inertia on a 1-D row of
# period 2.46 A (ay = 1000 A makes the surface flat across the scan).
ROW = ("&surface ax = 2.46, ay = 1000.0 /\n"
       "&scan ny = 1 /\n"
       "&thermal realizations = 1 /\n")


def case_kramers_hang(args):
    base = os.path.join(args.inputs, "naf_thermal_velocity.nml")
    row = write(args, "row.nml", ROW + "&integrator max_wall_time = 60.0 /\n")
    stderr, elapsed = run(args, "--quiet", "-o", "row.h5", base, row, timeout=300)
    with h5py.File(os.path.join(args.workdir, "row.h5"), "r") as f:
        friction = f["afm/friction"][()]
        slips = f["afm/slips/support"].size
    # The bound: thermal activation lowers the friction below the v -> 0 limit at
    # T = 0 (the quasistatic tip on the same row, 2.54 nN).
    zero = write(args, "zero.nml", "&thermal temperature = 0.0 /\n&tip model = 'quasistatic' /\n")
    run(args, "--quiet", "-o", "zero.h5", base, row, zero)
    with h5py.File(os.path.join(args.workdir, "zero.h5"), "r") as f:
        limit = f["afm/friction"][()]
    if not (np.all(np.isfinite(friction)) and np.all(friction > 0.0) and np.all(friction < limit)):
        fail(f"friction {friction} nN: expected finite, positive and below the T = 0 limit {limit} nN")
    # On this row (eta = 10.4) the tip sticks and slips once per 2.46 A period:
    # 3 or 4 slips per 9.24 A trip.
    if slips < 6:
        fail(f"{slips} slips recorded, expected 6 to 8 (one per period and trip)")
    print(f"kramers on the 1-D row: {elapsed:.1f} s, friction {friction} nN (T = 0: {limit}), {slips} slips")


SLOW = "&scan velocity = 1.0e-7, ny = 1 /\n&thermal realizations = 4 /\n"


def case_kramers_wall_time(args):
    base = os.path.join(args.inputs, "naf_thermal_velocity.nml")
    slow = write(args, "slow.nml", SLOW + "&integrator max_wall_time = 3.0 /\n")
    stderr, elapsed = run(args, "--quiet", "-o", "slow.h5", base, slow, expect=4, timeout=600)
    for word in ["max_wall_time", "kramers", "line 0", "realization"]:
        if word not in stderr:
            fail(f"the message lacks {word!r}: {stderr}")
    if os.path.exists(os.path.join(args.workdir, "slow.h5")):
        fail("a failed run wrote its output")
    # Unbounded, this run takes some 10 minutes (110 s at 3e-7 A/s with 2 realizations,
    # scaled by 1/v and the realizations).
    if elapsed > 60.0:
        fail(f"the run took {elapsed:.1f} s to stop at max_wall_time = 3 s")
    print(f"stopped at max_wall_time = 3 s after {elapsed:.1f} s")


def case_kramers_stop(args):
    base = os.path.join(args.inputs, "naf_thermal_velocity.nml")
    slow = write(args, "slow.nml", SLOW)
    process = subprocess.Popen([args.binary, "-o", "slow.h5", base, slow], cwd=args.workdir,
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(3.0)
    if process.poll() is not None:
        fail(f"the run ended before the signal: {process.communicate()[1]}")
    signalled = time.monotonic()
    process.send_signal(signal.SIGTERM)
    _, stderr = process.communicate(timeout=300)
    elapsed = time.monotonic() - signalled
    if process.returncode != 6:
        fail(f"interrupted run exited {process.returncode}, expected 6: {stderr}")
    if "interrupted" not in stderr:
        fail(f"no message that the map was interrupted: {stderr}")
    # The trip looks at the request every 0.1 s of wall time (at each jump and
    # between hazard steps); seconds allow for a loaded machine.
    if elapsed > 20.0:
        fail(f"the run took {elapsed:.1f} s to stop after SIGTERM")
    print(f"stopped {elapsed:.2f} s after SIGTERM")


def case_kramers_cost(args):
    base = os.path.join(args.inputs, "naf_thermal_velocity.nml")
    # (max_wall_time above the estimate's 5 s sample, which it also bounds)
    slow = write(args, "slow.nml", SLOW + "&integrator max_wall_time = 10.0 /\n")
    stderr, _ = run(args, "-o", "slow.h5", base, slow, expect=4, timeout=600)
    lines = [line for line in stderr.splitlines() if "s of computing per process" in line]
    if len(lines) != 1 or "1/(v c)" not in lines[0]:
        fail(f"no cost warning before a run of minutes: {stderr}")
    estimate = float(lines[0].split("s of computing")[0].split()[-1])
    if estimate < 60.0:
        fail(f"the estimate {estimate} s is below the warning's limit of 60 s")
    fast = write(args, "fast.nml", "&scan ny = 1 /\n&thermal realizations = 2 /\n")
    stderr, _ = run(args, "-o", "fast.h5", base, fast)
    if "computing per process" in stderr:
        fail(f"a cost warning for a run of a second: {stderr}")
    print(f"estimate {estimate} s for the slow run")


# The T = 0 mapping: NaF with ay = 1e4 A (a 1-D row), V0 = 0.165 eV, a = 4 A,
# k = 0.86 N/m, c = 1e-6 N s/m, the overdamped tip, 128 samples over 4 periods after
# a lead-in of one period, trace and retrace; no &integrator group.
T0_ROW = """&job scene = 'afm' /
&surface potential = 'naf', v0 = 0.165, ax = 4.0, ay = 1.0e4 /
&tip model = 'overdamped', kx = 0.86, ky = 0.86, cx = 1.0e-6, cy = 1.0e-6 /
&scan velocity = 10.0, length = 16.0, width = 0.0, nx = 128, ny = 1, lead_in = 4.0 /
"""
STEPPERS = ["rkf45", "rkck", "rk8pd", "rk2", "rk4", "msadams", "rk2imp", "rk4imp", "bsimp", "msbdf", "rodas4"]


def case_overdamped_slips(args):
    row = write(args, "row.nml", T0_ROW)
    # The oracle: the quasistatic tip (the v -> 0 limit, which the overdamped tip
    # at 10 A/s follows: it lags its minimum by v c/k = 1.2e-5 A) and rk8pd at
    # rtol = atol = 1e-9.
    run(args, "--quiet", "-o", "qs.h5", row, "--set", "tip.model='quasistatic'")
    with h5py.File(os.path.join(args.workdir, "qs.h5"), "r") as f:
        quasistatic = float(f["afm/friction"][0])
    run(args, "--quiet", "-o", "ref.h5", row, "--set", "integrator.method='rk8pd'",
        "--set", "integrator.rtol=1e-9", "--set", "integrator.atol=1e-9")
    with h5py.File(os.path.join(args.workdir, "ref.h5"), "r") as f:
        reference = float(f["afm/friction"][0])
        forces = np.concatenate([f["afm/trace/f_along"][0], f["afm/retrace/f_along"][0]])
    # Their difference is the lag's, ~1e-6 of the friction.
    if abs(reference - quasistatic) > 1e-4 * reference:
        fail(f"reference {reference} and quasistatic {quasistatic} nN differ")
    caught = []
    for method in STEPPERS:
        out = f"{method}.h5"
        done = subprocess.run([args.binary, "--quiet", "-o", out, row, "--set", f"integrator.method='{method}'"],
                              cwd=args.workdir, capture_output=True, text=True, timeout=600)
        if done.returncode == 0:
            with h5py.File(os.path.join(args.workdir, out), "r") as f:
                value = float(f["afm/friction"][0])
                worst = np.max(np.abs(np.concatenate([f["afm/trace/f_along"][0], f["afm/retrace/f_along"][0]])
                                      - forces))
            # A slip a sample early or late, or at a wrong site, is an error of
            # 0.1 to 0.3 nN at that sample (the force drops by 0.27 nN at a slip);
            # the tolerances' own error is k (atol + rtol |u|) = 4e-4 nN a sample,
            # a few times that over a trip (rk4imp: 3.7e-3 nN, a smooth bias).
            if worst > 0.02 or abs(value - reference) > 5e-3:
                fail(f"{method} at its default tolerances: {value} nN against {reference} nN, a sample off by "
                     f"{worst} nN, not flagged")
            # A bias with every slip in its place (rk4imp: 1.1e-3 nN on the friction,
            # the tip 17 times its tolerances' bound from where it follows its minimum)
            # is warned about; a stepper within 1e-4 nN of the reference is not.
            warned = "times the tolerances' bound" in done.stderr
            if abs(value - reference) > 5e-4 and not warned:
                fail(f"{method}: {value} nN against {reference} nN, a bias not warned about: {done.stderr}")
            if abs(value - reference) < 1e-4 and warned:
                fail(f"{method}: {value} nN against {reference} nN, warned about a bias: {done.stderr}")
            if warned:
                caught.append(method)
            print(f"{method}: {value:.6f} nN (reference {reference:.6f}), worst sample {worst:.2e} nN"
                  + (", bias warned" if warned else ""))
        elif done.returncode == 4:
            error = [line for line in done.stderr.splitlines() if "error:" in line]
            if len(error) != 1 or not ("overdamped tip at T = 0" in error[0] and ("slipped" in error[0] or "not slipped" in error[0])
                                       or "max_steps" in error[0]):
                fail(f"{method} failed without naming the slip or the step budget: {done.stderr}")
            caught.append(method)
            print(f"{method}: flagged: {error[0][:200]}")
        else:
            fail(f"{method} exited {done.returncode}: {done.stderr}")
    # rkf45 (the default), rkck and rk4 are the ones that go wrong here (premature
    # slips at the explicit pairs' stability limit); bsimp skips a site; rk4imp is
    # biased.
    for method in ("rkf45", "bsimp", "rk4imp"):
        if method not in caught:
            fail(f"{method} was expected to be flagged on this case")


def case_row(args):
    """&surface potential = 'row' (-V0 cos(2 pi x/ax), flat across) against NaF
    on its row of minima (y = 0, where Eq. 1 is the row exactly and the tip
    stays on it); at 300 K the reduced model against the Langevin tip on it."""
    naf = os.path.join(args.inputs, "naf.nml")
    one = write(args, "one.nml", "&scan ny = 1, width = 0.0 /\n")
    row = write(args, "row.nml", "&surface potential = 'row' /\n")
    tight = write(args, "tight.nml", "&integrator method = 'rk8pd', rtol = 1e-10, atol = 1e-10 /\n")
    for model, extra, bound in (("quasistatic", [], 1e-12), ("inertial", [tight], 1e-9)):
        files = []
        for name, surface in (("naf", []), ("row", [row])):
            out = f"{name}_{model}.h5"
            run(args, "--quiet", "-o", out, naf, one, *surface, *extra, "--set", f"tip.model='{model}'")
            files.append(os.path.join(args.workdir, out))
        with h5py.File(files[0], "r") as a, h5py.File(files[1], "r") as b:
            worst = max(np.max(np.abs(a[f"afm/{trip}/f_along"][()] - b[f"afm/{trip}/f_along"][()]))
                        for trip in ("trace", "retrace"))
            if np.any(b["afm/trace/tip_y"][()] != 0.0) or b["afm"].attrs["potential"] != b"row":
                fail("the row's tip left y = 0 or the file does not name the row")
        # The same equations to rounding (sin against the C library's sincos):
        # 3e-15 nN measured quasistatic, 8.5e-13 nN inertial at rtol = atol = 1e-10.
        if worst > bound:
            fail(f"{model}: row and NaF's row of minima differ by {worst} nN (bound {bound})")
        print(f"{model}: row against NaF's row, largest difference {worst:.1e} nN")
    base = os.path.join(args.inputs, "naf_thermal_velocity.nml")
    thermal = write(args, "thermal.nml", "&surface potential = 'row', ax = 2.46 /\n&scan ny = 1, velocity = 30.0 /\n"
                    "&thermal realizations = 4 /\n")
    results = {}
    for model in ("kramers", "langevin"):
        run(args, "--quiet", "-o", f"{model}.h5", base, thermal, "--set", f"thermal.model='{model}'")
        with h5py.File(os.path.join(args.workdir, f"{model}.h5"), "r") as f:
            results[model] = (float(f["afm/friction"][0]), float(f["afm/friction_sem"][0]))
    (mk, sk), (ml, sl) = results["kramers"], results["langevin"]
    # Measured 2.314 +- 0.052 against 2.250 +- 0.046 nN: 0.9 combined standard errors.
    if abs(mk - ml) > 3.0 * np.hypot(sk, sl):
        fail(f"on the row at 300 K: kramers {mk} +- {sk}, langevin {ml} +- {sl} nN, beyond 3 standard errors")
    print(f"row at 300 K, 30 A/s: kramers {mk:.4f} +- {sk:.4f}, langevin {ml:.4f} +- {sl:.4f} nN")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--binary", required=True)
    parser.add_argument("--inputs", required=True)
    parser.add_argument("--workdir", required=True)
    parser.add_argument("case")
    args = parser.parse_args()
    shutil.rmtree(args.workdir, ignore_errors=True)
    os.makedirs(args.workdir)
    {"kramers-hang": case_kramers_hang, "kramers-wall-time": case_kramers_wall_time,
     "kramers-stop": case_kramers_stop, "kramers-cost": case_kramers_cost,
     "overdamped-slips": case_overdamped_slips, "row": case_row}[args.case](args)
    print("1 passed, 0 failed")


if __name__ == "__main__":
    main()
