#!/usr/bin/env python3
"""The machine scene's stiff friction laws integrated by SciPy's solve_ivp
as a user's script would: the peer of `friction` in scripts/benchmark_laws.py,
timed there as a whole process (the interpreter's start, the imports, the
integration and the HDF5 file).

The same two cases as scripts/cvode_laws.c and the program's
inputs/machine_lugre.nml and machine_rate_state.nml with the benchmark's
settings, in the state (x, v, z) of a block of mass m on a spring:
  lugre       LuGre (Table I of its paper) on a belt at 0.1 m/s, m = 1 kg,
              k = 2 N/m, 30 s; z the bristles' deflection
  rate_state  Dieterich-Ruina with the aging law, a spring-slider at
              k = 0.2 k_c pulled at 1e-6 m/s, 3000 s; z the state theta
solve_ivp with the Jacobian estimated by differences (its default), scalar
tolerances (atol = rtol x 1e-3, as the benchmark's other runs), the solution
on the grid t = 0, DT_OUT, ..., t_end (t_eval).

Usage: scipy_laws.py CASE METHOD RTOL DT_OUT OUT.h5
  OUT.h5  t, x, v, z on the grid, each with its unit, as h5py writes them
Prints one line of JSON: seconds and cpu_seconds (solve_ivp alone, wall and
CPU time), rhs_evaluations, jacobian_evaluations.
Exit 2 on bad arguments (argparse's), 3 on a failure of the integration.
"""
import argparse
import json
import sys
import time

import h5py
import numpy as np
from scipy.integrate import solve_ivp


def lugre_field():
    """(field, y0, t_end)."""
    m, k, vb, fc, fs, vs, s0, s1, s2 = 1.0, 2.0, 0.1, 1.0, 1.5, 1e-3, 1e5, np.sqrt(1e5), 0.4

    def g(w):
        return fc + (fs - fc) * np.exp(-(w / vs) ** 2)

    def field(_, y):
        x, v, z = y
        w = v - vb
        zdot = w - s0 * abs(w) * z / g(w)
        return [v, (-k * x - (s0 * z + s1 * zdot + s2 * w)) / m, zdot]

    return field, [0.0, 0.0, -g(-vb) / s0], 30.0


# N/m: 0.2 k_c = 0.2 normal (b - a) / dc, which the program is given with
# --set (scripts/benchmark_laws.py), as it is x0 = y0[0]
RATE_STATE_STIFFNESS = 0.2 * 1.0 * (0.015 - 0.010) / 1e-5


def rate_state_field():
    """(field, y0, t_end)."""
    mass, normal, a, b, dc, v0, mu0, velocity = 1.0, 1.0, 0.010, 0.015, 1e-5, 1e-6, 0.6, 1e-6
    k = RATE_STATE_STIFFNESS

    def field(t, y):
        x, v, theta = y
        psi = mu0 + b * np.log(v0 * max(theta, 1e-300) / dc)
        big = np.log(max(abs(v), 1e-300) / (2.0 * v0)) + psi / a
        mu = np.sign(v) * a * (big + np.log(2.0)) if big > 18.0 else a * np.arcsinh(np.sign(v) * np.exp(big))
        return [v, (-k * (x - velocity * t) - normal * mu) / mass, 1.0 - abs(v) * theta / dc]

    x0 = -mu0 * normal / k
    return field, [x0, 1.01 * velocity, dc / (1.01 * velocity)], 3000.0


CASES = {"lugre": lugre_field, "rate_state": rate_state_field}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("case", choices=sorted(CASES))
    parser.add_argument("method", help="solve_ivp's method: LSODA, Radau, BDF ...")
    parser.add_argument("rtol", type=float)
    parser.add_argument("dt_out", type=float, help="s between output points")
    parser.add_argument("out", help="the HDF5 file to write")
    args = parser.parse_args()   # (a bad argument: argparse's message, exit 2)
    name, method, rtol, dt, out = args.case, args.method, args.rtol, args.dt_out, args.out
    if not (rtol > 0 and dt > 0):
        parser.error("RTOL and DT_OUT must be positive")
    field, y0, t_end = CASES[name]()
    t = np.linspace(0.0, t_end, round(t_end / dt) + 1)
    start, cpu = time.perf_counter(), time.process_time()
    solution = solve_ivp(field, (0.0, t_end), y0, method=method, t_eval=t, rtol=rtol, atol=rtol * 1e-3)
    seconds, cpu = time.perf_counter() - start, time.process_time() - cpu
    if solution.status != 0 or solution.y.shape[1] != t.size:
        print(f"scipy_laws: {method} failed: {solution.message}", file=sys.stderr)
        return 3
    with h5py.File(out, "w") as f:
        group = f.create_group(name)
        for key, values, unit in (("t", solution.t, "s"), ("x", solution.y[0], "m"), ("v", solution.y[1], "m/s"),
                                  ("z", solution.y[2], "m" if name == "lugre" else "s")):
            group.create_dataset(key, data=values).attrs["units"] = unit
        group.attrs["method"] = method
        group.attrs["rtol"] = rtol
    print(json.dumps({"seconds": seconds, "cpu_seconds": cpu, "rhs_evaluations": int(solution.nfev),
                      "jacobian_evaluations": int(solution.njev)}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
