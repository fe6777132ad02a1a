#!/usr/bin/env python3
"""Benchmark the brake to tau = 1000 as whole processes against its peers.

Measures and prints (this is not a test; nothing fails on a missed target):

* The program, serial (no mpirun), whole process, on inputs/brake.nml with
  t_end = 1000 and dt_out = 1 and the &analysis diagnostics off (a plain
  integration writing the trajectory, the output ngspice gives), for both
  models along a tolerance ladder with method = 'auto' (atol = rtol / 100;
  switched: event tolerance min(1e-10, rtol / 10)), the regularized law also
  with the Rosenbrock steppers rodas3 and rodas4 along quarter-decade rungs;
  and once the input as it is (with its &analysis), for scale.
* ngspice on the paper's network model, the netlist `friction --netlist`
  writes for the same input (the regularized arctan law; written once, not
  timed), along reltol = --ngspice-ladder (vntol = abstol = chgtol =
  reltol / 100): the ngspice process's wall clock.
* SciPy's DOP853 on the switched model with events (scripts/scipy_brake.py,
  a separate Python process), along rtol = 1e-5 ... 1e-12 (atol = rtol / 100):
  its process's wall clock, and its integration time alone.

Errors: the largest |x - x_ref| (m) on the grid tau = 1, ..., 1000 against
the program's reference of the same model (regularized: rk8pd rtol 1e-13;
switched: rk8pd rtol 1e-14, event tolerance 1e-13), so ngspice is measured
on the law its netlist holds and SciPy on the switched model.  ngspice is
also set against every run with the switched model admitted, each measured
against the regularized law's reference: the switched model is the law's
limit epsilon' -> infinity, and the difference between the two models'
references is printed with it.  At each
peer's ladder point the cheapest run of the program's ladders with an equal
or smaller error is taken (no interpolation), and the ratios printed, of
the process wall clock and of the process CPU time (user + system).

The program's runs and ngspice's are interleaved: each round runs every
setting once, and the medians are over --repeats rounds, so a change of the
shared machine's load falls on all of them alike.

Usage (normally through scripts/benchmark_brake_peers, which builds first):

    python3 scripts/benchmark_brake_peers.py [--binary PATH] [--repeats N] [--quick]
                                             [--ngspice-ladder R1,R2,...] [--json FILE]
"""

from __future__ import annotations

import argparse
import json
import shutil
import statistics
import sys
import tempfile
from pathlib import Path

try:
    import h5py
    import numpy as np
except ImportError as exc:  # pragma: no cover - environment problem
    sys.exit(f"benchmark_brake_peers: {exc}; run scripts/install-deps")

sys.path.insert(0, str(Path(__file__).resolve().parent))
import ngspice_compare  # noqa: E402
from benchmark_stiff import run_process  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
BRAKE = ROOT / "inputs" / "brake.nml"
SCIPY_PEER = ROOT / "scripts" / "scipy_brake.py"
T_END = 1000.0
PLAIN = ("&analysis spectrum = .false., poincare = .false., lyapunov = .false., rosenstein = .false.,"
         " lyapunov_spectrum = .false. /\n")
TARGET_RATIO = 20.0
ROSENBROCK = ("rodas3", "rodas4")


def log(msg: str) -> None:
    print(f"benchmark_brake_peers: {msg}", file=sys.stderr, flush=True)


class Program:
    def __init__(self, binary: Path, workdir: Path, repeats: int):
        self.binary, self.workdir, self.repeats = binary, workdir, repeats
        self.count = 0

    def run(self, text: str, repeats: int | None = None, with_input_analysis: bool = False) -> dict:
        self.count += 1
        nml = self.workdir / f"b{self.count}.nml"
        nml.write_text(text)
        out = self.workdir / f"b{self.count}.h5"
        walls, cpus, computes = [], [], []
        for _ in range(repeats or self.repeats):
            result, wall, cpu = run_process([str(self.binary), "-q", "-f", "-o", str(out), str(BRAKE), str(nml)])
            if result.returncode != 0:
                raise RuntimeError(f"friction: {result.stderr.strip()}")
            with h5py.File(out, "r") as f:
                computes.append(float(f["brake"].attrs["compute_time"]))
            walls.append(wall)
            cpus.append(cpu)
        with h5py.File(out, "r") as f:
            method = f.attrs["method"]
            return {"t": f["brake/t"][()], "x": f["brake/x"][()], "wall": statistics.median(walls),
                    "cpu": statistics.median(cpus), "compute": statistics.median(computes),
                    "method": method.decode() if isinstance(method, bytes) else str(method)}


def integrator(method: str, rtol: float, atol: float) -> str:
    return f"&integrator method = '{method}', rtol = {rtol:.17g}, atol = {atol:.17g} /\n"


def error_on_grid(t: np.ndarray, x: np.ndarray, t_ref: np.ndarray, x_ref: np.ndarray) -> float:
    """Largest |x - x_ref| at tau >= 1 (both on the grid of dt_out = 1)."""
    if len(t) != len(t_ref) or not np.allclose(t, t_ref):
        raise RuntimeError("grids differ")
    keep = t_ref >= 1.0
    return float(np.max(np.abs(x[keep] - x_ref[keep])))


def program_text(model: str, method: str, rtol: float) -> str:
    extra = f"&brake t_end = {T_END}, dt_out = 1.0, model = '{model}'"
    if model == "switched":
        extra += f", event_tolerance = {min(1e-10, rtol / 10):.17g}"
    return PLAIN + extra + " /\n" + integrator(method, rtol, rtol / 100)


def program_jobs(model: str, method: str, tols) -> list[dict]:
    return [{"model": model, "method": method, "rtol": rtol, "walls": [], "cpus": [], "computes": []}
            for rtol in tols]


def run_job(prog: Program, job: dict) -> None:
    """One run of a program setting; its times appended, its result kept."""
    log(f"program {job['model']} {job['method']} rtol {job['rtol']:g}")
    r = prog.run(program_text(job["model"], job["method"], job["rtol"]), repeats=1)
    job["walls"].append(r["wall"])
    job["cpus"].append(r["cpu"])
    job["computes"].append(r["compute"])
    job["result"] = r


def finish_jobs(jobs: list[dict], ref) -> list[dict]:
    """Rows of medians and errors."""
    rows = []
    for job in jobs:
        r = job["result"]
        rows.append({"rtol": job["rtol"], "method": r["method"], "error": error_on_grid(r["t"], r["x"], *ref),
                     "wall": statistics.median(job["walls"]), "cpu": statistics.median(job["cpus"]),
                     "compute": statistics.median(job["computes"])})
    return rows


def matched(rows: list[dict], level: float, key: str) -> tuple[float | None, str]:
    """The cheapest run of the program's ladder whose error is at most level
    (no interpolation: a cost the program was seen to reach), and its rung."""
    good = [r for r in rows if r["error"] <= level]
    if not good:
        return None, "not reached"
    best = min(good, key=lambda r: r[key])
    return best[key], f"({best['method']} at {best['rtol']:.0e})"


NGSPICE_HEADER = ("| reltol | error (m) | ngspice process wall, CPU | its analysis time | program process wall "
                  "(its run) | program process CPU (its run) | ratio, wall | ratio, CPU |\n"
                  "|---|---|---|---|---|---|---|---|")


def print_ngspice_row(s_row: dict, candidates: list[dict]) -> tuple[float | None, float | None]:
    """One ngspice setting against the cheapest of the candidates at its
    error (matched), printed as a row of NGSPICE_HEADER; the program's
    wall and CPU times (None when no candidate is that accurate)."""
    wall, cpu = s_row["wall_time"], s_row["process_cpu"]
    mine_wall, note_wall = matched(candidates, s_row["error"], "wall")
    mine_cpu, note_cpu = matched(candidates, s_row["error"], "cpu")
    head = (f"| {s_row['reltol']:.0e} | {s_row['error']:.2e} | {wall * 1e3:.0f} ms, {cpu * 1e3:.0f} ms | "
            f"{s_row['analysis_time'] * 1e3:.0f} ms | ")
    if mine_wall:
        print(head + f"{mine_wall * 1e3:.1f} ms {note_wall} | {mine_cpu * 1e3:.1f} ms {note_cpu} | "
              f"{wall / mine_wall:.1f} | {cpu / mine_cpu:.1f} |")
    else:
        print(head + f"{note_wall} | | - | - |")
    return mine_wall, mine_cpu


def print_program(title: str, rows: list[dict]) -> None:
    print(f"\n{title}:")
    print("| rtol | method | error (m) | process wall | process CPU | integration |")
    print("|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['rtol']:.0e} | {r['method']} | {r['error']:.2e} | {r['wall'] * 1e3:.1f} ms | "
              f"{r['cpu'] * 1e3:.1f} ms | {r['compute'] * 1e3:.1f} ms |")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--binary", type=Path, default=ROOT / "build" / "friction")
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--quick", action="store_true", help="short ladders, 1 repeat")
    p.add_argument("--ngspice", default="ngspice")
    p.add_argument("--ngspice-ladder", default="1e-6,1e-7,1e-8,1e-9,1e-10")
    p.add_argument("--json", type=Path)
    args = p.parse_args(argv)
    binary = args.binary.resolve()
    if not binary.exists():
        sys.exit(f"benchmark_brake_peers: {binary} not found; build first (scripts/build)")
    repeats = 1 if args.quick else args.repeats
    record: dict = {}
    with tempfile.TemporaryDirectory(prefix="benchmark_brake_peers_") as scratch:
        work = Path(scratch)
        prog = Program(binary, work, repeats)

        full = prog.run(f"&brake t_end = {T_END} /\n", repeats=repeats)
        print(f"friction inputs/brake.nml to tau = {T_END:g} as it is (switched, rk8pd 1e-10, dt_out 0.05, "
              f"with its &analysis), serial: process wall {full['wall'] * 1e3:.0f} ms, CPU "
              f"{full['cpu'] * 1e3:.0f} ms, integration {full['compute'] * 1e3:.1f} ms")
        record["input_as_is"] = {k: full[k] for k in ("wall", "cpu", "compute")}

        refs = {}
        for model, rtol, extra in (("regularized", 1e-13, ""), ("switched", 1e-14, ", event_tolerance = 1e-13")):
            log(f"reference {model}")
            r = prog.run(PLAIN + f"&brake t_end = {T_END}, dt_out = 1.0, model = '{model}'{extra} /\n"
                         + integrator("rk8pd", rtol, rtol / 100),
                         repeats=1)
            refs[model] = (r["t"], r["x"])

        reg_tols = [10.0 ** -k for k in range(3, 8 if args.quick else 12)]
        sw_tols = [10.0 ** -k for k in range(3, 8 if args.quick else 13)]
        # (Four rungs a decade: the error of a Rosenbrock run is not smooth
        # in rtol, and a coarse ladder would make the program pay for the
        # next rung's accuracy where a nearer one meets the peer's error.)
        ros_tols = ([1e-4, 1e-5, 1e-6] if args.quick else
                    [10.0 ** (-3.0 - i / 4.0) for i in range(21)])
        reg_jobs = program_jobs("regularized", "auto", reg_tols)
        sw_jobs = program_jobs("switched", "auto", sw_tols)
        ros_jobs = {m: program_jobs("regularized", m, ros_tols) for m in ROSENBROCK}
        jobs = reg_jobs + sw_jobs + [job for m in ROSENBROCK for job in ros_jobs[m]]
        ladder = [float(x) for x in args.ngspice_ladder.split(",")]
        if args.quick:
            ladder = ladder[:2]
        have_ngspice = shutil.which(args.ngspice) is not None
        spice = [{"reltol": reltol, "walls": [], "cpus": [], "analysis": []} for reltol in ladder] \
            if have_ngspice else []
        # Interleaved rounds: every setting once per round.
        for round_number in range(repeats):
            log(f"round {round_number + 1} of {repeats}")
            for job in jobs:
                run_job(prog, job)
            for s in spice:
                log(f"ngspice reltol {s['reltol']:g}")
                row = ngspice_compare.ngspice_work_precision(
                    [BRAKE], [s["reltol"]], refs["regularized"][0], refs["regularized"][1], binary=binary,
                    ngspice=args.ngspice, atol=s["reltol"] / 100, window=(1.0, T_END), repeats=1,
                    extra=f"&brake t_end = {T_END}, dt_out = 1.0 /\n")[0]
                s["walls"].append(row["wall_time"])
                s["cpus"].append(row["process_cpu"])
                s["analysis"].append(row["cpu_time"])
                s["error"] = row["error"]
        reg = finish_jobs(reg_jobs, refs["regularized"])
        sw = finish_jobs(sw_jobs, refs["switched"])
        # The switched model is the arctan law's limit epsilon' -> infinity:
        # how far its x lies from the arctan law's reference (the model's
        # own difference, before any integration error).
        model_gap = error_on_grid(*refs["switched"], *refs["regularized"])
        sw_as_regularized = [dict(row, method=f"switched, {row['method']}",
                                  error=error_on_grid(job["result"]["t"], job["result"]["x"], *refs["regularized"]))
                             for row, job in zip(sw, sw_jobs)]
        ros = {m: finish_jobs(ros_jobs[m], refs["regularized"]) for m in ROSENBROCK}
        print_program("The program, regularized law, whole process (method = 'auto')", reg)
        for m in ROSENBROCK:
            print_program(f"The program, regularized law, whole process ({m})", ros[m])
        print_program("The program, switched model, whole process (method = 'auto')", sw)
        record["program_regularized"], record["program_switched"] = reg, sw
        record["program_rosenbrock"] = ros
        # ngspice on the netlist of the regularized law.
        candidates = reg + [row for m in ROSENBROCK for row in ros[m]]
        print("\nngspice on the netlist (`friction --netlist`, regularized law), against the program at the same "
              "error (regularized law, whole processes, the cheapest of 'auto', rodas3 and rodas4):")
        print(NGSPICE_HEADER)
        if not have_ngspice:
            print(f"ngspice skipped: {args.ngspice} not found (Debian: apt-get install ngspice)")
        spice_rows = [{"reltol": s["reltol"], "error": s["error"], "wall_time": statistics.median(s["walls"]),
                       "process_cpu": statistics.median(s["cpus"]), "analysis_time": statistics.median(s["analysis"])}
                      for s in spice]
        for s_row in spice_rows:
            s_row["program_wall"], s_row["program_cpu"] = print_ngspice_row(s_row, candidates)
        record["ngspice"] = spice_rows
        # The same, with the switched model admitted: its runs measured
        # against the arctan law's reference (model difference included).
        print(f"\nThe switched model's reference against the regularized law's: {model_gap:.2e} m over tau = 1 ... "
              f"{T_END:g}.  ngspice against the program with the switched model admitted, its runs measured "
              "against the regularized law's reference (the model's difference included):")
        print(NGSPICE_HEADER)
        for s_row in spice_rows:
            s_row["either_model_wall"], s_row["either_model_cpu"] = print_ngspice_row(
                s_row, candidates + sw_as_regularized)
        record["model_gap"] = model_gap
        record["program_switched_against_regularized"] = sw_as_regularized
        # SciPy DOP853 on the switched model.
        print("\nSciPy DOP853, switched model with events (scripts/scipy_brake.py), against the program at the "
              "same error (switched model):")
        print("| rtol | error (m) | SciPy process | its integration | program process | program integration | "
              "ratio, process | ratio, integration |")
        print("|---|---|---|---|---|---|---|---|")
        try:
            import scipy  # noqa: F401
            have_scipy = True
        except ImportError:
            have_scipy = False
            print("SciPy skipped: not installed (python3 -m pip install scipy)")
        scipy_rows = []
        for rtol in (sw_tols if have_scipy else []):
            log(f"scipy rtol {rtol:g}")
            out = work / "scipy.npy"
            walls, computes = [], []
            for _ in range(repeats):
                result, wall, cpu = run_process([sys.executable, str(SCIPY_PEER), f"{rtol:.17g}",
                                                 f"{rtol / 100:.17g}", f"{T_END:g}", str(out)])
                if result.returncode != 0:
                    raise RuntimeError(f"scipy_brake: {result.stderr.strip()}")
                walls.append(wall)
                computes.append(json.loads(result.stdout)["compute_time"])
            t, x = np.load(out)
            error = error_on_grid(t, x, *refs["switched"])
            wall, compute = statistics.median(walls), statistics.median(computes)
            mine, note = matched(sw, error, "wall")
            mine_c, _ = matched(sw, error, "compute")
            if mine:
                print(f"| {rtol:.0e} | {error:.2e} | {wall * 1e3:.0f} ms | {compute * 1e3:.0f} ms | "
                      f"{mine * 1e3:.1f} ms {note} | {mine_c * 1e3:.2f} ms | {wall / mine:.0f} | "
                      f"{compute / mine_c:.0f} |")
            else:
                print(f"| {rtol:.0e} | {error:.2e} | {wall * 1e3:.0f} ms | {compute * 1e3:.0f} ms | {note} | | - | - |")
            scipy_rows.append({"rtol": rtol, "error": error, "wall": wall, "compute": compute,
                               "program_wall": mine, "program_compute": mine_c})
        record["scipy"] = scipy_rows
        print(f"\n(target: the program at least {TARGET_RATIO:.0f}x faster than each peer at equal or smaller error)")
    if args.json:
        args.json.write_text(json.dumps(record, indent=1, default=lambda v: v.tolist()
                                        if isinstance(v, np.ndarray) else float(v)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
