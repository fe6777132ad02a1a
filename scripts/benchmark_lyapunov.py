#!/usr/bin/env python3
"""Benchmark the whole Lyapunov spectrum of the brake and of the machine (docs/speed.md).

Measures and prints (not a test; nothing fails on a missed target):

* the plain switched run of inputs/brake.nml over [0, T] with every
  diagnostic off: its integration time, the file's `compute_time`;
* the same run with `lyapunov_spectrum = .true.` (only): the spectrum's
  cost is the difference of the two files' `wall_time` (the whole run,
  start-up and output included, which cancel in the difference);
* their ratio, the median over --repeats runs of each, for the paper's case
  (a period-1 orbit) and a chaotic point (mu = 0.35, v'_dr = -2e-4).
  Target: at most 5.

The output grid is coarse (dt_out = 1) so that the plain run's time is
integration, not writing points.

With --machine, the machine scene instead: each smooth law's input
(inputs/machine_*.nml, the spectrum after a transient of 10 s, 100 s for
rate and state) as whole processes, wall clock, plain and with the
spectrum, the median over --repeats; with --reference PATH, another build
timed in the same run, the two interleaved (old against new).  Printed
with the exponents, their sum and spectrum_divergence.

Usage (normally through scripts/benchmark_lyapunov, which builds first):

    python3 scripts/benchmark_lyapunov.py [--repeats N] [--t-end T] [--binary PATH]
    python3 scripts/benchmark_lyapunov.py --machine [--repeats N] [--binary PATH] [--reference PATH]
"""
import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import h5py

ROOT = Path(__file__).resolve().parent.parent

OFF = ("&analysis spectrum = .false., poincare = .false., lyapunov = .false., rosenstein = .false.,"
       " lyapunov_spectrum = .false., orbit = .false. /\n")
ON = ("&analysis spectrum = .false., poincare = .false., lyapunov = .false., rosenstein = .false.,"
      " lyapunov_spectrum = .true., orbit = .false. /\n")
CASES = {"paper case (period 1)": "", "chaotic (mu = 0.35, v'_dr = -2e-4)": "mu = 0.35, v_dr_prime = -2.0e-4, "}


def run(args, workdir, name, brake, analysis):
    extra = workdir / f"{name}.nml"
    extra.write_text(f"&brake {brake}t_end = {args.t_end}, dt_out = 1.0 /\n" + analysis)
    out = workdir / f"{name}.h5"
    subprocess.run([args.binary, "--quiet", "--force", "-o", str(out), str(ROOT / "inputs" / "brake.nml"),
                    str(extra)], check=True, cwd=workdir)
    with h5py.File(out, "r") as f:
        return float(f["brake"].attrs["compute_time"]), float(f.attrs["wall_time"])


# (label, input, --set values, the spectrum's transient in s)
MACHINE_CASES = [
    ("LuGre, Table I (sigma0 = 1e5 N/m)", "machine_lugre.nml", {}, 10.0),
    ("LuGre, sigma0 = 100 N/m, sigma1 = 10 N s/m", "machine_lugre.nml", {"law.sigma0": 100.0, "law.sigma1": 10.0}, 10.0),
    ("Dahl (sigma0 = 1e5 N/m)", "machine_dahl.nml", {}, 10.0),
    ("elasto-plastic (Table I)", "machine_elastoplastic.nml", {}, 10.0),
    ("arctan", "machine_arctan.nml", {}, 10.0),
    ("Karnopp", "machine_karnopp.nml", {}, 10.0),
    ("rate and state (aging)", "machine_rate_state.nml", {}, 100.0),
]


def run_machine(binary, workdir, name, sets, spectrum, transient):
    """One whole process; its wall clock, and (exponents, spectrum_divergence) with the spectrum."""
    out = workdir / f"{name}.h5"
    command = [binary, "--quiet", "--force", "-o", str(out), str(ROOT / "inputs" / sets[0])]
    for key, value in sets[1].items():
        command += ["--set", f"{key}={value}"]
    if spectrum:
        command += ["--set", "analysis.lyapunov_spectrum=.true.",
                    "--set", f"analysis.lyapunov_spectrum_transient={transient}"]
    start = time.perf_counter()
    subprocess.run(command, check=True, cwd=workdir)
    wall = time.perf_counter() - start
    if not spectrum:
        return wall, None
    with h5py.File(out, "r") as f:
        g = f["machine/lyapunov"]
        # (Karnopp's law runs through its band's switches, whose saltations the divergence leaves out: none.)
        return wall, (g["exponents"][:], float(g.attrs.get("spectrum_divergence", float("nan"))))


def machine(args):
    binaries = {"this build": args.binary}
    if args.reference:
        binaries["reference"] = args.reference
    print(f"machine scene, inputs/machine_*.nml (rodas4, rtol 1e-9), whole processes, wall clock; median of "
          f"{args.repeats}, binaries interleaved")
    header = "| case | plain run | with the spectrum |"
    if args.reference:
        header += " reference, with the spectrum | this / reference |"
    print(header + " exponents (1/s) | sum | spectrum_divergence |")
    print("|---" * (header.count("|") + 2) + "|")
    with tempfile.TemporaryDirectory() as tmp:
        workdir = Path(tmp)
        for label, path, sets, transient in MACHINE_CASES:
            plain, on = [], {name: [] for name in binaries}
            found = {}
            for _ in range(args.repeats):
                plain.append(run_machine(args.binary, workdir, "plain", (path, sets), False, transient)[0])
                for name, binary in binaries.items():
                    wall, found[name] = run_machine(binary, workdir, "spectrum", (path, sets), True, transient)
                    on[name].append(wall)
            exponents, divergence = found["this build"]
            row = f"| {label} | {statistics.median(plain) * 1e3:.0f} ms | {statistics.median(on['this build']) * 1e3:.0f} ms |"
            if args.reference:
                ratios = [a / b for a, b in zip(on["this build"], on["reference"])]
                row += f" {statistics.median(on['reference']) * 1e3:.0f} ms | {statistics.median(ratios):.2f} |"
            row += (f" {', '.join(f'{e:.6g}' for e in exponents)} | {exponents.sum():.6f} | {divergence:.6f} |")
            print(row)
            if args.reference:
                old, old_divergence = found["reference"]
                print(f"|   (reference) | | | | | {', '.join(f'{e:.6g}' for e in old)} | {old.sum():.6f} | "
                      f"{old_divergence:.6f} |")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--t-end", type=float, default=20000.0)
    parser.add_argument("--binary", default=str(ROOT / "build" / "friction"))
    parser.add_argument("--machine", action="store_true", help="the machine scene's smooth laws instead")
    parser.add_argument("--reference", help="with --machine: another build to time alongside")
    args = parser.parse_args()
    if args.machine:
        if args.repeats < 1:
            sys.exit("benchmark_lyapunov: --repeats >= 1")
        machine(args)
        return
    if args.repeats < 1 or not args.t_end > 101.0:
        sys.exit("benchmark_lyapunov: --repeats >= 1 and --t-end > 101 (the spectrum's transient is 100)")
    print(f"tau in [0, {args.t_end:g}], switched model, rk8pd rtol 1e-10 (inputs/brake.nml), dt_out = 1; "
          f"median of {args.repeats}")
    print("| case | plain run: integration | plain run: wall | with the spectrum: wall | spectrum's cost | ratio |")
    print("|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        workdir = Path(tmp)
        for label, brake in CASES.items():
            compute, wall_off, wall_on = [], [], []
            for _ in range(args.repeats):
                c, w = run(args, workdir, "off", brake, OFF)
                compute.append(c)
                wall_off.append(w)
                wall_on.append(run(args, workdir, "on", brake, ON)[1])
            c, off, on = (statistics.median(v) for v in (compute, wall_off, wall_on))
            ratios = [(b - a) / x for a, b, x in zip(wall_off, wall_on, compute)]
            print(f"| {label} | {c * 1e3:.1f} ms | {off * 1e3:.1f} ms | {on * 1e3:.1f} ms | {(on - off) * 1e3:.1f} ms"
                  f" | {statistics.median(ratios):.2f} |")
    print("ratio = (wall with the spectrum - wall without) / integration of the plain run; target <= 5")


if __name__ == "__main__":
    main()
