"""Plot a Girling brake run written by `friction` (scene 'brake').

Reads one output file and writes two PNGs into the output directory
(default: the current directory, like `friction` itself):

  <stem>_phase.png  the phase plane (x, x') over a time window, as in the
                    paper's Fig. 12 (default: the run's second half, after the
                    transient; the paper's window is --window 100 1000); stick
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

A command line over friction.plot.brake_phase and friction.plot.brake_x
(python/friction/plot.py); installed with the package as the command
friction-plot-brake.
"""

import argparse
import sys
from pathlib import Path


import friction
from friction.commands import save_figures
import friction.plot

# As the user typed it: plot_brake.py (scripts/ in the repository) or friction-plot-brake
# (the console command the package installs).
PROG = Path(sys.argv[0]).name if sys.argv and sys.argv[0].endswith("friction-plot-brake") else "plot_brake.py"


def parse_args(argv):
    parser = argparse.ArgumentParser(
        prog=PROG,
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("file", type=Path, help="friction output file (HDF5, scene 'brake')")
    parser.add_argument("--window", type=float, nargs=2, default=None,
                        metavar=("T0", "T1"),
                        help="time window of the phase plane (default: the run's second half, after the "
                             "transient; 100 1000 is the paper's Fig. 12)")
    parser.add_argument("-o", "--output-dir", type=Path, default=Path("."), metavar="DIR",
                        help="directory for the PNGs, created if missing (default: .)")
    parser.add_argument("--dpi", type=int, default=150, help="resolution (default: %(default)s)")
    args = parser.parse_args(argv)
    if args.dpi <= 0:
        parser.error("--dpi must be positive")
    if args.window is not None and not args.window[0] < args.window[1]:
        parser.error("--window T0 T1 needs T0 < T1")
    return args


def main(argv=None):
    args = parse_args(argv)
    try:
        data = friction.load(args.file, scene="brake")
        figures = {"phase": friction.plot.brake_phase(data, args.window),
                   "x": friction.plot.brake_x(data, args.window)}
    except friction.FileError as err:
        print(f"{PROG}: {args.file}: {err}", file=sys.stderr)
        return 2
    except ValueError as err:  # the window: the plots name it "window T0 T1"
        print(f"{PROG}: {args.file}: --{err}", file=sys.stderr)
        return 2

    return save_figures(PROG, figures, args.output_dir, args.file.stem, args.dpi)


if __name__ == "__main__":
    sys.exit(main())
