#!/usr/bin/env python3
"""Friction against temperature, NaF at 0.1 Å/s (docs/physics.md, friction
at a temperature): runs `friction` on inputs/naf_thermal_temperature.nml at
each temperature of TEMPERATURES with the thermal reduced model (at 0 K the
quasistatic tip); writes the mean friction with its standard error per point
to <out>/thermal_temperature.csv and draws <out>/thermal_temperature.png
with friction.plot.friction_temperature (the law F = F_c - C T^(2/3) of
thermally activated slips fitted through the points below 300 K).

Examples:
  thermal_temperature.py --binary build/friction
  thermal_temperature.py --binary build/friction --ranks 2 -o docs

Exit codes: 0 done, 1 a run failed or the PNG could not be written, 2 bad
command line.
"""

import argparse
import csv
import os
import subprocess
import sys
import tempfile
from pathlib import Path

_PACKAGE = Path(__file__).resolve().parent.parent / "python"
if _PACKAGE.is_dir():
    sys.path.insert(0, str(_PACKAGE))
sys.path.insert(0, str(Path(__file__).resolve().parent))
from thermal_velocity import run_point  # noqa: E402

#: K: 0 (the quasistatic tip), the range where the slips are thermally
#: activated forward jumps, and above 300 K, where jumps back set in.
TEMPERATURES = (0.0, 25.0, 50.0, 100.0, 150.0, 200.0, 250.0, 300.0, 350.0, 400.0, 450.0, 500.0, 600.0)


def run_sweep(binary, inputs, ranks, workdir, mpiexec="mpiexec"):
    """Every temperature of TEMPERATURES: a list of dicts (temperature in
    K, friction and its standard error in nN, wall seconds)."""
    base = os.path.join(inputs, "naf_thermal_temperature.nml")
    rows = []
    for temperature in TEMPERATURES:
        override = f"&thermal temperature = {temperature!r} /\n"
        if temperature == 0.0:
            override += "&tip model = 'quasistatic' /\n"
        friction, sem, seconds = run_point(binary, [base], override, f"t_{temperature:g}", ranks, workdir, mpiexec)
        rows.append({"temperature": temperature, "friction": friction, "sem": sem, "seconds": seconds})
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--binary", required=True, help="the friction program")
    parser.add_argument("--inputs", default=str(Path(__file__).resolve().parent.parent / "inputs"))
    parser.add_argument("--ranks", type=int, default=2)
    parser.add_argument("--mpiexec", default="mpiexec")
    parser.add_argument("-o", "--output", default=".", help="directory for the CSV and the PNG")
    parser.add_argument("--dpi", type=int, default=120)
    args = parser.parse_args()
    from friction import plot
    os.makedirs(args.output, exist_ok=True)
    try:
        with tempfile.TemporaryDirectory() as workdir:
            rows = run_sweep(args.binary, args.inputs, args.ranks, workdir, args.mpiexec)
    except subprocess.CalledProcessError as exc:
        print(f"thermal_temperature.py: a run failed: {exc}", file=sys.stderr)
        return 1
    with open(os.path.join(args.output, "thermal_temperature.csv"), "w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    for row in rows:
        print(f"T = {row['temperature']:5g} K: friction {row['friction']:.4f} +- {row['sem']:.4f} nN "
              f"({row['seconds']:.1f} s)")
    fc, c, alpha, alpha_se = plot.temperature_fit(rows)
    print(f"F = F_c - C T^(2/3) below 300 K: F_c = {fc:.4f} nN, C = {c:.5f} nN/K^(2/3); "
          f"free exponent {alpha:.3f} +- {alpha_se:.3f}")
    fig = plot.friction_temperature(rows)
    try:
        fig.savefig(os.path.join(args.output, "thermal_temperature.png"), dpi=args.dpi)
    except OSError as exc:
        print(f"thermal_temperature.py: {exc}", file=sys.stderr)
        return 1
    print(f"total {sum(r['seconds'] for r in rows):.1f} s on {args.ranks} rank(s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
