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
* the same fit on one process, for the speed-up (--no-serial skips it).

    python3 scripts/benchmark_fit.py [--workers N] [--size N] [--no-serial]

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
    args = parser.parse_args(argv)
    print(f"friction {friction.library_version()}, {os.cpu_count()} processors; {args.size} x {args.size} NaF "
          "image, trace and retrace of fx")
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
    return 0


if __name__ == "__main__":
    sys.exit(main())
