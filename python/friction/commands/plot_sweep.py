"""Plot a parameter sweep (`friction` with a &sweep group; docs/sweeps.md).

Writes into the output directory (default: the current directory), for a
brake sweep:

  <stem>_bifurcation.png  the local maxima of x after the transient against
                          the swept parameter (a bifurcation diagram)
  <stem>_lyapunov.png     the Benettin exponent and the stick fraction
                          against the parameter
  <stem>_atlas.png        with a second variable: maps of the exponent and
                          the stick fraction over the grid (then only this
                          one when the second variable has more than 8 values)

for an AFM sweep:

  <stem>_friction.png     the mean friction and the maximum lateral force
                          against the parameter

and for a machine sweep (&job scene = 'machine'):

  <stem>_bifurcation.png  the local maxima of x over the second half of each
                          run against the parameter
  <stem>_machine.png      the mean friction force and the stick fraction;
                          the stick/slip events, Benettin's exponent and the
                          periodic orbit's period and largest multiplier |mu|
                          when the sweep has them

With a second swept variable, each of its values is a line (a colour) of its
own.  Failed points are marked by red lines; pending points (an interrupted
sweep) are left out.

Examples:
  plot_sweep.py brake_sweep.h5
  plot_sweep.py brake_sweep.h5 -o plots --dpi 200
  plot_sweep.py afm_sweep.h5
  plot_sweep.py machine_orbit_sweep.h5

Exit codes: 0 done, 1 a PNG could not be written, 2 bad command line or bad
input file (missing, not a sweep file).

A command line over friction.plot.sweep (python/friction/plot.py); installed with the package as the command
friction-plot-sweep.
"""

import argparse
import sys
from pathlib import Path


import friction
import friction.plot

# As the user typed it: plot_sweep.py (scripts/ in the repository) or friction-plot-sweep
# (the console command the package installs).
PROG = Path(sys.argv[0]).name if sys.argv and sys.argv[0].endswith("friction-plot-sweep") else "plot_sweep.py"


def main(argv=None):
    parser = argparse.ArgumentParser(description="Plot a parameter sweep (brake: bifurcation diagram, exponent; "
                                     "AFM: friction and maximum force; machine: maxima, friction force, "
                                     "stick fraction, events, orbit).")
    parser.add_argument("file", type=Path, help="friction sweep output (.h5)")
    parser.add_argument("-o", "--output-dir", type=Path, default=Path("."), help="directory for the PNGs")
    parser.add_argument("--dpi", type=int, default=150)
    args = parser.parse_args(argv)
    try:
        figures = friction.plot.sweep(args.file)
    except friction.FileError as err:
        print(f"{PROG}: {args.file}: {err}", file=sys.stderr)
        return 2
    try:
        args.output_dir.mkdir(parents=True, exist_ok=True)
        for name, figure in figures.items():
            figure.savefig(args.output_dir / f"{args.file.stem}_{name}.png", dpi=args.dpi)
    except OSError as err:
        print(f"{PROG}: cannot write the PNGs: {err}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
