#!/usr/bin/env python3
"""Plot a friction-force map written by `friction` (scene 'afm').

Reads one output file and writes two PNGs into the output directory
(default: the current directory, like `friction` itself):

  <stem>_maps.png  the lateral force maps Fx and Fy side by side over the
                   scanned area (as in the paper's Fig. 7b/8b); the trace
                   trip by default, --trip retrace for the other one
  <stem>_loop.png  the friction loop of one scan line: f_along on trace and
                   retrace against the support position, with the line's
                   friction from /afm/friction; skipped, with a note, when
                   the run had retrace off

Map axes are the support position along the scan (support_x) and across it
(support_y), both in angstrom; Fx and Fy are along the lattice x and y axes.
Lines are counted from 0, as in /afm/support_y.

Examples:
  plot_afm.py naf.h5
  plot_afm.py naf.h5 --trip retrace --line 0 -o plots --dpi 200

Exit codes: 0 done, 1 a PNG could not be written, 2 bad command line or
bad input file (missing, not a friction map, line out of range).
"""

import argparse
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # headless: no display needed

from friction_output import InputError, open_output, text  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

POTENTIAL_LABELS = {"naf": "NaF(001)", "hopg": "HOPG"}


def read_scan(path):
    """Read the map and its axes from a friction output file into a dict."""
    with open_output(path, "afm", "force-map") as f:
        afm = f["afm"]
        scan = {
            "potential": text(afm.attrs["potential"]),
            "angle": float(afm.attrs["angle"]),
            "x": afm["support_x"][()],
            "y": afm["support_y"][()],
            "friction": afm["friction"][()] if "friction" in afm else None,
        }
        for trip in ("trace", "retrace"):
            if trip in afm:
                scan[trip] = {q: afm[trip][q][()] for q in ("fx", "fy", "f_along")}
    if "trace" not in scan:
        raise InputError("no /afm/trace group")
    shape = (scan["y"].size, scan["x"].size)
    for trip in ("trace", "retrace"):
        for name, values in scan.get(trip, {}).items():
            if values.shape != shape:
                raise InputError(f"/afm/{trip}/{name} has shape {values.shape}, "
                                 f"expected (ny, nx) = {shape}")
    return scan


def _pixel_extent(x, y):
    """imshow extent with pixel centres on the support positions (Å)."""
    dx = (x[-1] - x[0]) / (x.size - 1) if x.size > 1 else 1.0
    dy = (y[-1] - y[0]) / (y.size - 1) if y.size > 1 else dx
    return [x[0] - dx / 2, x[-1] + dx / 2, y[0] - dy / 2, y[-1] + dy / 2]


def _describe(scan):
    name = POTENTIAL_LABELS.get(scan["potential"], scan["potential"])
    return f"{name}, scan angle {scan['angle']:g}°"


def plot_maps(scan, trip, out, dpi, cmap):
    """Fx and Fy maps side by side; colour scale symmetric about 0 nN."""
    extent = _pixel_extent(scan["x"], scan["y"])
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.8), layout="constrained")
    for ax, key, label in zip(axes, ("fx", "fy"), ("$F_x$", "$F_y$")):
        values = scan[trip][key]
        finite = np.abs(values[np.isfinite(values)])
        limit = float(finite.max()) if finite.size and finite.max() > 0 else 1.0
        image = ax.imshow(values, origin="lower", extent=extent, aspect="equal",
                          interpolation="nearest", cmap=cmap, vmin=-limit, vmax=limit)
        ax.set_title(f"{label} (lattice {key[1]} axis)")
        ax.set_xlabel("support position along the scan (Å)")
        ax.set_ylabel("line offset across the scan (Å)")
        fig.colorbar(image, ax=ax, shrink=0.9, label=f"{label} (nN)")
    fig.suptitle(f"Lateral force maps, {trip}: {_describe(scan)}")
    fig.savefig(out, dpi=dpi)
    plt.close(fig)


def plot_loop(scan, line, out, dpi):
    """Trace and retrace f_along of one line: the friction loop."""
    x = scan["x"]
    trace = scan["trace"]["f_along"][line]
    retrace = scan["retrace"]["f_along"][line]
    friction = scan["friction"][line]
    fig, ax = plt.subplots(figsize=(8, 4.8), layout="constrained")
    ax.fill_between(x, retrace, trace, color="0.88", label="loop")
    ax.plot(x, trace, "-", color="tab:red", label="trace (→)")
    ax.plot(x, retrace, "-", color="tab:blue", label="retrace (←)")
    ax.axhline(0.0, color="0.5", linewidth=0.6)
    ax.set_xlabel("support position along the scan (Å)")
    ax.set_ylabel("$F_\\parallel$, force along the scan (nN)")
    ax.set_xlim(x[0], x[-1])
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small")
    ax.set_title(f"Friction loop, line {line} (offset {scan['y'][line]:.3g} Å), "
                 f"{_describe(scan)}\nfriction = {friction:.4g} nN")
    fig.savefig(out, dpi=dpi)
    plt.close(fig)


def parse_args(argv):
    parser = argparse.ArgumentParser(
        prog="plot_afm.py",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("file", type=Path, help="friction output file (HDF5, scene 'afm')")
    parser.add_argument("--trip", choices=("trace", "retrace"), default="trace",
                        help="trip shown in the force maps (default: %(default)s)")
    parser.add_argument("--line", type=int, default=None, metavar="N",
                        help="scan line of the friction loop, 0 .. ny-1 (default: ny // 2)")
    parser.add_argument("-o", "--output-dir", type=Path, default=Path("."), metavar="DIR",
                        help="directory for the PNGs, created if missing (default: .)")
    parser.add_argument("--dpi", type=int, default=150, help="resolution (default: %(default)s)")
    parser.add_argument("--cmap", default="RdBu_r",
                        help="matplotlib colour map of the force maps (default: %(default)s)")
    args = parser.parse_args(argv)
    if args.dpi <= 0:
        parser.error("--dpi must be positive")
    if args.cmap not in matplotlib.colormaps:
        parser.error(f"--cmap {args.cmap!r}: no such matplotlib colour map")
    return args


def main(argv=None):
    args = parse_args(argv)
    prog = "plot_afm.py"
    try:
        scan = read_scan(args.file)
        ny = scan["y"].size
        line = ny // 2 if args.line is None else args.line
        if not 0 <= line < ny:
            raise InputError(f"--line {line} out of range: the file has lines 0 .. {ny - 1}")
        if args.trip not in scan:
            raise InputError(f"no /afm/{args.trip}: the run had retrace off")
    except InputError as err:
        print(f"{prog}: {args.file}: {err}", file=sys.stderr)
        return 2

    stem = args.file.stem
    maps = args.output_dir / f"{stem}_maps.png"
    loop = args.output_dir / f"{stem}_loop.png"
    try:
        args.output_dir.mkdir(parents=True, exist_ok=True)
        plot_maps(scan, args.trip, maps, args.dpi, args.cmap)
        print(f"wrote {maps}")
        if "retrace" in scan and scan["friction"] is not None:
            plot_loop(scan, line, loop, args.dpi)
            print(f"wrote {loop}")
        else:
            print(f"{prog}: {args.file}: no retrace in this file (run had retrace = .false.), "
                  f"friction loop skipped", file=sys.stderr)
    except OSError as err:
        print(f"{prog}: cannot write into {args.output_dir}: {err}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
