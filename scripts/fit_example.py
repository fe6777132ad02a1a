#!/usr/bin/env python3
"""Fit V0 and the spring constant k of a NaF scan line to a "measured" one.

The paper's use of the software: adjust the model of the microscope to a
measured friction image.  Here the measurement is synthetic: the line the C
API computes for V0 = 0.8 eV and k = kx = ky = 6 N/m, plus Gaussian noise
of 0.05 nN (fixed seed).  Starting from V0 = 0.5 eV, k = 12 N/m, a
Nelder-Mead search over (log V0, log k) minimises the sum of squared
differences in fx.  scipy is not needed: the search is a few lines of numpy.

    fit_example.py [--check]      --check: exit 1 unless both are within 2 %

Prints the recovered values and their relative errors.
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import friction_capi  # noqa: E402

TRUE = {"v0": 0.8, "k": 6.0}
START = {"v0": 0.5, "k": 12.0}
NOISE = 0.05          # nN, standard deviation of the measurement noise
TOLERANCE = 0.02      # relative, on each recovered parameter
# One line of a map: the scene's defaults (inputs/naf.nml's values) but these.
SCENE = {"surface.potential": "naf", "scan.angle": 0.0, "scan.length": 20.0, "scan.nx": 128, "scan.ny": 1,
         "scan.retrace": False, "integrator.method": "rkf45", "integrator.rtol": 1.0e-6,
         "integrator.atol": 1.0e-7}
MODEL = friction_capi.Config("afm", values=SCENE)


def model_line(v0, k):
    """fx (nN) of the scene for potential amplitude v0 (eV) and springs k (N/m)."""
    MODEL.set("surface.v0", v0).set("tip.kx", k).set("tip.ky", k)
    fx, _ = MODEL.afm_line(0)
    return fx


def nelder_mead(f, x0, step=0.2, tolerance=1e-6, max_evaluations=400):
    """Minimise f from x0 (standard reflection/expansion/contraction/shrink)."""
    n = len(x0)
    simplex = [np.asarray(x0, float)] + [np.asarray(x0, float) + step * np.eye(n)[i] for i in range(n)]
    values = [f(x) for x in simplex]
    evaluations = n + 1
    while evaluations < max_evaluations:
        order = np.argsort(values)
        simplex = [simplex[i] for i in order]
        values = [values[i] for i in order]
        if abs(values[-1] - values[0]) <= tolerance * (abs(values[0]) + 1e-30) and \
                max(np.max(np.abs(x - simplex[0])) for x in simplex[1:]) < 1e-6:
            break
        centroid = np.mean(simplex[:-1], axis=0)
        reflected = centroid + (centroid - simplex[-1])
        f_reflected = f(reflected)
        evaluations += 1
        if f_reflected < values[0]:
            expanded = centroid + 2.0 * (centroid - simplex[-1])
            f_expanded = f(expanded)
            evaluations += 1
            simplex[-1], values[-1] = (expanded, f_expanded) if f_expanded < f_reflected else \
                (reflected, f_reflected)
        elif f_reflected < values[-2]:
            simplex[-1], values[-1] = reflected, f_reflected
        else:
            contracted = centroid + 0.5 * (simplex[-1] - centroid)
            f_contracted = f(contracted)
            evaluations += 1
            if f_contracted < values[-1]:
                simplex[-1], values[-1] = contracted, f_contracted
            else:
                for i in range(1, n + 1):
                    simplex[i] = simplex[0] + 0.5 * (simplex[i] - simplex[0])
                    values[i] = f(simplex[i])
                evaluations += n
    best = int(np.argmin(values))
    return simplex[best], values[best], evaluations


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help=f"fail unless within {TOLERANCE:.0%}")
    args = parser.parse_args()

    rng = np.random.default_rng(8)
    measured = model_line(TRUE["v0"], TRUE["k"])
    measured = measured + NOISE * rng.standard_normal(measured.size)

    def cost(p):
        return float(np.sum((model_line(np.exp(p[0]), np.exp(p[1])) - measured) ** 2))

    best, residual, evaluations = nelder_mead(cost, [np.log(START["v0"]), np.log(START["k"])])
    fitted = {"v0": float(np.exp(best[0])), "k": float(np.exp(best[1]))}
    print(f"friction {friction_capi.version()}: NaF line, {SCENE['scan.nx']} samples, noise {NOISE} nN")
    print(f"start  V0 = {START['v0']:.4f} eV, k = {START['k']:.4f} N/m")
    errors = {}
    for key, unit in (("v0", "eV"), ("k", "N/m")):
        errors[key] = abs(fitted[key] - TRUE[key]) / TRUE[key]
        print(f"{key:>5}: fitted {fitted[key]:.4f} {unit}, true {TRUE[key]:.4f} {unit}, "
              f"relative error {errors[key]:.2e}")
    rms = np.sqrt(residual / SCENE["scan.nx"])
    print(f"rms residual {rms:.4f} nN (noise {NOISE} nN), {evaluations} line evaluations")
    if args.check and not all(e <= TOLERANCE for e in errors.values()):
        print(f"FAIL: a parameter is off by more than {TOLERANCE:.0%}")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
