#!/usr/bin/env python3
"""The machine's periodic orbit in a sweep (/sweep/orbit_found, orbit_period,
orbit_max_multiplier, orbit_critical_real, orbit_critical_imag), each point
against an oracle that is not the sweep's own output:

  forced-linear   a sweep of the support frequency of the support-driven
                  oscillator with the arctan law in its viscous limit: each
                  point's period is the forcing period and its multipliers
                  exp(lambda T) in closed form
  lugre-points    a sweep of inputs/machine_orbit.nml's belt velocity, from
                  stick-slip to stable steady sliding: each point against the
                  same point run alone (the plain run's /machine/orbit, written
                  by another path), NaN where no orbit was found
  ranks           that sweep on 2 ranks writes the same file as on 1 rank

    machine_sweep_orbit.py --binary build/friction --mpiexec mpiexec --inputs inputs --workdir DIR CASE
"""
import sys
from pathlib import Path

import h5py
import numpy as np

from helpers import file_contents, fail, require, run
from machine_cases import run_program, case_main

ORBIT = ("orbit_found", "orbit_period", "orbit_max_multiplier", "orbit_critical_real", "orbit_critical_imag")


def sweep(args, name, files, groups, sets=None, ranks=None):
    """The program on `files` (in --inputs) and the groups' text (a file of
    the work directory) with --set `sets`, on `ranks` ranks through mpiexec
    (None: directly); the /sweep datasets by name."""
    work = Path(args.workdir)
    extra = work / f"{name}.nml"
    extra.write_text(groups)
    out = work / f"{name}.h5"
    command = [args.binary, "--quiet", "--force", "-o", out] + [Path(args.inputs) / f for f in files] + [extra]
    for key, value in (sets or {}).items():
        command += ["--set", f"{key}={value}"]
    if ranks is not None:
        command = [args.mpiexec, "-n", str(ranks)] + command
    run(command, cwd=work)
    with h5py.File(out) as f:
        return {key: f["sweep"][key][()] for key in f["sweep"]}, out


def alone(args, name, files, sets):
    """The same point run alone: its /machine/orbit (found, period, the
    section map's multipliers by decreasing modulus)."""
    with h5py.File(run_program(args, name, files, sets)) as f:
        g = f["machine/orbit"]
        found = int(g.attrs["found"])
        if not found:
            return found, None, None, g.attrs["reason"].decode()
        mu = g["floquet_multipliers"][()]
        mu = mu[:, 0] + 1j * mu[:, 1]
        if g.attrs["section"].decode().strip() == "v_rising":
            mu = mu[1:]   # the trivial 1 along the flow is not the section map's
        return found, g.attrs["period"], mu, ""


def forced_linear(args):
    # As machine_orbit_oracles.py's forced-linear: m x'' = -k (x - u) - F(x'), u = A sin(2 pi f t), the arctan
    # law with delta = 0 and eps |x'| <= 3e-4, F = c x' to 3e-8 relative: a linear oscillator, whose period map
    # has the multipliers exp(lambda / f), lambda = -c/(2m) +- i sqrt(k/m - (c/2m)^2).
    m, k, mu, normal, eps, amp = 1.0, 2.0, 1.0, 10.0, 0.01, 0.01
    frequencies = [0.25, 0.3, 0.35]
    got, _ = sweep(args, "linear", ["machine_arctan.nml"],
                   "&sweep\n  sweep_variable = 'machine.support_frequency'\n  sweep_spacing = 'list'\n"
                   f"  sweep_values = {', '.join(map(str, frequencies))}\n/\n",
                   {"machine.belt_velocity": 0.0, "machine.v0": 0.0, "machine.normal": normal,
                    "machine.support_amplitude": amp, "machine.support_frequency": frequencies[0],
                    "machine.t_end": 40.0, "law.mu": mu, "law.epsilon": eps, "law.delta": 0.0,
                    "analysis.orbit": ".true.", "analysis.orbit_transient": 20.0, "analysis.orbit_tolerance": 1e-12})
    c = 2 * mu * normal * eps / np.pi
    lam = -c / (2 * m) + 1j * np.sqrt(k / m - (c / (2 * m)) ** 2)
    require(np.array_equal(got["status"], [1, 1, 1]) and np.array_equal(got["orbit_found"], [1, 1, 1]),
            "forced-linear: every point done with its orbit found")
    for i, f in enumerate(frequencies):
        expected = np.exp(lam / f)
        expected = expected if expected.imag > 0 else np.conj(expected)   # the pair's positive imaginary part first
        critical = got["orbit_critical_real"][i] + 1j * got["orbit_critical_imag"][i]
        print(f"forced-linear: f = {f} Hz: period {got['orbit_period'][i]!r} s against {1 / f!r}; "
              f"|mu| {got['orbit_max_multiplier'][i]:.12f} against {abs(expected):.12f}; "
              f"mu {critical:.10f} against {expected:.10f} (difference {abs(critical - expected):.2e})")
        # The stroboscopic section's period is the forcing period, set, not integrated: to rounding.
        if abs(got["orbit_period"][i] - 1 / f) > 1e-12:
            fail(f"forced-linear: period {got['orbit_period'][i]} at f = {f}")
        # The multipliers from the variational equations at rtol 1e-9 (|mu| about 0.9): 1e-7 is 100 rtol, as
        # machine_orbit_oracles.py's forced-linear allows for the same oscillator.
        if abs(critical - expected) > 1e-7 or abs(got["orbit_max_multiplier"][i] - abs(expected)) > 1e-7:
            fail(f"forced-linear: multiplier {critical} against exp(lambda T) = {expected} at f = {f}")
    print("ok: forced-linear: three points' periods and multipliers against the linear oscillator's closed form")


LUGRE_VALUES = [0.0026, 0.0034, 0.1, 0.3]   # m/s: stick-slip on both sides of the Hopf point; steady sliding
LUGRE_SWEEP = ("&analysis\n  continuation = ''\n/\n&sweep\n  sweep_variable = 'machine.belt_velocity'\n"
               f"  sweep_spacing = 'list'\n  sweep_values = {', '.join(map(str, LUGRE_VALUES))}\n/\n")


def lugre_points(args):
    got, _ = sweep(args, "lugre", ["machine_orbit.nml"], LUGRE_SWEEP)
    for name in ORBIT:
        require(name in got, f"lugre-points: /sweep/{name} written")
    for i, value in enumerate(LUGRE_VALUES):
        found, period, mu, reason = alone(args, f"alone{i}", ["machine_orbit.nml"],
                                          {"analysis.continuation": "''", "machine.belt_velocity": value})
        row = {name: got[name][i] for name in ORBIT}
        print(f"lugre-points: belt_velocity {value}: sweep {row}; alone: found {found}, period {period}, "
              f"section multipliers {mu} {reason}")
        if got["status"][i] != 1 or row["orbit_found"] != found:
            fail(f"lugre-points: point {i + 1}: status {got['status'][i]}, found {row['orbit_found']} "
                 f"where the run alone found {found}")
        if found:
            # The same computation of the same settings on one process: bit for bit, any difference is the
            # sweep's plumbing (another point's value, a column out of place).
            same = (row["orbit_period"] == period and row["orbit_max_multiplier"] == abs(mu[0])
                    and row["orbit_critical_real"] == mu[0].real and row["orbit_critical_imag"] == mu[0].imag
                    and abs(mu[0]) == np.max(np.abs(mu)))
            if not same:
                fail(f"lugre-points: point {i + 1} differs from the run alone")
        elif not all(np.isnan(row[name]) for name in ORBIT[1:]):
            fail(f"lugre-points: point {i + 1} has no orbit but not NaN: {row}")
    found = got["orbit_found"]
    require(list(found) == [1, 1, 1, 0], "lugre-points: stick-slip found at 2.6 and 3.4 mm/s (beyond the "
            "subcritical Hopf point) and 0.1 m/s, none at 0.3 m/s (steady sliding), as each point alone")
    # The LuGre paper's cycle sticks: its section multipliers lie below 1e-6 (docs/chaos.md).
    require(np.all(got["orbit_max_multiplier"][:3] < 1e-6), "lugre-points: the stick-slip orbits' |mu| < 1e-6")


def ranks(args):
    _, one = sweep(args, "one", ["machine_orbit.nml"], LUGRE_SWEEP, ranks=1)
    _, two = sweep(args, "two", ["machine_orbit.nml"], LUGRE_SWEEP, ranks=2)
    # What says how the run went, not what it computed: timings, the number of ranks, their memory.
    how = {"wall_time", "compute_time", "created", "nranks"}
    a, b = (file_contents(path, ignore=how) for path in (one, two))
    a, b = ({key: value for key, value in items.items() if not key.startswith(("sweep/compute_time",
                                                                              "sweep/peak_memory_per_rank"))}
            for items in (a, b))
    if a.keys() != b.keys():
        fail(f"ranks: the files hold different objects: {sorted(set(a) ^ set(b))}")
    # NaN where no orbit: compared as the same value.
    differ = [key for key in a if not np.array_equal(np.asarray(a[key]), np.asarray(b[key]),
                                                     equal_nan=np.asarray(a[key]).dtype.kind == "f")]
    if differ:
        fail(f"ranks: 1 and 2 ranks differ in {differ}")
    print(f"ok: ranks: the sweep's file on 2 ranks is the one on 1 rank ({len(a)} datasets and attributes)")


def main():
    return case_main(__doc__, {"forced-linear": forced_linear, "lugre-points": lugre_points, "ranks": ranks},
                     extra=["--mpiexec"])


if __name__ == "__main__":
    sys.exit(main())
