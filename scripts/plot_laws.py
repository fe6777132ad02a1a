#!/usr/bin/env python3
"""The friction laws' signature behaviours (docs/laws.md), drawn from the
library through the Python package (friction.law, one C API call per
history) and, for the mechanisms, from the program's files:

  laws_steady.png         steady friction against sliding velocity
  laws_dahl_loop.png      Dahl's hysteresis loops under a displacement
  laws_presliding.png     LuGre and the elasto-plastic law under a small
                          oscillating displacement (pre-sliding)
  laws_rate_state.png     rate and state after a tenfold velocity step
  laws_gms_memory.png     the Generalized Maxwell-Slip law's pre-sliding
                          loops with nonlocal memory
  machine_stick_slip.png  the belt oscillator's phase plane with four laws

    scripts/plot_laws.py [--out DIR] [--binary build/friction]
"""
import argparse
import subprocess
import sys
import tempfile
from pathlib import Path

import h5py
import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "python"))
from friction.law import Law  # noqa: E402


def steady(out):
    v = np.logspace(-6, 1, 400)
    fig, ax = plt.subplots(figsize=(6, 4))
    for model, values, label in (("coulomb", {"mu": 1.0, "mu_s": 1.5, "sigma2": 0.4}, "Coulomb (μs N = 1.5 N)"),
                                 ("stribeck", {"sigma2": 0.4}, "Stribeck"),
                                 ("lugre", {"sigma2": 0.4}, "LuGre (steady)"),
                                 ("arctan", {"mu": 1.0, "epsilon": 1e4, "delta": 0.1}, "arctan, ε = 1e4 s/m"),
                                 ("table", {"table_file": str(ROOT / "inputs" / "machine_table.txt")},
                                  "table (4 rows a decade)")):
        with Law(model, values) as law:
            force, _ = law.history(np.linspace(0.0, 1.0, v.size), v)
        ax.semilogx(v, force, label=label, lw=1.2, ls="--" if model == "table" else "-")
    ax.set_xlabel("sliding velocity v (m/s)")
    ax.set_ylabel("steady friction F (N)")
    ax.set_ylim(0.0, 2.0)
    ax.legend(fontsize=8)
    ax.set_title("Steady friction: the Stribeck effect and its absence")
    fig.tight_layout()
    fig.savefig(out / "laws_steady.png", dpi=110)


def dahl_loop(out):
    fig, ax = plt.subplots(figsize=(5, 4))
    t = np.linspace(0.0, 4.0, 4001)
    for amplitude in (5e-6, 1e-5, 2e-5, 4e-5):
        x = amplitude * np.sin(2 * np.pi * t)
        with Law("dahl") as law:
            force, _ = law.history(t, x, displacement=True)
        keep = t >= 2.0
        ax.plot(1e6 * x[keep], force[keep], lw=1.2, label=f"A = {1e6 * amplitude:g} µm")
    ax.set_xlabel("displacement x (µm)")
    ax.set_ylabel("friction F (N)")
    ax.set_title("Dahl: rate-independent hysteresis (F_c = 1 N)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "laws_dahl_loop.png", dpi=110)


def presliding(out):
    fig, ax = plt.subplots(figsize=(5, 4))
    t = np.linspace(0.0, 30.0, 30001)
    x = 1.4e-5 * (t / 30.0) * np.sin(2 * np.pi * t / 10.0)   # growing cycles from rest
    for model, label in (("lugre", "LuGre"), ("elastoplastic", "elasto-plastic, z_ba = 5 µm")):
        with Law(model, {"sigma2": 0.4}) as law:
            force, _ = law.history(t, x, displacement=True)
        ax.plot(1e6 * x, force, lw=1.0, label=label)
    ax.set_xlabel("displacement x (µm)")
    ax.set_ylabel("friction F (N)")
    ax.set_title("Pre-sliding below F_s: a spring σ0 with memory")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "laws_presliding.png", dpi=110)


def rate_state(out):
    fig, ax = plt.subplots(figsize=(6, 4))
    t = np.concatenate([[0.0], np.linspace(10.0, 10.0 + 8.0, 801)])
    x = np.where(t <= 10.0, 1e-6 * t, 1e-5 + 1e-5 * (t - 10.0))
    for evolution in ("aging", "slip"):
        with Law("rate_state", evolution=evolution) as law:
            force, _ = law.history(t, x, displacement=True)
        ax.plot(1e5 * (x[1:] - 1e-5), force[1:], lw=1.2, label=f"{evolution} law")
    ax.axhline(0.6 + (0.010 - 0.015) * np.log(10.0), color="k", lw=0.6, ls=":")
    ax.set_xlabel("slip after the step / D_c")
    ax.set_ylabel("μ (N = 1 N)")
    ax.set_title("Rate and state: v0 → 10 v0, direct effect a ln 10, then μ_ss")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "laws_rate_state.png", dpi=110)


def stick_slip(out, binary):
    fig, ax = plt.subplots(figsize=(6, 4))
    with tempfile.TemporaryDirectory() as scratch:
        for model in ("coulomb", "stribeck", "lugre", "karnopp"):
            path = Path(scratch) / f"{model}.h5"
            subprocess.run([binary, "--quiet", "--force", "-o", str(path),
                            str(ROOT / "inputs" / f"machine_{model}.nml")], check=True)
            with h5py.File(path) as f:
                t, x, v = f["machine/t"][:], f["machine/x"][:], f["machine/v"][:]
            keep = t >= 15.0
            ax.plot(x[keep], v[keep], lw=1.0, label=model)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("v (m/s)")
    ax.set_title("The belt oscillator (1 kg, 2 N/m, belt 0.1 m/s): stick at v = 0.1")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "machine_stick_slip.png", dpi=110)


def gms_memory(out):
    # Slowly (1e-5 m/s, far below v_s): reversals at 40, -40, 15, -5, 15 and 40 µm.
    turns = 1e-6 * np.array([0.0, 40.0, -40.0, 15.0, -5.0, 15.0, 40.0])
    path = np.concatenate([[0.0]] + [np.linspace(a, b, 400)[1:] for a, b in zip(turns[:-1], turns[1:])])
    # A rest sample first (the states start in steady sliding at the first velocity: at rest, relaxed).
    x = np.concatenate([[0.0], path])
    t = np.concatenate([[-1.0], np.cumsum(np.r_[0.0, np.abs(np.diff(path))]) / 1e-5])
    with Law("gms") as law:
        force, _ = law.history(t, x, displacement=True)
    fig, ax = plt.subplots(figsize=(5, 4))
    ax.plot(1e6 * x, force, lw=1.0, color="C0")
    ax.plot(1e6 * x[:400], force[:400], lw=2.0, color="C1", label="virgin curve")
    ax.set_xlabel("displacement x (µm)")
    ax.set_ylabel("friction F (N)")
    ax.set_title("GMS: Masing loops with nonlocal memory")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "laws_gms_memory.png", dpi=110)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", default=".")
    parser.add_argument("--binary", default=str(ROOT / "build" / "friction"))
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    steady(out)
    dahl_loop(out)
    presliding(out)
    rate_state(out)
    gms_memory(out)
    stick_slip(out, args.binary)
    return 0


if __name__ == "__main__":
    sys.exit(main())
