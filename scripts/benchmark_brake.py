#!/usr/bin/env python3
"""Benchmark friction's Girling brake: cost of every GSL stepper at matched accuracy.

Measures and prints (this is not a test; nothing fails on a missed target):

* References for the paper's case (inputs/brake.nml, tau in [0, 3200]):
  regularized law: rk8pd at rtol 1e-13, checked against rk4imp at 1e-12;
  switched model: rk8pd at rtol 1e-14 (event tolerance 1e-13), checked
  against rk8pd at 1e-13 (event tolerance 1e-12).  The agreement of each
  pair is printed: it bounds the references' own error.
* Matched accuracy, regularized law, every stepper: along a tolerance
  ladder (rtol = 1e-4, 1e-5, ..., atol = rtol / 100), the first rung whose
  error in x at tau = 200 and tau = 1000 is below --target-regularized (m),
  with its integration time and right-hand-side evaluations.  A stepper
  that does not get there within --max-wall seconds per run is listed as such.
* The same for the switched model, every stepper, with the error taken as
  the largest |x - x_ref| over the whole grid of tau in [0, 3200]
  (--target-switched, default 1e-8 m: the issue's target, to be reached in
  under 20 ms).
* Silently wrong answers: every stepper on the regularized law at
  rtol 1e-6, its error and event count next to the reference's.

Times are the file's /brake attribute compute_time (the integration alone,
median of --repeats runs); the whole process (start-up, input, HDF5 output)
adds about 0.3 s.  Right-hand sides include the Jacobian-free evaluations of
the event locator's probes and interpolants.

Usage (normally through scripts/benchmark_brake, which builds first):

    python3 scripts/benchmark_brake.py [--repeats N] [--quick] [--json FILE]
                                       [--binary PATH] [--max-wall S]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

try:
    import h5py
    import numpy as np
except ImportError as exc:  # pragma: no cover - environment problem
    sys.exit(f"benchmark_brake: {exc}; run scripts/install-deps")

ROOT = Path(__file__).resolve().parent.parent
INPUT = ROOT / "inputs" / "brake.nml"
METHODS = ("rk2", "rk4", "rkf45", "rkck", "rk8pd", "rk1imp", "rk2imp", "rk4imp", "bsimp",
           "msadams", "msbdf")
LADDER = tuple(10.0 ** -k for k in range(4, 13))
CHECK_TIMES = (200.0, 1000.0)


def log(msg: str) -> None:
    print(f"benchmark_brake: {msg}", file=sys.stderr, flush=True)


@dataclass
class Run:
    """One friction run and what its file says."""

    ok: bool
    message: str
    compute_time: float = float("nan")
    rhs: int = 0
    steps: int = 0
    events: int = 0
    t: np.ndarray | None = None
    x: np.ndarray | None = None


class Friction:
    """Runs the program on generated overrides of inputs/brake.nml."""

    def __init__(self, binary: Path, workdir: Path, max_wall: float):
        self.binary = binary
        self.workdir = workdir
        self.max_wall = max_wall
        self.count = 0

    def run(self, model: str, method: str, rtol: float, atol: float, t_end: float, dt_out: float,
            event_tolerance: float = 1e-10, brake_vars: str = "") -> Run:
        """One run; `brake_vars` are more &brake settings (e.g. "epsilon_prime = 1e5").
        A run still going 60 s after its max_wall_time is killed and reported failed."""
        self.count += 1
        nml = self.workdir / f"run{self.count}.nml"
        out = self.workdir / f"run{self.count}.h5"
        nml.write_text(
            f"&brake model = '{model}', t_end = {t_end!r}, dt_out = {dt_out!r}, "
            f"event_tolerance = {event_tolerance!r}{', ' + brake_vars if brake_vars else ''} /\n"
            f"&integrator method = '{method}', rtol = {rtol!r}, atol = {atol!r}, "
            f"max_steps = 200000000, max_wall_time = {self.max_wall!r} /\n"
            # The integration alone is measured: no chaos diagnostics.
            "&analysis spectrum = .false., poincare = .false., lyapunov = .false., rosenstein = .false.,"
            " lyapunov_spectrum = .false., orbit = .false. /\n")
        try:
            proc = subprocess.run([str(self.binary), "--quiet", "--force", "-o", str(out), str(INPUT), str(nml)],
                                  capture_output=True, text=True, cwd=self.workdir,
                                  timeout=(self.max_wall + 60.0) if self.max_wall > 0 else None)
        except subprocess.TimeoutExpired:
            return Run(False, f"killed: still running {self.max_wall + 60.0:g} s after its start")
        if proc.returncode != 0:
            # The error itself, not a warning said before it (the creep band's).
            lines = proc.stderr.strip().splitlines()
            errors = [ln.replace("friction: error: ", "") for ln in lines if ln.startswith("friction: error: ")]
            return Run(False, " ".join(errors) if errors else proc.stderr.strip())
        with h5py.File(out, "r") as f:
            result = Run(True, "", float(f["brake"].attrs["compute_time"]), int(f.attrs["rhs_evaluations"]),
                         int(f.attrs["integrator_steps"]), int(f["brake/events/t"].size),
                         f["brake/t"][()], f["brake/x"][()])
        out.unlink()
        nml.unlink()
        return result

    def timed(self, repeats: int, *args, **kwargs) -> Run:
        """The run, with its compute_time the median over repeats."""
        runs = [self.run(*args, **kwargs) for _ in range(repeats)]
        if not all(r.ok for r in runs):
            return next(r for r in runs if not r.ok)
        best = runs[0]
        best.compute_time = statistics.median(r.compute_time for r in runs)
        return best


def error_at(run: Run, ref: Run, times) -> float:
    """max |x - x_ref| at the given times (on both grids)."""
    worst = 0.0
    for t in times:
        i = int(np.argmin(np.abs(run.t - t)))
        j = int(np.argmin(np.abs(ref.t - t)))
        if abs(run.t[i] - t) > 1e-9 or abs(ref.t[j] - t) > 1e-9:
            raise RuntimeError(f"tau = {t} not on the grid")
        worst = max(worst, abs(run.x[i] - ref.x[j]))
    return worst


def error_over_grid(run: Run, ref: Run) -> float:
    if run.x.shape != ref.x.shape:
        raise RuntimeError("grids differ")
    return float(np.max(np.abs(run.x - ref.x)))


def ladder(fr: Friction, model: str, method: str, target: float, measure, t_end: float, dt_out: float,
           repeats: int, rungs) -> dict:
    """The loosest rung of the ladder that meets the target."""
    tried = []
    for rtol in rungs:
        kwargs = {}
        if model == "switched":
            kwargs["event_tolerance"] = min(1e-10, rtol)
        r = fr.run(model, method, rtol, rtol / 100, t_end, dt_out, **kwargs)
        if not r.ok:
            tried.append({"rtol": rtol, "failed": r.message})
            log(f"  {model} {method} rtol {rtol:.0e}: failed ({r.message[:90]})")
            if "max_wall_time" in r.message:
                break
            continue
        err = measure(r)
        tried.append({"rtol": rtol, "error": err, "time": r.compute_time, "rhs": r.rhs})
        log(f"  {model} {method} rtol {rtol:.0e}: error {err:.1e} m, {r.compute_time:.3f} s")
        if err <= target:
            best = fr.timed(repeats, model, method, rtol, rtol / 100, t_end, dt_out, **kwargs)
            return {"method": method, "rtol": rtol, "error": err, "time": best.compute_time, "rhs": best.rhs,
                    "steps": best.steps, "events": best.events, "ladder": tried}
    return {"method": method, "rtol": None, "ladder": tried}


def print_matched(title: str, rows: list, target: float, error_label: str) -> None:
    print(f"\n{title} (target: error <= {target:.0e} m)\n")
    print(f"| method | rtol needed | {error_label} | time | rhs evaluations | steps |")
    print("|---|---|---|---|---|---|")
    for row in sorted(rows, key=lambda r: (r["rtol"] is None, r.get("time", 0))):
        if row["rtol"] is None:
            last = row["ladder"][-1] if row["ladder"] else {}
            why = last.get("failed", f"error {last.get('error', float('nan')):.1e} m at rtol {last.get('rtol', 0):.0e}")
            print(f"| {row['method']} | not reached | | | | {why[:80]} |")
        else:
            print(f"| {row['method']} | {row['rtol']:.0e} | {row['error']:.1e} m | {row['time'] * 1e3:.1f} ms "
                  f"| {row['rhs']:,} | {row['steps']:,} |")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--binary", type=Path, default=ROOT / "build" / "friction")
    parser.add_argument("--repeats", type=int, default=3, help="runs per timed case (median)")
    parser.add_argument("--quick", action="store_true", help="a coarser ladder, one repeat")
    parser.add_argument("--json", type=Path, help="also write the results here")
    parser.add_argument("--max-wall", type=float, default=30.0, help="wall-time guard per run, s")
    parser.add_argument("--target-regularized", type=float, default=1e-7)
    parser.add_argument("--target-switched", type=float, default=1e-8)
    args = parser.parse_args()
    if not args.binary.exists():
        print(f"benchmark_brake: {args.binary}: no such program (run scripts/build)", file=sys.stderr)
        return 2
    repeats = 1 if args.quick else max(1, args.repeats)
    rungs = LADDER[::2] if args.quick else LADDER
    results = {"machine": platform.node(), "processor": platform.processor() or platform.machine(),
               "cpus": os.cpu_count()}

    with tempfile.TemporaryDirectory(prefix="benchmark_brake_") as tmp:
        fr = Friction(args.binary, Path(tmp), args.max_wall)

        log("references")
        reg_ref = fr.run("regularized", "rk8pd", 1e-13, 1e-15, 1000.0, 100.0)
        reg_chk = fr.run("regularized", "rk4imp", 1e-12, 1e-14, 1000.0, 100.0)
        sw_ref = fr.run("switched", "rk8pd", 1e-14, 1e-16, 3200.0, 1.0, event_tolerance=1e-13)
        sw_chk = fr.run("switched", "rk8pd", 1e-13, 1e-15, 3200.0, 1.0, event_tolerance=1e-12)
        for name, r in [("regularized reference", reg_ref), ("regularized check", reg_chk),
                        ("switched reference", sw_ref), ("switched check", sw_chk)]:
            if not r.ok:
                print(f"benchmark_brake: {name} failed: {r.message}", file=sys.stderr)
                return 1
        reg_agree = error_at(reg_chk, reg_ref, CHECK_TIMES)
        sw_agree = error_over_grid(sw_chk, sw_ref)
        results["references"] = {
            "regularized": {"method": "rk8pd", "rtol": 1e-13, "check": "rk4imp 1e-12", "agreement": reg_agree,
                            "events": reg_ref.events},
            "switched": {"method": "rk8pd", "rtol": 1e-14, "check": "rk8pd 1e-13", "agreement": sw_agree,
                         "events": sw_ref.events}}

        log("regularized law, matched accuracy")
        reg_rows = [ladder(fr, "regularized", m, args.target_regularized,
                           lambda r: error_at(r, reg_ref, CHECK_TIMES), 1000.0, 100.0, repeats, rungs)
                    for m in METHODS]
        log("switched model, matched accuracy")
        sw_rows = [ladder(fr, "switched", m, args.target_switched,
                          lambda r: error_over_grid(r, sw_ref), 3200.0, 1.0, repeats, rungs)
                   for m in METHODS]
        log("regularized law at rtol 1e-6")
        loose = []
        for m in METHODS:
            r = fr.run("regularized", m, 1e-6, 1e-8, 1000.0, 100.0)
            if r.ok:
                loose.append({"method": m, "error": error_at(r, reg_ref, CHECK_TIMES), "events": r.events,
                              "time": r.compute_time})
            else:
                loose.append({"method": m, "failed": r.message})
        results.update({"regularized": reg_rows, "switched": sw_rows, "loose": loose,
                        "targets": {"regularized": args.target_regularized, "switched": args.target_switched}})

    print(f"# Girling brake benchmark ({results['cpus']} CPUs, {results['processor']})\n")
    print("References:")
    print(f"- regularized law, tau in [0, 1000]: rk8pd rtol 1e-13; rk4imp at 1e-12 agrees to "
          f"{reg_agree:.1e} m at tau = 200 and 1000 ({reg_ref.events} creep-band events)")
    print(f"- switched model, tau in [0, 3200]: rk8pd rtol 1e-14; rk8pd at 1e-13 agrees to "
          f"{sw_agree:.1e} m over the grid ({sw_ref.events} events)")
    print_matched("Regularized law (epsilon' = 3.5121e7), tau in [0, 1000], error in x at tau = 200 and 1000",
                  reg_rows, args.target_regularized, "error")
    print_matched("Switched model, tau in [0, 3200], largest error in x over the grid (dt_out = 1)",
                  sw_rows, args.target_switched, "error")
    print("\nRegularized law at rtol 1e-6, atol 1e-8 (does the stepper know it is wrong?)\n")
    print("| method | error in x at tau = 200, 1000 | events (reference: %d) | time |" % reg_ref.events)
    print("|---|---|---|---|")
    for row in loose:
        if "failed" in row:
            print(f"| {row['method']} | failed: {row['failed'][:70]} | | |")
        else:
            print(f"| {row['method']} | {row['error']:.1e} m | {row['events']} | {row['time'] * 1e3:.0f} ms |")
    if args.json:
        args.json.write_text(json.dumps(results, indent=1, default=float))
        log(f"wrote {args.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
