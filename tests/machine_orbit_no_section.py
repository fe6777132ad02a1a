#!/usr/bin/env python3
"""The machine's orbit when Newton's start never returns to the section:
Dahl's law (α = 2) on the belt oscillator settles into steady sliding, so
there is no orbit, and the file says so.  The section point the file and a
continuation's branch read was left unset there: the program aborted in
the heap (a continuation), failed writing /machine/orbit/point (exit 5) or
wrote NaN into the branch (found by the fuzzing suite's laws class).

Each run ends with exit 0, the orbit not found, its point finite, and the
equilibrium and its eigenvalues those of steady sliding in closed form:
e = -F_c/k, z = F_c/σ0 (Dahl's deflection saturated), and the
eigenvalues 0 (the saturated deflection: dż/dz ∝ (1 - σ0 z/F_c)^(α-1) = 0)
and (-c ± i sqrt(4 m k - c²))/(2 m) of the spring, damper and mass.

    machine_orbit_no_section.py --binary B --inputs DIR --workdir DIR dahl
"""
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from machine_cases import case_main  # noqa: E402

M, K, C = 0.1, 1.0, 0.1


def dahl(args):
    work = Path(args.workdir)
    for fc, tool in [(1.0, ""), (1.0, "continuation = 'belt_velocity', continuation_end = -2.0,"
                                      " continuation_points = 2,"), (2.0, "continuation = 'belt_velocity',"
                                                                          " continuation_end = -2.0,"
                                                                          " continuation_points = 2,")]:
        name = f"dahl-{fc:g}-{'branch' if tool else 'orbit'}"
        path = work / f"{name}.nml"
        path.write_text(
            "&job scene = 'machine' /\n"
            f"&machine mass = {M}, stiffness = {K}, damping = {C}, normal = 1.0, belt_velocity = -1.0,"
            " t_end = 3.0, dt_out = 1.0, steady_start = .true. /\n"
            f"&law model = 'dahl', fc = {fc}, sigma0 = 1.0, alpha = 2.0 /\n"
            f"&analysis orbit = .true., orbit_max_iterations = 8, window_start = 0.0, window_end = 3.0, {tool}"
            " orbit_transient = 0.0 /\n"
            "&integrator method = 'rodas4', rtol = 1e-3 /\n")
        out = work / f"{name}.h5"
        result = subprocess.run([args.binary, "--quiet", "--force", "-o", str(out), str(path)],
                                capture_output=True, text=True, timeout=60)
        assert result.returncode == 0, (result.returncode, result.stderr)
        with h5py.File(out, "r") as handle:
            orbit = handle["machine/orbit"]
            point, equilibrium = orbit["point"][()], orbit["equilibrium"][()]
            eigenvalues = orbit["equilibrium_eigenvalues"][()]
            print(f"{name}: found {orbit.attrs['found']} ({orbit.attrs['reason'].decode()}), point {point},"
                  f" equilibrium {equilibrium}")
            assert orbit.attrs["found"] == 0 and point.shape == (3,) and np.isfinite(point).all()
            if tool:
                branch = orbit["branch/point"][()]
                assert branch.shape == (2, 3) and np.isfinite(branch).all(), branch
        # Rounding of the equilibrium's Newton solve and of the eigen-solver: 1e-12.
        assert np.allclose(equilibrium, [-fc / K, 0.0, fc / 1.0], rtol=0, atol=1e-12), equilibrium
        expected = sorted([0.0 + 0.0j, complex(-C / (2 * M), np.sqrt(4 * M * K - C * C) / (2 * M)),
                           complex(-C / (2 * M), -np.sqrt(4 * M * K - C * C) / (2 * M))], key=lambda z: (z.real, z.imag))
        found = sorted([complex(a, b) for a, b in eigenvalues], key=lambda z: (z.real, z.imag))
        assert np.allclose(found, expected, rtol=0, atol=1e-12), (found, expected)


if __name__ == "__main__":
    sys.exit(case_main(__doc__, {"dahl": dahl}))
