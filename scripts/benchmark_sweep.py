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
* What a point keeps (docs/sweeps.md): a graphite sweep of the tip's kx (8
  points of a 2-line, 12-sample scan of inputs/graphite.nml) on 1 and 2
  ranks; each rank builds the surface table for its first point and keeps
  it, so its first point's cost (/sweep/compute_time) holds the build and
  the others do not: printed are the first points' costs, the median of the
  others, and the points per second.
* Peak resident memory (VmHWM) of every rank, from /sweep/peak_memory_per_rank,
  for a large sweep (--large points of a short brake run) on 1 and 2 ranks,
  and for a large AFM sweep (inputs/afm_sweep.nml as a 32 x 32 grid of V0 and
  velocity, --large points in all, small maps), with a quarter of the points
  for comparison: memory per rank must not grow with the points.
* Scale (--scale): a cheap 2-D brake grid (tau = 60, both variables in
  &brake) of 1e3, 1e4 and 1e5 points (--counts) on 1 and 2 ranks: points per
  second per core, peak memory per rank (VmHWM), the file's size, and the
  cost the sweep adds per point besides computing it (wall time less the
  points' compute time, per point: messages, checkpoint, the copy into the
  output).  Then the cost of an atlas point (a point of
  inputs/brake_sweep.nml, the median of its 48), and from both the projected
  wall time of a 1e6-point atlas on 1, 16 and 64 nodes of --cores-per-node
  cores: max(points x cost / ranks, points x added cost), the second term
  being rank 0's share (taking every point's message, batch and copy; the
  larger added cost of 1 and 2 ranks), which does not shrink with more ranks.

Usage (normally through scripts/benchmark_sweep, which builds first):

    python3 scripts/benchmark_sweep.py [--repeats N] [--large N] [--memory-only] [--scale]
                                       [--counts N ...] [--cores-per-node N] [--binary PATH] [--mpiexec PATH]
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
                f["sweep/peak_memory_per_rank"][()] / 1024.0, f["sweep/compute_time"][()])   # bytes -> KiB


# The cheap grid of --scale: mu (valid, below mu_s = 0.59) by xi, tau = 60.
CHEAP = ("&brake mu = 0.5, mu_s = 0.59, t_end = 60.0, dt_out = 0.5 /\n"
         "&analysis window_start = 10.0, window_end = 60.0, spectrum = .false., lyapunov = .false.,"
         " rosenstein = .false., lyapunov_spectrum = .false. /\n"
         "&sweep sweep_variable = 'brake.mu', sweep_spacing = 'linear', sweep_from = 0.3, sweep_to = 0.58,"
         " sweep_count = {rows},\n sweep_variable2 = 'brake.xi', sweep_spacing2 = 'linear', sweep_from2 = 0.1,"
         " sweep_to2 = 0.5, sweep_count2 = {columns} /\n")


def grid_shape(n):
    """rows x columns = n, as square as n allows."""
    rows = int(np.sqrt(n))
    while n % rows:
        rows -= 1
    return rows, n // rows


def hours(seconds):
    return f"{seconds / 3600:.2f} h" if seconds >= 3600 else f"{seconds / 60:.1f} min"


def scale(args, workdir):
    """The --scale section: throughput and memory against the number of points, and the projection."""
    brake = ROOT / "inputs" / "brake.nml"
    print(f"{'points':>7} {'ranks':>5} {'wall s':>8} {'points/s/core':>14} {'VmHWM per rank MiB':>19} "
          f"{'file MiB':>9} {'added ms/point':>15}")
    added = {}
    for n in args.counts:
        rows, columns = grid_shape(n)
        (workdir / "cheap.nml").write_text(CHEAP.format(rows=rows, columns=columns))
        for ranks in (1, 2):
            points, wall, memory, cost = run(args, workdir, ranks, [brake, workdir / "cheap.nml"], "cheap.h5")
            size = (workdir / "cheap.h5").stat().st_size / 2**20
            # Rank 0 computes too: what the sweep adds per point is the wall
            # time less the compute time of the points, shared by the ranks.
            extra = (wall - cost.sum() / ranks) / points
            added[n] = max(added.get(n, 0.0), extra)
            print(f"{points:>7} {ranks:>5} {wall:>8.2f} {points / wall / ranks:>14.0f} "
                  f"{', '.join(f'{m / 1024:.1f}' for m in memory):>19} {size:>9.1f} {1e3 * extra:>15.3f}")
    # An atlas point: a point of inputs/brake_sweep.nml.
    _, _, _, cost = run(args, workdir, 2, [ROOT / "inputs" / "brake_sweep.nml"], "atlas.h5")
    point = float(np.median(cost))
    extra = added[max(added)]
    n = 1_000_000
    print(f"\natlas point (inputs/brake_sweep.nml, median of {cost.size}): {point * 1e3:.1f} ms; "
          f"added by the sweep per point (the larger of 1 and 2 ranks, {max(added)} points): {extra * 1e3:.3f} ms")
    print(f"projected 1e6-point atlas, {args.cores_per_node} ranks per node:")
    for nodes in (1, 16, 64):
        ranks = nodes * args.cores_per_node
        compute = n * point / ranks
        writer = n * extra
        print(f"  {nodes:>3} node(s), {ranks:>5} ranks: {hours(max(compute, writer))} "
              f"(computing {hours(compute)}, rank 0's share {hours(writer)})")


KEPT = ("&scan nx = 12, ny = 2, length = 2.0, width = 1.0 /\n"
        "&sweep sweep_variable = 'tip.kx', sweep_spacing = 'linear', sweep_from = 0.25, sweep_to = 2.5,"
        " sweep_count = 8 /\n")


def kept(args, workdir):
    """The graphite table built once per rank, not once per point."""
    (workdir / "kept.nml").write_text(KEPT)
    for ranks in (1, 2):
        walls, firsts, others = [], [], []
        for _ in range(args.repeats):
            points, wall, _, cost = run(args, workdir, ranks, [ROOT / "inputs" / "graphite.nml",
                                                               workdir / "kept.nml"], "kept.h5")
            # (Dynamic scheduling hands out points 1, 2, ... in order: with
            # r ranks the first r points are the ranks' first.)
            walls.append(wall)
            firsts.append(float(np.max(cost[:ranks])))
            others.append(float(np.median(cost[ranks:])))
        print(f"graphite kx sweep ({points} points) on {ranks} rank(s): first point per rank "
              f"{1e3 * statistics.median(firsts):.0f} ms (table built), other points "
              f"{1e3 * statistics.median(others):.0f} ms (table kept); "
              f"{points / statistics.median(walls):.1f} points/s")


def rate(args, workdir, ranks, files):
    rates = []
    for k in range(args.repeats):
        n, wall, _, cost = run(args, workdir, ranks, files, "bench.h5")
        rates.append(n / wall)
    return statistics.median(rates), cost


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--large", type=int, default=1000, help="points of the memory sweep")
    parser.add_argument("--memory-only", action="store_true", help="only the memory figures")
    parser.add_argument("--scale", action="store_true", help="only the scale figures and the atlas projection")
    parser.add_argument("--counts", type=int, nargs="+", default=[1000, 10000, 100000],
                        help="points of the scale sweeps")
    parser.add_argument("--cores-per-node", type=int, default=32, help="ranks per node of the projection")
    parser.add_argument("--binary", default=str(ROOT / "build" / "friction"))
    parser.add_argument("--mpiexec", default=shutil.which("mpiexec") or "mpiexec")
    args = parser.parse_args()
    if args.large < 4:
        parser.error("--large must be at least 4")
    sweep = ROOT / "inputs" / "brake_sweep.nml"
    with tempfile.TemporaryDirectory() as tmp:
        workdir = Path(tmp)
        if args.scale:
            scale(args, workdir)
            return 0
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
        if not args.memory_only:
            kept(args, workdir)
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
