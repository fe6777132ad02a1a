#!/usr/bin/env python3
"""Benchmark the whole Lyapunov spectrum of the brake (docs/speed.md).

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

Usage (normally through scripts/benchmark_lyapunov, which builds first):

    python3 scripts/benchmark_lyapunov.py [--repeats N] [--t-end T] [--binary PATH]
"""
import argparse
import statistics
import subprocess
import sys
import tempfile
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


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--t-end", type=float, default=20000.0)
    parser.add_argument("--binary", default=str(ROOT / "build" / "friction"))
    args = parser.parse_args()
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
