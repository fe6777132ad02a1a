#!/usr/bin/env python3
"""Dahl's law at a Coulomb level F_c far below the mechanism's forces, on
the brake (&brake model = 'law', inputs/brake_lugre.nml's mechanism and
stepper, rodas4): the run completes and its motion is that of the
frictionless brake, the limit F_c -> 0, whose exact solution is the
exponential of the linear system (SciPy's expm).

At v_rel = 0 Dahl's deflection has no stiffness, σ0 |v| / F_c vanishes
with |v|: the first step (1e-3 τ) left the rest before the Jacobian saw
it, and the stepper's trial states overflowed ("the right-hand side became
NaN or Inf at τ = 0", exit 4, for F_c = 1e-12 N with σ0 = 1e9 N/m).  A
trial state where the right-hand side is not finite is now a rejected
step, which the stepper halves.

    dahl_small_fc.py --binary B --inputs DIR --workdir DIR brake-limit
"""
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
from scipy.linalg import expm

sys.path.insert(0, str(Path(__file__).resolve().parent))
from machine_cases import case_main  # noqa: E402

OFF = ("&analysis spectrum = .false., poincare = .false., lyapunov = .false., lyapunov_spectrum = .false.,"
       " orbit = .false., rosenstein = .false. /\n")


def frictionless(attrs, t):
    """x, x', y, y' of Eq. 10 without friction from the rest at x = y = 0:
    x'' = -(2 x - y), ξ y'' = x - κ y, x' = v'_dr + v_rel, as the exponential of
    the affine system in (x, v_rel, y, w, 1)."""
    xi, kappa, v_dr = attrs["xi"], attrs["kappa"], attrs["v_dr_prime"]
    m = np.zeros((5, 5))
    m[0, 1], m[0, 4] = 1.0, v_dr
    m[1, 0], m[1, 2] = -2.0, 1.0
    m[2, 3] = 1.0
    m[3, 0], m[3, 2] = 1.0 / xi, -kappa / xi
    s = np.array([expm(m * tau) @ np.array([0.0, 0.0, 0.0, 0.0, 1.0]) for tau in t])
    return np.stack([s[:, 0], s[:, 1] + v_dr, s[:, 2], s[:, 3]], axis=1)


def brake_limit(args):
    work = Path(args.workdir)
    # (F_c, σ0, α): each stopped at τ = 0 before; the last is the message's own F_c = 2.2e-16 N.
    for fc, sigma0, alpha in [(1.0e-12, 1.0e9, 1.0), (2.2e-16, 1.0e9, 1.0), (2.2e-16, 1.0e5, 2.5)]:
        name = f"dahl-{fc:g}-{sigma0:g}-{alpha:g}"
        path = work / f"{name}.nml"
        path.write_text(f"&brake t_end = 100.0 /\n&law model = 'dahl', fc = {fc!r}, sigma0 = {sigma0!r},"
                        f" alpha = {alpha!r} /\n" + OFF)
        out = work / f"{name}.h5"
        result = subprocess.run([args.binary, "--quiet", "--force", "-o", str(out),
                                 str(Path(args.inputs) / "brake_lugre.nml"), str(path)],
                                capture_output=True, text=True)
        assert result.returncode == 0, result.stderr
        with h5py.File(out, "r") as handle:
            brake = handle["brake"]
            t = brake["t"][()]
            run = np.stack([brake[k][()] for k in ("x", "v", "y", "w")], axis=1)
            exact = frictionless(brake.attrs, t)
            k1 = brake.attrs["k1"]
        worst = np.abs(run - exact).max()
        # The friction, |F| <= F_c, moves the brake by at most (F_c / k1) τ^2 / 2 in its units (m; 2e-11 m
        # for F_c = 1e-12 N at τ = 100); the integration at rtol 1e-9 is within 3e-11 m of the exact
        # motion (amplitude 1.1e-4 m): 1e-9 m bounds both with margin and is 1e-5 of the motion.
        print(f"{name}: {len(t)} points, worst |run - frictionless| = {worst:.3g} m"
              f" (friction's bound {fc / k1 * t[-1] ** 2 / 2:.2g} m)")
        assert worst < 1.0e-9, worst
        assert t[-1] == 100.0


if __name__ == "__main__":
    sys.exit(case_main(__doc__, {"brake-limit": brake_limit}))
