#!/usr/bin/env python3
"""Plot a parameter sweep (`friction` with a &sweep group; docs/sweeps.md).

Writes into the output directory (default: the current directory), for a
brake sweep:

  <stem>_bifurcation.png  the local maxima of x after the transient against
                          the swept parameter (a bifurcation diagram)
  <stem>_lyapunov.png     the Benettin exponent and the stick fraction
                          against the parameter

and for an AFM sweep:

  <stem>_friction.png     the mean friction and the maximum lateral force
                          against the parameter

With a second swept variable, each of its values is a line (a colour) of its
own.  Failed points are marked by red lines; pending points (an interrupted
sweep) are left out.

Examples:
  plot_sweep.py brake_sweep.h5
  plot_sweep.py brake_sweep.h5 -o plots --dpi 200
  plot_sweep.py afm_sweep.h5

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
        s = {"scene": text(f.attrs["sweep_scene"]) if "sweep_scene" in f.attrs else "brake",
             "variable": text(f.attrs["sweep_variable"])}
        keys = ["values", "status"]
        if s["scene"] == "brake":
            keys += ["maxima", "maxima_offset", "maxima_count", "lyapunov", "stick_fraction"]
        else:
            keys += ["mean_friction", "max_force"]
        missing = [key for key in keys if key not in g]
        if missing:
            raise InputError("/sweep lacks " + ", ".join(missing))
        s.update({key: g[key][()] for key in keys})
        if "sweep_variable2" in f.attrs:
            s["variable2"] = text(f.attrs["sweep_variable2"])
            s["values2"] = g["values2"][()]
    n = s["values"].size
    if any(s[key].size != n for key in keys if key != "maxima"):
        raise InputError("per-point datasets of different lengths")
    if s["scene"] == "brake" and s["maxima_count"].sum() != s["maxima"].size:
        raise InputError("maxima_count does not add up to the maxima")
    return s


def series(s):
    """(label, mask) per value of the second variable; one series without."""
    if "values2" not in s:
        return [(None, np.ones(s["values"].size, bool))]
    return [(f"{s['variable2']} = {value:g}", s["values2"] == value) for value in np.unique(s["values2"])]


def mark_failed(ax, s):
    failed = s["status"] == 2
    for k, value in enumerate(np.unique(s["values"][failed])):
        ax.axvline(value, color="r", lw=0.8, alpha=0.5, label="failed" if k == 0 else None)


def log_scale(values):
    """A log axis for positive values spread over more than a decade."""
    values = values[np.isfinite(values)]
    return values.size > 1 and values.min() > 0 and values.max() / values.min() > 10


def plot_brake(s, stem, outdir, dpi):
    done = s["status"] == 1
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for k, (label, mask) in enumerate(series(s)):
        counts = np.where(mask, s["maxima_count"], 0)
        keep = np.repeat(mask, s["maxima_count"])
        parameter = np.repeat(s["values"], counts)
        ax.plot(parameter, s["maxima"][keep], ",", color="k" if label is None else f"C{k}", alpha=0.6)
        if label is not None:
            ax.plot([], [], "o", color=f"C{k}", label=label)
    mark_failed(ax, s)
    ax.set_xlabel(s["variable"])
    ax.set_ylabel("local maxima of x after the transient (m)")
    ax.set_title("bifurcation diagram")
    if ax.get_legend_handles_labels()[0]:
        ax.legend()
    fig.tight_layout()
    fig.savefig(outdir / f"{stem}_bifurcation.png", dpi=dpi)
    plt.close(fig)

    fig, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(7, 6))
    top.axhline(0.0, color="0.6", lw=0.8)
    for k, (label, mask) in enumerate(series(s)):
        keep = done & mask
        top.plot(s["values"][keep], s["lyapunov"][keep], "o-", ms=3, color=f"C{k}", label=label)
        bottom.plot(s["values"][keep], s["stick_fraction"][keep], "o-", ms=3, color=f"C{k}")
    top.set_ylabel("Benettin exponent (1/τ)")
    bottom.set_ylabel("stick fraction")
    bottom.set_xlabel(s["variable"])
    if "values2" in s:
        top.legend(fontsize="small")
    fig.tight_layout()
    fig.savefig(outdir / f"{stem}_lyapunov.png", dpi=dpi)
    plt.close(fig)


def plot_afm(s, stem, outdir, dpi):
    done = s["status"] == 1
    fig, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(7, 6.5))
    for k, (label, mask) in enumerate(series(s)):
        keep = done & mask
        top.plot(s["values"][keep], s["mean_friction"][keep], "o-", ms=3, color=f"C{k}", label=label)
        bottom.plot(s["values"][keep], s["max_force"][keep], "o-", ms=3, color=f"C{k}")
    for ax in (top, bottom):
        mark_failed(ax, s)
    if log_scale(s["values"]):
        bottom.set_xscale("log")
    if log_scale(s["mean_friction"][done]):
        top.set_yscale("log")
    top.set_ylabel("mean friction (nN)")
    top.set_title("half the width of the friction loop, over the map")
    bottom.set_ylabel("maximum lateral force (nN)")
    bottom.set_xlabel(s["variable"])
    if top.get_legend_handles_labels()[0]:
        top.legend(fontsize="small")
    fig.tight_layout()
    fig.savefig(outdir / f"{stem}_friction.png", dpi=dpi)
    plt.close(fig)


def main():
    parser = argparse.ArgumentParser(description="Plot a parameter sweep (brake: bifurcation diagram, exponent; "
                                     "AFM: friction and maximum force).")
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
        (plot_brake if s["scene"] == "brake" else plot_afm)(s, args.file.stem, args.output_dir, args.dpi)
    except OSError as err:
        print(f"plot_sweep.py: cannot write the PNGs: {err}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
