#!/usr/bin/env python3
"""Sang, Dube and Grant's beta fitted to the program's friction against velocity, against the barrier
shape parameter the program reports for the landscape (docs/physics.md, Barrier shapes beyond the
sinusoid).

    fourier_sang.py --binary build/friction [--input inputs/row_fourier_thermal.nml]
                    [--velocities 0.01,0.03,0.1,0.3,1,3,10,30] [--temperature K] [--jobs 2] [-o DIR]

Runs the input (a one-dimensional Fourier landscape with &thermal model = 'kramers') at each velocity,
fits F = F_c - (beta k_B T ln(v_c/v))^(2/3) through the mean friction and its standard error with
friction.thermal.fit_sang, and prints the table, the fit with its standard errors, and the file's
/surface beta and critical_friction (the landscape's own, at its fold) with the difference in
standard errors.  Measures and prints; asserts nothing.
"""
import argparse
import concurrent.futures
import math
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import h5py
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "python"))
from friction import thermal  # noqa: E402


def point(binary, source, velocity, seed, temperature, directory):
    out = Path(directory) / f"v{velocity:g}.h5"
    extra = ["--set", f"thermal.temperature={temperature!r}"] if temperature else []
    # (A seed per point: with one seed the points' noise is shared and the fit's chi2 means little.)
    subprocess.run([binary, "--quiet", "-f", "-o", str(out), source, "--set", f"scan.velocity={velocity!r}",
                    "--set", f"thermal.seed={seed}", *extra], check=True, capture_output=True, text=True)
    with h5py.File(out, "r") as f:
        friction, sem = f["afm/friction"][()], f["afm/friction_sem"][()]
        temperature = float(f["afm"].attrs["temperature"])
        shape = f["surface"].attrs
        return (float(np.mean(friction)), float(math.sqrt(np.sum(sem**2)) / sem.size), temperature,
                float(shape["beta"]), float(shape["critical_friction"]))


EV_NN = 1.602176634                       # nN per eV/A
N_PER_M = 1.0 / 1.602176634e-19 / 1e20    # eV/A^2 per N/m (and eV s/A^2 per N s/m)


def predicted(path, velocities):
    """The friction the reduced model should give at each velocity, from Kramers' overdamped rate with the
    landscape's own minimum, saddle and curvatures along the support's path before the fold (the jump
    forced where the barrier falls to 1 k_B T), as the mean energy a jump dissipates over a period: the
    curve Sang's law is fitted to, without the law's asymptotic approximation.  Trace only (+x), scan
    along x."""
    from scipy.optimize import brentq, minimize_scalar
    with h5py.File(path, "r") as f:
        c, s = f["surface/cosine"][()], f["surface/sine"][()]
        attrs = f["afm"].attrs
        a, k = float(attrs["ax"]), float(attrs["kx"]) * N_PER_M
        damping, kt = float(attrs["cx"]) * N_PER_M, float(attrs["temperature"]) * thermal.K_B
        x_fold = float(f["surface/fold/position"][0])
    kn = np.arange(1, c.size + 1) * 2.0 * np.pi / a

    def derivative(x, order):
        arg = kn * np.asarray(x, float)[..., None]
        terms = [-(c * np.cos(arg) + s * np.sin(arg)), kn * (c * np.sin(arg) - s * np.cos(arg)),
                 kn**2 * (c * np.cos(arg) + s * np.sin(arg))]
        return terms[order].sum(-1)

    def energy(X, x):
        return derivative(x, 0) + 0.5 * k * (x - X)**2

    def slope(X, x):
        return derivative(x, 1) + k * (x - X)
    # The fold: the maximum of V'(x) + k x near the reported one, and the support there.
    xc = minimize_scalar(lambda x: -float(derivative(x, 1) + k * x), bounds=(x_fold - 0.05 * a, x_fold + 0.05 * a),
                         method="bounded", options={"xatol": 1e-12}).x
    support = float(derivative(xc, 1) + k * xc) / k

    def roots(X, lo, hi, rising):
        x = np.linspace(lo, hi, 4001)
        e = slope(X, x)
        idx = np.nonzero((e[:-1] < 0) & (e[1:] >= 0) if rising else (e[:-1] > 0) & (e[1:] <= 0))[0]
        return [brentq(lambda t: float(slope(X, t)), x[i], x[i + 1], xtol=1e-13) for i in idx]
    xs = support - np.linspace(2.0, 0.0, 801)[:-1]
    rate, dissipated, barrier = [], [], []
    for X in xs:
        m = max(roots(X, xc - 0.5 * a, xc, True))
        sd = min(t for t in roots(X, m, xc + 0.5 * a, False) if t > m)
        land = min(roots(X, sd, sd + 1.5 * a, True))
        kw, kb = float(derivative(m, 2)) + k, float(derivative(sd, 2)) + k
        barrier.append(float(energy(X, sd) - energy(X, m)))
        rate.append(math.sqrt(kw * abs(kb)) / (2.0 * math.pi * damping) * math.exp(-barrier[-1] / kt))
        dissipated.append(float(energy(X, m) - energy(X, land)))
    barrier, rate, dissipated = np.array(barrier), np.array(rate), np.array(dissipated)
    inside = barrier > kt
    if not inside[0] or rate[0] * 2.0 / min(velocities) > 1e-3:
        return None
    curve = []
    for v in velocities:
        hazard = np.concatenate([[0.0], np.cumsum(0.5 * (rate[1:] + rate[:-1]) * np.diff(xs))]) / v
        survival = np.where(inside, np.exp(-hazard), 0.0)
        # E[D(X*)] = D(X_0) + integral of S(X) dD/dX (the jump forced at the floor with the rest).
        mean = dissipated[0] + np.sum(0.5 * (survival[1:] + survival[:-1]) * np.diff(dissipated))
        curve.append(mean / a * EV_NN)
    return np.array(curve)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--binary", required=True, help="the friction program")
    parser.add_argument("--input", default=str(Path(__file__).resolve().parent.parent / "inputs"
                                                / "row_fourier_thermal.nml"))
    parser.add_argument("--velocities", default="0.01,0.03,0.1,0.3,1,3,10,30", help="angstrom/s, comma-separated")
    parser.add_argument("--temperature", type=float, help="K, instead of the input's")
    parser.add_argument("--jobs", type=int, default=1, help="runs at once")
    parser.add_argument("-o", "--output", help="directory for the runs' files (default: a temporary one)")
    args = parser.parse_args()
    velocities = [float(v) for v in args.velocities.split(",")]
    with tempfile.TemporaryDirectory() as scratch:
        directory = args.output or scratch
        os.makedirs(directory, exist_ok=True)
        with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
            results = list(pool.map(lambda k: point(args.binary, args.input, velocities[k], k + 1, args.temperature,
                                                    directory), range(len(velocities))))
        curve = predicted(Path(directory) / f"v{velocities[0]:g}.h5", velocities)
    friction = np.array([r[0] for r in results])
    sem = np.array([r[1] for r in results])
    temperature, beta, critical = results[0][2], results[0][3], results[0][4]
    print(f"{'v (A/s)':>10} {'friction (nN)':>14} {'sem':>8}")
    for v, f, s in zip(velocities, friction, sem):
        print(f"{v:10.3g} {f:14.5f} {s:8.5f}")
    fit = thermal.fit_sang(np.array(velocities), friction, temperature, sem)
    b, db = fit.values["beta"], fit.errors["beta"]
    fc, dfc = fit.values["F_c"], fit.errors["F_c"]
    print(f"Sang fit at {temperature:g} K: beta = {b:.4f} +- {db:.4f} nN^1.5/eV, F_c = {fc:.4f} +- {dfc:.4f} nN, "
          f"v_c = {fit.values['v_c']:.4g} A/s, chi2/dof = {fit.chi2:.1f}/{fit.dof}")
    print(f"landscape: beta = {beta:.4f} nN^1.5/eV ({(b - beta) / db:+.2f} standard errors), "
          f"F_c = {critical:.4f} nN ({(fc - critical) / dfc:+.2f} standard errors)")
    if curve is not None:
        pfit = thermal.fit_sang(np.array(velocities), curve, temperature, sem)
        print("Kramers' rate on this landscape predicts: " + " ".join(f"{f:.5f}" for f in curve) + " nN")
        print(f"  (program - prediction)/sem: " + " ".join(f"{d:+.2f}" for d in (friction - curve) / sem))
        print(f"  Sang fit to the prediction: beta = {pfit.values['beta']:.4f} +- {pfit.errors['beta']:.4f}, "
              f"F_c = {pfit.values['F_c']:.4f} +- {pfit.errors['F_c']:.4f} nN")


if __name__ == "__main__":
    main()
