#!/usr/bin/env python3
"""The paper's brake, switched model, as a SciPy user would write it: the
peer of `friction` in scripts/benchmark_brake_peers.py.

Eq. 10 in nondimensional time (docs/physics.md, Equations and parameters)
with the stick/slip decision of the switched model (docs/physics.md, Two
friction models), every phase integrated by scipy.integrate.solve_ivp with
DOP853 and terminal events:

* stick: x' = v'_dr, x'' = 0, xi y'' = x - kappa y, until |2x - y| reaches
  mu_s N' (N' = (1 - kappa) y + g'); the slip starts against the force,
  s = -sign(2x - y);
* slip with sign s: x'' = -(2x - y) - mu N' s / (1 + delta' s v_rel),
  v_rel = x' - v'_dr, until v_rel returns to 0; then stick if
  |2x - y| <= mu_s N', else slip on the other way.

The parameters are those of inputs/brake.nml; the state starts at rest on
the belt.  x is sampled on tau = 0, 1, ..., T (t_eval of each phase).

Usage: scipy_brake.py RTOL ATOL T_END OUT.npy
Prints one line of JSON: compute_time (s, the integration alone, after the
imports), events, rhs_evaluations.
"""

import json
import sys
import time

import numpy as np
from scipy.integrate import solve_ivp

XI, KAPPA, G_PRIME, MU, MU_S, DELTA, V_DR = 0.412, 1.5, 0.01778, 0.59, 0.59, 3.5121, -0.002788


def normal(y):
    return (1.0 - KAPPA) * y + G_PRIME


def stick_rhs(t, u):
    x, v, y, w = u
    return [V_DR, 0.0, w, (x - KAPPA * y) / XI]


def slip_rhs(s):
    def rhs(t, u):
        x, v, y, w = u
        v_rel = v - V_DR
        return [v, -(2.0 * x - y) - MU * normal(y) * s / (1.0 + DELTA * s * v_rel), w, (x - KAPPA * y) / XI]
    return rhs


def limit_up(t, u):     # 2x - y reaches +mu_s N'
    return MU_S * normal(u[2]) - (2.0 * u[0] - u[2])


def limit_down(t, u):   # 2x - y reaches -mu_s N'
    return MU_S * normal(u[2]) + (2.0 * u[0] - u[2])


for event in (limit_up, limit_down):
    event.terminal, event.direction = True, -1


def main():
    if len(sys.argv) == 2 and sys.argv[1] in ("-h", "--help"):
        print(__doc__)
        return 0
    if len(sys.argv) != 5:
        sys.exit("usage: scipy_brake.py RTOL ATOL T_END OUT.npy")
    rtol, atol, t_end = float(sys.argv[1]), float(sys.argv[2]), float(sys.argv[3])
    grid = np.arange(0.0, np.floor(t_end) + 1.0)
    x_out = np.full(grid.size, np.nan)
    start = time.perf_counter()
    t, u, phase = 0.0, np.array([0.0, V_DR, 0.0, 0.0]), 0   # phase: 0 stick, +-1 slip sign
    x_out[0] = u[0]
    events = rhs = 0
    while t < t_end:
        if phase == 0:
            fun, watch = stick_rhs, [limit_up, limit_down]
        else:
            def v_rel_zero(tt, uu):
                return uu[1] - V_DR
            v_rel_zero.terminal, v_rel_zero.direction = True, -phase
            fun, watch = slip_rhs(phase), [v_rel_zero]
        inside = grid[(grid > t) & (grid <= t_end)]
        sol = solve_ivp(fun, (t, t_end), u, method="DOP853", rtol=rtol, atol=atol, events=watch,
                        t_eval=inside)
        if sol.status < 0:
            sys.exit(f"scipy_brake: solve_ivp failed at tau = {t}: {sol.message}")
        rhs += sol.nfev
        if len(sol.t):   # (a list when no sample falls in the phase)
            x_out[np.searchsorted(grid, np.asarray(sol.t))] = np.asarray(sol.y)[0]
        if sol.status == 0:
            break
        fired = [k for k, te in enumerate(sol.t_events) if te.size]
        k = fired[0]
        t, u = float(sol.t_events[k][0]), np.array(sol.y_events[k][0])
        events += 1
        force = 2.0 * u[0] - u[2]
        if phase == 0:
            phase = -1 if force > 0 else 1
        else:
            u[1] = V_DR                        # v_rel = 0 exactly
            phase = 0 if abs(force) <= MU_S * normal(u[2]) else (-1 if force > 0 else 1)
    compute = time.perf_counter() - start
    np.save(sys.argv[4], np.vstack([grid, x_out]))
    print(json.dumps({"compute_time": compute, "events": events, "rhs_evaluations": int(rhs)}))


if __name__ == "__main__":
    main()
