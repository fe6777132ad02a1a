#!/usr/bin/env python3
"""Benchmark friction's parameter sweeps (docs/sweeps.md).

Measures and prints (not a test; nothing fails on a missed target):

* Points per second on 1 and 2 ranks, dynamic (points on demand) against
  static (contiguous blocks), for two brake sweeps:
  - the belt-velocity sweep of inputs/brake_sweep.nml (48 points) run to
    tau = 6000, so that a point costs about 0.15 s and start-up is small;
    costs are uneven (chaotic points cost more);
  - a sweep with strongly uneven costs: the same brake with t_end from 20000
    down to 500 (the cost of a point is proportional to its span; this
    stands in for sweeps where long or chaotic points cluster at one end).
  Points/s = points / the file's wall_time (whole run: start-up, input,
  every point, output); the median of --repeats runs.
* Peak resident memory (VmHWM) of every rank, from /sweep/peak_memory_per_rank,
  for a large sweep (--large points of a short brake run) on 1 and 2 ranks,
  and for a large AFM sweep (inputs/afm_sweep.nml as a 32 x 32 grid of V0 and
  velocity, --large points in all, small maps), with a quarter of the points
  for comparison: memory per rank must not grow with the points.

Usage (normally through scripts/benchmark_sweep, which builds first):

    python3 scripts/benchmark_sweep.py [--repeats N] [--large N] [--memory-only] [--binary PATH] [--mpiexec PATH]
"""
import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

import h5py
import numpy as np

ROOT = Path(__file__).resolve().parent.parent

UNEVEN = ("&sweep sweep_variable = 'brake.t_end', sweep_spacing = 'linear',"
          " sweep_from = 20000.0, sweep_to = 500.0, sweep_count = 24 /\n"
          "&analysis window_start = 100.0, window_end = 300.0, lyapunov_transient = 100.0 /\n")
STATIC = "&sweep sweep_schedule = 'static' /\n"
LONGER = "&brake t_end = 6000.0 /\n"


def run(args, workdir, ranks, files, name):
    out = workdir / name
    cmd = [args.binary, "--quiet", "--force", "-o", str(out), *map(str, files)]
    if ranks > 1:
        cmd = [args.mpiexec, "-n", str(ranks), *cmd]
    subprocess.run(cmd, check=True, cwd=workdir)
    with h5py.File(out, "r") as f:
        return (f["sweep/values"].size, float(f.attrs["wall_time"]),
                f["sweep/peak_memory_per_rank"][()], f["sweep/compute_time"][()])


def rate(args, workdir, ranks, files):
    rates = []
    for k in range(args.repeats):
        n, wall, _, cost = run(args, workdir, ranks, files, "bench.h5")
        rates.append(n / wall)
    return statistics.median(rates), cost


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--large", type=int, default=1000, help="points of the memory sweep (at most 1024)")
    parser.add_argument("--memory-only", action="store_true", help="only the memory figures")
    parser.add_argument("--binary", default=str(ROOT / "build" / "friction"))
    parser.add_argument("--mpiexec", default=shutil.which("mpiexec") or "mpiexec")
    args = parser.parse_args()
    if not 4 <= args.large <= 1024:
        parser.error("--large must be in [4, 1024]")
    sweep = ROOT / "inputs" / "brake_sweep.nml"
    with tempfile.TemporaryDirectory() as tmp:
        workdir = Path(tmp)
        (workdir / "uneven.nml").write_text(UNEVEN)
        (workdir / "static.nml").write_text(STATIC)
        (workdir / "longer.nml").write_text(LONGER)
        if not args.memory_only:
            print(f"{'sweep':<22} {'ranks':>5} {'schedule':>9} {'points/s':>9} {'speed-up':>9}")
        for label, files in () if args.memory_only else (("belt velocity (48)", [sweep, workdir / "longer.nml"]), ("uneven t_end (24)", [sweep, workdir / "uneven.nml"])):
            one, cost = rate(args, workdir, 1, files)
            print(f"{label:<22} {1:>5} {'-':>9} {one:>9.2f} {1.0:>9.2f}")
            for schedule, extra in (("dynamic", []), ("static", [workdir / "static.nml"])):
                two, _ = rate(args, workdir, 2, files + extra)
                print(f"{label:<22} {2:>5} {schedule:>9} {two:>9.2f} {two / one:>9.2f}")
            print(f"{'':<22} point cost {cost.min():.3f} .. {cost.max():.3f} s, total {cost.sum():.2f} s")
        (workdir / "large.nml").write_text(
            "&brake t_end = 200.0, dt_out = 0.1 /\n"
            "&analysis window_start = 50.0, window_end = 200.0, lyapunov_transient = 50.0 /\n"
            f"&sweep sweep_count = {args.large} /\n")
        for ranks in (1, 2):
            for n in (args.large // 4, args.large):
                (workdir / "count.nml").write_text(f"&sweep sweep_count = {n} /\n")
                _, wall, memory, _ = run(args, workdir, ranks, [sweep, workdir / "large.nml",
                                                               workdir / "count.nml"], "large.h5")
                print(f"memory: brake, {n:>5} points on {ranks} rank(s): VmHWM per rank "
                      f"{', '.join(f'{m / 1024:.1f}' for m in memory)} MiB ({wall:.1f} s)")
        afm = ROOT / "inputs" / "afm_sweep.nml"
        side = int(np.sqrt(args.large))
        for ranks in (1, 2):
            for rows in (side // 4, side):
                (workdir / "afm_large.nml").write_text(
                    "&scan nx = 64, ny = 2 /\n"
                    f"&sweep sweep_count = {rows}, sweep_spacing2 = 'log', sweep_from2 = 100.0,"
                    f" sweep_to2 = 10000.0, sweep_count2 = {side} /\n")
                _, wall, memory, _ = run(args, workdir, ranks, [afm, workdir / "afm_large.nml"], "afm_large.h5")
                print(f"memory: AFM,   {rows * side:>5} points on {ranks} rank(s): VmHWM per rank "
                      f"{', '.join(f'{m / 1024:.1f}' for m in memory)} MiB ({wall:.1f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
