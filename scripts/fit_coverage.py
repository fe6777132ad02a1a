#!/usr/bin/env python3
"""Coverage of friction.fit.image's intervals: how often estimate +- 1.96 standard errors holds the truth.

A small image with Gaussian noise of 2 % of its standard deviation, N times with different
seeds, each fitted; for each parameter the count of fits whose 95 % interval holds the truth,
against the binomial band: the central 95 % of Binomial(N, 0.95), the counts a correct interval
gives 19 times in 20.  The fits are shared among processes (one fit each).  --scene chooses:

  naf       NaF, 4 lines of 32 samples, trace of fx; V0 = 0.8 eV, k = kx = ky = 6 N/m, an offset
            of 0.05 nN and a drift of 0.02 angstrom per line along x; fitted from V0 = 0.6 eV,
            k = 8 N/m with the nuisances offset and drift_x (the default);
  hopg      the paper's HOPG (V0 = 0.5 eV, k = 25 N/m, 7 degrees) on 10 x 5 angstrom, 4 lines of
            32 samples, trace of fx, the same offset and drift; from V0 = 0.35 eV, k = 18 N/m;
  graphite  graphite under the Lennard-Jones tip through its table (inputs/graphite.nml with
            graphite_damped.nml and graphite_stiff.nml), 4 lines of 32 samples, trace and retrace
            of fx, k = 2.5 N/m, support_z = -6 angstrom, an offset of 0.01 nN, no drift; from
            k = 3.25 N/m, support_z = -5 angstrom with the offset.

--start truth starts each fit at the truth (the nuisances too): the intervals of the minimum
around the truth, apart from whether a fit from afar finds it.  A fit whose noise estimate is
more than 1.5 times the noise added has stopped in another minimum: those are counted.

    python3 scripts/fit_coverage.py [--scene naf|hopg|graphite] [--start given|truth] [--count N]
                                    [--workers N] [--seed S]

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

INPUTS = ROOT / "inputs"
# name: (files, values, truth, start, nuisances, channels, drift along x per line)
SCENES = {
    "naf": ([INPUTS / "naf.nml"],
            {"scan.nx": 32, "scan.ny": 4, "scan.width": 3.0, "scan.retrace": False, "integrator.rtol": 1e-6,
             "integrator.atol": 1e-7, "surface.v0": 0.8, "tip.kx": 6.0, "tip.ky": 6.0},
            {"surface.v0": 0.8, "tip.kx=tip.ky": 6.0, "offset": 0.05, "drift_x": 0.02},
            {"surface.v0": 0.6, "tip.kx=tip.ky": 8.0}, ("offset", "drift_x"), ("trace/fx",), 0.02),
    "hopg": ([INPUTS / "hopg.nml"],
             {"scan.nx": 32, "scan.ny": 4, "scan.length": 10.0, "scan.width": 5.0, "scan.retrace": False,
              "integrator.rtol": 1e-6, "integrator.atol": 1e-7, "surface.v0": 0.5, "tip.kx": 25.0, "tip.ky": 25.0},
             {"surface.v0": 0.5, "tip.kx=tip.ky": 25.0, "offset": 0.05, "drift_x": 0.02},
             {"surface.v0": 0.35, "tip.kx=tip.ky": 18.0}, ("offset", "drift_x"), ("trace/fx",), 0.02),
    "graphite": ([INPUTS / "graphite.nml", INPUTS / "graphite_damped.nml", INPUTS / "graphite_stiff.nml"],
                 {"scan.nx": 32, "scan.ny": 4, "integrator.rtol": 1e-6, "integrator.atol": 1e-6,
                  "tip.kx": 2.5, "tip.ky": 2.5, "tip.support_z": -6.0},
                 {"tip.kx=tip.ky": 2.5, "tip.support_z": -6.0, "offset": 0.01},
                 {"tip.kx=tip.ky": 3.25, "tip.support_z": -5.0}, ("offset",), ("trace/fx", "retrace/fx"), 0.0),
}


def clean_image(scene):
    import friction
    files, values, truth, _, _, channels, drift = SCENES[scene]
    with friction.Config("afm", files=files, values=values) as cfg:
        origin = float(cfg["scan.origin_x"])
        lines = {c: [] for c in channels}
        for j in range(values["scan.ny"]):
            cfg.set("scan.origin_x", origin + drift * j)
            for c in channels:
                lines[c].append(getattr(cfg.afm_line(j, c.startswith("trace")), c.split("/")[1]))
    return {c: np.array(v) for c, v in lines.items()}


def one_fit(args):
    scene, clean, sigma, seed, from_truth = args
    import friction
    import friction.fit
    files, values, truth, start, nuisances, channels, _ = SCENES[scene]
    rng = np.random.default_rng(seed)
    measured = {c: clean[c] + truth["offset"] + sigma * rng.standard_normal(clean[c].shape) for c in channels}
    # The configuration's own values of the free parameters are not the truth: only the start counts.
    values = {k: v for k, v in values.items() if k not in ("surface.v0", "tip.kx", "tip.ky", "tip.support_z")}
    with friction.Config("afm", files=files, values=values) as cfg:
        if from_truth:
            start = {n: truth[n] for n in start}
            nuisances = {n: truth.get(n, 0.0) for n in nuisances}
        fit = friction.fit.image(measured, cfg, start, nuisances=nuisances, workers=1)
    return fit.converged, {n: (fit.values[n], fit.errors[n]) for n in truth}, fit.noise


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", choices=sorted(SCENES), default="naf", help="the image (default naf)")
    parser.add_argument("--start", choices=("given", "truth"), default="given",
                        help="the fits' start: the scene's (default) or the truth")
    parser.add_argument("--count", type=int, default=100, help="noise realizations (default 100)")
    parser.add_argument("--workers", type=int, default=2, help="processes (default 2)")
    parser.add_argument("--seed", type=int, default=1000, help="the first seed (default 1000)")
    args = parser.parse_args(argv)
    from scipy.stats import binom
    clean = clean_image(args.scene)
    sigma = 0.02 * float(np.std(np.concatenate([v.ravel() for v in clean.values()])))
    start = time.perf_counter()
    jobs = [(args.scene, clean, sigma, args.seed + i, args.start == "truth") for i in range(args.count)]
    with concurrent.futures.ProcessPoolExecutor(args.workers, mp_context=multiprocessing.get_context("spawn")) as pool:
        results = list(pool.map(one_fit, jobs))
    wall = time.perf_counter() - start
    low, high = binom.interval(0.95, args.count, 0.95)
    converged = sum(ok for ok, _, _ in results)
    elsewhere = sum(noise > 1.5 * sigma for _, _, noise in results)
    seeds = f"{args.seed}..{args.seed + args.count - 1}"
    origin = "the truth" if args.start == "truth" else "the scene's start"
    print(f"{args.scene}: {args.count} noise realizations (seeds {seeds}), noise {sigma:.4f} nN, {converged} "
          f"converged, {elsewhere} in another minimum (noise estimate over 1.5 times the noise), from {origin}; "
          f"{wall:.0f} s on {args.workers} processes")
    print(f"binomial band (central 95 % of Binomial({args.count}, 0.95)): {int(low)} to {int(high)}")
    for name, truth in SCENES[args.scene][2].items():
        z = np.array([(values[name][0] - truth) / values[name][1] for _, values, _ in results])
        covered = int(np.sum(np.abs(z) < 1.959964))
        inside = "inside" if low <= covered <= high else "OUTSIDE"
        print(f"  {name:<16} covered {covered:>4} of {args.count} ({inside} the band); median |z| "
              f"{np.median(np.abs(z)):.3f} (0.674 for a normal z); z's standard deviation {np.std(z, ddof=1):.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
