#!/usr/bin/env python3
"""Benchmark the NaF tip against SUNDIALS CVODE, and the stiff tips of method = 'auto'.

Measures and prints (this is not a test; nothing fails on a missed target):

* The whole process `friction inputs/naf.nml` (128 x 128, trace + retrace,
  serial, no mpirun): wall clock and CPU time, median of --repeats, next to
  the target (under 0.3 s).
* Work against error on that map for the program (rkf45, rkck, rk8pd and
  the Rosenbrock steppers rodas3, rodas4 along rtol = atol = 1e-3 ... 1e-9)
  and for a C program on CVODE
  (scripts/cvode_naf.c: BDF with the dense analytic Jacobian, rtol = atol =
  1e-3 ... 1e-10), the error being the largest |F - F_ref| over fx and fy
  of trace and retrace against the program's rk8pd at rtol = atol = 1e-11
  (itself checked against 1e-10).  The --repeats rounds are interleaved:
  after the first, which walks the ladders, each round runs every setting
  of the program and of CVODE once.  At the error levels --levels the cost
  each needs is interpolated log-log between its ladder points; the best of
  the program's steppers is set against CVODE: compute time (the file's
  wall_time: input, set-up, integration, not the write; CVODE: its
  integration and sampling), whole-process wall clock and CPU time.
* The stiff tips of method = 'auto' (docs/speed.md, Stiff tips): the same
  map with 16 lines and the damping --stiff-damping (N s/m), 'auto' against
  bsimp, rodas3, rodas4, rkck, rk8pd and CVODE at equal error.
* With --crossover, instead of all that: the crossover of the rule, tips of
  growing stiffness S (NaF and HOPG, 4 lines of 128 samples), the fastest
  explicit stepper (rkck, rk8pd) against bsimp and rodas4 at equal error,
  and the stepper 'auto' picks at rtol 1e-3.

The CVODE program is compiled here with $CC (default cc) against SUNDIALS
(Debian: libsundials-dev); without it the CVODE rows are skipped with a
note.  Usage (normally through scripts/benchmark_stiff, which builds first):

    python3 scripts/benchmark_stiff.py [--repeats N] [--binary PATH] [--quick] [--crossover]
                                       [--levels E1,E2] [--stiff-damping C] [--json FILE]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

try:
    import h5py
    import numpy as np
except ImportError as exc:  # pragma: no cover - environment problem
    sys.exit(f"benchmark_stiff: {exc}; run scripts/install-deps")

ROOT = Path(__file__).resolve().parent.parent
NAF = ROOT / "inputs" / "naf.nml"
HOPG = ROOT / "inputs" / "hopg.nml"
# (label, input, tip/scan overrides): the paper's tips, then stiffer ones.
CROSSOVER = [
    ("NaF, paper", NAF, ""),
    ("HOPG, paper", HOPG, ""),
    ("NaF, c = 3e-3", NAF, "&tip cx = 3e-3, cy = 3e-3 /\n"),
    ("NaF, c = 1e-2", NAF, "&tip cx = 1e-2, cy = 1e-2 /\n"),
    ("HOPG, c = 1e-2", HOPG, "&tip cx = 1e-2, cy = 1e-2 /\n"),
    ("NaF, m = 1e-9", NAF, "&tip mass = 1e-9 /\n"),
    ("NaF, 40 Å/s", NAF, "velocity = 40.0"),
    ("NaF, c = 3e-2", NAF, "&tip cx = 3e-2, cy = 3e-2 /\n"),
    ("NaF, c = 1e-1", NAF, "&tip cx = 1e-1, cy = 1e-1 /\n"),
]
PEER_SOURCE = ROOT / "scripts" / "cvode_naf.c"
TARGET_PROCESS_S = 0.3
FORCES = ("afm/trace/fx", "afm/trace/fy", "afm/retrace/fx", "afm/retrace/fy")
SUNDIALS_LIBS = ["-lsundials_cvode", "-lsundials_nvecserial", "-lsundials_sunmatrixdense",
                 "-lsundials_sunlinsoldense", "-lsundials_sunnonlinsolfixedpoint", "-lm"]


def log(msg: str) -> None:
    print(f"benchmark_stiff: {msg}", file=sys.stderr, flush=True)


def run_process(command: list[str]) -> tuple[subprocess.CompletedProcess, float, float]:
    """Run a whole process: its result, wall clock (s) and CPU time (user +
    system, s, from the child's own rusage: wait4 before Popen reaps it)."""
    start = time.perf_counter()
    proc = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    # Read the pipes fully, then reap the child ourselves to get its rusage.
    out = proc.stdout.read()
    err = proc.stderr.read()
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - start
    proc.returncode = os.waitstatus_to_exitcode(status)
    proc.stdout.close()
    proc.stderr.close()
    return (subprocess.CompletedProcess(command, proc.returncode, out.decode(), err.decode()), wall,
            usage.ru_utime + usage.ru_stime)


class Bench:
    def __init__(self, binary: Path, workdir: Path, repeats: int):
        self.binary, self.workdir, self.repeats = binary, workdir, repeats
        self.peer: Path | None = None
        self.count = 0

    # ---------------------------------------------------------- the program
    def friction(self, method: str, rtol: float, atol: float, extra: str = "", repeats: int | None = None,
                 base: Path = NAF):
        """Median over repeats of (compute, process wall, process CPU); forces; attributes."""
        self.count += 1
        nml = self.workdir / f"o{self.count}.nml"
        nml.write_text(extra + f"&integrator method = '{method}', rtol = {rtol:.17g}, atol = {atol:.17g} /\n")
        out = self.workdir / f"o{self.count}.h5"
        computes, walls, cpus = [], [], []
        for _ in range(repeats or self.repeats):
            result, wall, cpu = run_process([str(self.binary), "-q", "-f", "-o", str(out), str(base), str(nml)])
            if result.returncode != 0:
                raise RuntimeError(f"friction {method} {rtol:g}: {result.stderr.strip()}")
            with h5py.File(out, "r") as f:
                computes.append(float(f.attrs["wall_time"]))
            walls.append(wall)
            cpus.append(cpu)
        with h5py.File(out, "r") as f:
            forces = np.concatenate([f[name][()].ravel() for name in FORCES])
            ran = f.attrs["method"]
            ran = ran.decode() if isinstance(ran, bytes) else str(ran)
            rhs = int(f.attrs["rhs_evaluations"])
        return {"compute": statistics.median(computes), "wall": statistics.median(walls),
                "cpu": statistics.median(cpus), "rhs": rhs, "ran": ran}, forces

    # ---------------------------------------------------------- the peer
    def build_peer(self) -> str | None:
        """Compile scripts/cvode_naf.c; None when done, else why not."""
        cc = os.environ.get("CC", "cc")
        if shutil.which(cc) is None:
            return f"no C compiler ({cc})"
        exe = self.workdir / "cvode_naf"
        result = subprocess.run([cc, "-O2", "-o", str(exe), str(PEER_SOURCE), *SUNDIALS_LIBS],
                                capture_output=True, text=True)
        if result.returncode != 0:
            return ("could not build the CVODE peer (Debian: apt-get install libsundials-dev): "
                    + result.stderr.strip().splitlines()[-1] if result.stderr.strip() else "")
        self.peer = exe
        return None

    def cvode(self, rtol: float, nx: int, ny: int, damping: float, repeats: int | None = None):
        out = self.workdir / "cvode.bin"
        computes, walls, cpus = [], [], []
        for _ in range(repeats or self.repeats):
            result, wall, cpu = run_process([str(self.peer), "bdf", f"{rtol:.17g}", f"{rtol:.17g}", str(nx),
                                             str(ny), str(out), f"{damping:.17g}"])
            if result.returncode != 0:
                raise RuntimeError(f"cvode_naf {rtol:g}: {result.stderr.strip()}")
            record = json.loads(result.stdout)
            computes.append(record["compute_time"])
            walls.append(wall)
            cpus.append(cpu)
        return {"compute": statistics.median(computes), "wall": statistics.median(walls),
                "cpu": statistics.median(cpus), "rhs": record["rhs_evaluations"],
                "steps": record["steps"]}, np.fromfile(out)


def cost_at(points: list[dict], level: float, key: str) -> float | None:
    """The cost (key) to reach error <= level: log-log interpolation between the
    last ladder point above the level and the first at or below it; the
    first point's cost if it is already below; None if never reached."""
    pts = sorted(points, key=lambda p: -p["error"])
    for k, p in enumerate(pts):
        if p["error"] <= level:
            if k == 0:
                return p[key]
            q = pts[k - 1]
            a = (math.log(level) - math.log(q["error"])) / (math.log(p["error"]) - math.log(q["error"]))
            return math.exp(math.log(q[key]) + a * (math.log(p[key]) - math.log(q[key])))
    return None


def ladder_table(name: str, rows: list[dict]) -> None:
    print(f"\n{name}:")
    print("| method | rtol | error (nN) | compute | process wall | process CPU | rhs |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['method']} | {r['rtol']:.0e} | {r['error']:.2e} | {r['compute'] * 1e3:.1f} ms | "
              f"{r['wall'] * 1e3:.1f} ms | {r['cpu'] * 1e3:.1f} ms | {r['rhs']:,} |")


def compare(title: str, series: dict, levels: list[float], summary: list) -> None:
    """Best program method against CVODE at each level."""
    print(f"\n{title}: cost at equal force error (log-log interpolation between ladder points)")
    print("| error level | best of the program | compute | CVODE BDF compute | ratio | "
          "process wall: program, CVODE, ratio | process CPU: program, CVODE, ratio |")
    print("|---|---|---|---|---|---|---|")
    for level in levels:
        best = None
        for method, pts in series.items():
            if method == "cvode":
                continue
            c = cost_at(pts, level, "compute")
            if c is not None and (best is None or c < best[1]):
                best = (method, c)
        peer = {key: cost_at(series.get("cvode", []), level, key) for key in ("compute", "wall", "cpu")}
        if best is None:
            print(f"| {level:.0e} | not reached | | | | | |")
            continue
        mine = {key: cost_at(series[best[0]], level, key) for key in ("compute", "wall", "cpu")}

        def ratio(key):
            return f"{peer[key] / mine[key]:.1f}" if peer[key] and mine[key] else "-"

        def ms(value):
            return f"{value * 1e3:.1f} ms" if value else "not reached"

        print(f"| {level:.0e} | {best[0]} | {ms(mine['compute'])} | {ms(peer['compute'])} | {ratio('compute')} | "
              f"{ms(mine['wall'])}, {ms(peer['wall'])}, {ratio('wall')} | "
              f"{ms(mine['cpu'])}, {ms(peer['cpu'])}, {ratio('cpu')} |")
        summary.append({"case": title, "level": level, "best": best[0], "program": mine, "cvode": peer})


def crossover(bench: Bench, levels: list[float]) -> list[dict]:
    """The explicit pairs against bsimp and rodas4 on tips of growing stiffness."""
    print("| tip | auto picks | error level | fastest explicit | its time | bsimp's time | explicit / bsimp | "
          "rodas4's time | explicit / rodas4 |")
    print("|---|---|---|---|---|---|---|---|---|")
    rows = []
    for label, base, override in CROSSOVER:
        scan = f", {override}" if override.startswith("velocity") else ""
        tip = "" if scan else override
        extra = f"&scan ny = 4{scan} /\n{tip}"
        log(f"crossover: {label}")
        ref = bench.friction("rk8pd", 1e-12, 1e-12, extra, repeats=1, base=base)[1]
        picked = bench.friction("auto", 1e-3, 1e-3, extra, repeats=1, base=base)[0]["ran"]
        series = {}
        for method in ("rkck", "rk8pd", "bsimp", "rodas4"):
            series[method] = []
            for rtol in (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8):
                cost, forces = bench.friction(method, rtol, rtol, extra, base=base)
                error = float(np.abs(forces - ref).max())
                series[method].append({"error": error, "compute": cost["compute"]})
                if error < min(levels) / 10 or cost["compute"] > 5.0:
                    break
        for level in levels:
            explicit = [(m, cost_at(series[m], level, "compute")) for m in ("rkck", "rk8pd")]
            explicit = [e for e in explicit if e[1] is not None]
            implicit = cost_at(series["bsimp"], level, "compute")
            rosenbrock = cost_at(series["rodas4"], level, "compute")
            best = min(explicit, key=lambda e: e[1]) if explicit else None
            ratio = f"{best[1] / implicit:.2f}" if best and implicit else "-"
            ratio_r = f"{best[1] / rosenbrock:.2f}" if best and rosenbrock else "-"
            print(f"| {label} | {picked} | {level:.0e} | {best[0] if best else '-'} | "
                  f"{best[1] * 1e3:.1f} ms | " if best else f"| {label} | {picked} | {level:.0e} | - | - | ", end="")
            print(f"{implicit * 1e3:.1f} ms | {ratio} | " if implicit else "not reached | - | ", end="")
            print(f"{rosenbrock * 1e3:.1f} ms | {ratio_r} |" if rosenbrock else "not reached | - |")
            rows.append({"tip": label, "auto": picked, "level": level, "explicit": best,
                         "bsimp": implicit, "rodas4": rosenbrock})
    return rows


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--binary", type=Path, default=ROOT / "build" / "friction")
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--quick", action="store_true", help="8 lines, short ladders, 1 repeat")
    p.add_argument("--levels", default="1e-4,1e-7", help="force error levels, nN")
    p.add_argument("--stiff-damping", type=float, default=3.0e-2, help="N s/m for the stiff tip")
    p.add_argument("--crossover", action="store_true", help="only the crossover table of the rule")
    p.add_argument("--json", type=Path)
    args = p.parse_args(argv)
    if not args.binary.exists():
        sys.exit(f"benchmark_stiff: {args.binary} not found; build first (scripts/build)")
    levels = [float(x) for x in args.levels.split(",")]
    repeats = 1 if args.quick else args.repeats
    ny = 8 if args.quick else 128
    record = {"levels": levels, "summary": []}
    with tempfile.TemporaryDirectory(prefix="benchmark_stiff_") as scratch:
        bench = Bench(args.binary.resolve(), Path(scratch), repeats)
        if args.crossover:
            record["crossover"] = crossover(bench, levels)
            if args.json:
                args.json.write_text(json.dumps(record, indent=1, default=float))
            return 0
        why = bench.build_peer()
        if why:
            log(why)
            print(f"CVODE peer skipped: {why}")

        # The input file as it is, whole process.
        if not args.quick:
            plain = bench.friction("rkf45", 1e-3, 1e-4, repeats=max(repeats, 5))[0]
            print(f"friction inputs/naf.nml (128 x 128, trace + retrace, serial): process wall "
                  f"{plain['wall'] * 1e3:.0f} ms, CPU {plain['cpu'] * 1e3:.0f} ms, file wall_time "
                  f"{plain['compute'] * 1e3:.0f} ms (target: process under {TARGET_PROCESS_S * 1e3:.0f} ms)")
            record["input_file"] = plain

        for title, lines, damping, methods in (
                (f"NaF {ny} x 128, the paper's tip (c = 1e-3 N s/m)", ny, 1.0e-3,
                 ("rkf45", "rkck", "rk8pd", "rodas3", "rodas4")),
                (f"NaF 16 x 128, stiff tip (c = {args.stiff_damping:g} N s/m)", 16, args.stiff_damping,
                 ("auto", "bsimp", "rodas3", "rodas4", "rkck", "rk8pd"))):
            extra = (f"&scan ny = {lines} /\n&tip cx = {damping:.17g}, cy = {damping:.17g} /\n")
            log(f"{title}: reference")
            ref = bench.friction("rk8pd", 1e-11, 1e-11, extra, repeats=1)[1]
            check = bench.friction("rk8pd", 1e-10, 1e-10, extra, repeats=1)[1]
            ref_check = float(np.abs(check - ref).max())
            print(f"\n{title}: reference rk8pd rtol = atol = 1e-11; against 1e-10: {ref_check:.1e} nN")
            series, rows, failures = {}, [], []
            # A first round runs each ladder until it is done (and gives
            # the errors); the other rounds run every setting of the program
            # and of CVODE once each, in turn, so that a change of the
            # machine's load falls on both, not on one ladder.
            reruns = []
            tols = [10.0 ** -k for k in range(3, 6 if args.quick else 10)]
            for method in methods:
                series[method] = []
                for rtol in tols:
                    log(f"{title}: {method} {rtol:g}")
                    cost, forces = bench.friction(method, rtol, rtol, extra, repeats=1)
                    error = float(np.abs(forces - ref).max())
                    label = method if method != "auto" else f"auto ({cost['ran']})"
                    row = {"method": label, "rtol": rtol, "error": error, **cost}
                    rows.append(row)
                    series[method].append(row)
                    reruns.append((row, lambda m=method, r=rtol: bench.friction(m, r, r, extra, repeats=1)[0]))
                    if error < 10 * ref_check or cost["compute"] > 10.0:
                        break
            if bench.peer is not None:
                series["cvode"] = []
                for rtol in [10.0 ** -k for k in range(3, 6 if args.quick else 11)]:
                    log(f"{title}: CVODE BDF {rtol:g}")
                    try:
                        cost, forces = bench.cvode(rtol, 128, lines, damping, repeats=1)
                    except RuntimeError as exc:
                        failures.append(f"CVODE BDF at rtol {rtol:g}: " + " ".join(str(exc).split()))
                        continue
                    error = float(np.abs(forces - ref).max())
                    row = {"method": "CVODE BDF", "rtol": rtol, "error": error, **cost}
                    rows.append(row)
                    series["cvode"].append(row)
                    reruns.append((row, lambda r=rtol, n=lines, c=damping: bench.cvode(r, 128, n, c, repeats=1)[0]))
                    if error < 10 * ref_check or cost["compute"] > 20.0:
                        break
            samples = {id(row): {key: [row[key]] for key in ("compute", "wall", "cpu")} for row, _ in reruns}
            for round_ in range(2, repeats + 1):
                log(f"{title}: round {round_} of {repeats}")
                for row, rerun in reruns:
                    cost = rerun()
                    for key in samples[id(row)]:
                        samples[id(row)][key].append(cost[key])
            for row, _ in reruns:
                for key, values in samples[id(row)].items():
                    row[key] = statistics.median(values)
            ladder_table(title, rows)
            for failure in failures:
                print(f"failed: {failure}")
            compare(title, series, levels, record["summary"])
            record[title] = rows
    if args.json:
        args.json.write_text(json.dumps(record, indent=1, default=float))
    return 0


if __name__ == "__main__":
    sys.exit(main())
