"""Plot the chaos diagnostics of a Girling brake run (`friction` with an
&analysis group; docs/physics.md, Chaos diagnostics).

Reads one output file and writes into the output directory (default: the
current directory, like `friction` itself) the PNGs of what the file holds:

  <stem>_spectrum.png  the amplitude spectrum of the analysed variable over
                       its window, as the paper's Fig. 13, with the peak
                       frequency and the bin width (the resolution)
  <stem>_poincare.png  the stroboscopic map (x, x') at the strobe period, as
                       the paper's Fig. 14, beside the true section (x, y)
  <stem>_lyapunov.png  the running Benettin estimate (from the equations)
                       and the Rosenstein divergence curve with its fit range
                       and slope (from the series)
  <stem>_floquet.png   the periodic orbit's Floquet multipliers and the
                       unit circle (&analysis orbit)
  <stem>_bifurcation.png  along a continuation line: the attractor's slip
                       onsets, the followed orbit (stable solid, unstable
                       dashed), the detected bifurcations annotated, and the
                       largest |multiplier| (&analysis continuation)

Frequencies in cycles per unit tau, exponents in 1/tau (natural log).

Examples:
  plot_chaos.py brake.h5
  plot_chaos.py brake.h5 -o plots --dpi 200

Exit codes: 0 done, 1 a PNG could not be written, 2 bad command line or
bad input file (missing, not a brake run, no diagnostics in it).

A command line over friction.plot.brake_spectrum, friction.plot.poincare,
friction.plot.lyapunov, friction.plot.floquet and friction.plot.orbit_branch
(python/friction/plot.py); installed with the package as the command
friction-plot-chaos.
"""

import argparse
import sys
from pathlib import Path


import friction
from friction.commands import save_figures
import friction.plot

# As the user typed it: plot_chaos.py (scripts/ in the repository) or friction-plot-chaos
# (the console command the package installs).
PROG = Path(sys.argv[0]).name if sys.argv and sys.argv[0].endswith("friction-plot-chaos") else "plot_chaos.py"
# (PNG name, the group it needs, the function drawing it)
PLOTS = (("spectrum", "brake/spectrum", friction.plot.brake_spectrum),
         ("poincare", "brake/poincare", friction.plot.poincare),
         ("lyapunov", "brake/lyapunov", friction.plot.lyapunov),
         ("floquet", "brake/orbit", friction.plot.floquet),
         ("bifurcation", "brake/orbit/branch", friction.plot.orbit_branch))


def parse_args(argv):
    parser = argparse.ArgumentParser(
        prog=PROG,
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("file", type=Path, help="friction output file (HDF5, scene 'brake', &analysis on)")
    parser.add_argument("-o", "--output-dir", type=Path, default=Path("."), metavar="DIR",
                        help="directory for the PNGs, created if missing (default: .)")
    parser.add_argument("--dpi", type=int, default=150, help="resolution (default: %(default)s)")
    args = parser.parse_args(argv)
    if args.dpi <= 0:
        parser.error("--dpi must be positive")
    return args


def main(argv=None):
    args = parse_args(argv)
    try:
        data = friction.load(args.file, scene="brake")
        present = [(name, draw) for name, group, draw in PLOTS if group in friction.groups(data)]
        if not present:
            raise friction.FileError("no chaos diagnostics in the file (run friction with an &analysis group)")
        figures = {name: draw(data) for name, draw in present}
    except friction.FileError as err:
        print(f"{PROG}: {args.file}: {err}", file=sys.stderr)
        return 2
    return save_figures(PROG, figures, args.output_dir, args.file.stem, args.dpi)


if __name__ == "__main__":
    sys.exit(main())
