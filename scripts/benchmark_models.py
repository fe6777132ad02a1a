#!/usr/bin/env python3
"""Benchmark the AFM tip models: what the reduced ones cost in accuracy and
save in time against the full (inertial) model.

Measures and prints (this is not a test; nothing fails on a missed target),
for each scene (inputs/naf.nml, inputs/hopg.nml, inputs/graphite.nml with
inputs/graphite_damped.nml, on fewer lines; NaF and HOPG also at 10 Å/s and
NaF at 1 Å/s, towards where the quasistatic model holds) and each model:

* time: the file's wall_time (one rank, MPI start-up to just before the file
  is written), median of --repeats runs, and the speed-up over the inertial
  model measured in the same run of this script;
* mean friction over the map (mean of /afm/friction) and the largest force
  max |f_along| (trace and retrace), each with its difference from the
  inertial model's;
* sample by sample: the largest and the RMS |f_along - f_along(inertial)|
  over trace and retrace, without the first sample of each trip (there the
  full tip is at rest at the support by definition, the quasistatic one in
  its minimum);
* the quasistatic model's jumps, and the warnings the program printed.

Every model runs with the scene's integrator settings; the overdamped model
also with msbdf, because without inertia a stiff surface (the graphite
scene's Lennard-Jones wall in z) makes the equations stiff.

Usage (from anywhere; normally through scripts/benchmark_models, which builds first):

    python3 scripts/benchmark_models.py [--repeats N] [--quick] [--json FILE] [--binary PATH]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

try:
    import h5py
    import numpy as np
except ImportError as exc:  # pragma: no cover - environment problem
    sys.exit(f"benchmark_models: {exc}; run scripts/install-deps")

ROOT = Path(__file__).resolve().parent.parent
INPUTS = ROOT / "inputs"

# name, input files, override text (lines cut for speed), lines in --quick mode
SCENES = [
    ("naf", ["naf.nml"], "&scan ny = 16 /", 4),
    ("naf 10 Å/s", ["naf.nml"], "&scan ny = 16, velocity = 10.0 /", 4),
    ("naf 1 Å/s", ["naf.nml"], "&scan ny = 16, velocity = 1.0 /", 4),
    ("hopg", ["hopg.nml"], "&scan ny = 16 /", 4),
    ("hopg 10 Å/s", ["hopg.nml"], "&scan ny = 16, velocity = 10.0 /", 4),
    ("graphite (damped)", ["graphite.nml", "graphite_damped.nml"], "&scan ny = 4 /", 2),
]
# model, integrator method override (None: the scene's)
MODELS = [("inertial", None), ("overdamped", None), ("overdamped", "msbdf"), ("quasistatic", None)]


def log(msg: str) -> None:
    print(f"benchmark_models: {msg}", file=sys.stderr, flush=True)


class Friction:
    def __init__(self, binary: Path, workdir: Path):
        self.binary = binary
        self.workdir = workdir
        self.env = dict(os.environ)
        if hasattr(os, "geteuid") and os.geteuid() == 0:
            # Open MPI refuses to run as root unless both are set.
            self.env["OMPI_ALLOW_RUN_AS_ROOT"] = "1"
            self.env["OMPI_ALLOW_RUN_AS_ROOT_CONFIRM"] = "1"
        self.count = 0

    def override(self, name: str, text: str) -> Path:
        path = self.workdir / f"{name}.nml"
        path.write_text(text + "\n")
        return path

    def run(self, files: list[Path]) -> tuple[Path, float, list[str]]:
        """One rank, no mpirun: the single-process cost."""
        self.count += 1
        out = self.workdir / f"run{self.count:04d}.h5"
        cmd = [str(self.binary), "--quiet", "--force", "-o", str(out)] + [str(p) for p in files]
        proc = subprocess.run(cmd, env=self.env, cwd=self.workdir, capture_output=True, text=True)
        if proc.returncode != 0:
            raise RuntimeError(f"friction failed ({proc.returncode}): {' '.join(cmd)}\n{proc.stderr}")
        warnings = [line[len("friction: warning: "):] for line in proc.stderr.splitlines()
                    if line.startswith("friction: warning: ")]
        with h5py.File(out, "r") as f:
            wall = float(f.attrs["wall_time"])
        return out, wall, warnings


def read_map(path: Path) -> dict:
    with h5py.File(path, "r") as f:
        trace = f["afm/trace/f_along"][()]
        retrace = f["afm/retrace/f_along"][()]
        jumps = None
        if "afm/trace/jumps" in f:
            jumps = int(f["afm/trace/jumps"][()].sum() + f["afm/retrace/jumps"][()].sum())
        return {
            "friction": float(np.mean(f["afm/friction"][()])),
            "max_force": float(max(np.abs(trace).max(), np.abs(retrace).max())),
            # without the first sample of each trip (trace: index 0; retrace: the last)
            "samples": np.concatenate([trace[:, 1:].ravel(), retrace[:, :-1].ravel()]),
            "jumps": jumps,
        }


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeats", type=int, default=3, help="runs per case; the median is shown (default 3)")
    p.add_argument("--quick", action="store_true", help="one run per case on fewer lines")
    p.add_argument("--json", help="also write the figures to this file")
    p.add_argument("--binary", default=str(ROOT / "build" / "friction"),
                   help="the friction executable (default: build/friction)")
    args = p.parse_args()
    if args.repeats < 1:
        p.error("--repeats must be at least 1")
    repeats = 1 if args.quick else args.repeats
    binary = Path(args.binary).resolve()
    if not os.access(binary, os.X_OK):
        p.error(f"{args.binary} is not an executable; build first (scripts/build)")

    rows = []
    notes: dict[str, int] = {}
    with tempfile.TemporaryDirectory(prefix="friction-models-bench-") as tmp:
        fr = Friction(binary, Path(tmp))
        for scene, files, override, quick_lines in SCENES:
            text = override
            if args.quick:
                text = text.replace("ny = 16", f"ny = {quick_lines}").replace("ny = 4 ", f"ny = {quick_lines} ")
            base = [INPUTS / f for f in files] + [fr.override(f"scene{fr.count}", text)]
            reference = None
            for model, method in MODELS:
                extra = f"&tip model = '{model}' /"
                if method:
                    extra += f"\n&integrator method = '{method}' /"
                inputs = base + [fr.override(f"model{fr.count}", extra)]
                label = model + (f" ({method})" if method else "")
                log(f"{scene}: {label} x {repeats}")
                walls, path, warnings = [], None, []
                for _ in range(repeats):
                    path, wall, warnings = fr.run(inputs)
                    walls.append(wall)
                data = read_map(path)
                wall = statistics.median(walls)
                if reference is None:
                    reference = (data, wall)
                ref, ref_wall = reference
                delta = data["samples"] - ref["samples"]
                marks = []
                for w in warnings:
                    if w not in notes:
                        notes[w] = len(notes) + 1
                    marks.append(notes[w])
                rows.append({
                    "scene": scene, "model": label, "wall_s": wall, "walls_s": walls,
                    "speedup": ref_wall / wall, "friction_nN": data["friction"],
                    "friction_diff_nN": data["friction"] - ref["friction"],
                    "max_force_nN": data["max_force"], "max_force_diff_nN": data["max_force"] - ref["max_force"],
                    "largest_diff_nN": float(np.abs(delta).max()),
                    "rms_diff_nN": float(np.sqrt(np.mean(delta ** 2))),
                    "jumps": data["jumps"], "warnings": marks,
                })

    print(f"AFM tip models against the inertial one: one rank, median of {repeats} run(s); "
          "forces in nN, differences from the inertial row of the same scene")
    head = (f"{'scene':<18} {'model':<19} {'time s':>8} {'speed-up':>8} {'friction':>9} {'Δ':>9} "
            f"{'max F':>7} {'Δ':>8} {'largest Δ':>9} {'rms Δ':>8} {'jumps':>6} warn")
    print(head)
    print("-" * len(head))
    for r in rows:
        jumps = "" if r["jumps"] is None else str(r["jumps"])
        warn = ",".join(str(m) for m in r["warnings"])
        print(f"{r['scene']:<18} {r['model']:<19} {r['wall_s']:8.3f} {r['speedup']:7.1f}x "
              f"{r['friction_nN']:9.4f} {r['friction_diff_nN']:+9.4f} {r['max_force_nN']:7.3f} "
              f"{r['max_force_diff_nN']:+8.4f} {r['largest_diff_nN']:9.4f} {r['rms_diff_nN']:8.4f} "
              f"{jumps:>6} {warn}")
    if notes:
        print("\nwarnings printed by friction:")
        for text, number in notes.items():
            print(f"  {number}: {text}")
    if args.json:
        Path(args.json).write_text(json.dumps({"repeats": repeats, "rows": rows, "warnings": notes}, indent=2))


if __name__ == "__main__":
    main()
