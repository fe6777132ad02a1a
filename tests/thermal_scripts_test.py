"""Tests of the friction-velocity curve's script (scripts/thermal_velocity.py)
and of the fit it draws (friction.plot.sang_fit), run by pytest under CTest
(tests/scripts_thermal.cmake).

Oracle for the fit: synthetic friction from Sang, Dubé and Grant's law
F = F_c - (beta k_B T ln(v_c/v))^(2/3) (PRL 87, 174301, 2001) with known
F_c, beta and v_c, at the velocities and with the standard errors of the
curve in docs/physics.md (NaF at 300 K)."""

import math
import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "python"))
sys.path.insert(0, str(ROOT / "scripts"))

from friction.plot import sang_fit  # noqa: E402
import thermal_velocity  # noqa: E402

KT = 8.617333262e-5 * 300.0                      # eV at 300 K
F_C, BETA, V_C = 0.45, 4.0, 30.0                 # nN, nN^(3/2)/eV, Å/s
VELOCITIES = np.array([1e-4, 1e-3, 1e-2, 0.1, 0.3, 1.0, 3.0, 10.0])
SEM = np.full(VELOCITIES.size, 0.002)            # nN: small noise, where the fit is linear


def law(v, fc=F_C, beta=BETA, vc=V_C):
    return fc - (beta * KT * np.log(vc / v)) ** (2.0 / 3.0)


def test_recovers_exact_law():
    """Noise-free points: the fit solves F_c and B = (beta k_B T)^(2/3)
    exactly for each v_c on its grid, whose step in ln(ln v_c - ln v_max)
    is ln(6000)/3999 = 0.0022 (4000 points over 0.01 to 60): ln v_c to
    +-0.0011 x ln(v_c/v_max) = 0.0013 here, so v_c to 0.2 %; F_c and B
    move with it by at most 1e-3 nN and 1 % (their first-order
    sensitivities to ln v_c, from covariance's Jacobian, are 0.07 nN and
    0.6 % per 0.01)."""
    fc, b, vc = sang_fit(VELOCITIES, law(VELOCITIES), SEM)
    beta = b ** 1.5 / KT
    print(f"exact: F_c = {fc:.6f} nN, beta = {beta:.5f}, v_c = {vc:.4f} A/s")
    assert abs(math.log(vc / V_C)) < 0.002
    assert abs(fc - F_C) < 1e-3
    assert abs(b - (BETA * KT) ** (2.0 / 3.0)) < 0.01 * b
    assert abs(beta - BETA) < 0.015 * BETA


def covariance(fc, b, lnvc, v, sem):
    """The least-squares covariance (J^T W J)^-1 of (F_c, B, ln v_c) for
    F = F_c - B (ln v_c - ln v)^(2/3): the standard errors a fit through
    points of these standard errors has, to first order."""
    x = lnvc - np.log(v)
    jac = np.vstack([np.ones_like(x), -x ** (2.0 / 3.0), -b * (2.0 / 3.0) * x ** (-1.0 / 3.0)]).T
    return np.linalg.inv(jac.T @ (jac / sem[:, None] ** 2))


def test_recovers_noisy_law():
    """Gaussian noise of the points' standard errors (0.002 nN) in 60
    draws: the errors of (F_c, B, ln v_c) over their first-order standard
    errors (the covariance above) must be standard normal: their mean
    within 3/sqrt(60) of 0 and their standard deviation within 0.63 to
    1.37 (4 standard errors of a sample deviation, 1/sqrt(120)).  A biased
    or inefficient fit fails one or the other.  Measured with seed 1: means
    0.09 to 0.11, deviations 0.92 to 0.97 over 100 draws."""
    rng = np.random.default_rng(1)
    cov = covariance(F_C, (BETA * KT) ** (2.0 / 3.0), math.log(V_C), VELOCITIES, SEM)
    se = np.sqrt(np.diag(cov))
    truth = np.array([F_C, (BETA * KT) ** (2.0 / 3.0), math.log(V_C)])
    z = []
    for _ in range(60):
        fc, b, vc = sang_fit(VELOCITIES, law(VELOCITIES) + rng.normal(0.0, SEM), SEM)
        z.append((np.array([fc, b, math.log(vc)]) - truth) / se)
    z = np.array(z)
    print(f"standard errors (F_c, B, ln v_c): {se}; z means {z.mean(axis=0)}, deviations {z.std(axis=0)}")
    assert np.all(np.abs(z.mean(axis=0)) < 3.0 / math.sqrt(60))
    assert np.all((z.std(axis=0) > 0.63) & (z.std(axis=0) < 1.37))


def test_overlap():
    """The script's overlap: (F_kramers - F_langevin) over the combined
    standard error, at the velocities both models ran at, slowest first."""
    rows = [{"model": "kramers", "velocity": 1.0, "friction": 0.40, "sem": 0.03},
            {"model": "langevin", "velocity": 1.0, "friction": 0.36, "sem": 0.04},
            {"model": "kramers", "velocity": 0.1, "friction": 0.25, "sem": 0.01},
            {"model": "langevin", "velocity": 0.1, "friction": 0.25, "sem": 0.01},
            {"model": "langevin", "velocity": 100.0, "friction": 0.7, "sem": 0.01}]
    gaps = thermal_velocity.overlap(rows)
    assert [v for v, _ in gaps] == [0.1, 1.0]
    assert np.allclose([g for _, g in gaps], [0.0, 0.8], rtol=0, atol=1e-12)


def test_points_overlap_two_decades():
    """The curve's points: both models at every velocity of two decades."""
    kramers = {v for m, v in thermal_velocity.POINTS if m == "kramers"}
    langevin = {v for m, v in thermal_velocity.POINTS if m == "langevin"}
    both = sorted(kramers & langevin)
    assert both[-1] / both[0] >= 100.0


def test_command_line():
    """--help names the options; a bad option is exit code 2."""
    script = str(ROOT / "scripts" / "thermal_velocity.py")
    ok = subprocess.run([sys.executable, script, "--help"], capture_output=True, text=True)
    assert ok.returncode == 0 and "--binary" in ok.stdout and "--ranks" in ok.stdout
    bad = subprocess.run([sys.executable, script, "--no-such-option"], capture_output=True, text=True)
    assert bad.returncode == 2 and "Traceback" not in bad.stderr


def test_temperature_fit():
    """friction.plot.temperature_fit on F = F_c - C T^(2/3) exactly (with
    a point above 300 K that it must leave out, and one whose standard
    error is 0): F_c and C to 1e-9, the free exponent to its grid step
    0.001."""
    from friction.plot import temperature_fit
    rows = [{"temperature": t, "friction": 0.8 - 0.015 * t ** (2.0 / 3.0), "sem": 0.01 if t != 50.0 else 0.0}
            for t in (25.0, 50.0, 100.0, 150.0, 200.0, 250.0)]
    rows.append({"temperature": 600.0, "friction": 0.0, "sem": 0.01})
    rows.append({"temperature": 0.0, "friction": 0.81, "sem": 0.0})
    fc, c, alpha, alpha_se = temperature_fit(rows)
    assert abs(fc - 0.8) < 1e-9 and abs(c - 0.015) < 1e-9
    assert abs(alpha - 2.0 / 3.0) <= 0.001 and alpha_se < 0.1


def test_temperature_command_line():
    """thermal_temperature.py: --help names the options; a bad option is
    exit code 2."""
    script = str(ROOT / "scripts" / "thermal_temperature.py")
    ok = subprocess.run([sys.executable, script, "--help"], capture_output=True, text=True)
    assert ok.returncode == 0 and "--binary" in ok.stdout
    bad = subprocess.run([sys.executable, script, "--no-such-option"], capture_output=True, text=True)
    assert bad.returncode == 2 and "Traceback" not in bad.stderr
