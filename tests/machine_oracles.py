#!/usr/bin/env python3
"""The machine scene's runs, through the program and its file, against
oracles computed here:

  lugre-radau          the LuGre paper's stick-slip (m = 1 kg, k = 2 N/m, belt
                       0.1 m/s, Table I) against SciPy's Radau on the same
                       equations, written out below
  rate-state-critical  a sweep of the spring-slider's stiffness finds the onset
                       of instability at k_c = N (b - a)/D_c (1 + m V^2/(N a D_c)),
                       without and with the inertial correction

    machine_oracles.py --binary build/friction --inputs inputs --workdir DIR CASE
"""
import argparse
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
from scipy.integrate import solve_ivp


def run(args, name, files, sets):
    out = Path(args.workdir) / f"{name}.h5"
    command = [args.binary, "--quiet", "--force", "-o", str(out)] + [str(Path(args.inputs) / f) for f in files]
    for key, value in sets.items():
        command += ["--set", f"{key}={value}"]
    subprocess.run(command, check=True)
    with h5py.File(out) as f:
        return {key: f["machine"][key][:] for key in ("t", "x", "v", "force")}


def lugre_radau(args):
    # Both integrations are far tighter than the bound: the program's x moves by 1.3e-10 m from
    # rtol 1e-9 to 1e-11, Radau's by 2e-11 m from rtol 1e-10 to 1e-12 (measured); 1e-8 m is 70 times
    # either, and a wrong term of the law (a sign, σ1 left out) moves x by 1e-2 m.
    got = run(args, "lugre", ["machine_lugre.nml"], {"machine.t_end": 20.0})
    m, k, vb, fc, fs, vs, s0, s1, s2 = 1.0, 2.0, 0.1, 1.0, 1.5, 1e-3, 1e5, np.sqrt(1e5), 0.4

    def g(w):
        return fc + (fs - fc) * np.exp(-(w / vs) ** 2)

    def field(_, y):
        x, v, z = y
        w = v - vb
        zdot = w - s0 * abs(w) * z / g(w)
        return [v, (-k * x - (s0 * z + s1 * zdot + s2 * w)) / m, zdot]

    z0 = -g(-vb) / s0   # the bristles in steady sliding at w = -0.1 m/s (the block at rest)
    oracle = solve_ivp(field, (0.0, 20.0), [0.0, 0.0, z0], method="Radau", t_eval=got["t"], rtol=1e-10, atol=1e-13)
    assert oracle.status == 0, oracle.message
    difference = np.max(np.abs(got["x"] - oracle.y[0]))
    sticks = np.count_nonzero(np.abs(got["v"] - vb) < 1e-3)
    print(f"lugre-radau: max |x - x_Radau| = {difference:.2e} m over 20 s; "
          f"{sticks} grid points near stick; v in [{got['v'].min():.3f}, {got['v'].max():.3f}] m/s")
    assert difference < 1e-8, difference
    assert sticks > 100 and got["v"].min() < -0.2, "stick-slip, not steady sliding"


def growth_rate(got, velocity):
    """The slope of ln |v - V| at its peaks after the first 200 s: the
    disturbance's growth rate (1/s)."""
    dv = got["v"] - velocity
    peaks = [i for i in range(1, dv.size - 1) if abs(dv[i]) >= abs(dv[i - 1]) and abs(dv[i]) > abs(dv[i + 1])]
    t = got["t"][peaks]
    keep = t > 200.0
    return np.polyfit(t[keep], np.log(np.abs(dv[peaks]))[keep], 1)[0]


def rate_state_critical(args):
    # The growth rate changes sign once across the sweep (steps of 3 % of the expected k_c, not
    # aligned with it); the onset is the linear interpolation between the two stiffnesses around
    # the sign change, and the rate is linear in k there (measured: 5e-4 per s for every 2 %), so
    # the interpolation is far inside the 1 % the check asks.
    normal, a, b, dc, velocity = 1.0, 0.010, 0.015, 1e-5, 1e-6
    for mass in (1.0, 2e4):
        expected = normal * (b - a) / dc * (1.0 + mass * velocity ** 2 / (normal * a * dc))
        stiffness = expected * np.arange(0.86, 1.15, 0.03)
        rates = []
        for k in stiffness:
            got = run(args, "slider", ["machine_rate_state.nml"],
                      {"machine.stiffness": k, "machine.mass": mass, "machine.x0": -0.6 * normal / k})
            rates.append(growth_rate(got, velocity))
        rates = np.array(rates)
        change = np.nonzero(np.diff(np.sign(rates)))[0]
        assert change.size == 1 and rates[0] > 0 > rates[-1], rates
        i = change[0]
        onset = stiffness[i] - rates[i] * (stiffness[i + 1] - stiffness[i]) / (rates[i + 1] - rates[i])
        print(f"rate-state-critical: m = {mass:g} kg: onset at k = {onset:.4f} N/m, "
              f"k_c = {expected:.4f} N/m ({onset / expected - 1.0:+.2e})")
        assert abs(onset / expected - 1.0) < 0.01


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--binary", required=True)
    parser.add_argument("--inputs", required=True)
    parser.add_argument("--workdir", required=True)
    parser.add_argument("case", choices=["lugre-radau", "rate-state-critical"])
    args = parser.parse_args()
    Path(args.workdir).mkdir(parents=True, exist_ok=True)
    {"lugre-radau": lugre_radau, "rate-state-critical": rate_state_critical}[args.case](args)
    return 0


if __name__ == "__main__":
    sys.exit(main())
