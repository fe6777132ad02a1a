#!/usr/bin/env python3
"""Thermal friction in the experimentalists' terms, one case per CTest test.

    thermal_experiment_test.py --binary BIN --workdir DIR CASE

Cases:
  attempt-frequency  &thermal attempt_frequency gives the same file, bit for bit, as the
                     damping it stands for (overdamped reduced model, inertial Langevin tip),
                     that damping is the formula's, and the input errors name file and line
  attempt-fit        the attempt frequency a fit of the program's friction against velocity
                     implies matches the one given, within the fit's standard errors
  loop-forces        each line's mean |F| and mean peak force of the friction loop, and a
                     sweep's, against the same reduction of the written f_along arrays
  kramers-slips      the reduced model's slips record the barrier and prefactor of the exit
                     taken, against the one-dimensional landscape at the recorded support
"""
import argparse
import math
import os
import subprocess
import sys

import h5py
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python"))
import friction.thermal as thermal  # noqa: E402

#: N/m in the program's internal unit, eV/A^2 (1 N/m = 0.06241509 eV/A^2).
N_PER_M = 1.0 / 1.602176634e-19 / 1.0e20
#: The root attributes that differ between two runs of the same input: when, how long, the echo.
VOLATILE = {"created", "wall_time", "wall_time_units", "input"}


def fail(message):
    print("FAIL: " + message)
    sys.exit(1)


def write(args, name, text):
    path = os.path.join(args.workdir, name)
    with open(path, "w") as handle:
        handle.write(text)
    return path


def run(args, *rest, expect=0):
    cmd = [args.binary, "--quiet", "--force", *rest]
    done = subprocess.run(cmd, cwd=args.workdir, capture_output=True, text=True, timeout=600)
    if done.returncode != expect:
        fail(f"{' '.join(cmd)} exited {done.returncode}, expected {expect}: {done.stderr}")
    return done.stderr


def same_files(one, two):
    """Every dataset and attribute of two files equal bit for bit, VOLATILE root attributes aside."""
    with h5py.File(one, "r") as a, h5py.File(two, "r") as b:
        names_a, names_b = [], []
        a.visit(names_a.append)
        b.visit(names_b.append)
        if names_a != names_b:
            fail(f"{one} and {two} hold different objects: {set(names_a) ^ set(names_b)}")
        for name in ["/"] + names_a:
            attrs_a, attrs_b = dict(a[name].attrs), dict(b[name].attrs)
            keys = set(attrs_a) | set(attrs_b)
            if name == "/":
                keys -= VOLATILE
            for key in sorted(keys):
                if key not in attrs_a or key not in attrs_b:
                    fail(f"{name} attribute {key} in one file only")
                x, y = np.asarray(attrs_a[key]), np.asarray(attrs_b[key])
                if x.dtype.hasobject or y.dtype.hasobject:
                    continue  # dimension-scale references: where, not what
                if x.tobytes() != y.tobytes():
                    fail(f"{name} attribute {key}: {x} against {y}")
            if isinstance(a[name], h5py.Dataset):
                x, y = a[name][()], b[name][()]
                if np.asarray(x).dtype.kind == "O":
                    continue  # dimension-scale references: where, not what
                if np.asarray(x).tobytes() != np.asarray(y).tobytes():
                    fail(f"{name} differs between {one} and {two}")


# A one-dimensional row with a soft spring: K = 4 pi^2 V0/ax^2 = 19.77 N/m, eta = 19.8.
ROW = ("&surface potential = 'row', v0 = 0.5, ax = 4.0 /\n"
       "&tip model = '{model}', kx = 1.0, ky = 1.0 /\n"
       "&scan velocity = {velocity}, length = 8.0, lead_in = 2.0, nx = 33, ny = 1, width = 0.0 /\n")


def case_attempt_frequency(args):
    curvature = 4.0 * math.pi ** 2 * 0.5 / 4.0 ** 2 / N_PER_M   # N/m
    spring, mass = 1.0, 1.0e-8
    # (The inertial tip of 1e-8 kg has 7.25 kHz in the well: its f0 must be below.)
    for model, thermal_model, velocity, f0 in (("overdamped", "kramers", 10.0, 1.0e6),
                                               ("inertial", "langevin", 1.0e5, 1.0e3)):
        expected = math.sqrt(curvature ** 2 - spring ** 2) / (2.0 * math.pi * f0)
        if model == "inertial":
            # Kramers' moderate-to-strong damping prefactor solved for gamma = c/m.
            w, b = math.sqrt((curvature + spring) / mass), math.sqrt((curvature - spring) / mass)
            lam = 2.0 * math.pi * f0 * b / w
            expected = mass * (b * b - lam * lam) / lam
        base = write(args, f"{model}.nml", ROW.format(model=model, velocity=velocity)
                     + f"&thermal temperature = 300.0, model = '{thermal_model}', realizations = 2 /\n")
        given = write(args, f"{model}_f0.nml", f"&thermal attempt_frequency = {f0!r} /\n")
        run(args, "-o", f"{model}_f0.h5", base, given)
        with h5py.File(os.path.join(args.workdir, f"{model}_f0.h5"), "r") as f:
            cx, cy = float(f["afm"].attrs["cx"]), float(f["afm"].attrs["cy"])
        # The formula in Python against the program's, to rounding (a few ulp of a sqrt and a quotient).
        if cx != cy or abs(cx - expected) > 1e-13 * expected:
            fail(f"{model}: attempt_frequency = {f0} ran with cx = {cx!r}, cy = {cy!r}; the formula gives {expected!r}")
        run(args, "-o", f"{model}_c.h5", base, "--set", f"tip.cx={cx!r}", "--set", f"tip.cy={cy!r}")
        same_files(os.path.join(args.workdir, f"{model}_f0.h5"), os.path.join(args.workdir, f"{model}_c.h5"))
        print(f"{model} ({thermal_model}): attempt_frequency = {f0:g} Hz runs cx = cy = {cx:.6e} N s/m, "
              f"the same file as that damping")

    base = write(args, "base.nml", ROW.format(model="overdamped", velocity=10.0)
                 + "&thermal temperature = 300.0, model = 'kramers' /\n")
    # Both the attempt frequency and a damping: refused, naming the file and line of attempt_frequency.
    both = write(args, "both.nml", "&tip cx = 1e-6 /\n&thermal\n  attempt_frequency = 1e6\n/\n")
    stderr = run(args, "-o", "both.h5", base, both, expect=3)
    if "both.nml:3: &thermal: attempt_frequency" not in stderr or "cx" not in stderr:
        fail(f"attempt_frequency with cx: {stderr!r}")
    stderr = run(args, "-o", "both.h5", base, "--set", "thermal.attempt_frequency=1e6", "--set", "tip.cy=1e-6",
                 expect=3)
    if "&thermal: attempt_frequency" not in stderr:
        fail(f"attempt_frequency with --set tip.cy: {stderr!r}")
    # A spring stiffer than the surface's curvature: the tip at rest has no barrier.
    stderr = run(args, "-o", "both.h5", base, "--set", "thermal.attempt_frequency=1e6", "--set", "tip.kx=30",
                 expect=3)
    if "attempt_frequency" not in stderr or "no barrier" not in stderr:
        fail(f"attempt_frequency with kx > K: {stderr!r}")
    # The inertial tip cannot have a prefactor above its frequency in the well.
    stderr = run(args, "-o", "both.h5", base, "--set", "tip.model='inertial'", "--set",
                 "thermal.model='langevin'", "--set", "thermal.attempt_frequency=1e9", expect=3)
    if "attempt_frequency" not in stderr or "frequency in the well" not in stderr:
        fail(f"attempt_frequency above the well's frequency: {stderr!r}")
    if os.path.exists(os.path.join(args.workdir, "both.h5")):
        fail("a refused input wrote its output")
    print("attempt_frequency with cx or cy, with k > K and above the well's frequency: refused (exit 3)")


def case_attempt_fit(args):
    """The formula of docs/physics.md (The attempt frequency): Sang et al.'s law with the
    exponent 3/2 and F_c the quasistatic friction, fitted as the logarithmic law of
    (F_c - F)^(3/2) against ln v, gives v_c, and f0 = sqrt(K^2 - k^2) k v_c/(e^gamma s k_B T)."""
    v0, ax, spring, f0, temperature = 2.0, 4.0, 15.8, 1.0e6, 300.0
    velocities = np.array([0.01, 0.3, 10.0, 300.0])
    row = ("&surface potential = 'row', v0 = 2.0, ax = 4.0 /\n"
           "&tip model = '{model}', kx = 15.8, ky = 15.8 /\n"
           "&scan velocity = {velocity!r}, length = 12.0, lead_in = 4.0, nx = 96, ny = 1, width = 0.0 /\n")
    write(args, "zero.nml", row.format(model="quasistatic", velocity=1.0))
    run(args, "-o", "zero.h5", "zero.nml")
    with h5py.File(os.path.join(args.workdir, "zero.h5"), "r") as f:
        f_c = float(f["afm/friction"][0])
    friction, sem = [], []
    for v in velocities:
        write(args, "hot.nml", row.format(model="overdamped", velocity=float(v))
              + f"&thermal temperature = {temperature}, model = 'kramers', realizations = 8, "
                f"attempt_frequency = {f0!r} /\n")
        run(args, "-o", "hot.h5", "hot.nml")
        with h5py.File(os.path.join(args.workdir, "hot.h5"), "r") as f:
            friction.append(float(f["afm/friction"][0]))
            sem.append(float(f["afm/friction_sem"][0]))
            damping = float(f["afm"].attrs["cx"])
    friction, sem = np.array(friction), np.array(sem)
    if not np.all(friction < f_c):
        fail(f"friction {friction} nN not below the quasistatic {f_c} nN")
    y = (f_c - friction) ** 1.5
    fit = thermal.fit_log(velocities, y, temperature, 1.5 * np.sqrt(f_c - friction) * sem)
    a, b = fit.values["F_0[0]"], fit.values["F_1[0]"]
    gradient = np.array([-1.0 / b, a / b ** 2])
    ln_vc, ln_vc_se = -a / b, math.sqrt(gradient @ fit.covariance @ gradient)
    curvature = 4.0 * math.pi ** 2 * v0 / ax ** 2 / N_PER_M
    eta = curvature / spring
    s = 0.5 * v0 * (2.0 * math.pi / ax) ** 3 * math.sqrt(1.0 - 1.0 / eta ** 2)    # eV/A^3
    kt = thermal.K_B * temperature
    gamma_e = 0.5772156649015329
    # (eV, A and s throughout: the curvatures in eV/A^2.)
    implied = math.sqrt(curvature ** 2 - spring ** 2) * N_PER_M * spring * N_PER_M * math.exp(ln_vc) \
        / (math.exp(gamma_e) * s * kt)
    z = math.log(implied / f0) / ln_vc_se
    print(f"F_c = {f_c:.5f} nN; friction {np.round(friction, 4)} +- {np.round(sem, 4)} nN at {velocities} A/s; "
          f"damping {damping:.5e} N s/m")
    print(f"fitted v_c = {math.exp(ln_vc):.4g} A/s (se of ln v_c {ln_vc_se:.3f}, chi2 {fit.chi2:.2f} for "
          f"{fit.dof}); implied f0 = {implied:.4g} Hz against {f0:g}: {z:+.2f} standard errors")
    # 3 standard errors: the formula is the asymptote near the fold; on this row
    # it is 2.4 standard errors of a four times larger run low (docs/physics.md).
    # Read as f0 = k/(2 pi c) the same fit is a factor 4.9 off (4.5 standard
    # errors here), without the 2 pi a factor 6.3 (5.2).
    if not abs(z) < 3.0:
        fail(f"implied f0 = {implied:.4g} Hz is {z:+.2f} standard errors from the {f0:g} Hz given")


def loop_oracle(trace, retrace):
    """Per line, from the force arrays alone: the mean |F| over both trips, and the peaks,
    the force where a run of falling samples begins that falls by more than a quarter of
    the trip's range (met in the order of the support's motion, the retrace's force
    against the motion -F), pooled over both trips; a trip without one gives its
    largest force against the motion."""
    mean_abs = 0.5 * (np.mean(np.abs(trace), axis=1) + np.mean(np.abs(retrace), axis=1))
    peaks = []
    for j in range(trace.shape[0]):
        found = []
        for force in (trace[j], -retrace[j][::-1]):
            before = len(found)
            least = 0.25 * (force.max() - force.min())
            falling = np.diff(force) < 0.0
            k = 0
            while k < falling.size:
                if not falling[k]:
                    k += 1
                    continue
                end = k
                while end < falling.size and falling[end]:
                    end += 1
                if force[k] - force[end] > least:
                    found.append(force[k])
                k = end
            if len(found) == before:
                found.append(force.max())   # no slip: the trip's top
        peaks.append(found)
    return mean_abs, peaks


def case_loop_forces(args):
    """/afm/mean_abs_force and /afm/peak_force against the same reduction of the written
    f_along arrays, on the paper's NaF map (deterministic), a Langevin map and a sweep."""
    naf = "&surface potential = 'naf' /\n&scan nx = 128, ny = 3, velocity = 400.0 /\n"
    write(args, "naf.nml", naf)
    write(args, "hot.nml", naf + "&tip model = 'overdamped' /\n&thermal temperature = 300.0, realizations = 2 /\n")
    for name in ("naf", "hot"):
        run(args, "-o", f"{name}.h5", f"{name}.nml")
        with h5py.File(os.path.join(args.workdir, f"{name}.h5"), "r") as f:
            trace, retrace = f["afm/trace/f_along"][()], f["afm/retrace/f_along"][()]
            mean_abs, peak = f["afm/mean_abs_force"][()], f["afm/peak_force"][()]
            unit = f["afm/peak_force"].attrs["units"]
        want_abs, peaks = loop_oracle(trace, retrace)
        want_peak = np.array([np.mean(p) for p in peaks])
        # The same sums in another order: a few ulp of forces of order 1 nN.
        if not np.allclose(mean_abs, want_abs, rtol=1e-12, atol=1e-14):
            fail(f"{name}: mean_abs_force {mean_abs} against {want_abs} from f_along")
        if not (np.allclose(peak, want_peak, rtol=1e-12, atol=1e-14) and np.all(np.isfinite(peak))):
            fail(f"{name}: peak_force {peak} against {want_peak} from f_along")
        # NaF at 400 A/s sticks and slips at least once per 4.62 A (twice between the
        # rows of minima): 4 or more slips a trip over 20 A, 8 a line.  (The mean of
        # two realizations at 300 K may fall in two steps where they slip apart.)
        counts = [len(p) for p in peaks]
        if name == "naf" and not all(8 <= c <= 20 for c in counts):
            fail(f"{name}: {counts} peaks per line over trace and retrace, expected 8 to 20")
        if unit not in ("nN", b"nN"):
            fail(f"{name}: peak_force in {unit!r}")
        # Below the peaks lies the mean |F|; above it the friction.
        with h5py.File(os.path.join(args.workdir, f"{name}.h5"), "r") as f:
            friction = f["afm/friction"][()]
        if not (np.all(friction <= mean_abs) and np.all(mean_abs < peak)):
            fail(f"{name}: friction {friction}, mean |F| {mean_abs}, peak {peak} out of order")
        print(f"{name}: mean |F| {np.round(mean_abs, 4)} nN, peak {np.round(peak, 4)} nN "
              f"({counts} peaks), as from f_along")
    # A sweep's points: the same reduction over the whole map of each point.
    write(args, "sweep.nml", naf.replace("ny = 3", "ny = 2")
          + "&sweep sweep_variable = 'scan.velocity', sweep_values = 100.0, 1000.0 /\n")
    run(args, "-o", "sweep.h5", "sweep.nml")
    with h5py.File(os.path.join(args.workdir, "sweep.h5"), "r") as f:
        swept_abs, swept_peak = f["sweep/mean_abs_force"][()], f["sweep/peak_force"][()]
    for i, velocity in enumerate((100.0, 1000.0)):
        run(args, "-o", "point.h5", "naf.nml", "--set", "scan.ny=2", "--set", f"scan.velocity={velocity}")
        with h5py.File(os.path.join(args.workdir, "point.h5"), "r") as f:
            trace, retrace = f["afm/trace/f_along"][()], f["afm/retrace/f_along"][()]
        want_abs, peaks = loop_oracle(trace, retrace)
        pooled = [p for line in peaks for p in line]
        if not (math.isclose(swept_abs[i], np.mean(want_abs), rel_tol=1e-12)
                and math.isclose(swept_peak[i], np.mean(pooled), rel_tol=1e-12)):
            fail(f"sweep point {i}: mean_abs_force {swept_abs[i]}, peak_force {swept_peak[i]} against "
                 f"{np.mean(want_abs)}, {np.mean(pooled)} from the map's f_along")
    print(f"sweep: mean_abs_force {swept_abs}, peak_force {swept_peak} nN, as from each point's map")


def case_kramers_slips(args):
    """Each slip of the reduced model on a one-dimensional row (flat across, so the tip's
    minimum and saddles lie on y = 0) records the barrier and the rate prefactor of the
    exit it took: against the 1-D landscape E(x) = -V0 cos(2 pi x/a) + k (x - X)^2/2 at
    the recorded support X, with the minimum x_w = X - F/k from the recorded force F and
    the saddle next to it on the side of the jump, solved here by Newton's method:
    barrier E(x_s) - E(x_w), prefactor sqrt(E''(x_w) |E''(x_s)|)/(2 pi c) (Smoluchowski;
    the spring across, the same at both points, cancels)."""
    v0, a, spring = 0.5, 4.0, 1.0
    write(args, "slips.nml", ROW.format(model="overdamped", velocity=10.0).replace("length = 8.0", "length = 16.0")
          + "&thermal temperature = 300.0, model = 'kramers', realizations = 4, attempt_frequency = 1e6 /\n")
    run(args, "-o", "slips.h5", "slips.nml")
    with h5py.File(os.path.join(args.workdir, "slips.h5"), "r") as f:
        slips = {key: f["afm/slips"][key][()] for key in ("trip", "support", "force", "jump", "barrier", "prefactor")}
        units = (f["afm/slips/barrier"].attrs["units"], f["afm/slips/prefactor"].attrs["units"])
        damping = float(f["afm"].attrs["cx"]) * N_PER_M     # eV s/A^2
    k = spring * N_PER_M
    q = 2.0 * math.pi / a

    def de(x, support):
        return v0 * q * math.sin(q * x) + k * (x - support)

    def d2e(x):
        return v0 * q * q * math.cos(q * x) + k

    def energy(x, support):
        return -v0 * math.cos(q * x) + 0.5 * k * (x - support) ** 2

    def newton(x, support):
        for _ in range(100):
            step = de(x, support) / d2e(x)
            x -= step
            if abs(step) < 1e-14:
                break
        return x

    n = slips["support"].size
    if n < 16 or tuple(u.decode() if isinstance(u, bytes) else u for u in units) != ("eV", "1/s"):
        fail(f"{n} slips (expected 4 a trip), units {units}")
    worst = [0.0, 0.0]
    for i in range(n):
        support, force = slips["support"][i], slips["force"][i]
        well = newton(support - force / (spring * 0.1), support)    # F = k (X - x), k in nN/A
        motion = 1.0 if slips["trip"][i] == 0 else -1.0
        ahead = motion * math.copysign(1.0, slips["jump"][i])
        saddle = newton(well + ahead * 0.4 * a, support)
        if not (d2e(well) > 0 and d2e(saddle) < 0 and 0 < ahead * (saddle - well) < a):
            fail(f"slip {i}: no well and saddle found at X = {support} (x_w {well}, x_s {saddle})")
        barrier = energy(saddle, support) - energy(well, support)
        prefactor = math.sqrt(d2e(well) * -d2e(saddle)) / (2.0 * math.pi * damping)
        errors = (abs(slips["barrier"][i] - barrier), abs(slips["prefactor"][i] / prefactor - 1.0))
        worst = [max(w, e) for w, e in zip(worst, errors)]
    # The program's points are converged Newton iterates: the barrier is quadratic in
    # their error, the prefactor linear (the third derivative times it over the second).
    if not (worst[0] < 1e-9 and worst[1] < 1e-7):
        fail(f"barrier off by up to {worst[0]:.2e} eV, prefactor by {worst[1]:.2e} (relative)")
    if not np.all(slips["barrier"] > 0.0):
        fail("a slip at zero barrier where no minimum vanishes")
    print(f"{n} slips: barriers {slips['barrier'].min():.4f} to {slips['barrier'].max():.4f} eV, prefactors "
          f"{slips['prefactor'].min():.4g} to {slips['prefactor'].max():.4g} /s; against the 1-D landscape "
          f"within {worst[0]:.1e} eV and {worst[1]:.1e}")


CASES = {"attempt-frequency": case_attempt_frequency, "attempt-fit": case_attempt_fit,
         "loop-forces": case_loop_forces, "kramers-slips": case_kramers_slips}


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--binary", required=True)
    parser.add_argument("--workdir", required=True)
    parser.add_argument("case", choices=sorted(CASES))
    args = parser.parse_args()
    os.makedirs(args.workdir, exist_ok=True)
    CASES[args.case](args)
    print("PASS")


if __name__ == "__main__":
    main()
