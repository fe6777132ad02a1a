#!/usr/bin/env python3
"""Benchmark the periodic orbit of the brake and its continuation (docs/speed.md).

Measures and prints (not a test; nothing fails):

* the switched run of inputs/brake.nml over [0, 3200] with every diagnostic
  off, and with only `orbit` on: Newton's cost is the difference of the two
  files' `wall_time` (start-up and output cancel), for the paper's case and
  the chaotic point (mu = 0.35, v'_dr = -2e-4, where Newton finds the
  unstable period-1 orbit), with its Newton steps;
* inputs/brake_continuation.nml (59 points in mu): the whole run's
  `wall_time` and the time per point of the line.

With --machine instead: the machine's orbits of laws with states, whose
section map carries its tangent by exponentials (docs/chaos.md):
inputs/machine_orbit.nml's first point (LuGre at Table I's stiffness) with
the orbit and without (Newton's cost), the whole continuation, and the GMS
stick-slip orbit of inputs/machine_gms.nml (stopped after --limit seconds);
--before PATH runs the same with a second program (an earlier build) in the
same run, case by case, for the ratio.

Medians over --repeats runs of each.

Usage (normally through scripts/benchmark_orbit, which builds first):

    python3 scripts/benchmark_orbit.py [--repeats N] [--binary PATH]
    python3 scripts/benchmark_orbit.py --machine [--before PATH] [--limit S] [--repeats N]
"""
import argparse
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

import h5py

ROOT = Path(__file__).resolve().parent.parent

DIAGNOSTICS_OFF = ("spectrum = .false., poincare = .false., lyapunov = .false., rosenstein = .false.,"
                   " lyapunov_spectrum = .false.")
CASES = {"paper case (stable, complex pair)": "", "chaotic (mu = 0.35, v'_dr = -2e-4)": "mu = 0.35, v_dr_prime = -2.0e-4, "}


def run(args, workdir, name, texts):
    files = [str(ROOT / "inputs" / "brake.nml")]
    for k, text in enumerate(texts):
        path = workdir / f"{name}_{k}.nml"
        if text.endswith(".nml"):
            files.append(text)
            continue
        path.write_text(text)
        files.append(str(path))
    out = workdir / f"{name}.h5"
    subprocess.run([args.binary, "--quiet", "--force", "-o", str(out), *files], check=True, cwd=workdir)
    with h5py.File(out, "r") as f:
        steps = int(f["brake/orbit"].attrs["iterations"]) if "brake/orbit" in f else 0
        return float(f.attrs["wall_time"]), steps


def machine_run(binary, workdir, name, sets, limit):
    """A machine input with --set options: (its wall_time or None when stopped after `limit` s, the orbit's
    attributes and its exponents)."""
    out = workdir / f"{name}.h5"
    command = [binary, "--quiet", "--force", "-o", str(out), str(ROOT / "inputs" / sets[0])]
    for item in sets[1:]:
        command += ["--set", item]
    try:
        subprocess.run(command, check=True, cwd=workdir, timeout=limit, capture_output=True)
    except subprocess.TimeoutExpired:
        return None, {}, []
    with h5py.File(out, "r") as f:
        orbit = f.get("machine/orbit")
        attrs = dict(orbit.attrs) if orbit is not None else {}
        exponents = orbit["floquet_exponents"][()].tolist() if orbit is not None and "floquet_exponents" in orbit \
            else []
        return float(f.attrs["wall_time"]), attrs, exponents


def machine(args):
    programs = {"this build": args.binary}
    if args.before:
        programs["before"] = args.before
    one = ["machine_orbit.nml", "analysis.continuation=''"]
    cases = [("LuGre Table I, one orbit (run + Newton)", one, args.repeats),
             ("the same without the orbit (run only)", one + ["analysis.orbit=.false."], args.repeats),
             ("LuGre Table I, continuation (9 points)", ["machine_orbit.nml"], args.repeats),
             ("GMS (4 elements, Table I), one orbit", ["machine_gms.nml", "analysis.orbit=.true.",
                                                      "analysis.orbit_transient=20"], 1)]
    print(f"machine orbits of laws with states; median wall_time of {args.repeats} (GMS once, stopped after "
          f"{args.limit:.0f} s)")
    print("| case | program | wall | Newton steps | period (s) | exponents ln|mu|/T (1/s) |")
    print("|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        workdir = Path(tmp)
        for label, sets, repeats in cases:
            for name, binary in programs.items():
                walls, attrs, exponents = [], {}, []
                for _ in range(repeats):
                    wall, attrs, exponents = machine_run(binary, workdir, "m", sets, args.limit)
                    if wall is None:
                        walls = None
                        break
                    walls.append(wall)
                if walls is None:
                    print(f"| {label} | {name} | stopped after {args.limit:.0f} s | | | |")
                    continue
                found = attrs.get("found", 0) == 1
                print(f"| {label} | {name} | {statistics.median(walls):.3f} s | {attrs.get('iterations', '')} | "
                      f"{attrs['period'] if found else attrs.get('reason', b'').decode()} | "
                      f"{', '.join(f'{e:.6g}' for e in exponents) if found else ''} |")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--binary", default=str(ROOT / "build" / "friction"))
    parser.add_argument("--machine", action="store_true", help="the machine's orbits of laws with states")
    parser.add_argument("--before", help="a second program to time the same machine cases with")
    parser.add_argument("--limit", type=float, default=120.0, help="seconds after which a machine case stops")
    args = parser.parse_args()
    if args.repeats < 1:
        sys.exit("benchmark_orbit: --repeats >= 1")
    if args.machine:
        machine(args)
        return
    print(f"switched model, rk8pd rtol 1e-10 (inputs/brake.nml), tau in [0, 3200], dt_out = 1; "
          f"median of {args.repeats}")
    print("| case | run: wall | with orbit: wall | Newton's cost | Newton steps |")
    print("|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        workdir = Path(tmp)
        for label, brake in CASES.items():
            off, on, steps = [], [], 0
            for _ in range(args.repeats):
                grid = f"&brake {brake}dt_out = 1.0 /\n"
                off.append(run(args, workdir, "off", [grid, f"&analysis {DIAGNOSTICS_OFF}, orbit = .false. /\n"])[0])
                wall, steps = run(args, workdir, "on", [grid, f"&analysis {DIAGNOSTICS_OFF}, orbit = .true. /\n"])
                on.append(wall)
            a, b = statistics.median(off), statistics.median(on)
            print(f"| {label} | {a * 1e3:.1f} ms | {b * 1e3:.1f} ms | {(b - a) * 1e3:.1f} ms | {steps} |")
        continuation = str(ROOT / "inputs" / "brake_continuation.nml")
        walls = [run(args, workdir, "line", [continuation])[0] for _ in range(args.repeats)]
        with h5py.File(workdir / "line.h5", "r") as f:
            points = f["brake/orbit/branch/parameter"].size
        wall = statistics.median(walls)
        print(f"continuation (inputs/brake_continuation.nml, {points} points): wall {wall:.2f} s, "
              f"{wall / points * 1e3:.0f} ms per point (a run of [0, 1200] and a Newton solve each)")


if __name__ == "__main__":
    main()
