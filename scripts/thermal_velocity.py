#!/usr/bin/env python3
"""The friction-velocity curve of NaF at 300 K (docs/physics.md, the thermal
reduced model): runs `friction` on inputs/naf_thermal_velocity.nml at each
support velocity, with the Langevin tip at the fast end and the thermal
reduced model (&thermal model = 'kramers') at the slow end, overlapping in
the middle; writes the mean friction with its standard error per point to
<out>/thermal_velocity.csv and draws <out>/thermal_velocity.png with
friction.plot.friction_velocity (Sang, Dubé and Grant's law fitted through
the reduced model's points).

Examples:
  thermal_velocity.py --binary build/friction
  thermal_velocity.py --binary build/friction --ranks 2 -o docs

Exit codes: 0 done, 1 a run failed or the PNG could not be written, 2 bad
command line.
"""

import argparse
import csv
import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

_PACKAGE = Path(__file__).resolve().parent.parent / "python"
if _PACKAGE.is_dir():
    sys.path.insert(0, str(_PACKAGE))

#: The points: the reduced model from 1e-4 Å/s (slower, jumps back set in
#: and the friction falls to zero) to 30 Å/s (faster, its jumps reach its
#: 1 k_B T floor); the Langevin tip from 0.1 Å/s (its cost grows as 1/v) to
#: 1e4 Å/s (faster, the tip does not reach its steady drag within the
#: 1 Å lead-in: the relaxation time c/k = 1e-4 s is 1 Å of support travel
#: there).  The two overlap from 0.1 to 30 Å/s.
POINTS = [("kramers", v) for v in (1e-4, 1e-3, 1e-2, 0.1, 0.3, 1.0, 3.0, 10.0, 30.0)] + \
         [("langevin", v) for v in (0.1, 0.3, 1.0, 3.0, 10.0, 30.0, 100.0, 1000.0, 10000.0)]

#: The Langevin step, s: 4 times the default (5 % of c/k_max = 1.26 µs for
#: the overdamped tip on NaF), a tenth of the stability limit 2 c/k_max =
#: 50 µs.  Measured at 10 Å/s with 128 realizations: 0.4604 +- 0.0037 nN
#: against 0.4594 +- 0.0039 at the default step (docs/physics.md).
LANGEVIN_STEP = 5.0e-6


def run_point(binary, files, override, tag, ranks, workdir, mpiexec="mpiexec"):
    """One run of `friction` on the files and the namelist text `override`:
    (mean friction over the lines, its standard error (nN; the lines are
    independent), wall seconds)."""
    import h5py
    import numpy as np
    extra = os.path.join(workdir, f"{tag}.nml")
    out = os.path.join(workdir, f"{tag}.h5")
    with open(extra, "w") as handle:
        handle.write(override)
    cmd = [binary, "--quiet", "--force", "-o", out, *files, extra]
    if ranks > 1:
        cmd = [mpiexec, "-n", str(ranks)] + cmd
    start = time.perf_counter()
    subprocess.run(cmd, check=True)
    seconds = time.perf_counter() - start
    with h5py.File(out, "r") as f:
        lines = f["afm/friction"][()]
        sems = f["afm/friction_sem"][()] if "afm/friction_sem" in f else np.zeros_like(lines)
    return float(lines.mean()), float(np.sqrt(np.sum(sems ** 2)) / len(lines)), seconds


def run_curve(binary, inputs, ranks, workdir, mpiexec="mpiexec"):
    """Every point of POINTS: a list of dicts (model, velocity in Å/s,
    friction and its standard error in nN, wall seconds)."""
    rows = []
    base = os.path.join(inputs, "naf_thermal_velocity.nml")
    for model, velocity in POINTS:
        step = LANGEVIN_STEP if model == "langevin" else 0.0
        override = f"&scan velocity = {velocity!r} /\n&thermal model = '{model}', time_step = {step!r} /\n"
        friction, sem, seconds = run_point(binary, [base], override, f"{model}_{velocity:g}", ranks, workdir,
                                           mpiexec)
        rows.append({"model": model, "velocity": velocity, "friction": friction, "sem": sem, "seconds": seconds})
    return rows


def overlap(rows):
    """(velocity, (F_kramers - F_langevin) / combined standard error) at
    every velocity both models ran at, slowest first."""
    by = {(r["model"], r["velocity"]): r for r in rows}
    both = sorted(v for m, v in by if m == "kramers" and ("langevin", v) in by)
    return [(v, (by["kramers", v]["friction"] - by["langevin", v]["friction"])
             / math.hypot(by["kramers", v]["sem"], by["langevin", v]["sem"])) for v in both]


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
            rows = run_curve(args.binary, args.inputs, args.ranks, workdir, args.mpiexec)
    except subprocess.CalledProcessError as exc:
        print(f"thermal_velocity.py: a run failed: {exc}", file=sys.stderr)
        return 1
    table = os.path.join(args.output, "thermal_velocity.csv")
    with open(table, "w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    for row in rows:
        print(f"{row['model']:8s} v = {row['velocity']:8g} A/s: friction {row['friction']:.4f} +- "
              f"{row['sem']:.4f} nN ({row['seconds']:.1f} s)")
    for v, gap in overlap(rows):
        print(f"overlap at v = {v:g} A/s: kramers - langevin = {gap:+.2f} combined standard errors")
    fig = plot.friction_velocity(rows)
    try:
        fig.savefig(os.path.join(args.output, "thermal_velocity.png"), dpi=args.dpi)
    except OSError as exc:
        print(f"thermal_velocity.py: {exc}", file=sys.stderr)
        return 1
    print(f"total {sum(r['seconds'] for r in rows):.1f} s on {args.ranks} rank(s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
