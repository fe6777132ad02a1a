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

A command line over friction.plot.afm_maps and friction.plot.friction_loop
(python/friction/plot.py); installed with the package as the command
friction-plot-afm.
"""

import argparse
import sys
from pathlib import Path


import friction
import friction.plot
from matplotlib import colormaps

# As the user typed it: plot_afm.py (scripts/ in the repository) or friction-plot-afm
# (the console command the package installs).
PROG = Path(sys.argv[0]).name if sys.argv and sys.argv[0].endswith("friction-plot-afm") else "plot_afm.py"


def parse_args(argv):
    parser = argparse.ArgumentParser(
        prog=PROG,
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
    if args.cmap not in colormaps:
        parser.error(f"--cmap {args.cmap!r}: no such matplotlib colour map")
    return args


def main(argv=None):
    args = parse_args(argv)
    try:
        data = friction.load(args.file, scene="afm")
        ny = data["afm/support_y"].size
        line = ny // 2 if args.line is None else args.line
        if not 0 <= line < ny:
            raise friction.FileError(f"--line {line} out of range: the file has lines 0 .. {ny - 1}")
        if f"afm/{args.trip}/fx" not in friction.paths(data):
            raise friction.FileError(f"no /afm/{args.trip}: the run had retrace off")
        maps_figure = friction.plot.afm_maps(data, args.trip, args.cmap)
        has_loop = "afm/retrace/f_along" in friction.paths(data) and "afm/friction" in friction.paths(data)
        loop_figure = friction.plot.friction_loop(data, line) if has_loop else None
    except friction.FileError as err:
        print(f"{PROG}: {args.file}: {err}", file=sys.stderr)
        return 2

    stem = args.file.stem
    maps = args.output_dir / f"{stem}_maps.png"
    loop = args.output_dir / f"{stem}_loop.png"
    try:
        args.output_dir.mkdir(parents=True, exist_ok=True)
        maps_figure.savefig(maps, dpi=args.dpi)
        print(f"wrote {maps}")
        if loop_figure is not None:
            loop_figure.savefig(loop, dpi=args.dpi)
            print(f"wrote {loop}")
        else:
            print(f"{PROG}: {args.file}: no retrace in this file (run had retrace = .false.), "
                  f"friction loop skipped", file=sys.stderr)
    except OSError as err:
        print(f"{PROG}: cannot write into {args.output_dir}: {err}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
