#!/usr/bin/env python3
"""Karnopp's band with an edge at v = 0 (the belt at ±dv): a block sliding
in enters the band there and holds.  The velocity the block is put at, just
inside the edge, was found by steps of one unit in v's last place, which
are subnormal at 0: the run never ended (found by the fuzzing suite's laws
class, a belt at -dv).  Now it ends, and its motion agrees with rk8pd at a
tighter tolerance (a different method).

    band_edge_at_rest.py --binary B --inputs DIR --workdir DIR machine
"""
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from machine_cases import case_main  # noqa: E402


def run(args, name, text):
    path = Path(args.workdir) / f"{name}.nml"
    path.write_text(text)
    out = Path(args.workdir) / f"{name}.h5"
    # (A hang is what this checks: 60 s is a thousand times the run.)
    result = subprocess.run([args.binary, "--quiet", "--force", "-o", str(out),
                             str(Path(args.inputs) / "machine_karnopp.nml"), str(path)],
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr
    with h5py.File(out, "r") as handle:
        machine = handle["machine"]
        return {key: machine[key][()] for key in ("t", "x", "v", "stick")}, machine["events/t"][()]


def machine(args):
    for belt in (-1.0e-4, 1.0e-4):   # dv = 1e-4 m/s: the band's upper or lower edge at v = 0
        motion = f"&machine belt_velocity = {belt!r}, v0 = {-3000.0 * belt!r}, t_end = 10.0 /\n"
        ours, events = run(args, f"rodas4{belt:+g}", motion + "&integrator method = 'rodas4', rtol = 1e-10 /\n")
        other, other_events = run(args, f"rk8pd{belt:+g}", motion +
                                  "&integrator method = 'rk8pd', rtol = 1e-12, atol = 1e-14 /\n")
        worst = np.abs(ours["x"] - other["x"]).max()
        print(f"belt {belt:+g} m/s: events at {events} s (rk8pd {other_events}), held {ours['stick'].sum()} of "
              f"{len(ours['t'])} points, worst |x - x_rk8pd| = {worst:.3g} m")
        # One entry into the band, then held to the end; x within the tolerances' reach (rtol 1e-10 of
        # a motion of 0.1 m: 1e-11 m; 1e-9 m leaves room for the event time's 1e-10 s).
        assert len(events) == len(other_events) == 1 and abs(events[0] - other_events[0]) < 1e-9
        assert (ours["stick"] == other["stick"]).all() and ours["stick"][-1] == 1
        assert worst < 1.0e-9, worst


if __name__ == "__main__":
    sys.exit(case_main(__doc__, {"machine": machine}))
