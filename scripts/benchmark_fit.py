#!/usr/bin/env python3
"""Benchmark friction.fit.image: a 64 x 64 NaF image, three free parameters and the nuisances.

Measures and prints (this is not a test; nothing fails on a missed target):

* a synthetic "measured" NaF image (inputs/naf.nml, 64 lines of 64 samples, trace and retrace
  of fx), V0 = 0.8 eV, k = kx = ky = 6 N/m, lattice constant ax = ay = 4.62 angstrom, times a
  calibration of 1.05, an offset of 0.05 nN, a drift of the support of (0.01, -0.005) angstrom
  per line and Gaussian noise of 2 % of the image's standard deviation (seed 1);
* its fit from V0 = 0.6 eV, k = 8 N/m, ax = ay = 4.5 angstrom with the nuisances offset,
  calibration, drift_x and drift_y: the wall time (target: under 60 s on 2 cores), the model
  images and scan lines computed, the estimates against the truth in standard errors;
* the same fit on one process, for the speed-up (--no-serial skips it);
* graphite under the Lennard-Jones tip, the lattice sum through its table (inputs/graphite.nml
  with graphite_damped.nml and graphite_stiff.nml: kx = ky = 2.5 N/m, rkf45 at rtol 1e-6),
  an 8 x 8 image (--graphite-size), trace and retrace of fx: first the cost of one line with
  the table built, with the table kept, and with the scan moved (the table built again), the
  medians of 5; then the fit of k and the support's height with the offset, from k = 3.25 N/m
  and support_z = -5 angstrom, repeated (--repeats, default 3): the median wall time, the model
  images to converge, the time per image and per line; with --drift the same with a drift of
  0.01 angstrom per line in the image and drift_x fitted (a drift moves each line's scan: the
  table is built again for every line).

    python3 scripts/benchmark_fit.py [--workers N] [--size N] [--no-serial] [--scene naf|graphite]
                                     [--graphite-size N] [--repeats N] [--drift]

The library is found as the package finds it (FRICTION_LIBRARY, the build tree).
"""
import argparse
import os
import resource
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "python"))

import numpy as np  # noqa: E402

import friction  # noqa: E402
import friction.fit  # noqa: E402

TRUE = {"surface.v0": 0.8, "tip.kx=tip.ky": 6.0, "surface.ax=surface.ay": 4.62}
START = {"surface.v0": 0.6, "tip.kx=tip.ky": 8.0, "surface.ax=surface.ay": 4.5}
NUISANCES = {"offset": 0.05, "calibration": 1.05, "drift_x": 0.01, "drift_y": -0.005}
# rtol 1e-4: the finite differences' step of 1e-6 then has a Jacobian error near 1e-5 (docs/fitting.md).
TOLERANCES = {"integrator.rtol": 1e-4, "integrator.atol": 1e-5}


def measured_image(size):
    """The synthetic measurement, line by line with the support's origin moved by j * drift."""
    values = {"scan.nx": size, "scan.ny": size, **TOLERANCES, "surface.v0": 0.8, "tip.kx": 6.0, "tip.ky": 6.0,
              "surface.ax": 4.62, "surface.ay": 4.62}
    with friction.Config("afm", files=[ROOT / "inputs" / "naf.nml"], values=values) as cfg:
        clean = {"trace/fx": [], "retrace/fx": []}
        for j in range(size):
            cfg.set("scan.origin_x", NUISANCES["drift_x"] * j).set("scan.origin_y", NUISANCES["drift_y"] * j)
            clean["trace/fx"].append(cfg.afm_line(j, True).fx)
            clean["retrace/fx"].append(cfg.afm_line(j, False).fx)
    clean = {k: np.array(v) for k, v in clean.items()}
    sigma = 0.02 * np.std(np.concatenate([v.ravel() for v in clean.values()]))
    rng = np.random.default_rng(1)
    return {k: NUISANCES["calibration"] * v + NUISANCES["offset"] + sigma * rng.standard_normal(v.shape)
            for k, v in clean.items()}, sigma


def fit(measured, size, workers):
    values = {"scan.nx": size, "scan.ny": size, **TOLERANCES}
    with friction.Config("afm", files=[ROOT / "inputs" / "naf.nml"], values=values) as cfg:
        start, cpu = time.perf_counter(), _cpu()
        result = friction.fit.image(measured, cfg, START, nuisances=list(NUISANCES), workers=workers)
        return result, time.perf_counter() - start, _cpu() - cpu


def _cpu():
    """CPU seconds of this process and its finished children (the pool's workers, reaped at the fit's end)."""
    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


def report(label, result, wall, cpu, truth):
    print(f"{label}: {wall:.1f} s wall, {cpu:.1f} s CPU, load average {os.getloadavg()[0]:.1f}; "
          f"{result.evaluations} model images, {result.lines_computed} scan lines "
          f"({1e3 * wall / result.lines_computed:.1f} ms of wall per line); "
          f"{'converged' if result.converged else 'NOT converged'} ({result.reason})")
    for name in result.names:
        z = (result.values[name] - truth[name]) / result.errors[name]
        print(f"  {name:<22} {result.values[name]:>11.5g} +- {result.errors[name]:<9.2g} true {truth[name]:<8g}"
              f" ({z:+.2f} SE)")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=2, help="processes computing lines (default 2)")
    parser.add_argument("--size", type=int, default=64, help="lines and samples per line (default 64)")
    parser.add_argument("--no-serial", action="store_true", help="skip the one-process fit")
    parser.add_argument("--scene", choices=("naf", "graphite"), action="append",
                        help="the benchmark to run (repeatable; default both)")
    parser.add_argument("--graphite-size", type=int, default=8, help="graphite's lines and samples (default 8)")
    parser.add_argument("--repeats", type=int, default=3, help="graphite fits whose median is quoted (default 3)")
    parser.add_argument("--drift", action="store_true", help="also fit graphite's drift (minutes: the table "
                        "is built again for every line)")
    args = parser.parse_args(argv)
    scenes = args.scene or ["naf", "graphite"]
    print(f"friction {friction.library_version()}, {os.cpu_count()} processors")
    if "naf" in scenes:
        print(f"{args.size} x {args.size} NaF image, trace and retrace of fx")
        measured, sigma = measured_image(args.size)
        print(f"noise {sigma:.4f} nN (2 % of the image's standard deviation)")
        truth = {**TRUE, **NUISANCES}
        result, wall, cpu = fit(measured, args.size, args.workers)
        report(f"{args.workers} processes", result, wall, cpu, truth)
        if not args.no_serial and args.workers > 1:
            serial, serial_wall, serial_cpu = fit(measured, args.size, 1)
            report("1 process", serial, serial_wall, serial_cpu, truth)
            print(f"speed-up {serial_wall / wall:.2f}x on {args.workers} processes (the same fit: "
                  f"{'yes' if serial.values == result.values else 'no'})")
    if "graphite" in scenes:
        graphite(args.graphite_size, args.workers, args.repeats, args.drift)
    return 0


# ---------------------------------------------------------------- graphite through the table

GRAPHITE = [ROOT / "inputs" / "graphite.nml", ROOT / "inputs" / "graphite_damped.nml",
            ROOT / "inputs" / "graphite_stiff.nml"]
# rtol 1e-6: the finite differences' step of 1e-6 on a tip that slides along steep walls.
GRAPHITE_TOLERANCES = {"integrator.rtol": 1e-6, "integrator.atol": 1e-6}
GRAPHITE_TRUE = {"tip.kx=tip.ky": 2.5, "tip.support_z": -6.0, "offset": 0.01}
GRAPHITE_START = {"tip.kx=tip.ky": 3.25, "tip.support_z": -5.0}
GRAPHITE_DRIFT = 0.01   # angstrom per line, along x, in the --drift image


def graphite_values(size):
    return {"scan.nx": size, "scan.ny": size, **GRAPHITE_TOLERANCES}


def line_costs(size, repeats=5):
    """Seconds of one line (medians of `repeats`): the table built (a new configuration), kept
    (the same configuration again), built again (the scan's origin moved by 0.01 angstrom)."""
    built, kept, moved = [], [], []
    for _ in range(repeats):
        with friction.Config("afm", files=GRAPHITE, values=graphite_values(size)) as cfg:
            start = time.perf_counter()
            cfg.afm_line(0)
            built.append(time.perf_counter() - start)
            start = time.perf_counter()
            cfg.afm_line(1)
            kept.append(time.perf_counter() - start)
            cfg.set("scan.origin_x", float(cfg["scan.origin_x"]) + 0.01)
            start = time.perf_counter()
            cfg.afm_line(1)
            moved.append(time.perf_counter() - start)
    return float(np.median(built)), float(np.median(kept)), float(np.median(moved))


def graphite_image(size, drift):
    """The synthetic measurement: the map at the truth, line j's scan moved by j * drift along x,
    plus the offset and Gaussian noise of 2 % of its standard deviation (seed 1)."""
    values = {**graphite_values(size), "tip.kx": 2.5, "tip.ky": 2.5, "tip.support_z": -6.0}
    with friction.Config("afm", files=GRAPHITE, values=values) as cfg:
        origin = float(cfg["scan.origin_x"])
        clean = {"trace/fx": [], "retrace/fx": []}
        for j in range(size):
            cfg.set("scan.origin_x", origin + drift * j)
            clean["trace/fx"].append(cfg.afm_line(j, True).fx)
            clean["retrace/fx"].append(cfg.afm_line(j, False).fx)
    clean = {k: np.array(v) for k, v in clean.items()}
    sigma = 0.02 * np.std(np.concatenate([v.ravel() for v in clean.values()]))
    rng = np.random.default_rng(1)
    return {k: v + GRAPHITE_TRUE["offset"] + sigma * rng.standard_normal(v.shape) for k, v in clean.items()}, sigma


def graphite(size, workers, repeats, drift):
    print(f"graphite (Lennard-Jones through the table): {size} x {size} image, trace and retrace of fx, "
          f"{workers} processes")
    built, kept, moved = line_costs(size)
    print(f"one line of {size} samples (medians of 5): {1e3 * built:.0f} ms with the table built, "
          f"{1e3 * kept:.1f} ms with it kept ({built / kept:.0f}x), {1e3 * moved:.0f} ms with the scan moved")
    cases = [("k, support_z and the offset", 0.0, ("offset",), repeats)]
    if drift:
        cases.append(("the same and drift_x", GRAPHITE_DRIFT, ("offset", "drift_x"), repeats))
    for label, shift, nuisances, count in cases:
        measured, sigma = graphite_image(size, shift)
        runs = []
        for _ in range(count):
            with friction.Config("afm", files=GRAPHITE, values=graphite_values(size)) as cfg:
                start, cpu = time.perf_counter(), _cpu()
                result = friction.fit.image(measured, cfg, GRAPHITE_START, nuisances=nuisances, workers=workers)
                runs.append((time.perf_counter() - start, _cpu() - cpu, result))
        wall, cpu, result = sorted(runs, key=lambda run: run[0])[len(runs) // 2]
        print(f"{label} (noise {sigma:.5f} nN): median of {len(runs)} fits {wall:.1f} s wall, {cpu:.1f} s CPU "
              f"(walls {', '.join(f'{w:.1f}' for w, _, _ in runs)} s); {result.evaluations} model images, "
              f"{1e3 * wall / result.evaluations:.0f} ms wall and {1e3 * cpu / result.evaluations:.0f} ms CPU "
              f"per image")
        report("  median fit", result, wall, cpu, {**GRAPHITE_TRUE, "drift_x": shift})


if __name__ == "__main__":
    sys.exit(main())
