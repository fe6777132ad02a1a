#!/usr/bin/env python3
"""Benchmark friction's AFM friction maps: speed, accuracy and MPI speed-up.

Measures and prints (this is not a test; nothing fails on a missed target):

* NaF and HOPG maps as the input files give them (default tolerance):
  time per map and per scan line on 1 and 2 ranks (median of --repeats runs),
  the 2-rank speed-up, and the force error against a reference run.
* The reference runs themselves: rk8pd at rtol = atol = 1e-11, checked for
  convergence against rk8pd at rtol = atol = 1e-10.
* The issue's target case, a 256-line x 256-point NaF trace+retrace map:
  time on one rank, force error and 2-rank speed-up next to the targets
  (< 0.5 s on one core, error < 1e-3 nN; speed-up >= 1.8x on 2 ranks).
* A tolerance/method ladder for that map: time and error of each setting.
* A long NaF map (3000 lines of 128 points) with checkpoints every 2 s and
  without: what a long map pays for being resumable (--no-checkpoints skips it).

Times: "wall" is the file's root attribute wall_time (max over ranks, from
MPI start-up to just before writing the file); "process" is the wall clock
of the whole mpirun command (start-up, input, output included).
Force error: max |F - F_ref| over fx and fy of trace and retrace, in nN.

Usage (from anywhere; normally through scripts/benchmark_afm, which builds first):

    python3 scripts/benchmark_afm.py [--repeats N] [--quick] [--json FILE]
                                     [--binary PATH] [--mpirun CMD] [--no-ladder]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import re
import shlex
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

try:
    import h5py
    import numpy as np
except ImportError as exc:  # pragma: no cover - environment problem
    sys.exit(f"benchmark_afm: {exc}; run scripts/install-deps")

ROOT = Path(__file__).resolve().parent.parent
INPUTS = ROOT / "inputs"

REF_METHOD, REF_TOL, REF_CHECK_TOL = "rk8pd", 1e-11, 1e-10
TARGET_TIME_S, TARGET_ERROR_NN, TARGET_SPEEDUP = 0.5, 1e-3, 1.8
CHECKPOINT_INTERVAL = 2.0   # s: &scan checkpoint_interval of the long map's checkpointed runs
LADDER = (
    [("rkf45", tol) for tol in (1e-4, 1e-5, 1e-6, 1e-7)]
    + [(m, 1e-6) for m in ("rk4imp", "bsimp", "rk8pd", "rkck")]
)
FORCE_DATASETS = ("afm/trace/fx", "afm/trace/fy", "afm/retrace/fx", "afm/retrace/fy")


def log(msg: str) -> None:
    print(f"benchmark_afm: {msg}", file=sys.stderr, flush=True)


# --------------------------------------------------------------------------
# Running friction
# --------------------------------------------------------------------------


@dataclass
class Run:
    """One friction invocation and what it reported."""

    wall: float  # root attribute wall_time, s
    process: float  # wall clock of the whole command, s
    steps: int
    rhs: int
    nranks: int
    path: Path


@dataclass
class Measurement:
    """Repeated runs of one setting: medians plus the last output file."""

    label: str
    case: str
    nx: int
    ny: int
    method: str
    tol: str
    ranks: int
    runs: list[Run] = field(default_factory=list)
    error: float | None = None  # nN, against the reference

    @property
    def wall(self) -> float:
        return statistics.median(r.wall for r in self.runs)

    @property
    def process(self) -> float:
        return statistics.median(r.process for r in self.runs)

    @property
    def per_line(self) -> float:
        return self.wall / self.ny

    @property
    def path(self) -> Path:
        return self.runs[-1].path

    def as_dict(self) -> dict:
        return {
            "label": self.label,
            "case": self.case,
            "nx": self.nx,
            "ny": self.ny,
            "method": self.method,
            "tol": self.tol,
            "ranks": self.ranks,
            "repeats": len(self.runs),
            "wall_time_median_s": self.wall,
            "wall_time_per_line_s": self.per_line,
            "process_time_median_s": self.process,
            "wall_times_s": [r.wall for r in self.runs],
            "process_times_s": [r.process for r in self.runs],
            "integrator_steps": self.runs[-1].steps,
            "rhs_evaluations": self.runs[-1].rhs,
            "max_force_error_nN": self.error,
        }


class Friction:
    def __init__(self, binary: Path, mpirun: list[str], workdir: Path):
        self.binary = binary
        self.mpirun = mpirun
        self.workdir = workdir
        self.inputs = workdir / "inputs"
        self.env = dict(os.environ)
        if hasattr(os, "geteuid") and os.geteuid() == 0:
            # Open MPI refuses to run as root unless both are set.
            self.env["OMPI_ALLOW_RUN_AS_ROOT"] = "1"
            self.env["OMPI_ALLOW_RUN_AS_ROOT_CONFIRM"] = "1"
        self._count = 0

    def override(self, name: str, text: str) -> Path:
        path = self.workdir / f"{name}.nml"
        path.write_text(text + "\n")
        return path

    def run(self, inputs: list[Path], ranks: int, timeout: float | None = None) -> Run:
        """Run once; RuntimeError on a non-zero exit, subprocess.TimeoutExpired
        after `timeout` seconds (None: no limit).  An empty launcher runs the
        program directly (one rank, MPI singleton)."""
        self._count += 1
        out = self.workdir / f"run{self._count:04d}.h5"
        launch = self.mpirun + ["-n", str(ranks)] if self.mpirun else []
        cmd = launch + [str(self.binary), "--quiet", "--force",
                        "-o", str(out)] + [str(p) for p in inputs]
        t0 = time.perf_counter()
        proc = subprocess.run(cmd, env=self.env, cwd=self.workdir, timeout=timeout,
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        elapsed = time.perf_counter() - t0
        if proc.returncode != 0:
            raise RuntimeError(
                f"command failed with exit code {proc.returncode}: {shlex.join(cmd)}\n"
                f"{proc.stdout}{proc.stderr}")
        with h5py.File(out, "r") as f:
            a = f.attrs
            return Run(wall=float(a["wall_time"]), process=elapsed,
                       steps=int(a["integrator_steps"]), rhs=int(a["rhs_evaluations"]),
                       nranks=int(a["nranks"]), path=out)


def read_forces(path: Path) -> dict[str, np.ndarray]:
    with h5py.File(path, "r") as f:
        return {name: f[name][()] for name in FORCE_DATASETS}


def max_force_difference(a: Path, b: Path) -> float:
    fa, fb = read_forces(a), read_forces(b)
    worst = 0.0
    for name in FORCE_DATASETS:
        if fa[name].shape != fb[name].shape:
            raise RuntimeError(f"{name}: shapes differ {fa[name].shape} vs {fb[name].shape}")
        worst = max(worst, float(np.max(np.abs(fa[name] - fb[name]))))
    return worst


def input_settings(path: Path) -> tuple[str, str]:
    """Method and tolerance as the run recorded them in its `input` attribute."""
    with h5py.File(path, "r") as f:
        text = f.attrs["input"]
        text = text.decode() if isinstance(text, bytes) else str(text)
    method = re.search(r'METHOD\s*=\s*["\']?\s*([A-Za-z0-9_]+)', text, re.I)
    rtol = re.search(r"RTOL\s*=\s*([-+0-9.EeDd]+)", text, re.I)
    atol = re.search(r"ATOL\s*=\s*([-+0-9.EeDd]+)", text, re.I)

    def fmt(m):
        return f"{float(m.group(1).replace('D', 'E').replace('d', 'e')):.0e}" if m else "?"

    tol = fmt(rtol) if fmt(rtol) == fmt(atol) else f"{fmt(rtol)}/{fmt(atol)}"
    return (method.group(1) if method else "?"), tol


# --------------------------------------------------------------------------
# The benchmark
# --------------------------------------------------------------------------


class Benchmark:
    def __init__(self, args, fr: Friction):
        self.args = args
        self.fr = fr
        self.refs: dict[tuple, dict] = {}
        self.results: dict = {"maps": [], "references": [], "target": {}, "ladder": []}

    def map_override(self, nx: int | None, ny: int | None) -> list[Path]:
        if nx is None:
            return []
        return [self.fr.override(f"map{nx}x{ny}", f"&scan nx = {nx}, ny = {ny} /")]

    @staticmethod
    def integrator_override_text(method: str, tol: float) -> str:
        return f"&integrator rtol = {tol:g}, atol = {tol:g}, method = '{method}' /"

    def measure(self, label, case, size, ranks, extra=(), repeats=None) -> Measurement:
        inputs = [self.fr.inputs / f"{case}.nml"] + self.map_override(*size) + list(extra)
        repeats = repeats or self.args.repeats
        runs = []
        for i in range(repeats):
            log(f"{label}: {ranks} rank(s), run {i + 1}/{repeats}")
            runs.append(self.fr.run(inputs, ranks))
        with h5py.File(runs[-1].path, "r") as f:
            ny, nx = f["afm/trace/fx"].shape
        method, tol = input_settings(runs[-1].path)
        return Measurement(label, case, nx, ny, method, tol, ranks, runs)

    def reference(self, case: str, size) -> dict:
        """The tight reference for a map, and its own convergence check."""
        key = (case, size)
        if key not in self.refs:
            ref_o = self.fr.override(f"ref{REF_TOL:g}",
                                     self.integrator_override_text(REF_METHOD, REF_TOL))
            chk_o = self.fr.override(f"ref{REF_CHECK_TOL:g}",
                                     self.integrator_override_text(REF_METHOD, REF_CHECK_TOL))
            ref = self.measure(f"{case} reference", case, size, 1, [ref_o], repeats=1)
            chk = self.measure(f"{case} reference check", case, size, 1, [chk_o], repeats=1)
            diff = max_force_difference(ref.path, chk.path)
            entry = {"case": case, "nx": ref.nx, "ny": ref.ny, "method": REF_METHOD,
                     "tol": REF_TOL, "check_tol": REF_CHECK_TOL, "wall_time_s": ref.wall,
                     "check_wall_time_s": chk.wall,
                     "max_force_difference_nN": diff, "path": ref.path}
            self.refs[key] = entry
            self.results["references"].append(
                {k: v for k, v in entry.items() if k != "path"})
        return self.refs[key]

    def error(self, m: Measurement, size) -> float:
        m.error = max_force_difference(m.path, self.reference(m.case, size)["path"])
        return m.error

    def run(self) -> None:
        a = self.args
        default_size = (64, 64) if a.quick else (None, None)  # None: as the input says
        target_size = (128, 128) if a.quick else (256, 256)

        # 1. default maps, 1 and 2 ranks
        self.default_rows = []
        for case in ("naf", "hopg"):
            one = self.measure(f"{case} map", case, default_size, 1)
            two = self.measure(f"{case} map", case, default_size, 2)
            self.error(one, default_size)
            self.error(two, default_size)
            rank_diff = max_force_difference(one.path, two.path)
            self.default_rows.append((one, two, rank_diff))
            for m in (one, two):
                d = m.as_dict()
                d["speedup_vs_1_rank"] = one.wall / m.wall
                d["process_speedup_vs_1_rank"] = one.process / m.process
                d["max_difference_1_vs_2_ranks_nN"] = rank_diff
                self.results["maps"].append(d)

        # 2. target case: NaF 256 x 256, trace + retrace
        one = self.measure("naf target", "naf", target_size, 1)
        two = self.measure("naf target", "naf", target_size, 2)
        self.error(one, target_size)
        self.error(two, target_size)
        self.target = (one, two, max_force_difference(one.path, two.path))
        self.results["target"] = {
            "one_rank": one.as_dict(), "two_ranks": two.as_dict(),
            "speedup": one.wall / two.wall, "process_speedup": one.process / two.process,
            "max_difference_1_vs_2_ranks_nN": self.target[2],
            "targets": {"time_one_core_s": TARGET_TIME_S, "error_nN": TARGET_ERROR_NN,
                        "speedup_two_ranks": TARGET_SPEEDUP},
            "met": {"time": one.wall < TARGET_TIME_S,
                    "error": one.error < TARGET_ERROR_NN,
                    "speedup": one.wall / two.wall >= TARGET_SPEEDUP},
        }

        # 3. tolerance / method ladder on the target map, 1 rank
        self.ladder = []
        if not a.no_ladder:
            for method, tol in LADDER:
                o = self.fr.override(f"ladder_{method}_{tol:g}",
                                     self.integrator_override_text(method, tol))
                m = self.measure(f"ladder {method} {tol:g}", "naf", target_size, 1, [o],
                                 repeats=a.ladder_repeats)
                self.error(m, target_size)
                self.ladder.append(m)
                self.results["ladder"].append(m.as_dict())

        # 4. the cost of a long map's checkpoints: every CHECKPOINT_INTERVAL s against none
        self.checkpoints = None
        if not a.no_checkpoints:
            lines = 1500 if a.quick else 3000
            size = (128, lines)
            pair = []
            for label, interval in (("no checkpoints", 1e6), ("checkpoints", CHECKPOINT_INTERVAL)):
                o = self.fr.override(f"checkpoints_{interval:g}", f"&scan checkpoint_interval = {interval:g} /")
                pair.append(self.measure(f"naf {lines} lines, {label}", "naf", size, 1, [o]))
            self.checkpoints = tuple(pair)
            self.results["checkpoints"] = {
                "interval_s": CHECKPOINT_INTERVAL, "without": pair[0].as_dict(), "with": pair[1].as_dict(),
                "ratio": pair[1].wall / pair[0].wall,
                "per_line_ms": 1e3 * (pair[1].wall - pair[0].wall) / lines}

    # ---------------------------------------------------------------- output

    def report(self, header: dict) -> str:
        a = self.args
        lines = []
        w = lines.append
        w("friction AFM benchmark")
        w("=" * 22)
        for k, v in header.items():
            w(f"  {k:<10} {v}")
        w("  times      median of the repeats; 'wall' = file attribute wall_time (max over")
        w("             ranks, MPI start-up to before writing), 'process' = whole mpirun command")
        w("  error      max |F - F_ref| over fx, fy of trace and retrace, nN; reference")
        w(f"             {REF_METHOD} rtol = atol = {REF_TOL:g} on the same map")
        w("")

        w("1. Maps as the input files give them (default tolerance), trace + retrace")
        hdr = (f"  {'case':<5} {'map':>9} {'method':<7} {'rtol/atol':>11} {'ranks':>5} "
               f"{'wall/map s':>10} {'wall/line ms':>12} {'process s':>9} "
               f"{'speed-up':>8} {'error nN':>9}")
        w(hdr)
        w("  " + "-" * (len(hdr) - 2))
        for one, two, _ in self.default_rows:
            for m in (one, two):
                sp = "" if m.ranks == 1 else f"{one.wall / m.wall:.2f}x"
                size = f"{m.nx}x{m.ny}"
                w(f"  {m.case:<5} {size:>9} {m.method:<7} {m.tol:>11} {m.ranks:>5} "
                  f"{m.wall:>10.3f} {1e3 * m.per_line:>12.2f} {m.process:>9.3f} "
                  f"{sp:>8} {m.error:>9.2e}")
        for one, _, diff in self.default_rows:
            w(f"  {one.case}: max |F(1 rank) - F(2 ranks)| = {diff:.2e} nN")
        w("")

        w(f"2. References ({REF_METHOD}, rtol = atol = {REF_TOL:g}) and their convergence")
        hdr = (f"  {'case':<5} {'map':>9} {'wall s':>8} "
               f"{f'max |F({REF_TOL:g}) - F({REF_CHECK_TOL:g})| nN':>34}")
        w(hdr)
        w("  " + "-" * (len(hdr) - 2))
        for r in self.refs.values():
            size = f"{r['nx']}x{r['ny']}"
            w(f"  {r['case']:<5} {size:>9} {r['wall_time_s']:>8.3f} "
              f"{r['max_force_difference_nN']:>34.2e}")
        w("  (an error well above the reference's own difference is resolved by it)")
        w("")

        one, two, diff = self.target
        speedup = one.wall / two.wall
        title = f"NaF {one.ny}-line x {one.nx}-point trace+retrace map"
        if a.quick:
            title += "  [--quick: smaller than the issue's 256 x 256]"
        w(f"3. Target case: {title}")

        def verdict(ok):
            return "met" if ok else "NOT met"

        w(f"  time on 1 rank (wall, median)  {one.wall:9.3f} s    target < {TARGET_TIME_S:g} s on one core"
          f"   {verdict(one.wall < TARGET_TIME_S)}")
        w(f"  time on 1 rank (process)       {one.process:9.3f} s")
        w(f"  time per scan line, 1 rank     {1e3 * one.per_line:9.3f} ms")
        w(f"  force error vs reference       {one.error:9.2e} nN   target < {TARGET_ERROR_NN:g} nN"
          f"              {verdict(one.error < TARGET_ERROR_NN)}")
        w(f"  time on 2 ranks (wall, median) {two.wall:9.3f} s    (process {two.process:.3f} s)")
        w(f"  speed-up on 2 ranks (wall)     {speedup:9.2f} x    target >= {TARGET_SPEEDUP:g}x on 2 ranks"
          f"     {verdict(speedup >= TARGET_SPEEDUP)}")
        w(f"  speed-up on 2 ranks (process)  {one.process / two.process:9.2f} x")
        w(f"  max |F(1 rank) - F(2 ranks)|   {diff:9.2e} nN")
        w("")

        if self.ladder:
            w(f"4. Speed/accuracy ladder: NaF {one.ny}x{one.nx} map, 1 rank, "
              f"median of {a.ladder_repeats}")
            hdr = (f"  {'method':<7} {'rtol=atol':>9} {'wall/map s':>10} {'wall/line ms':>12} "
                   f"{'steps':>10} {'rhs evals':>10} {'error nN':>9}  targets")
            w(hdr)
            w("  " + "-" * (len(hdr) - 2))
            for m in self.ladder:
                ok_t = m.wall < TARGET_TIME_S
                ok_e = m.error < TARGET_ERROR_NN
                marks = f"{'time' if ok_t else '----'} {'error' if ok_e else '-----'}"
                w(f"  {m.method:<7} {m.tol:>9} {m.wall:>10.3f} {1e3 * m.per_line:>12.2f} "
                  f"{m.runs[-1].steps:>10d} {m.runs[-1].rhs:>10d} {m.error:>9.2e}  {marks}")
            w(f"  (targets: 'time' = under {TARGET_TIME_S:g} s, 'error' = under "
              f"{TARGET_ERROR_NN:g} nN; steps and rhs evals are totals over the map)")
        if self.checkpoints:
            without, with_ = self.checkpoints
            w("")
            w(f"5. A long map's checkpoints: NaF {with_.ny} lines x {with_.nx} points, 1 rank, "
              f"median of {a.repeats}")
            w(f"  without checkpoints            {without.wall:9.3f} s")
            w(f"  checkpoints every {CHECKPOINT_INTERVAL:g} s         {with_.wall:9.3f} s    "
              f"{with_.wall / without.wall:.2f} x, "
              f"{1e3 * (with_.wall - without.wall) / with_.ny:.2f} ms a line "
              f"(the line itself: {1e3 * without.per_line:.2f} ms)")
        return "\n".join(lines)


def snapshot_program(binary: Path, workdir: Path) -> Path:
    """A private copy of the program, of the parallel program beside it
    (friction-mpi, which it runs under mpirun) and of its shared library (libfriction.so,
    found first through LD_LIBRARY_PATH), so that a rebuild during a
    benchmark neither breaks it nor mixes two builds in one table.  (The
    program alone is not enough: it loads the library from the build tree
    through its run path.)"""
    snapshot = workdir / "friction"
    shutil.copy2(binary, snapshot)
    # The parallel program the serial one hands a launched run to, beside it.
    parallel = Path(binary).resolve().parent / "friction-mpi"
    if parallel.exists():
        shutil.copy2(parallel, workdir / "friction-mpi")
    libraries = sorted(Path(binary).resolve().parent.glob("libfriction.so*"))
    if libraries:
        (workdir / "lib").mkdir(exist_ok=True)
        for library in libraries:
            shutil.copy2(library, workdir / "lib" / library.name, follow_symlinks=True)
        os.environ["LD_LIBRARY_PATH"] = os.pathsep.join(
            [str(workdir / "lib")] + [d for d in os.environ.get("LD_LIBRARY_PATH", "").split(os.pathsep) if d])
    return snapshot


def git_state() -> str:
    """The source commit, with '-dirty' when the working tree has changes."""
    try:
        out = subprocess.run(["git", "-C", str(ROOT), "describe", "--always", "--dirty"],
                             capture_output=True, text=True, timeout=30)
        return out.stdout.strip() or "unknown"
    except (OSError, subprocess.SubprocessError):
        return "unknown"


def main(argv=None) -> int:
    p = argparse.ArgumentParser(
        description="Benchmark friction's AFM maps (prints a table; not a test).")
    p.add_argument("--repeats", type=int, default=None,
                   help="runs per timing, median reported (default 5; 2 with --quick)")
    p.add_argument("--ladder-repeats", type=int, default=None,
                   help="runs per ladder setting (default: --repeats)")
    p.add_argument("--quick", action="store_true",
                   help="fewer repeats and smaller maps (64x64 default maps, 128x128 target)")
    p.add_argument("--no-ladder", action="store_true", help="skip the tolerance ladder")
    p.add_argument("--no-checkpoints", action="store_true",
                   help="skip the long map with and without checkpoints")
    p.add_argument("--json", metavar="FILE", help="also save the results as JSON to FILE")
    p.add_argument("--binary", default=str(ROOT / "build" / "friction"),
                   help="the friction executable (default: build/friction)")
    p.add_argument("--mpirun", default="mpirun",
                   help="MPI launcher command, '-n N' is appended (default: mpirun)")
    p.add_argument("--keep", action="store_true",
                   help="keep the temporary directory with all outputs")
    args = p.parse_args(argv)
    if args.repeats is None:
        args.repeats = 2 if args.quick else 5
    if args.ladder_repeats is None:
        args.ladder_repeats = args.repeats
    if args.repeats < 1 or args.ladder_repeats < 1:
        p.error("repeats must be at least 1")

    binary = Path(args.binary).resolve()
    if not os.access(binary, os.X_OK):
        p.error(f"{binary} is not an executable; build first (scripts/build)")

    try:
        version = subprocess.run([str(binary), "--version"], capture_output=True, text=True,
                                 env=Friction(binary, [], Path()).env, timeout=60).stdout.strip().split("\n")[0]
    except (OSError, subprocess.SubprocessError):
        version = "?"
    try:
        cpus = len(os.sched_getaffinity(0))
    except AttributeError:
        cpus = os.cpu_count() or 1

    workdir = Path(tempfile.mkdtemp(prefix="friction-bench-"))
    # Run private copies of the program, its library and the input files, so
    # a rebuild or an edit during the benchmark neither breaks it nor mixes
    # two versions in one table.
    snapshot = snapshot_program(binary, workdir)
    shutil.copytree(INPUTS, workdir / "inputs")
    fr = Friction(snapshot, shlex.split(args.mpirun), workdir)
    bench = Benchmark(args, fr)
    t0 = time.perf_counter()
    try:
        bench.run()
    except RuntimeError as exc:
        log(str(exc))
        if args.keep:
            log(f"outputs kept in {workdir}")
        else:
            shutil.rmtree(workdir, ignore_errors=True)
        return 1
    total = time.perf_counter() - t0

    header = {
        "binary": f"{os.path.relpath(binary)} ({version}, source {git_state()})",
        "machine": f"{platform.machine()}, {cpus} CPUs available, {platform.processor() or platform.system()}",
        "repeats": f"{args.repeats} (ladder {args.ladder_repeats}){'  --quick' if args.quick else ''}",
        "launcher": f"{args.mpirun} -n N",
    }
    print(bench.report(header))
    print(f"\n(benchmark took {total:.0f} s)")

    if args.json:
        bench.results["meta"] = {
            "version": version, "source": git_state(), "cpus": cpus, "machine": platform.machine(),
            "repeats": args.repeats, "ladder_repeats": args.ladder_repeats,
            "quick": args.quick, "launcher": args.mpirun, "benchmark_seconds": total,
            "created": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
        }
        Path(args.json).write_text(json.dumps(bench.results, indent=2) + "\n")
        log(f"results saved to {args.json}")

    if args.keep:
        log(f"outputs kept in {workdir}")
    else:
        shutil.rmtree(workdir, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
