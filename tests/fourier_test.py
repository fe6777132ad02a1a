#!/usr/bin/env python3
"""The one-dimensional Fourier landscape (&surface potential = 'fourier'), one case per CTest test.

    fourier_test.py --binary BIN --inputs DIR --workdir DIR CASE

Cases:
  row           one coefficient, cosine(1) = v0, against potential = 'row': the same file
                bit for bit (datasets and attributes but the name of the potential and the
                echoed input) at T = 0 for each tip model, and at 300 K in the reduced
                (Kramers) model and the Langevin tip with a fixed seed
  shape         the barrier's shape the file reports (/surface: beta, critical_friction)
                against an independent computation of the barrier and the dissipated energy
                near the fold (SciPy root finding on V(x) + k/2 (x - X)^2), for the
                sinusoid and two harmonics; and critical_friction against the program's own
                quasistatic friction at T = 0
  kramers-rate  two harmonics at 300 K: the reduced model's jump positions against the
                distribution Kramers' rate gives with the landscape's own saddle and
                curvatures (computed here): their mean within 3 standard errors, and a
                Kolmogorov-Smirnov test
  bad-input     NaN, all-zero and too many coefficients, a non-positive period, a
                coefficient for another potential: refused naming file, line, group and
                variable, exit code 3, no file written
"""
import argparse
import math
import os
import shutil
import subprocess
import sys

import h5py
import numpy as np
from scipy import integrate, stats
from scipy.optimize import brentq, minimize_scalar

EV_NN = 1.602176634                       # nN per eV/A
N_PER_M = 1.0 / 1.602176634e-19 / 1e20    # eV/A^2 per N/m (and eV s/A^2 per N s/m)
K_B = 8.617333262e-5                      # eV/K


def fail(message):
    print("FAIL: " + message)
    sys.exit(1)


def write(args, name, text):
    path = os.path.join(args.workdir, name)
    with open(path, "w") as handle:
        handle.write(text)
    return path


def run(args, *rest, expect=0):
    cmd = [args.binary, *rest]
    done = subprocess.run(cmd, cwd=args.workdir, capture_output=True, text=True, timeout=600)
    if done.returncode != expect:
        fail(f"{' '.join(cmd)} exited {done.returncode}, expected {expect}: {done.stderr}")
    return done


class Landscape:
    """V(x) = -sum_n [c_n cos(n q x) + s_n sin(n q x)], q = 2 pi/a (eV, A), evaluated here independently."""

    def __init__(self, c, s, a):
        self.c, self.s, self.a = np.asarray(c, float), np.asarray(s, float), a
        self.kn = np.arange(1, len(c) + 1) * 2.0 * np.pi / a

    def _trig(self, x):
        arg = self.kn * np.asarray(x, float)[..., None]
        return np.cos(arg), np.sin(arg)

    def V(self, x):
        co, si = self._trig(x)
        return -(self.c * co + self.s * si).sum(-1)

    def dV(self, x):
        co, si = self._trig(x)
        return (self.kn * (self.c * si - self.s * co)).sum(-1)

    def d2V(self, x):
        co, si = self._trig(x)
        return (self.kn**2 * (self.c * co + self.s * si)).sum(-1)


def stationary(land, k, X, lo, hi, n=20000):
    """Minima and maxima of E(x) = V(x) + k/2 (x - X)^2 on [lo, hi]: the sign changes of E' on a grid, by brentq."""
    x = np.linspace(lo, hi, n)
    slope = land.dV(x) + k * (x - X)
    mins, maxs = [], []
    for i in np.nonzero(np.sign(slope[:-1]) != np.sign(slope[1:]))[0]:
        root = brentq(lambda t: float(land.dV(t) + k * (t - X)), x[i], x[i + 1], xtol=1e-14, rtol=1e-15)
        (mins if slope[i] < 0 else maxs).append(root)
    return np.array(mins), np.array(maxs)


def energy(land, k, X, x):
    return land.V(x) + 0.5 * k * (x - X)**2


def track(land, k):
    """The quasistatic tip as the support moves in +x from 0 in steps of 0.01 A: the tip just before each of
    its first four jumps, and the support there."""
    X, jumps = 0.0, []
    mins, _ = stationary(land, k, 0.0, -land.a, land.a)
    x = mins[np.argmin(np.abs(mins))]
    while len(jumps) < 4:
        X += 0.01
        mins, _ = stationary(land, k, X, x - 0.25 * land.a, x + 2.5 * land.a, 4000)
        near = mins[np.abs(mins - x) < 0.05 * land.a]
        if near.size:
            x = near[np.argmin(np.abs(near - x))]
        else:
            jumps.append((X, x))
            x = mins[mins > x].min()
    return jumps


def landing(land, k, X, start):
    """The first minimum of E past `start` (a saddle or the fold)."""
    x = np.linspace(start + 1e-4, start + 3.0 * land.a, 30001)
    j = np.nonzero(land.dV(x) + k * (x - X) >= 0.0)[0][0]
    return brentq(lambda t: float(land.dV(t) + k * (t - X)), x[j - 1], x[j], xtol=1e-15, rtol=1e-15)


def fold(land, k):
    """The fold the tracked tip meets: the tip x_c and support X_c where its minimum merges with the saddle
    ahead (the maximum of V'(x) + k x near the tip before the last jump, by SciPy's bounded Brent), and
    the support travel between the last two jumps."""
    jumps = track(land, k)
    g = lambda x: float(land.dV(x) + k * x)
    x_from = jumps[-1][1]
    xc = minimize_scalar(lambda x: -g(x), bounds=(x_from - 0.05 * land.a, x_from + 0.05 * land.a),
                         method="bounded", options={"xatol": 1e-12}).x
    return xc, g(xc) / k, jumps[-1][0] - jumps[-2][0]


def barrier_at(land, k, X, xc, travel, near=True):
    """Before the fold (X < X_c): the barrier ahead of the minimum, the mean force along x if the jump
    came at X (the energy the jump dissipates over the travel between jumps), the curvatures of E at
    the minimum and at the saddle.  Near the fold (near=True) the two are found in brackets either side
    of x_c, 3 times sqrt(k (X_c - X)/sigma) wide (sigma = |V'''(x_c)|/2 by differences), where
    they are; farther, from a grid over a period."""
    slope = lambda x: float(land.dV(x) + k * (x - X))
    if near:
        sigma = abs(land.d2V(xc + 1e-4) - land.d2V(xc - 1e-4)) / 4e-4
        width = 3.0 * math.sqrt(k * (land.dV(xc) / k + xc - X) / sigma)
        m = brentq(slope, xc - width, xc, xtol=1e-15, rtol=1e-15)
        s = brentq(slope, xc, xc + width, xtol=1e-15, rtol=1e-15)
    else:
        mins, maxs = stationary(land, k, X, xc - 0.5 * land.a, xc + 0.5 * land.a, 4000)
        m = mins[mins < xc].max()
        s = maxs[maxs > m].min()
    after = landing(land, k, X, s)
    return (energy(land, k, X, s) - energy(land, k, X, m),
            (energy(land, k, X, m) - energy(land, k, X, after)) / travel,
            land.d2V(m) + k, land.d2V(s) + k)


def shape_oracle(land, k):
    """mu of dE = mu (F_c - F)^1.5 (eV, eV/A) and F_c, from the barrier and the dissipated energy at support
    positions 1e-6 to 1e-3 A before the fold."""
    xc, support, travel = fold(land, k)
    f_c = (energy(land, k, support, xc) - energy(land, k, support, landing(land, k, support, xc))) / travel
    d = np.geomspace(1e-6, 1e-3, 10)
    ratio = []
    for dx in d:
        de, f = barrier_at(land, k, support - dx, xc, travel)[:2]
        ratio.append(de / (f_c - f)**1.5)
    # The ratio tends to mu as 1 + O(sqrt(dX)) (the minimum moves as sqrt(dX) from x_c): fitted by
    # mu + b sqrt(dX) + c dX.
    basis = np.vstack([np.ones_like(d), np.sqrt(d), d]).T
    return np.linalg.lstsq(basis, np.array(ratio), rcond=None)[0][0], f_c, support, travel


ROW_BASE = ("&surface ax = 4.0, v0 = 0.165 /\n"
            "&integrator method = 'auto' /\n"
            "&tip kx = 0.86, ky = 0.86, cx = 1e-6, cy = 1e-6 /\n"
            "&scan length = 16.0, width = 0.0, nx = 128, ny = 1, velocity = 10.0 /\n")


def case_row(args):
    base = write(args, "base.nml", ROW_BASE)
    row = write(args, "row.nml", "&surface potential = 'row' /\n")
    fourier = write(args, "fourier.nml", "&surface potential = 'fourier' /\n&fourier cosine(1) = 0.165 /\n")
    thermal = "&thermal temperature = 300.0, realizations = 4, seed = 7, model = '{}' /\n"
    cases = [("quasistatic", []), ("overdamped", []), ("inertial", ["--set", "tip.mass=1e-12"]),
             ("kramers", [write(args, "kramers.nml", thermal.format("kramers")), "--set", "tip.model='overdamped'"]),
             ("langevin", [write(args, "langevin.nml", thermal.format("langevin") + "&scan velocity = 4000.0 /\n"),
                           "--set", "tip.model='overdamped'"])]
    for name, extra in cases:
        files = []
        for surface, given in (("row", row), ("fourier", fourier)):
            out = f"{surface}_{name}.h5"
            model = ["--set", f"tip.model='{name}'"] if name in ("quasistatic", "overdamped", "inertial") else []
            run(args, "--quiet", "-o", out, base, given, *extra, *model)
            files.append(os.path.join(args.workdir, out))
        with h5py.File(files[0], "r") as a, h5py.File(files[1], "r") as b:
            names = []
            a["afm"].visit(names.append)
            compared = 0
            for key in names:
                if isinstance(a["afm"][key], h5py.Dataset):
                    if a["afm"][key][()].tobytes() != b["afm"][key][()].tobytes():
                        fail(f"{name}: /afm/{key} differs between the row and its one-term Fourier series")
                    compared += 1
            for key, value in a["afm"].attrs.items():
                if key != "potential" and np.asarray(value).tobytes() != np.asarray(b["afm"].attrs[key]).tobytes():
                    fail(f"{name}: /afm attribute {key} differs")
            if b["afm"].attrs["potential"] != b"fourier":
                fail("the file does not name the Fourier surface")
            friction = float(np.mean(b["afm/friction"][()]))
        # Bit for bit: the series' one term is evaluated with the row's operations in its order
        # (0 - c1 cos(qx), c1 (1 q) sin(1 q x) + 0, ...), and the Langevin step's curvature is sampled
        # at the same points.
        print(f"{name}: {compared} datasets the same bit for bit (friction {friction:.6f} nN)")


def read_shape(path):
    with h5py.File(path, "r") as f:
        s = f["surface"]
        return float(s.attrs["beta"]), float(s.attrs["critical_friction"]), float(s.attrs["barrier_exponent"]), \
            f["surface/fold/support"][()], f["surface/fold/folds"][()]


def case_shape(args):
    # Sinusoid: the row above (eta = 7.6); two harmonics: a flatter well and a sharper crest.
    for label, c, kx in (("sinusoid", [0.165], 0.86), ("two harmonics", [0.2, -0.05], 2.0)):
        land = Landscape(c, [0.0] * len(c), 4.0)
        k = kx * N_PER_M
        mu, f_c, xc, travel = shape_oracle(land, k)
        beta_oracle, fc_oracle = EV_NN**1.5 / mu, f_c * EV_NN
        coefficients = ", ".join(repr(v) for v in c)
        extra = write(args, "shape.nml", f"&surface potential = 'fourier' /\n&fourier cosine = {coefficients} /\n"
                      f"&tip model = 'quasistatic', kx = {kx}, ky = {kx} /\n"
                      "&scan length = 16.0, nx = 3201, velocity = 1.0 /\n")
        out = f"shape_{label.replace(' ', '_')}.h5"
        done = run(args, "-o", out, write(args, "base.nml", ROW_BASE), extra)
        beta, fc, exponent, support, folds = read_shape(os.path.join(args.workdir, out))
        with h5py.File(os.path.join(args.workdir, out), "r") as f:
            # The steady state: the mean force over the two whole periods after each trip's first jump
            # (the trip starts with the tip at rest under the support).
            means = []
            for trip in ("trace", "retrace"):
                jumps = np.nonzero(np.abs(np.diff(f[f"afm/{trip}/tip_x"][0])) > 1.0)[0]
                first = jumps[0] + 1 if trip == "trace" else jumps[-1] + 1
                force = f[f"afm/{trip}/f_along"][0]
                means.append(np.mean(force[first:first + 1600]) if trip == "trace"
                             else -np.mean(force[first - 1600:first]))
            quasistatic = 0.5 * sum(means)
        if "beta = 1/mu" not in done.stderr + done.stdout:
            fail(f"the run's summary does not give the barrier shape: {done.stderr}")
        # The oracle's mu is extrapolated to the fold from 1e-6 to 1e-3 A before it; the next term of
        # the series left out moves it by ~1e-6 of mu (3e-6 measured on two harmonics), so 1e-4.  F_c: the
        # fold's energies to rounding, 1e-8.
        if abs(beta / beta_oracle - 1.0) > 1e-4 or abs(fc / fc_oracle - 1.0) > 1e-8 or exponent != 1.5:
            fail(f"{label}: beta {beta}, F_c {fc} nN, exponent {exponent}; oracle beta {beta_oracle}, F_c {fc_oracle}")
        if not (np.all(folds == 1) and abs(math.remainder(support[0] - xc, 4.0)) < 1e-6):
            fail(f"{label}: folds {folds}, fold's support {support} against the oracle's {xc} (mod 4 A)")
        # The quasistatic tip's mean force over 1600 samples 0.005 A apart (two periods): the sawtooth's
        # Riemann sum is off by at most one sample's share of the jump in force, k * jump * 0.005 A / 8 A,
        # 1.5e-3 nN for the two harmonics' spring.
        if abs(quasistatic - fc) > 1.5e-3:
            fail(f"{label}: the quasistatic friction {quasistatic} nN is not the critical friction {fc} nN")
        print(f"{label}: beta {beta:.6f} (oracle {beta_oracle:.6f}) nN^1.5/eV, F_c {fc:.6f} (oracle "
              f"{fc_oracle:.6f}, quasistatic run {quasistatic:.6f}) nN")


def case_kramers_rate(args):
    # At 50 K the jumps come 0.5 to 1 A before the fold, at barriers of 5 to 10 k_B T.
    c, kx, cx, temperature, velocity, a = [0.2, -0.05], 2.0, 1e-6, 50.0, 30.0, 4.0
    land = Landscape(c, [0.0, 0.0], a)
    k, damping, kt = kx * N_PER_M, cx * N_PER_M, K_B * temperature
    x_fold, xc, travel = fold(land, k)
    # Kramers' overdamped rate with this landscape's saddle and curvatures, r = sqrt(k_w |k_b|)/(2 pi c)
    # exp(-dE/kT) (the y spring is the same at the minimum and the saddle and cancels), along the support's
    # path; the model forces the jump where dE falls to 1 k_B T.
    xs = xc - np.linspace(1.6, 0.0, 801)[:-1]
    rates, barriers = [], []
    for X in xs:
        de, _, kw, kb = barrier_at(land, k, X, x_fold, travel, near=False)
        barriers.append(de)
        rates.append(math.sqrt(kw * abs(kb)) / (2.0 * math.pi * damping) * math.exp(-de / kt))
    barriers, rates = np.array(barriers), np.array(rates)
    if barriers[0] < 20.0 * kt:
        fail("the oracle's path starts too close to the fold")
    floor = xs[np.nonzero(barriers <= kt)[0][0]] if np.any(barriers <= kt) else xc
    hazard = integrate.cumulative_trapezoid(rates / velocity, xs, initial=0.0)
    inside = xs <= floor

    def cdf(offset):
        return np.interp(np.asarray(offset) + xc, xs[inside], 1.0 - np.exp(-hazard[inside]), right=1.0)
    # The chance of reaching the floor, where the model forces the jump.
    forced = math.exp(-hazard[inside][-1])
    # The mean jump position relative to the fold: the path's start plus the integral of the survival.
    mean_predicted = (xs[0] - xc) + np.trapezoid(1.0 - cdf(xs[inside] - xc), xs[inside])
    nml = write(args, "rate.nml", "&surface potential = 'fourier', ax = 4.0 /\n&fourier cosine = 0.2, -0.05 /\n"
                f"&tip model = 'overdamped', kx = {kx}, ky = {kx}, cx = {cx}, cy = {cx} /\n"
                f"&scan length = 28.0, width = 0.0, nx = 8, ny = 1, velocity = {velocity}, lead_in = 4.0 /\n"
                f"&thermal temperature = {temperature}, model = 'kramers', realizations = 16, seed = 11 /\n")
    run(args, "--quiet", "-o", "rate.h5", nml)
    with h5py.File(os.path.join(args.workdir, "rate.h5"), "r") as f:
        support, trip = f["afm/slips/support"][()], f["afm/slips/trip"][()]
        jump = f["afm/slips/jump"][()]
    if np.any(jump <= 0.0):
        fail("a jump back on a landscape whose barrier behind is tens of eV")
    # Trace: the support moves in +x; retrace in -x over the mirror-symmetric landscape (cosines only).
    position = np.where(trip == 0, support, -support)
    offset = np.remainder(position - xc + 0.5 * a, a) - 0.5 * a
    n = offset.size
    mean, sem = float(np.mean(offset)), float(np.std(offset, ddof=1) / math.sqrt(n))
    ks = stats.kstest(offset, cdf)
    print(f"{n} jumps: mean position before the fold {mean:.5f} +- {sem:.5f} A, Kramers' rate predicts "
          f"{mean_predicted:.5f} A; forced at the floor {forced:.2e}; KS p = {ks.pvalue:.3f}")
    # Fixed seed: a correct rate gives |difference| < 3 standard errors with probability 0.997, and a KS
    # p-value above 1e-3 with probability 0.999; the rate's own error (hazard quadrature ~5e-5 relative,
    # the oracle's 1e-3 A grid) moves the mean by < 1e-4 A, a tenth of the standard error.
    if abs(mean - mean_predicted) > 3.0 * sem:
        fail(f"mean jump position {mean} +- {sem} A against Kramers' {mean_predicted} A")
    if ks.pvalue < 1e-3:
        fail(f"the jump positions do not follow Kramers' rate: KS p = {ks.pvalue}")


BAD = {
    "nan": ("&fourier cosine(2) = NaN /\n", ["&fourier", "cosine", "NaN", "expected a number"]),
    "zero": ("&fourier cosine(1) = 0.0, sine(3) = 0.0 /\n", ["&fourier", "cosine", "flat"]),
    "too-many": ("&fourier cosine(17) = 0.01 /\n", ["&fourier", "cosine", "17"]),
    "period": ("&surface ax = 0.0 /\n", ["&surface", "ax", "0.01"]),
    "other": ("&surface potential = 'row' /\n", ["&fourier", "sine(3)", "only with"]),
}


def case_bad_input(args):
    base = write(args, "base.nml", "&surface potential = 'fourier' /\n&fourier cosine(1) = 0.165, sine(3) = 0.01 /\n")
    for name, (text, words) in BAD.items():
        bad = write(args, f"{name}.nml", "\n" + text)
        done = run(args, "-o", f"{name}.h5", base, bad, expect=3)
        where = f"{name}.nml:2" if name not in ("other",) else ""
        missing = [w for w in words + [where] if w not in done.stderr]
        if missing:
            fail(f"{name}: the message lacks {missing}: {done.stderr!r}")
        if os.path.exists(os.path.join(args.workdir, f"{name}.h5")):
            fail(f"{name}: a file was written")
        print(f"{name}: {done.stderr.strip()[:160]}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--binary", required=True)
    parser.add_argument("--inputs", required=True)
    parser.add_argument("--workdir", required=True)
    parser.add_argument("case")
    args = parser.parse_args()
    shutil.rmtree(args.workdir, ignore_errors=True)
    os.makedirs(args.workdir)
    {"row": case_row, "shape": case_shape, "kramers-rate": case_kramers_rate,
     "bad-input": case_bad_input}[args.case](args)
    print("1 passed, 0 failed")


if __name__ == "__main__":
    main()
