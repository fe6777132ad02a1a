#!/usr/bin/env python3
"""The brake's periodic orbit in a sweep (/sweep/orbit_found, orbit_period,
orbit_max_multiplier, orbit_critical_real, orbit_critical_imag), each point
against the same point run alone (its /brake/orbit, written by another path):

  points   a sweep of inputs/brake.nml's damping ξ on brake_continuation.nml's
           slow belt, points with an orbit and without one: a point with an
           orbit has the run alone's period and multiplier bit for bit, a
           point without one NaN in the four (not 0, a multiplier an orbit
           through stick has)
  off      the same sweep with &analysis orbit off: NaN at every point

    brake_sweep_orbit.py --binary build/friction --inputs inputs --workdir DIR CASE
"""
import sys

import h5py
import numpy as np

from helpers import fail, require
from machine_cases import run_program, case_main
from machine_sweep_orbit import ORBIT, sweep

# Stick-slip at the paper's ξ = 0.412 and at 1.5 (orbits found), none found at 0.8 and 3.0 (Newton's
# step stops reducing the residual there: the run alone's reason).
XI = [0.412, 0.8, 1.5, 3.0]
QUIET = {"analysis.spectrum": ".false.", "analysis.poincare": ".false.", "analysis.lyapunov": ".false.",
         "analysis.lyapunov_spectrum": ".false.", "analysis.rosenstein": ".false.",
         "analysis.orbit_transient": 200.0, "brake.t_end": 1200.0, "brake.v_dr_prime": -2.0e-4}
SWEEP = ("&sweep\n  sweep_variable = 'brake.xi'\n  sweep_spacing = 'list'\n"
         f"  sweep_values = {', '.join(map(str, XI))}\n/\n")


def alone(args, name, sets):
    """The point run alone: found, period and the section map's critical
    multiplier (the second of /brake/orbit's: the first is the trivial 1)."""
    with h5py.File(run_program(args, name, ["brake.nml"], sets)) as f:
        g = f["brake/orbit"]
        if not int(g.attrs["found"]):
            return 0, None, None, g.attrs["reason"].decode()
        mu = g["floquet_multipliers"][()]
        return 1, g.attrs["period"], mu[1, 0] + 1j * mu[1, 1], ""


def points(args):
    got, _ = sweep(args, "xi", ["brake.nml"], SWEEP, {**QUIET, "analysis.orbit": ".true."})
    for i, xi in enumerate(XI):
        found, period, mu, reason = alone(args, f"alone{i}", {**QUIET, "analysis.orbit": ".true.", "brake.xi": xi})
        row = {name: got[name][i] for name in ORBIT}
        print(f"points: xi {xi}: sweep {row}; alone: found {found}, period {period}, critical {mu} {reason}")
        if got["status"][i] != 1 or row["orbit_found"] != found:
            fail(f"points: xi {xi}: status {got['status'][i]}, found {row['orbit_found']} where the run alone "
                 f"found {found}")
        if found:
            # The same computation of the same settings on one process: bit for bit, any difference is the
            # sweep's plumbing (another point's value, a column out of place).
            if not (row["orbit_period"] == period and row["orbit_max_multiplier"] == abs(mu)
                    and row["orbit_critical_real"] == mu.real and row["orbit_critical_imag"] == mu.imag):
                fail(f"points: xi {xi} differs from the run alone")
        elif not all(np.isnan(row[name]) for name in ORBIT[1:]):
            fail(f"points: xi {xi} has no orbit but not NaN: {row}")
    require(list(got["orbit_found"]) == [1, 0, 1, 0], "points: orbits at xi 0.412 and 1.5, none at 0.8 and 3.0")
    print("ok: points: the points with an orbit are the runs alone's, those without NaN")


def off(args):
    got, _ = sweep(args, "off", ["brake.nml"], SWEEP, {**QUIET, "analysis.orbit": ".false."})
    require(np.all(got["status"] == 1) and np.all(got["orbit_found"] == 0), "off: every point done, none found")
    for name in ORBIT[1:]:
        require(np.all(np.isnan(got[name])), f"off: /sweep/{name} NaN at every point: {got[name]}")
    print("ok: off: no orbit asked, NaN at every point")


def main():
    return case_main(__doc__, {"points": points, "off": off})


if __name__ == "__main__":
    sys.exit(main())
