#!/usr/bin/env python3
"""Fit V0 and the spring constant k of a NaF scan line to a "measured" one.

The paper's use of the software: adjust the model of the microscope to a
measured friction image.  Here the measurement is synthetic: the line the C
API computes for V0 = 0.8 eV and k = kx = ky = 6 N/m, plus Gaussian noise
of 0.05 nN (fixed seed).  Starting from V0 = 0.5 eV, k = 12 N/m, scipy's
least_squares over (log V0, log k) minimises the sum of squared differences
in fx, and the Jacobian gives each parameter's standard error.

    fit_example.py [--check]      --check: exit 1 unless both are within 2 %

Prints the recovered values and their relative errors.  A command line over
friction.fit.example and friction.fit.fit_line (python/friction/fit.py).
"""
import argparse
import sys
from pathlib import Path

# The package beside the scripts: python/ in the repository, share/friction/python when installed.
_PACKAGE = Path(__file__).resolve().parent.parent / "python"
if _PACKAGE.is_dir():
    sys.path.insert(0, str(_PACKAGE))

import friction  # noqa: E402
import friction.fit  # noqa: E402

TRUE = {"v0": 0.8, "k": 6.0}
START = {"v0": 0.5, "k": 12.0}
NOISE = 0.05          # nN, standard deviation of the measurement noise
TOLERANCE = 0.02      # relative, on each recovered parameter


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help=f"fail unless within {TOLERANCE:.0%}".replace("%", "%%"))   # argparse formats help with %
    args = parser.parse_args(argv)

    result, _ = friction.fit.example((TRUE["v0"], TRUE["k"]), (START["v0"], START["k"]), NOISE)
    fitted = {"v0": result.values["surface.v0"], "k": result.values[("tip.kx", "tip.ky")]}
    nx = friction.fit.NAF_LINE["scan.nx"]
    print(f"friction {friction.library_version()}: NaF line, {nx} samples, noise {NOISE} nN")
    print(f"start  V0 = {START['v0']:.4f} eV, k = {START['k']:.4f} N/m")
    errors = {}
    for key, unit in (("v0", "eV"), ("k", "N/m")):
        errors[key] = abs(fitted[key] - TRUE[key]) / TRUE[key]
        se = result.errors["surface.v0" if key == "v0" else ("tip.kx", "tip.ky")]
        print(f"{key:>5}: fitted {fitted[key]:.4f} {unit}, true {TRUE[key]:.4f} {unit}, "
              f"relative error {errors[key]:.2e}, standard error {se:.4f} {unit}")
    print(f"rms residual {result.rms:.4f} nN (noise {NOISE} nN), {result.evaluations} line evaluations")
    if args.check and not all(e <= TOLERANCE for e in errors.values()):
        print(f"FAIL: a parameter is off by more than {TOLERANCE:.0%}")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
