#!/usr/bin/env python3
"""Plot a Girling brake run written by `friction` (scene 'brake').

Reads one output file and writes two PNGs into the output directory
(default: the current directory, like `friction` itself):

  <stem>_phase.png  the phase plane (x, x') over a time window, as in the
                    paper's Fig. 12 (default window tau in [100, 1000]); stick
                    shows as the horizontal line x' = v'_dr, drawn in its own
                    colour from the file's stick flag, with the belt velocity
                    as a dashed line
  <stem>_x.png      x(tau) over the whole run, and over the last 30 units of
                    the window, stick stretches marked

Axes: x in m, x' in m per unit tau (the nondimensional time of Eq. 10,
tau = t sqrt(k1/m)).

Examples:
  plot_brake.py brake.h5
  plot_brake.py brake.h5 --window 0 3200 -o plots --dpi 200

Exit codes: 0 done, 1 a PNG could not be written, 2 bad command line or
bad input file (missing, not a brake run, window outside the run).
"""

import argparse
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # headless: no display needed

from friction_output import InputError, open_output, text  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def read_run(path):
    """Read the trajectory, events and parameters of a brake file into a dict."""
    with open_output(path, "brake", "brake") as f:
        brake = f["brake"]
        run = {name: brake[name][()] for name in ("t", "x", "v", "y", "w", "stick")}
        run["model"] = text(brake.attrs["model"])
        run["v_dr"] = float(brake.attrs["v_dr_prime"])
        run["method"] = text(f.attrs.get("method", b"?"))
        events = brake["events"]
        run["event_t"] = events["t"][()]
        run["event_kind"] = events["kind"][()]
    n = run["t"].size
    for name in ("x", "v", "y", "w", "stick"):
        if run[name].shape != (n,):
            raise InputError(f"/brake/{name} has shape {run[name].shape}, expected ({n},)")
    if n < 2:
        raise InputError("the run has fewer than two output points")
    return run


def _describe(run):
    return f"{run['model']} model ({run['method']}), $v'_{{dr}}$ = {run['v_dr']:g} m"


def plot_phase(run, window, out, dpi):
    """Phase plane (x, x') over the window; stick points in their own colour."""
    t0, t1 = window
    inside = (run["t"] >= t0) & (run["t"] <= t1)
    x, v, stick = run["x"][inside], run["v"][inside], run["stick"][inside] == 1
    fig, ax = plt.subplots(figsize=(8, 5.6), layout="constrained")
    ax.plot(x, v, "-", color="tab:blue", linewidth=0.6, label="slip and stick (trajectory)")
    if stick.any():
        ax.plot(x[stick], v[stick], ".", color="tab:red", markersize=2.5,
                label=f"stick: x' = v'$_{{dr}}$ ({stick.mean():.1%} of the points)")
    ax.axhline(run["v_dr"], color="0.4", linestyle="--", linewidth=0.8,
               label=f"belt velocity v'$_{{dr}}$ = {run['v_dr']:g}")
    ax.set_xlabel("x, block displacement (m)")
    ax.set_ylabel("x', block velocity (m per unit τ)")
    ax.set_title(f"Phase plane, τ ∈ [{t0:g}, {t1:g}] (paper Fig. 12)\n{_describe(run)}")
    ax.legend(loc="best", fontsize="small")
    fig.savefig(out, dpi=dpi)
    plt.close(fig)


def plot_x(run, window, out, dpi):
    """x(τ): the whole run above, the last 30 τ of the window below, where
    stick shows as straight stretches of slope v'_dr."""
    t, x, stick = run["t"], run["x"], run["stick"] == 1
    fig, (whole, zoom) = plt.subplots(2, 1, figsize=(11, 7), layout="constrained")
    zoom_from = max(window[0], window[1] - 30.0)
    for ax, (t0, t1) in ((whole, (t[0], t[-1])), (zoom, (zoom_from, window[1]))):
        inside = (t >= t0) & (t <= t1)
        ax.plot(t[inside], x[inside], "-", color="tab:blue", linewidth=0.6, label="x(τ)")
        part = inside & stick
        if part.any():
            ax.plot(t[part], x[part], ".", color="tab:red", markersize=1.5 if ax is whole else 3,
                    label="stick")
        ax.set_xlim(t0, t1)
        ax.set_ylabel("x, block displacement (m)")
    zoom.set_xlabel("τ = t √(k1/m)")
    whole.legend(loc="upper right", fontsize="small")
    n_events = run["event_t"].size
    whole.set_title(f"Block displacement, {_describe(run)}\n{n_events} stick/slip events, "
                    f"{stick.mean():.1%} of the points in stick; below: τ ∈ [{zoom_from:g}, {window[1]:g}]")
    fig.savefig(out, dpi=dpi)
    plt.close(fig)


def parse_args(argv):
    parser = argparse.ArgumentParser(
        prog="plot_brake.py",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("file", type=Path, help="friction output file (HDF5, scene 'brake')")
    parser.add_argument("--window", type=float, nargs=2, default=(100.0, 1000.0),
                        metavar=("T0", "T1"),
                        help="time window of the phase plane (default: 100 1000, as Fig. 12)")
    parser.add_argument("-o", "--output-dir", type=Path, default=Path("."), metavar="DIR",
                        help="directory for the PNGs, created if missing (default: .)")
    parser.add_argument("--dpi", type=int, default=150, help="resolution (default: %(default)s)")
    args = parser.parse_args(argv)
    if args.dpi <= 0:
        parser.error("--dpi must be positive")
    if not args.window[0] < args.window[1]:
        parser.error("--window T0 T1 needs T0 < T1")
    return args


def main(argv=None):
    args = parse_args(argv)
    prog = "plot_brake.py"
    try:
        run = read_run(args.file)
        t0, t1 = args.window
        inside = np.count_nonzero((run["t"] >= t0) & (run["t"] <= t1))
        if inside < 2:
            raise InputError(f"--window {t0:g} {t1:g} is outside the run "
                             f"(τ from {run['t'][0]:g} to {run['t'][-1]:g})")
    except InputError as err:
        print(f"{prog}: {args.file}: {err}", file=sys.stderr)
        return 2

    stem = args.file.stem
    phase = args.output_dir / f"{stem}_phase.png"
    xplot = args.output_dir / f"{stem}_x.png"
    try:
        args.output_dir.mkdir(parents=True, exist_ok=True)
        plot_phase(run, args.window, phase, args.dpi)
        print(f"wrote {phase}")
        plot_x(run, args.window, xplot, args.dpi)
        print(f"wrote {xplot}")
    except OSError as err:
        print(f"{prog}: cannot write into {args.output_dir}: {err}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
