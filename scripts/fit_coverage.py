#!/usr/bin/env python3
"""Coverage of friction.fit.image's intervals: how often estimate +- 1.96 standard errors holds the truth.

A small NaF image (4 lines of 32 samples, trace of fx; V0 = 0.8 eV, k = kx = ky = 6 N/m, an
offset of 0.05 nN and a drift of 0.02 angstrom per line along x) with Gaussian noise of 2 % of
its standard deviation, N times with different seeds, each fitted from V0 = 0.6 eV, k = 8 N/m
with the nuisances offset and drift_x.  For each parameter the count of fits whose 95 % interval
holds the truth, against the binomial band: the central 95 % of Binomial(N, 0.95), the counts a
correct interval gives 19 times in 20.  The fits are shared among processes (one fit each).

    python3 scripts/fit_coverage.py [--count N] [--workers N] [--seed S]

Prints the counts, the band and the median |estimate - truth| / standard error; exits 0 (it
measures, it is not a test).
"""
import argparse
import concurrent.futures
import multiprocessing
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "python"))

import numpy as np  # noqa: E402

VALUES = {"scan.nx": 32, "scan.ny": 4, "scan.width": 3.0, "scan.retrace": False, "integrator.rtol": 1e-6,
          "integrator.atol": 1e-7, "surface.v0": 0.8, "tip.kx": 6.0, "tip.ky": 6.0}
TRUTH = {"surface.v0": 0.8, "tip.kx=tip.ky": 6.0, "offset": 0.05, "drift_x": 0.02}
START = {"surface.v0": 0.6, "tip.kx=tip.ky": 8.0}


def clean_image():
    import friction
    with friction.Config("afm", files=[ROOT / "inputs" / "naf.nml"], values=VALUES) as cfg:
        lines = []
        for j in range(VALUES["scan.ny"]):
            cfg.set("scan.origin_x", TRUTH["drift_x"] * j)
            lines.append(cfg.afm_line(j).fx)
    return np.array(lines)


def one_fit(args):
    clean, sigma, seed = args
    import friction
    import friction.fit
    measured = clean + TRUTH["offset"] + sigma * np.random.default_rng(seed).standard_normal(clean.shape)
    with friction.Config("afm", files=[ROOT / "inputs" / "naf.nml"], values=VALUES) as cfg:
        for name in ("surface.v0", "tip.kx", "tip.ky"):
            cfg.set(name, 1.0)   # the truth is not the configuration's: only the start counts
        fit = friction.fit.image({"trace/fx": measured}, cfg, START, nuisances=("offset", "drift_x"), workers=1)
    return fit.converged, {n: (fit.values[n], fit.errors[n]) for n in TRUTH}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=100, help="noise realizations (default 100)")
    parser.add_argument("--workers", type=int, default=2, help="processes (default 2)")
    parser.add_argument("--seed", type=int, default=1000, help="the first seed (default 1000)")
    args = parser.parse_args(argv)
    from scipy.stats import binom
    clean = clean_image()
    sigma = 0.02 * float(np.std(clean))
    start = time.perf_counter()
    jobs = [(clean, sigma, args.seed + i) for i in range(args.count)]
    with concurrent.futures.ProcessPoolExecutor(args.workers, mp_context=multiprocessing.get_context("spawn")) as pool:
        results = list(pool.map(one_fit, jobs))
    wall = time.perf_counter() - start
    low, high = binom.interval(0.95, args.count, 0.95)
    converged = sum(ok for ok, _ in results)
    print(f"{args.count} noise realizations (seeds {args.seed}..{args.seed + args.count - 1}), noise {sigma:.4f} nN,"
          f" {converged} converged, {wall:.0f} s on {args.workers} processes")
    print(f"binomial band (central 95 % of Binomial({args.count}, 0.95)): {int(low)} to {int(high)}")
    for name, truth in TRUTH.items():
        z = np.array([(values[name][0] - truth) / values[name][1] for _, values in results])
        covered = int(np.sum(np.abs(z) < 1.959964))
        inside = "inside" if low <= covered <= high else "OUTSIDE"
        print(f"  {name:<16} covered {covered:>4} of {args.count} ({inside} the band); median |z| "
              f"{np.median(np.abs(z)):.3f} (0.674 for a normal z); z's standard deviation {np.std(z, ddof=1):.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
