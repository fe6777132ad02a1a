#!/usr/bin/env python3
"""The kernel against the paper's network model in ngspice, on the same scene.

Runs `friction` (the kernel) and `friction --netlist` + `ngspice -b` on the
scene the namelist files give, puts both on the kernel's output grid and
prints the largest difference and both times:

* brake: x (m) over the window, on the regularized arctan law (a switched
  input is compared as model = 'regularized': the netlist has the arctan law);
* microscope (NaF, HOPG): the lateral force along the scan, f_along (nN), on
  line 0, trace, at the kernel's samples.

ngspice saves its own time points.  They are put on the kernel's grid by cubic
Hermite interpolation with the derivative ngspice also writes (x' for x, the
force's time derivative for f_along), so the interpolation error (fourth order
in ngspice's step, itself at most one output interval) stays well below the
differences measured.  The kernel's first point, the initial state at time 0,
is not compared: ngspice's first saved point comes after its first step.

Times:
* kernel: the brake's /brake attribute compute_time (the integration alone);
  for the microscope the file's wall_time (input, set-up and the one line; the
  line dominates);
* ngspice: its own reported "Transient analysis time" (rusage trantime, s,
  1 ms resolution; called cpu_time in the records) and the wall time of the
  whole ngspice process.
Each is the median of --repeats runs.

Tolerances: the kernel runs with the input's &integrator (or --kernel-method,
--kernel-rtol, --kernel-atol); the netlist gets reltol = --rtol and
vntol = chgtol = abstol = --atol (default: the input's rtol and atol; see the
netlist's comments for the mapping).

Work-precision data (--ladder R1,R2,...): ngspice at each reltol against a
reference (the kernel at --reference-method/--reference-rtol, or the kernel
output file --reference FILE.h5), printing and emitting (error, cpu_time)
pairs.  From Python:

    import ngspice_compare as nc
    t, ref = nc.reference_from_h5("ref.h5")          # or your own arrays
    rows = nc.ngspice_work_precision(["inputs/brake.nml", "short.nml"], [1e-5, 1e-6, 1e-7],
                                     t, ref, binary="build/friction")
    # rows: [{"reltol", "atol", "error", "cpu_time", "wall_time", "points"}, ...]

Usage (normally through scripts/ngspice_compare, which builds first):

    python3 scripts/ngspice_compare.py INPUT.nml [MORE.nml ...] [--binary PATH] [--ngspice PATH]
        [--t-end TAU] [--window T0 T1] [--rtol R] [--atol A]
        [--kernel-method M] [--kernel-rtol R] [--kernel-atol A] [--repeats N]
        [--ladder R1,R2,...] [--reference FILE.h5] [--reference-method M] [--reference-rtol R]
        [--json FILE] [--hdf5 FILE] [--keep DIR]

Exit codes: 0 done, 2 bad arguments or input, 1 a run failed.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import resource
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
    sys.exit(f"ngspice_compare: {exc}; run scripts/install-deps")

ROOT = Path(__file__).resolve().parent.parent
DEFAULT_BINARY = ROOT / "build" / "friction"

# Overrides common to every run of the comparison (each group is read by one
# scene and ignored by the other): one line, trace; the brake on the arctan
# law without the chaos diagnostics.
COMMON = ("&scan ny = 1, retrace = .false. /\n"
          "&brake model = 'regularized' /\n"
          "&analysis spectrum = .false., poincare = .false., lyapunov = .false., rosenstein = .false.,"
          " lyapunov_spectrum = .false., orbit = .false. /\n"
          "&verify check = .false. /\n")


class CompareError(Exception):
    """A run failed or its output is not what was expected; code is the exit code to give."""

    def __init__(self, message: str, code: int = 1):
        super().__init__(message)
        self.code = code


def log(message: str) -> None:
    print(f"ngspice_compare: {message}", file=sys.stderr, flush=True)


# ---------------------------------------------------------------- running

def _overrides(directory: Path, name: str, extra: str) -> list[Path]:
    """COMMON, then each line of extra, as files read in order: a group may
    appear once per file, so each override gets its own."""
    paths = []
    for k, text in enumerate([COMMON] + [line + "\n" for line in extra.splitlines() if line.strip()]):
        path = directory / f"{name}_{k}.nml"
        path.write_text(text)
        paths.append(path)
    return paths


def _integrator(method: str | None, rtol: float | None, atol: float | None) -> str:
    parts = []
    if method:
        parts.append(f"method = '{method}'")
    if rtol is not None:
        parts.append(f"rtol = {rtol:.17g}")
    if atol is not None:
        parts.append(f"atol = {atol:.17g}")
    return f"&integrator {', '.join(parts)} /\n" if parts else ""


def _run(command: list[str], cwd: Path) -> subprocess.CompletedProcess:
    result = subprocess.run(command, cwd=cwd, capture_output=True, text=True)
    if result.returncode != 0:
        # friction's usage (2) and bad-input (3) exits are bad input here too.
        raise CompareError(f"{' '.join(map(str, command))} exited with {result.returncode}:\n"
                           f"{result.stderr.strip() or result.stdout.strip()}",
                           2 if result.returncode in (2, 3) else 1)
    return result


def run_kernel(binary: Path, inputs: list[Path], extra: str, workdir: Path, name: str,
               repeats: int = 1) -> dict:
    """The kernel on the scene (+ COMMON + extra); its samples and time (median)."""
    overrides = _overrides(workdir, name, extra)
    out = workdir / f"{name}.h5"
    times = []
    for _ in range(repeats):
        _run([str(binary), "-q", "-f", "-o", str(out), *map(str, inputs + overrides)], workdir)
        times.append(kernel_time(out))
    t, values = reference_from_h5(out)
    with h5py.File(out, "r") as f:
        method = f.attrs["method"].decode() if isinstance(f.attrs["method"], bytes) else str(f.attrs["method"])
        steps = int(f.attrs["integrator_steps"])
    return {"t": t, "values": values, "time": statistics.median(times), "method": method, "steps": steps,
            "file": out}


def kernel_time(path: Path) -> float:
    """Brake: /brake compute_time; microscope: the root wall_time (s)."""
    with h5py.File(path, "r") as f:
        if "brake" in f:
            return float(f["brake"].attrs["compute_time"])
        return float(f.attrs["wall_time"])


def _namelist_number(text: str, group: str, name: str) -> float:
    block = re.search(rf"&{group}\b(.*?)\n\s*/", text, re.S | re.I)
    if not block:
        raise CompareError(f"no &{group} in the file's input attribute")
    match = re.search(rf"\b{name}\s*=\s*([-+0-9.EeDd]+)", block.group(1), re.I)
    if not match:
        raise CompareError(f"no {group}.{name} in the file's input attribute")
    return float(match.group(1).replace("D", "E").replace("d", "e"))


def reference_from_h5(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """A kernel output file as (time, values) in the netlist's time and units.

    brake: (tau, x in m); microscope: (seconds from the trip's start, f_along
    of line 0 trace in nN), the sample i at (lead_in + support_x[i]) / velocity.
    """
    with h5py.File(path, "r") as f:
        if "brake" in f:
            return f["brake/t"][()], f["brake/x"][()]
        if "afm" not in f:
            raise CompareError(f"{path}: not a friction output file")
        text = f.attrs["input"]
        text = text.decode() if isinstance(text, bytes) else str(text)
        velocity = _namelist_number(text, "scan", "velocity")
        lead_in = _namelist_number(text, "scan", "lead_in")
        s = f["afm/support_x"][()]
        return (lead_in + s) / velocity, f["afm/trace/f_along"][0, :]


def netlist_scene(text: str) -> str:
    return "brake" if "Girling brake" in text.splitlines()[0] else "afm"


def run_ngspice(ngspice: str, binary: Path, inputs: list[Path], extra: str, workdir: Path, name: str,
                repeats: int = 1) -> dict:
    """Write the netlist (friction --netlist), run ngspice -b on it; its waveform and times."""
    overrides = _overrides(workdir, name, extra)
    netlist = workdir / f"{name}.cir"
    _run([str(binary), "-q", "-f", "--netlist", str(netlist), *map(str, inputs + overrides)], workdir)
    text = netlist.read_text()
    scene = netlist_scene(text)
    data = workdir / f"{name}.data"
    cpu, wall, process_cpu = [], [], []
    for _ in range(repeats):
        if data.exists():
            data.unlink()
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        start = time.perf_counter()
        result = subprocess.run([ngspice, "-b", netlist.name], cwd=workdir, capture_output=True, text=True)
        wall.append(time.perf_counter() - start)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        process_cpu.append(after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime)
        analysis = re.search(r"Transient analysis time\s*=\s*([0-9.eE+-]+)", result.stdout)
        if result.returncode != 0 or not data.exists() or not analysis:
            tail = "\n".join((result.stdout + result.stderr).strip().splitlines()[-15:])
            raise CompareError(f"ngspice -b {netlist} failed (exit {result.returncode}):\n{tail}")
        cpu.append(float(analysis.group(1)))
    table = np.loadtxt(data, skiprows=1, ndmin=2)
    header = data.read_text().splitlines()[0].split()
    columns = {key: table[:, k] for k, key in enumerate(header)}
    t_start = 0.0
    if scene == "brake":
        match = re.search(r"t_start = ([-+0-9.Ee]+)\)", text)
        t_start = float(match.group(1)) if match else 0.0
        value, derivative = columns["x"], columns["v"]
    else:
        value, derivative = columns["f_along"], columns["d_f_along"]
    return {"scene": scene, "t": columns["time"] + t_start, "values": value, "derivatives": derivative,
            "cpu_time": statistics.median(cpu), "wall_time": statistics.median(wall),
            "process_cpu": statistics.median(process_cpu), "points": int(table.shape[0]), "netlist": netlist}


# ---------------------------------------------------------- comparison

def hermite(tq: np.ndarray, t: np.ndarray, y: np.ndarray, dy: np.ndarray) -> np.ndarray:
    """Cubic Hermite interpolation of (t, y, y') at tq (inside [t[0], t[-1]])."""
    i = np.clip(np.searchsorted(t, tq, side="right") - 1, 0, len(t) - 2)
    h = t[i + 1] - t[i]
    s = (tq - t[i]) / h
    return ((2 * s**3 - 3 * s**2 + 1) * y[i] + (s**3 - 2 * s**2 + s) * h * dy[i]
            + (-2 * s**3 + 3 * s**2) * y[i + 1] + (s**3 - s**2) * h * dy[i + 1])


def on_grid(spice: dict, t: np.ndarray, window: tuple[float, float] | None = None):
    """The kernel's grid points ngspice covers (within window), and ngspice there."""
    keep = (t >= spice["t"][0]) & (t <= spice["t"][-1])
    if window is not None:
        keep &= (t >= window[0]) & (t <= window[1])
    if not keep.any():
        raise CompareError("no point of the kernel's grid inside ngspice's run and the window")
    return keep, hermite(t[keep], spice["t"], spice["values"], spice["derivatives"])


def max_difference(spice: dict, t: np.ndarray, reference: np.ndarray,
                   window: tuple[float, float] | None = None) -> tuple[float, float]:
    """Largest |ngspice - reference| on the grid (and where)."""
    keep, values = on_grid(spice, t, window)
    difference = np.abs(values - reference[keep])
    k = int(np.argmax(difference))
    return float(difference[k]), float(t[keep][k])


def ngspice_work_precision(inputs, reltols, reference_t, reference_values, *, binary=DEFAULT_BINARY,
                           ngspice="ngspice", atol=None, window=None, repeats=1, extra="", workdir=None):
    """(error, cpu_time) pairs of ngspice along a reltol ladder.

    inputs: namelist files of the scene; reltols: ngspice reltol values;
    reference_t, reference_values: the reference on the kernel's grid, in the
    netlist's time and units (reference_from_h5 gives them from a kernel file:
    brake tau and x in m, microscope seconds and f_along in nN); atol: ngspice's
    vntol = chgtol = abstol (None: the input's &integrator atol); window:
    (t0, t1) of the comparison or None for all; extra: more namelist text
    (e.g. "&brake t_end = 300.0 /\n").  Returns one dict per reltol:
    reltol, atol, error (largest difference on the grid, m or nN), t_error
    (where), cpu_time (ngspice's transient analysis time, s, median of
    repeats), wall_time and process_cpu (the ngspice process's wall clock
    and CPU time, user + system, s), points (saved time points).
    """
    rows = []
    inputs = [Path(p).resolve() for p in inputs]
    with tempfile.TemporaryDirectory(prefix="ngspice_wp_") as scratch:
        directory = Path(workdir or scratch)
        directory.mkdir(parents=True, exist_ok=True)
        for k, reltol in enumerate(reltols):
            spice = run_ngspice(ngspice, Path(binary).resolve(), inputs, extra + _integrator(None, reltol, atol),
                                directory, f"ladder{k}", repeats)
            error, where = max_difference(spice, np.asarray(reference_t), np.asarray(reference_values), window)
            rows.append({"reltol": reltol, "atol": atol, "error": error, "t_error": where,
                         "cpu_time": spice["cpu_time"], "wall_time": spice["wall_time"],
                         "process_cpu": spice["process_cpu"], "points": spice["points"]})
    return rows


# --------------------------------------------------------------- output

def write_json(path: Path, record: dict) -> None:
    def plain(value):
        if isinstance(value, np.ndarray):
            return value.tolist()
        if isinstance(value, Path):
            return str(value)
        if isinstance(value, dict):
            return {k: plain(v) for k, v in value.items()}
        if isinstance(value, list):
            return [plain(v) for v in value]
        return value
    path.write_text(json.dumps(plain(record), indent=1) + "\n")


def write_hdf5(path: Path, record: dict) -> None:
    """Scalars as root attributes, the curves as datasets, the ladder as a table;
    each dataset's unit as the program's files state theirs (docs/output.md#units-udunits-strings):
    the brake's time tau as a pure number, 'tau' beside it in units_tau."""
    unit, time_unit = record.get("unit", ""), record.get("time_unit", "s")
    units = {"t": time_unit, "kernel": unit, "ngspice": unit, "ladder/reltol": "1", "ladder/error": unit,
             "ladder/t_error": time_unit, "ladder/cpu_time": "s", "ladder/wall_time": "s", "ladder/points": "1"}
    with h5py.File(path, "w") as f:
        for key, value in record.items():
            if isinstance(value, np.ndarray):
                f[key] = value
            elif key == "ladder":
                for column in ("reltol", "error", "t_error", "cpu_time", "wall_time", "points"):
                    f[f"ladder/{column}"] = np.array([row[column] for row in value])
            elif value is not None and not isinstance(value, (dict, list)):
                f.attrs[key] = str(value) if isinstance(value, Path) else value
        for name, stated in units.items():
            if name in f and stated:
                f[name].attrs["units"] = "1" if stated == "tau" else stated
                if stated == "tau":
                    f[name].attrs["units_tau"] = "tau"


# ------------------------------------------------------------------ main

def parse_arguments(argv):
    parser = argparse.ArgumentParser(
        prog="ngspice_compare.py",
        description="The kernel against the paper's network model in ngspice: largest difference "
                    "(brake x in m; microscope f_along of line 0 in nN) and both times.")
    parser.add_argument("inputs", nargs="+", type=Path, help="namelist files of the scene, in order")
    parser.add_argument("--binary", type=Path, default=DEFAULT_BINARY, help="the friction program")
    parser.add_argument("--ngspice", default="ngspice", help="the ngspice program")
    parser.add_argument("--t-end", type=float, default=300.0,
                        help="brake: end of the run in tau (default 300; 0 keeps the input's)")
    parser.add_argument("--window", type=float, nargs=2, metavar=("T0", "T1"),
                        help="compare only inside [T0, T1] (tau for the brake, s for the microscope)")
    parser.add_argument("--rtol", type=float, help="ngspice reltol (default: the input's rtol)")
    parser.add_argument("--atol", type=float, help="ngspice vntol = chgtol = abstol (default: the input's atol)")
    parser.add_argument("--kernel-method", help="the kernel's GSL stepper (default: the input's)")
    parser.add_argument("--kernel-rtol", type=float, help="the kernel's rtol (default: the input's)")
    parser.add_argument("--kernel-atol", type=float, help="the kernel's atol (default: the input's)")
    parser.add_argument("--repeats", type=int, default=1, help="runs per timing, median reported (default 1)")
    parser.add_argument("--ladder", help="comma-separated ngspice reltol values: work-precision pairs")
    parser.add_argument("--reference", type=Path, help="--ladder: the reference, a kernel output file")
    parser.add_argument("--reference-method", default="rk8pd", help="--ladder: reference stepper (rk8pd)")
    parser.add_argument("--reference-rtol", type=float, default=1e-12,
                        help="--ladder: reference rtol (1e-12; atol = rtol/100)")
    parser.add_argument("--json", type=Path, help="write the record (curves, times, ladder) as JSON")
    parser.add_argument("--hdf5", type=Path, help="write the record as HDF5")
    parser.add_argument("--keep", type=Path, help="keep the runs' files in this directory")
    args = parser.parse_args(argv)
    for path in args.inputs:
        if not path.is_file():
            parser.error(f"{path}: no such file")
    if not Path(args.binary).is_file():
        parser.error(f"{args.binary}: no friction program (build first, or --binary)")
    # The runs happen in a scratch directory: a relative --binary is relative to here.
    args.binary = Path(args.binary).resolve()
    if shutil.which(args.ngspice) is None:
        parser.error(f"{args.ngspice}: ngspice not found (scripts/install-deps installs it)")
    if args.repeats < 1:
        parser.error("--repeats must be >= 1")
    if args.ladder:
        try:
            args.ladder = [float(v) for v in args.ladder.split(",")]
        except ValueError:
            parser.error(f"--ladder {args.ladder}: expected comma-separated numbers")
        if any(not v > 0 for v in args.ladder):
            parser.error("--ladder: reltol values must be > 0")
    if args.window and not args.window[1] > args.window[0]:
        parser.error("--window T0 T1 needs T1 > T0")
    return args


def compare(args) -> dict:
    inputs = [p.resolve() for p in args.inputs]
    extra = f"&brake t_end = {args.t_end:.17g} /\n" if args.t_end > 0 else ""
    with tempfile.TemporaryDirectory(prefix="ngspice_compare_") as scratch:
        workdir = Path(args.keep or scratch).resolve()
        workdir.mkdir(parents=True, exist_ok=True)
        kernel = run_kernel(args.binary, inputs,
                            extra + _integrator(args.kernel_method, args.kernel_rtol, args.kernel_atol),
                            workdir, "kernel", args.repeats)
        spice = run_ngspice(args.ngspice, args.binary, inputs, extra + _integrator(None, args.rtol, args.atol),
                            workdir, "spice", args.repeats)
        scene = spice["scene"]
        quantity, unit = ("x", "m") if scene == "brake" else ("f_along", "nN")
        keep, values = on_grid(spice, kernel["t"], tuple(args.window) if args.window else None)
        difference = values - kernel["values"][keep]
        k = int(np.argmax(np.abs(difference)))
        netlist_text = spice["netlist"].read_text()
        rel = re.search(r"reltol=([-+0-9.Ee]+)", netlist_text)
        record = {
            "scene": scene, "quantity": quantity, "unit": unit,
            "time_unit": "tau" if scene == "brake" else "s",
            "t": kernel["t"][keep], "kernel": kernel["values"][keep], "ngspice": values,
            "max_difference": float(abs(difference[k])), "t_max_difference": float(kernel["t"][keep][k]),
            "span": float(np.ptp(kernel["values"][keep])),
            "kernel_method": kernel["method"], "kernel_steps": kernel["steps"],
            "kernel_time": kernel["time"],
            "kernel_time_kind": "compute_time" if scene == "brake" else "wall_time",
            "ngspice_reltol": float(rel.group(1)) if rel else None,
            "ngspice_cpu_time": spice["cpu_time"], "ngspice_wall_time": spice["wall_time"],
            "ngspice_points": spice["points"], "repeats": args.repeats,
        }
        if args.ladder:
            if args.reference:
                t_ref, ref = reference_from_h5(args.reference)
                reference_name = str(args.reference)
            else:
                rt = args.reference_rtol
                reference = run_kernel(args.binary, inputs,
                                       extra + _integrator(args.reference_method, rt, rt / 100), workdir,
                                       "reference")
                t_ref, ref = reference["t"], reference["values"]
                reference_name = f"kernel {args.reference_method} rtol {rt:g} atol {rt / 100:g}"
            record["reference"] = reference_name
            record["kernel_error"] = float(np.max(np.abs(
                np.interp(kernel["t"][keep], t_ref, ref) - kernel["values"][keep]))) \
                if len(t_ref) == len(kernel["t"]) and np.allclose(t_ref, kernel["t"]) else None
            record["ladder"] = ngspice_work_precision(
                inputs, args.ladder, t_ref, ref, binary=args.binary, ngspice=args.ngspice, atol=args.atol,
                window=tuple(args.window) if args.window else None, repeats=args.repeats, extra=extra,
                workdir=workdir / "ladder")
            record["matched_ngspice_cpu_time"] = matched_time(record["ladder"], record.get("kernel_error"))
    return record


def matched_time(rows: list[dict], error: float | None) -> float | None:
    """ngspice's analysis time at the given error, interpolated log-log along
    the ladder (None when the error is outside the ladder's range)."""
    if error is None or not error > 0:
        return None
    points = sorted((r["error"], r["cpu_time"]) for r in rows if r["error"] > 0 and r["cpu_time"] > 0)
    if len(points) < 2 or not points[0][0] <= error <= points[-1][0]:
        return None
    e = np.log([p[0] for p in points])
    c = np.log([p[1] for p in points])
    return float(np.exp(np.interp(np.log(error), e, c)))


def report(record: dict) -> None:
    u, tu = record["unit"], record["time_unit"]
    what = ("brake (regularized arctan law), x" if record["scene"] == "brake"
            else "microscope line 0 trace, f_along")
    print(f"scene: {what} over {tu} in [{record['t'][0]:.6g}, {record['t'][-1]:.6g}], "
          f"{len(record['t'])} grid points")
    print(f"kernel:  {record['kernel_method']}, {record['kernel_steps']} steps, "
          f"{record['kernel_time_kind']} {record['kernel_time']:.4f} s")
    print(f"ngspice: reltol {record['ngspice_reltol']:.3g}, {record['ngspice_points']} time points, "
          f"analysis {record['ngspice_cpu_time']:.3f} s, wall {record['ngspice_wall_time']:.3f} s")
    print(f"max |ngspice - kernel| = {record['max_difference']:.3e} {u} at {tu} = "
          f"{record['t_max_difference']:.6g} (span of {record['quantity']}: {record['span']:.3e} {u})")
    if record["kernel_time"] > 0:
        print(f"time ratio ngspice analysis / kernel = {record['ngspice_cpu_time'] / record['kernel_time']:.3g}")
    if "ladder" in record:
        print(f"work-precision of ngspice against {record['reference']}:")
        if record.get("kernel_error") is not None:
            print(f"  (the kernel run above: error {record['kernel_error']:.3e} {u} "
                  f"in {record['kernel_time']:.4f} s)")
        print(f"  {'reltol':>8} {'error':>10} {'analysis s':>11} {'wall s':>8} {'points':>8}")
        for row in record["ladder"]:
            print(f"  {row['reltol']:8.0e} {row['error']:10.3e} {row['cpu_time']:11.3f} "
                  f"{row['wall_time']:8.3f} {row['points']:8d}")
        matched = record.get("matched_ngspice_cpu_time")
        if matched is not None and record["kernel_time"] > 0:
            print(f"at the kernel's error ngspice needs {matched:.4f} s (log-log along the ladder): "
                  f"ngspice / kernel = {matched / record['kernel_time']:.3g}")
        elif record.get("kernel_error") is not None:
            print("the kernel's error is outside the ladder's range: no matched-accuracy ratio")


def main(argv=None) -> int:
    args = parse_arguments(argv)
    try:
        record = compare(args)
    except CompareError as exc:
        log(str(exc))
        return exc.code
    report(record)
    if args.json:
        write_json(args.json, record)
    if args.hdf5:
        write_hdf5(args.hdf5, record)
    return 0


if __name__ == "__main__":
    sys.exit(main())
