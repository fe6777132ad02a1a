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
range of x.  The program's time is its whole process (start, input,
integration, HDF5 file): "friction" as it runs by default (free steps, the
grid from rodas4's continuous extension), "stepped" with &machine
dense_output = .false. (a step ends at every output time).  SciPy's is
solve_ivp alone (the interpreter already running), with the Jacobian
estimated by differences (its default).  CVODE's is its whole process too
(scripts/cvode_laws.c, compiled here: BDF, dense solver, the analytic
Jacobian; Debian: libsundials-dev, without which its rows are skipped).
The program's and CVODE's processes run interleaved (friction, stepped,
CVODE, friction, ...), so that a change of the machine's load falls on all
three alike; the ratio column is CVODE's median over the program's at the
same rtol.

    scripts/benchmark_laws [--repeats N] [--quick] [--limit S] [--chart FILE.png]

--chart draws the work-precision chart of each case (time against error,
one line per method) into FILE.png.
"""
import argparse
import json
import multiprocessing
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import h5py
import numpy as np
from scipy.integrate import solve_ivp

ROOT = Path(__file__).resolve().parent.parent
# s of integration before a run of the program is given up (its slowest
# successful run here takes 0.2 s; the free steps crawl on rate and state at
# rtol 1e-5 with atol 1e-8, above the creeping slip rate: docs/speed.md).
PROGRAM_LIMIT = 10.0


def program_run(binary, work, name, rtol, sets, limit=0.0):
    """(seconds of the whole process, t, x, steps, Jacobians); x is the
    program's message if it failed (or gave up after `limit` s)."""
    out = work / f"{name}.h5"
    command = [str(binary), "--quiet", "--force", "-o", str(out), str(ROOT / "inputs" / f"machine_{name}.nml"),
               "--set", f"integrator.rtol={rtol}", "--set", f"integrator.atol={rtol * 1e-3}",
               "--set", f"integrator.max_wall_time={limit}"]
    for key, value in sets.items():
        command += ["--set", f"{key}={value}"]
    start = time.perf_counter()
    result = subprocess.run(command, capture_output=True, text=True)
    elapsed = time.perf_counter() - start
    if result.returncode != 0:
        return elapsed, None, result.stderr.strip().splitlines()[-1], -1, -1
    with h5py.File(out) as f:
        return (elapsed, f["machine/t"][:], f["machine/x"][:], int(f.attrs["integrator_steps"]),
                int(f.attrs["jacobian_evaluations"]))


def lugre_field():
    m, k, vb, fc, fs, vs, s0, s1, s2 = 1.0, 2.0, 0.1, 1.0, 1.5, 1e-3, 1e5, np.sqrt(1e5), 0.4

    def g(w):
        return fc + (fs - fc) * np.exp(-(w / vs) ** 2)

    def field(_, y):
        x, v, z = y
        w = v - vb
        zdot = w - s0 * abs(w) * z / g(w)
        return [v, (-k * x - (s0 * z + s1 * zdot + s2 * w)) / m, zdot]

    return field, [0.0, 0.0, -g(-vb) / s0], 30.0, {}


def rate_state_field():
    mass, normal, a, b, dc, v0, mu0, velocity = 1.0, 1.0, 0.010, 0.015, 1e-5, 1e-6, 0.6, 1e-6
    k = 0.2 * normal * (b - a) / dc

    def field(t, y):
        x, v, theta = y
        psi = mu0 + b * np.log(v0 * max(theta, 1e-300) / dc)
        big = np.log(max(abs(v), 1e-300) / (2.0 * v0)) + psi / a
        mu = np.sign(v) * a * (big + np.log(2.0)) if big > 18.0 else a * np.arcsinh(np.sign(v) * np.exp(big))
        return [v, (-k * (x - velocity * t) - normal * mu) / mass, 1.0 - abs(v) * theta / dc]

    x0 = -mu0 * normal / k
    sets = {"machine.stiffness": k, "machine.x0": x0, "machine.t_end": 3000.0, "machine.dt_out": 0.1}
    return field, [x0, 1.01 * velocity, dc / (1.01 * velocity)], 3000.0, sets


def _solve(queue, name, method, t, rtol):
    field, y0, t_end, _ = {"lugre": lugre_field, "rate_state": rate_state_field}[name]()
    start = time.perf_counter()
    solution = solve_ivp(field, (0.0, t_end), y0, method=method, t_eval=t, rtol=rtol, atol=rtol * 1e-3)
    queue.put((time.perf_counter() - start, solution.status, solution.message, solution.y[0]))


def scipy_run(name, method, t, rtol, limit):
    """solve_ivp in a child process, given up after `limit` s (Radau took
    310 s to fail on the rate-and-state case at rtol 1e-5)."""
    queue = multiprocessing.Queue()
    child = multiprocessing.Process(target=_solve, args=(queue, name, method, t, rtol))
    child.start()
    try:
        return queue.get(timeout=limit)
    except Exception:
        return limit, -2, f"gave up after {limit:g} s", None
    finally:
        child.join(timeout=1)
        if child.is_alive():
            child.kill()
            child.join()


SUNDIALS_LIBS = ["-lsundials_cvode", "-lsundials_nvecserial", "-lsundials_sunmatrixdense",
                 "-lsundials_sunlinsoldense", "-lm"]


def build_cvode(work):
    """Compile scripts/cvode_laws.c: (the program, None) or (None, why not)."""
    cc = os.environ.get("CC", "cc")
    if shutil.which(cc) is None:
        return None, f"no C compiler ({cc})"
    exe = work / "cvode_laws"
    result = subprocess.run([cc, "-O2", "-o", str(exe), str(ROOT / "scripts" / "cvode_laws.c"), *SUNDIALS_LIBS],
                            capture_output=True, text=True)
    if result.returncode != 0:
        return None, "could not build the CVODE peer (Debian: apt-get install libsundials-dev)"
    return exe, None


def cvode_run(exe, work, name, rtol, dt_out):
    """(seconds of the whole process, x on the grid, counts) or (seconds, why it failed, None)."""
    out = work / f"cvode_{name}.bin"
    start = time.perf_counter()
    result = subprocess.run([str(exe), name, f"{rtol:.17g}", f"{rtol * 1e-3:.17g}", f"{dt_out:.17g}", str(out)],
                            capture_output=True, text=True)
    elapsed = time.perf_counter() - start
    if result.returncode != 0:
        return elapsed, result.stderr.strip().splitlines()[-1], None
    return elapsed, np.fromfile(out), json.loads(result.stdout)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=3, help="runs of the program and CVODE per point")
    parser.add_argument("--scipy-repeats", type=int, default=3, help="runs of SciPy per point")
    parser.add_argument("--quick", action="store_true", help="fewer tolerances")
    parser.add_argument("--binary", default=str(ROOT / "build" / "friction"))
    parser.add_argument("--limit", type=float, default=60.0,
                        help="seconds before a SciPy run or the program's integration is given up")
    parser.add_argument("--chart", help="draw the work-precision charts into this PNG")
    args = parser.parse_args()
    tolerances = [1e-5, 1e-7] if args.quick else [1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9]
    points = {}   # (case, method) -> [(error, seconds)]
    with tempfile.TemporaryDirectory() as scratch:
        work = Path(scratch)
        cvode, why_not = build_cvode(work)
        if why_not:
            print(f"CVODE rows skipped: {why_not}")
        for name, make in (("lugre", lugre_field), ("rate_state", rate_state_field)):
            _, _, t_end, sets = make()
            stepped = dict(sets, **{"machine.dense_output": ".false."})
            _, t, reference, _, _ = program_run(args.binary, work, name, 1e-12, stepped)
            scale = np.ptp(reference)
            print(f"\n{name}: {t.size} grid points to t = {t_end:g} s; error = max |x - x_ref| / range of x")
            print(f"{'method':10s} {'rtol':>8s} {'error':>10s} {'time (s)':>10s} {'steps':>8s} {'Jacobians':>9s}"
                  f" {'CVODE/this':>10s}")
            rows = []
            for rtol in tolerances:
                times = {"friction": [], "stepped": [], "CVODE": []}
                last = {}
                for _ in range(args.repeats):
                    for method, settings in (("friction", sets), ("stepped", stepped)):
                        seconds, _, x, steps, jacobians = program_run(args.binary, work, name, rtol, settings,
                                                                      min(args.limit, PROGRAM_LIMIT))
                        times[method].append(seconds)
                        last[method] = (x, steps, jacobians)
                    if cvode:
                        seconds, x, counts = cvode_run(cvode, work, name, rtol, float(t[1] - t[0]))
                        times["CVODE"].append(seconds)
                        last["CVODE"] = (x, counts)
                median = {method: statistics.median(v) for method, v in times.items() if v}
                for method in ("friction", "stepped"):
                    x, steps, jacobians = last[method]
                    if isinstance(x, str):
                        rows.append(f"{method:10s} {rtol:8.0e} {'failed':>10s} {median[method]:10.4f}  {x}")
                        continue
                    error = np.max(np.abs(x - reference)) / scale
                    points.setdefault((name, method), []).append((error, median[method]))
                    ratio = f"{median['CVODE'] / median[method]:10.2f}" if "CVODE" in median else ""
                    rows.append(f"{method:10s} {rtol:8.0e} {error:10.2e} {median[method]:10.4f} {steps:8d}"
                                f" {jacobians:9d} {ratio}")
                if cvode:
                    x, counts = last["CVODE"]
                    if isinstance(x, str) or x.size != t.size:
                        rows.append(f"{'CVODE':10s} {rtol:8.0e} {'failed':>10s} {median['CVODE']:10.4f}  "
                                    f"{x if isinstance(x, str) else ''}")
                    else:
                        error = np.max(np.abs(x - reference)) / scale
                        points.setdefault((name, "CVODE"), []).append((error, median["CVODE"]))
                        rows.append(f"{'CVODE':10s} {rtol:8.0e} {error:10.2e} {median['CVODE']:10.4f}"
                                    f" {counts['steps']:8d} {counts['jacobian_evaluations']:9d}")
            for key in ("friction", "stepped", "CVODE"):
                for row in rows:
                    if row.startswith(key):
                        print(row)
            for method in ("Radau", "LSODA"):
                for rtol in tolerances:
                    runs = [scipy_run(name, method, t, rtol, args.limit) for _ in range(args.scipy_repeats)]
                    seconds = statistics.median(run[0] for run in runs)
                    _, status, message, x = runs[-1]
                    if status != 0 or x is None or x.size != t.size:
                        print(f"{method:10s} {rtol:8.0e} {'failed':>10s} {seconds:10.4f}  {message}")
                        continue
                    error = np.max(np.abs(x - reference)) / scale
                    points.setdefault((name, method), []).append((error, seconds))
                    print(f"{method:10s} {rtol:8.0e} {error:10.2e} {seconds:10.4f}")
            sys.stdout.flush()
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
                              ("CVODE", "D-.")):
            data = sorted(points.get((name, method), []))
            if data:
                ax.loglog([e for e, _ in data], [s for _, s in data], style, label=method)
        ax.set_xlabel("error in x / range of x")
        ax.set_ylabel("time (s)")
        ax.set_title(title)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


if __name__ == "__main__":
    sys.exit(main())
