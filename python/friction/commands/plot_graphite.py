"""Plot a lattice-sum friction map written by `friction` (e.g. inputs/graphite.nml).

Reads one output file of an AFM scene with a crystal net (group /surface,
potential 'lj') and writes two PNGs into the output directory (default: the
current directory, like `friction` itself):

  <stem>_net.png    the crystal net as in the paper's Fig. 9a: atoms as dots
                    coloured by species, bonds (pairs closer than 1.2 x the
                    nearest-neighbour distance) as thin lines, the scan region
                    (the parallelogram the support covers) and the path of the
                    tip on one trace line (line 0 by default); zoomed to the
                    scan region plus --margin angstrom, or --whole for the net
  <stem>_lines.png  the scan lines stacked as in Fig. 9b: one force component
                    (Fx by default) of the trace trip (--trip retrace for the
                    other one) against the support position along the scan,
                    line j shifted up by j x the offset, labelled with its
                    offset across the scan

Positions are in angstrom in the lattice frame, forces in nN.  Lines are
counted from 0, as in /afm/support_y.  Files of the other AFM scenes (NaF,
HOPG: no /surface/atoms) are refused; plot those with plot_afm.py.

Examples:
  plot_graphite.py graphite.h5
  plot_graphite.py graphite.h5 --component f_along --trip retrace -o plots
  plot_graphite.py graphite.h5 --whole --no-tip --dpi 200

Exit codes: 0 done, 1 a PNG could not be written, 2 bad command line or
bad input file (missing, not a friction map, no crystal net, no such trip).

A command line over friction.plot.graphite_net and friction.plot.stacked_lines
(python/friction/plot.py); installed with the package as the command
friction-plot-graphite.
"""

import argparse
import sys
from pathlib import Path


import friction
import friction.plot
import numpy as np

# As the user typed it: plot_graphite.py (scripts/ in the repository) or friction-plot-graphite
# (the console command the package installs).
PROG = Path(sys.argv[0]).name if sys.argv and sys.argv[0].endswith("friction-plot-graphite") else "plot_graphite.py"


def parse_args(argv):
    parser = argparse.ArgumentParser(
        prog=PROG,
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("file", type=Path,
                        help="friction output file (HDF5, scene 'afm' with /surface)")
    parser.add_argument("--trip", choices=("trace", "retrace"), default="trace",
                        help="trip of the stacked lines (default: %(default)s)")
    parser.add_argument("--component", choices=tuple(friction.plot.COMPONENTS), default="fx",
                        help="force component of the stacked lines (default: %(default)s)")
    parser.add_argument("--offset", type=float, default=None, metavar="NN",
                        help="vertical shift between stacked lines, nN "
                             "(default: 1.2 x the largest peak-to-peak of the lines)")
    parser.add_argument("--margin", type=float, default=5.0, metavar="A",
                        help="net view: margin around the scan region, angstrom "
                             "(default: %(default)s)")
    parser.add_argument("--whole", action="store_true",
                        help="net view: show the whole net instead of the scan region")
    parser.add_argument("--tip-line", type=int, default=0, metavar="N",
                        help="net view: the trace line whose tip path is drawn, "
                             "0 .. ny-1 (default: %(default)s)")
    parser.add_argument("--no-tip", action="store_true",
                        help="net view: do not draw the tip path")
    parser.add_argument("-o", "--output-dir", type=Path, default=Path("."), metavar="DIR",
                        help="directory for the PNGs, created if missing (default: .)")
    parser.add_argument("--dpi", type=int, default=150, help="resolution (default: %(default)s)")
    args = parser.parse_args(argv)
    if args.dpi <= 0:
        parser.error("--dpi must be positive")
    if args.margin < 0 or not np.isfinite(args.margin):
        parser.error("--margin must be zero or positive")
    if args.offset is not None and not (args.offset > 0 and np.isfinite(args.offset)):
        parser.error("--offset must be positive")
    return args


def main(argv=None):
    args = parse_args(argv)
    try:
        data = friction.load(args.file, scene="afm")
        if "surface/atoms" not in friction.paths(data):
            raise friction.FileError("not a lattice-sum scene: no /surface/atoms "
                                     "(for NaF/HOPG maps use plot_afm.py)")
        ny = data["afm/support_y"].size
        if f"afm/{args.trip}/fx" not in friction.paths(data):
            raise friction.FileError(f"no /afm/{args.trip}: the run had retrace off")
        if f"afm/{args.trip}/{args.component}" not in friction.paths(data):
            raise friction.FileError(f"no /afm/{args.trip}/{args.component} in the file")
        tip_line = None if args.no_tip else args.tip_line
        if tip_line is not None and not 0 <= tip_line < ny:
            raise friction.FileError(f"--tip-line {tip_line} out of range: the file has lines 0 .. {ny - 1}")
        net_figure = friction.plot.graphite_net(data, args.margin, args.whole, tip_line)
        lines_figure = friction.plot.stacked_lines(data, args.trip, args.component, args.offset)
    except friction.FileError as err:
        print(f"{PROG}: {args.file}: {err}", file=sys.stderr)
        return 2

    net = args.output_dir / f"{args.file.stem}_net.png"
    lines = args.output_dir / f"{args.file.stem}_lines.png"
    try:
        args.output_dir.mkdir(parents=True, exist_ok=True)
        net_figure.savefig(net, dpi=args.dpi)
        print(f"wrote {net}")
        lines_figure.savefig(lines, dpi=args.dpi)
        print(f"wrote {lines}")
    except OSError as err:
        print(f"{PROG}: cannot write into {args.output_dir}: {err}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
