#!/usr/bin/env python3
"""Plot a brake parameter sweep (`friction` with a &sweep group; README:
Parameter sweeps).

Writes into the output directory (default: the current directory):

  <stem>_bifurcation.png  the local maxima of x after the transient against
                          the swept parameter (a bifurcation diagram)
  <stem>_lyapunov.png     the Benettin exponent and the stick fraction
                          against the parameter

Failed points are marked by red lines; pending points (an interrupted sweep)
are left out.

Examples:
  plot_sweep.py brake_sweep.h5
  plot_sweep.py brake_sweep.h5 -o plots --dpi 200

Exit codes: 0 done, 1 a PNG could not be written, 2 bad command line or bad
input file (missing, not a sweep file).
"""

import argparse
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # headless: no display needed

from friction_output import InputError, open_output, text  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def read_sweep(path):
    """The per-point datasets of /sweep, checked for consistency."""
    with open_output(path, "sweep", "sweep") as f:
        g = f["sweep"]
        s = {key: g[key][()] for key in ("values", "maxima", "maxima_offset", "maxima_count",
                                         "lyapunov", "stick_fraction", "status")}
        s["variable"] = text(f.attrs["sweep_variable"])
    n = s["values"].size
    if any(s[key].size != n for key in ("maxima_offset", "maxima_count", "lyapunov", "status")):
        raise InputError("per-point datasets of different lengths")
    if s["maxima_count"].sum() != s["maxima"].size:
        raise InputError("maxima_count does not add up to the maxima")
    return s


def plot(s, stem, outdir, dpi):
    done = s["status"] == 1
    failed = s["status"] == 2
    fig, ax = plt.subplots(figsize=(7, 4.5))
    parameter = np.repeat(s["values"], s["maxima_count"])
    ax.plot(parameter, s["maxima"], ",k", alpha=0.6)
    for k, value in enumerate(s["values"][failed]):
        ax.axvline(value, color="r", lw=0.8, alpha=0.5, label="failed" if k == 0 else None)
    ax.set_xlabel(s["variable"])
    ax.set_ylabel("local maxima of x after the transient (m)")
    ax.set_title("bifurcation diagram")
    if failed.any():
        ax.legend()
    fig.tight_layout()
    fig.savefig(outdir / f"{stem}_bifurcation.png", dpi=dpi)
    plt.close(fig)

    fig, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(7, 6))
    top.axhline(0.0, color="0.6", lw=0.8)
    top.plot(s["values"][done], s["lyapunov"][done], "o-", ms=3)
    top.set_ylabel("Benettin exponent (1/τ)")
    bottom.plot(s["values"][done], s["stick_fraction"][done], "o-", ms=3, color="C1")
    bottom.set_ylabel("stick fraction")
    bottom.set_xlabel(s["variable"])
    fig.tight_layout()
    fig.savefig(outdir / f"{stem}_lyapunov.png", dpi=dpi)
    plt.close(fig)


def main():
    parser = argparse.ArgumentParser(description="Plot a brake parameter sweep (bifurcation diagram, exponent).")
    parser.add_argument("file", type=Path, help="friction sweep output (.h5)")
    parser.add_argument("-o", "--output-dir", type=Path, default=Path("."), help="directory for the PNGs")
    parser.add_argument("--dpi", type=int, default=150)
    args = parser.parse_args()
    try:
        s = read_sweep(args.file)
    except InputError as err:
        print(f"plot_sweep.py: {args.file}: {err}", file=sys.stderr)
        return 2
    try:
        args.output_dir.mkdir(parents=True, exist_ok=True)
        plot(s, args.file.stem, args.output_dir, args.dpi)
    except OSError as err:
        print(f"plot_sweep.py: cannot write the PNGs: {err}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
