#!/usr/bin/env python3
"""The stiff friction laws as whole processes against SciPy's solve_ivp
(Radau, LSODA) and SUNDIALS CVODE (BDF) at equal accuracy: work-precision
data, printed as a table.
Not a test: the machine is shared and noisy, so each time is the median of
--repeats runs, and the ratios are of medians measured in one run.

  lugre       the LuGre paper's stick-slip (m = 1 kg, k = 2 N/m, belt 0.1 m/s,
              Table I: sigma0 = 1e5 N/m), 30 s
  rate_state  the spring-slider at k = 0.2 k_c (aging law, load point at
              1e-6 m/s), 3000 s: the slip rate spans ten decades

Accuracy: the largest difference in x on the output grid from a reference,
the program at rtol 1e-12 stepping onto every output time, relative to the
range of x.  Four times for each run:
  wall     the whole process: for the program its start, input, integration
           and HDF5 file, "friction" as it runs by default (free steps, the
           grid from rodas4's continuous extension), "stepped" with &machine
           dense_output = .false. (a step ends at every output time); for
           CVODE its process (scripts/cvode_laws.c, compiled here: BDF, dense
           solver, the analytic Jacobian; Debian: libsundials-dev, without
           which its rows are skipped), which writes x alone as raw doubles,
           and "CVODE+h5", the same program built with -DCVODE_LAWS_HDF5 by
           HDF5's h5pcc (HDF5's static archives, as the program links them,
           and --as-needed, as the program), which writes what a user keeps
           of the run: t, x, v, z (theta) and the force with their units in an
           HDF5 file (without h5pcc its rows are skipped); for SciPy a python3 process that
           imports SciPy, integrates with solve_ivp and writes its result
           with h5py, as a user's script would (scripts/scipy_laws.py: the
           Jacobian estimated by differences, its default)
  cpu      the same process's CPU time (user and system), which the load of
           a shared machine changes far less than its wall time
  compute  the integration alone (wall time inside the process): the
           program's compute_time (its file records it: the run's
           integration and output grid), CVODE's from its state vector's
           creation to the last output point (its process times it),
           solve_ivp's call (the interpreter already running)
  (cpu)    compute's CPU time: CVODE's and solve_ivp's over the same span
           (the process's CPU clock); the program's, which its file does not
           record, as its process's CPU time less that of the same run to
           the first output point (start, input and file alike)
The program's and CVODE's processes run interleaved (friction, stepped,
CVODE, CVODE+h5, friction, ...), so that a change of the machine's load
falls on all four alike; the ratio columns are CVODE's and CVODE+h5's
medians over the program's at the same rtol.  At the end, each peer's every point against the program's
fastest run (default settings) with an error at most the peer's: the ratio
of the peer's median to the program's, by each of the four times.

    scripts/benchmark_laws [--repeats N] [--quick] [--no-scipy] [--limit S] [--chart FILE.png]
    scripts/benchmark_laws --horizons [M1,M2,...] [--repeats N] [--quick]

--horizons runs the program (default settings) and the two CVODE peers alone
over M1, M2, ... times each case's span (default 1,2,4,10,100), the grid's
spacing kept, the error against a reference over the same span: how the
ratios change with the run's length, as the program's fixed cost (start,
input, the HDF5 file's creation) weighs less.  For each span it prints the
tables above and then, by span, each peer's CPU ratio at equal or smaller
error (the median over its points, their range, and at its most accurate
point), and the span at which the median, and the most accurate point's
ratio, reaches 1: the program's whole process as fast as the peer's (the
ratio interpolated linearly in the span's logarithm).
--chart draws the work-precision chart of each case (CPU time against error,
one line per method) into FILE.png.
"""
import argparse
import json
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import h5py
import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scripts"))
from scipy_laws import RATE_STATE_STIFFNESS, lugre_field as scipy_lugre, rate_state_field as scipy_rate_state  # noqa: E402,E501
# s of integration before a run of the program is given up (its slowest
# successful run here takes 0.2 s; the free steps crawled on rate and state at
# rtol 1e-4 and 1e-5 before the slip rate's relative bound: docs/speed.md).
PROGRAM_LIMIT = 10.0


def timed(command, timeout=None):
    """subprocess.run(command): (its result, (wall seconds, CPU seconds:
    user and system of the process)); TimeoutExpired passes through.  The
    CPU time is what a shared machine's load changes least."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    result = subprocess.run(command, capture_output=True, text=True, timeout=timeout)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return result, (wall, after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime)


def program_run(binary, work, name, rtol, sets, limit=0.0):
    """((wall, CPU) seconds of the whole process, t, x, steps, Jacobians,
    seconds of compute_time); x is the program's message if it failed (or
    gave up after `limit` s)."""
    out = work / f"{name}.h5"
    command = [str(binary), "--quiet", "--force", "-o", str(out), str(ROOT / "inputs" / f"machine_{name}.nml"),
               "--set", f"integrator.rtol={rtol}", "--set", f"integrator.atol={rtol * 1e-3}",
               "--set", f"integrator.max_wall_time={limit}"]
    for key, value in sets.items():
        command += ["--set", f"{key}={value}"]
    result, elapsed = timed(command)
    if result.returncode != 0:
        return elapsed, None, result.stderr.strip().splitlines()[-1], -1, -1, float("nan")
    with h5py.File(out) as f:
        return (elapsed, f["machine/t"][:], f["machine/x"][:], int(f.attrs["integrator_steps"]),
                int(f.attrs["jacobian_evaluations"]), float(f["machine"].attrs["compute_time"]))


def lugre_field():
    """(t_end, the program's --set settings) of the LuGre case."""
    return scipy_lugre()[2], {}


def rate_state_field():
    """(t_end, the program's --set settings) of the rate-and-state case:
    the stiffness and start of scripts/scipy_laws.py's."""
    _, y0, t_end = scipy_rate_state()
    sets = {"machine.stiffness": RATE_STATE_STIFFNESS, "machine.x0": y0[0], "machine.t_end": t_end,
            "machine.dt_out": 0.1}
    return t_end, sets


def scipy_run(work, name, method, rtol, dt_out, limit):
    """scripts/scipy_laws.py as a whole python3 process, given up after
    `limit` s (Radau took 310 s to fail on the rate-and-state case at rtol
    1e-5): ((wall, CPU) seconds of the process, (wall, CPU) seconds of
    solve_ivp alone, x or why it failed)."""
    out = work / f"scipy_{name}.h5"
    command = [sys.executable, str(ROOT / "scripts" / "scipy_laws.py"), name, method, f"{rtol:.17g}",
               f"{dt_out:.17g}", str(out)]
    try:
        result, elapsed = timed(command, limit)
    except subprocess.TimeoutExpired:
        return (limit, limit), (limit, limit), f"gave up after {limit:g} s"
    if result.returncode != 0:
        return elapsed, (float("nan"), float("nan")), (result.stderr.strip().splitlines() or ["failed"])[-1]
    with h5py.File(out) as f:
        alone = json.loads(result.stdout)
        return elapsed, (alone["seconds"], alone["cpu_seconds"]), f[f"{name}/x"][:]


SUNDIALS_LIBS = ["-lsundials_cvode", "-lsundials_nvecserial", "-lsundials_sunmatrixdense",
                 "-lsundials_sunlinsoldense", "-lm"]


def build_cvode(work, hdf5=False):
    """Compile scripts/cvode_laws.c: (the program, None) or (None, why not).
    With hdf5, the variant that writes an HDF5 file, by HDF5's h5pcc (its
    static archives) with --as-needed, as the program is linked."""
    cc = "h5pcc" if hdf5 else os.environ.get("CC", "cc")
    if shutil.which(cc) is None:
        return None, f"no C compiler ({cc})"
    exe = work / ("cvode_laws_h5" if hdf5 else "cvode_laws")
    flags = ["-DCVODE_LAWS_HDF5", "-Wl,--as-needed"] if hdf5 else []
    # (in the scratch directory: h5pcc leaves its object file where it runs)
    result = subprocess.run([cc, "-O2", *flags, "-o", str(exe), str(ROOT / "scripts" / "cvode_laws.c"), *SUNDIALS_LIBS],
                            capture_output=True, text=True, cwd=work)
    if result.returncode != 0:
        return None, (f"could not build the CVODE peer{' with HDF5' if hdf5 else ''}"
                      " (Debian: apt-get install libsundials-dev libhdf5-openmpi-dev)")
    return exe, None


def cvode_run(exe, work, name, rtol, dt_out, t_end, hdf5=False):
    """((wall, CPU) seconds of the whole process, x on the grid, counts with
    the integration's "seconds") or (seconds, why it failed, None)."""
    out = work / f"cvode_{name}.{'h5' if hdf5 else 'bin'}"
    result, elapsed = timed([str(exe), name, f"{rtol:.17g}", f"{rtol * 1e-3:.17g}", f"{dt_out:.17g}", str(out),
                             f"{t_end:.17g}"])
    if result.returncode != 0:
        return elapsed, result.stderr.strip().splitlines()[-1], None
    if hdf5:
        with h5py.File(out) as f:
            return elapsed, f["machine/x"][:], json.loads(result.stdout)
    return elapsed, np.fromfile(out), json.loads(result.stdout)


def equal_error(points, name):
    """Each peer's point against the program's fastest run (default
    settings) with an error at most the peer's, by each of the four times
    (wall, CPU, compute, compute's CPU): rows of text."""
    ours = points.get((name, "friction"), [])
    rows = []
    for method in ("CVODE", "CVODE+h5", "LSODA", "Radau"):
        for point in sorted(points.get((name, method), []), key=lambda p: p[-1]):
            error, rtol = point[0], point[-1]
            good = [p for p in ours if p[0] <= error]
            if not good:
                rows.append(f"{method:9s} {rtol:8.0e} {error:10.2e}  the program reaches no error this small")
                continue
            text = f"{method:9s} {rtol:8.0e} {error:10.2e}"
            for k in range(1, 5):
                fast = min(good, key=lambda p: p[k])
                text += f"  {point[k]:7.4f} {fast[k]:7.4f} ({fast[-1]:5.0e}) {point[k] / fast[k]:6.2f}"
            rows.append(text)
    return rows


def measure(args, work, peers, name, t_end, sets, tolerances, points, key, horizon=1.0):
    """The program's and the peers' processes at each rtol over `sets`'
    span, interleaved (the program by default and, at horizon 1, stepped),
    their four times' medians and errors against the program at rtol 1e-12
    stepping onto every output time: the table's rows, and each point in
    points[(key, method)].  Returns the reference's grid t, x and x's range."""
    stepped = dict(sets, **{"machine.dense_output": ".false."})
    _, t, reference, _, _, _ = program_run(args.binary, work, name, 1e-12, stepped)
    scale = np.ptp(reference)
    dt_out = float(t[1] - t[0])
    variants = (("friction", sets), ("stepped", stepped)) if horizon == 1.0 else (("friction", sets),)
    # (the give-up limit grows with the span: it is there for runs that crawl)
    limit = min(args.limit * horizon, PROGRAM_LIMIT * horizon)
    rows = []
    for rtol in tolerances:
        # (wall, cpu) of the processes, wall of the integration, cpu of the program's runs to dt_out
        times = {method: [] for method in (*(v for v, _ in variants), *(label for label, _ in peers))}
        computes = {method: [] for method in times}
        short = {v: [] for v, _ in variants}
        peer_cpu = {label: [] for label, _ in peers}
        last = {}
        for _ in range(args.repeats):
            for method, settings in variants:
                seconds, _, x, steps, jacobians, compute = program_run(
                    args.binary, work, name, rtol, settings, limit)
                times[method].append(seconds)
                computes[method].append(compute)
                last[method] = (x, steps, jacobians)
                to_first = dict(settings, **{"machine.t_end": dt_out})
                short[method].append(program_run(args.binary, work, name, rtol, to_first)[0][1])
            for label, exe in peers:
                seconds, x, counts = cvode_run(exe, work, name, rtol, dt_out, t_end, hdf5=label == "CVODE+h5")
                times[label].append(seconds)
                computes[label].append(counts["seconds"] if counts else float("nan"))
                peer_cpu[label].append(counts["cpu_seconds"] if counts else float("nan"))
                last[label] = (x, counts)
        median = {method: statistics.median(w for w, _ in v) for method, v in times.items() if v}
        cpu = {method: statistics.median(c for _, c in v) for method, v in times.items() if v}
        busy = {method: statistics.median(v) for method, v in computes.items() if v}
        busy_cpu = {method: cpu[method] - statistics.median(v) for method, v in short.items()}
        for label, values in peer_cpu.items():
            busy_cpu[label] = statistics.median(values)
        for method, _ in variants:
            x, steps, jacobians = last[method]
            if isinstance(x, str):
                rows.append(f"{method:10s} {rtol:8.0e} {'failed':>10s} {median[method]:8.4f}  {x}")
                continue
            error = np.max(np.abs(x - reference)) / scale
            four = (median[method], cpu[method], busy[method], busy_cpu[method])
            points.setdefault((key, method), []).append((error, *four, rtol))
            ratio = ""
            for label, _ in peers:
                theirs = (median[label], cpu[label], busy[label], busy_cpu[label])
                ratio += "".join(f" {c / o:6.2f}" for c, o in zip(theirs, four))
            rows.append(f"{method:10s} {rtol:8.0e} {error:10.2e}" + "".join(f" {v:8.4f}" for v in four)
                        + f" {steps:8d} {jacobians:9d}{ratio}")
        for label, _ in peers:
            x, counts = last[label]
            if isinstance(x, str) or x.size != t.size:
                rows.append(f"{label:10s} {rtol:8.0e} {'failed':>10s} {median[label]:8.4f}  "
                            f"{x if isinstance(x, str) else ''}")
            else:
                error = np.max(np.abs(x - reference)) / scale
                four = (median[label], cpu[label], busy[label], busy_cpu[label])
                points.setdefault((key, label), []).append((error, *four, rtol))
                rows.append(f"{label:10s} {rtol:8.0e} {error:10.2e}" + "".join(f" {v:8.4f}" for v in four)
                            + f" {counts['steps']:8d} {counts['jacobian_evaluations']:9d}")
    print(f"\n{key}: {t.size} grid points to t = {t_end:g} s; error = max |x - x_ref| / range of x;"
          f" times in s, medians: wall and cpu of the whole process, compute = the integration alone"
          f" (wall time, and cpu time: the program's the process's less that of the same run to the"
          f" first output point); CVODE/this, CVODE+h5/this: the ratios of the four")
    header = f"{'method':10s} {'rtol':>8s} {'error':>10s} {'wall':>8s} {'cpu':>8s} {'compute':>8s} {'(cpu)':>8s}"
    print(header + f" {'steps':>8s} {'Jacobians':>9s}" + "".join(f" {label + '/this':>27s}" for label, _ in peers))
    for method in (*(v for v, _ in variants), *(label for label, _ in peers)):
        for row in rows:
            if row.split()[0] == method:
                print(row)
    return t, reference, scale


def print_equal_error(points, key):
    """The table of each peer's points at equal or smaller error."""
    print(f"\n{key} at equal or smaller error: each peer's point against the program's fastest run"
          f" (default settings, its rtol in brackets) with an error at most the peer's, by each of the four"
          f" times; ratio = the peer's time / the program's")
    print(f"{'peer':9s} {'rtol':>8s} {'error':>10s}" + "".join(
        f"  {kind:>7s} {'friction':>7s} {'':7s} {'ratio':>6s}" for kind in ("wall", "cpu", "compute", "(cpu)")))
    for row in equal_error(points, key):
        print(row)
    sys.stdout.flush()


def cpu_ratios(points, key, peer):
    """The peer's CPU time of the whole process over the program's fastest
    run with an error at most the peer's, at each of the peer's points,
    the most accurate first."""
    ours = points.get((key, "friction"), [])
    ratios = []
    for point in sorted(points.get((key, peer), [])):
        good = [p for p in ours if p[0] <= point[0]]
        if good:
            ratios.append(point[2] / min(p[2] for p in good))
    return ratios


def crossover(spans, ratios):
    """The span at which the ratio reaches 1, interpolated linearly in the
    span's logarithm between the spans that bracket it: a text."""
    pairs = [(s, r) for s, r in zip(spans, ratios) if r == r]
    if pairs and pairs[0][1] >= 1.0:
        return f"at or below {pairs[0][0]:g} s"
    for (s0, r0), (s1, r1) in zip(pairs, pairs[1:]):
        if r0 < 1.0 <= r1:
            return f"{s0 * (s1 / s0) ** ((1.0 - r0) / (r1 - r0)):.3g} s"
    return f"beyond {pairs[-1][0]:g} s" if pairs else "not measured"


def horizons(args, work, peers, tolerances, points):
    """Each case over args.horizons times its span, the grid's spacing kept:
    the equal-error tables and, by span, the CPU ratios of each peer's
    points (their median and range, and at its most accurate point) and the
    span at which the median, and the most accurate point's, reaches 1: the
    program's whole process as fast as the peer's.  (The smallest ratio is
    not summed up: at loose tolerances the peer's error grows to the range
    of x on the longer spans, and any run of the program is as accurate.)"""
    multiples = [float(m) for m in args.horizons.split(",")]
    for name, make in (("lugre", lugre_field), ("rate_state", rate_state_field)):
        t_end, sets = make()
        spans = [t_end * multiple for multiple in multiples]
        for multiple, span in zip(multiples, spans):
            key = f"{name} x{multiple:g}"
            measure(args, work, peers, name, span, dict(sets, **{"machine.t_end": span}), tolerances, points, key,
                    multiple)
            print_equal_error(points, key)
        print(f"\n{name}: the whole process's CPU at equal or smaller error by span (the peer's / the program's:"
              f" the median over the peer's points, their range, and at the peer's most accurate point)")
        for label, _ in peers:
            medians, best = [], []
            for multiple, span in zip(multiples, spans):
                ratios = cpu_ratios(points, f"{name} x{multiple:g}", label)
                medians.append(statistics.median(ratios) if ratios else float("nan"))
                best.append(ratios[0] if ratios else float("nan"))
                text = f"{min(ratios):.2f} to {max(ratios):.2f}" if ratios else "no point"
                print(f"  {label:9s} {span:10g} s  median {medians[-1]:5.2f}  ({text}), most accurate {best[-1]:5.2f}")
            print(f"  {label:9s} the program as fast as {label}: at the median {crossover(spans, medians)},"
                  f" at the most accurate point {crossover(spans, best)}")
        sys.stdout.flush()


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=3, help="runs of the program and of each CVODE peer per point")
    parser.add_argument("--scipy-repeats", type=int, default=3, help="runs of SciPy per point")
    parser.add_argument("--quick", action="store_true", help="fewer tolerances")
    parser.add_argument("--no-scipy", action="store_true",
                        help="the program and CVODE alone (the whole processes interleaved), without SciPy's rows")
    parser.add_argument("--horizons", nargs="?", const="1,2,4,10,100",
                        help="the program and CVODE alone over these multiples of each case's span (default"
                             " 1,2,4,10,100), the grid's spacing kept: how the ratios change with the run's length")
    parser.add_argument("--binary", default=str(ROOT / "build" / "friction"))
    parser.add_argument("--limit", type=float, default=60.0,
                        help="seconds before a SciPy run or the program's integration is given up")
    parser.add_argument("--chart", help="draw the work-precision charts into this PNG")
    args = parser.parse_args()
    tolerances = [1e-5, 1e-7] if args.quick else [1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9]
    points = {}   # (case, method) -> [(error, wall, cpu, compute, compute cpu, rtol)]
    with tempfile.TemporaryDirectory() as scratch:
        work = Path(scratch)
        cvode, why_not = build_cvode(work)
        if why_not:
            print(f"CVODE rows skipped: {why_not}")
        cvode_h5, why_not = build_cvode(work, hdf5=True) if cvode else (None, None)
        if why_not:
            print(f"CVODE+h5 rows skipped: {why_not}")
        peers = [(label, exe) for label, exe in (("CVODE", cvode), ("CVODE+h5", cvode_h5)) if exe]
        if args.horizons:
            horizons(args, work, peers, tolerances, points)
            return 0
        for name, make in (("lugre", lugre_field), ("rate_state", rate_state_field)):
            t_end, sets = make()
            t, reference, scale = measure(args, work, peers, name, t_end, sets, tolerances, points, name)
            dt_out = float(t[1] - t[0])
            for method in () if args.no_scipy else ("Radau", "LSODA"):
                for rtol in tolerances:
                    runs = [scipy_run(work, name, method, rtol, dt_out, args.limit) for _ in range(args.scipy_repeats)]
                    four = tuple(statistics.median(run[i][j] for run in runs) for i in (0, 1) for j in (0, 1))
                    x = runs[-1][2]
                    if isinstance(x, str) or x.size != t.size:
                        print(f"{method:10s} {rtol:8.0e} {'failed':>10s}" + "".join(f" {v:8.4f}" for v in four)
                              + f"  {x if isinstance(x, str) else ''}")
                        continue
                    error = np.max(np.abs(x - reference)) / scale
                    points.setdefault((name, method), []).append((error, *four, rtol))
                    print(f"{method:10s} {rtol:8.0e} {error:10.2e}" + "".join(f" {v:8.4f}" for v in four))
            print_equal_error(points, name)
    if args.chart:
        chart(points, args.chart)
    return 0


def chart(points, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for ax, (name, title) in zip(axes, (("lugre", "LuGre stick-slip, 30 s"),
                                        ("rate_state", "rate and state spring-slider, 3000 s"))):
        for method, style in (("friction", "o-"), ("stepped", "o:"), ("Radau", "s--"), ("LSODA", "^:"),
                              ("CVODE", "D-."), ("CVODE+h5", "d-.")):
            data = sorted(points.get((name, method), []))
            if data:
                ax.loglog([p[0] for p in data], [p[2] for p in data], style, label=method)
        ax.set_xlabel("error in x / range of x")
        ax.set_ylabel("CPU time of the whole process (s)")
        ax.set_title(title)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


if __name__ == "__main__":
    sys.exit(main())
