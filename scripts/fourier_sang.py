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


if __name__ == "__main__":
    main()
