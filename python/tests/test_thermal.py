"""friction.thermal: the laws of thermally activated friction fitted to F(v, T).

Oracles: points drawn from each law with known parameters (noise-free, and
with Gaussian noise of fixed seeds, whose standard errors the fit must
report: the errors over the reported standard errors are standard normal);
the logarithmic law's estimates and standard errors against the closed form
of weighted linear regression."""
import math

import numpy as np
import pytest

import friction.thermal as thermal

F_C, BETA, V_C = 0.45, 4.0, 30.0                         # nN, nN^(3/2)/eV, Å/s
VELOCITIES = np.array([1e-4, 1e-3, 1e-2, 0.1, 0.3, 1.0, 3.0, 10.0])
TEMPERATURES = np.array([150.0, 225.0, 300.0])
V, T = (a.ravel() for a in np.meshgrid(VELOCITIES, TEMPERATURES))
SEM = np.full(V.size, 0.002)                            # nN


def test_sang_exact_over_temperatures():
    """Noise-free points of one law at three temperatures: F_c, beta and
    v_c come back to the fit's tolerance (1e-12 in the parameters), far
    inside 1e-6 relative."""
    fit = thermal.fit_sang(V, thermal.sang(V, T, F_C, BETA, V_C), T, SEM)
    assert fit.converged
    assert fit.values["F_c"] == pytest.approx(F_C, rel=1e-6)
    assert fit.values["beta"] == pytest.approx(BETA, rel=1e-6)
    assert fit.values["v_c"] == pytest.approx(V_C, rel=1e-6)
    assert fit.chi2 < 1e-12 and fit.dof == V.size - 3


def test_sang_standard_errors_are_right():
    """60 noisy draws (seed 7, noise = the points' standard errors): the
    errors of (F_c, beta, ln v_c) over the standard errors the fit reports
    must be standard normal: means within 3/sqrt(60) of 0, deviations
    within 0.63 to 1.37 (4 standard errors of a sample deviation,
    1/sqrt(120)).  Wrong standard errors or a biased fit fail."""
    rng = np.random.default_rng(7)
    truth = thermal.sang(V, T, F_C, BETA, V_C)
    z = []
    for _ in range(60):
        fit = thermal.fit_sang(V, truth + rng.normal(0.0, SEM), T, SEM)
        assert fit.converged
        se_ln_vc = fit.errors["v_c"] / fit.values["v_c"]
        z.append([(fit.values["F_c"] - F_C) / fit.errors["F_c"],
                  (fit.values["beta"] - BETA) / fit.errors["beta"],
                  math.log(fit.values["v_c"] / V_C) / se_ln_vc])
    z = np.array(z)
    print("z means", z.mean(axis=0), "deviations", z.std(axis=0))
    assert np.all(np.abs(z.mean(axis=0)) < 3.0 / math.sqrt(60))
    assert np.all((z.std(axis=0) > 0.63) & (z.std(axis=0) < 1.37))


def test_log_law_is_weighted_linear_regression():
    """At one temperature the logarithmic law is a straight line in ln v:
    the estimates and standard errors of the textbook weighted regression
    (slope sum w (x - xbar)(y - ybar) / sum w (x - xbar)^2, its error
    1/sqrt(sum w (x - xbar)^2)), to 1e-9 relative."""
    rng = np.random.default_rng(3)
    sem = np.linspace(0.001, 0.004, VELOCITIES.size)
    f = 0.3 + 0.012 * np.log(VELOCITIES) + rng.normal(0.0, sem)
    fit = thermal.fit_log(VELOCITIES, f, 300.0, sem)
    w, x = 1.0 / sem ** 2, np.log(VELOCITIES)
    xbar, ybar = np.sum(w * x) / w.sum(), np.sum(w * f) / w.sum()
    sxx = np.sum(w * (x - xbar) ** 2)
    slope = np.sum(w * (x - xbar) * (f - ybar)) / sxx
    intercept = ybar - slope * xbar
    assert fit.values["F_1[0]"] == pytest.approx(slope, rel=1e-9)
    assert fit.values["F_0[0]"] == pytest.approx(intercept, rel=1e-9)
    assert fit.errors["F_1[0]"] == pytest.approx(1.0 / math.sqrt(sxx), rel=1e-9)
    assert fit.errors["F_0[0]"] == pytest.approx(math.sqrt(1.0 / w.sum() + xbar ** 2 / sxx), rel=1e-9)
    assert np.allclose(fit.predict(VELOCITIES), intercept + slope * x)


def test_compare_prefers_the_law_the_points_follow():
    """Eight decades of velocity at three temperatures, noise 0.002 nN
    (seed 11): points of Sang et al.'s law prefer it by AIC, and points of
    the logarithmic law (one line per temperature) prefer that; each
    difference is tens of chi^2 units, far beyond the noise."""
    rng = np.random.default_rng(11)
    sang_points = thermal.sang(V, T, F_C, BETA, V_C) + rng.normal(0.0, SEM)
    fits = thermal.compare(V, sang_points, T, SEM)
    print(fits["sang"].summary(), fits["log"].summary(), sep="\n")
    assert fits["preferred"] == "sang" and fits["log"].aic - fits["sang"].aic > 20
    log_points = 0.3 + 0.002 * T / 100 * np.log(V) + rng.normal(0.0, SEM)
    fits = thermal.compare(V, log_points, T, SEM)
    assert fits["preferred"] == "log" and fits["sang"].aic - fits["log"].aic > 20


def test_without_standard_errors_the_residuals_scale_them():
    """No sem: the standard errors are scaled by the residuals (curve_fit's
    absolute_sigma=False); with the true sem they differ by sqrt(chi2/dof)."""
    rng = np.random.default_rng(5)
    f = thermal.sang(V, T, F_C, BETA, V_C) + rng.normal(0.0, SEM)
    absolute = thermal.fit_sang(V, f, T, SEM)
    scaled = thermal.fit_sang(V, f, T)
    factor = math.sqrt(absolute.chi2 / absolute.dof)
    for name in ("F_c", "beta", "v_c"):
        assert scaled.values[name] == pytest.approx(absolute.values[name], rel=1e-6)
        assert scaled.errors[name] == pytest.approx(absolute.errors[name] * factor, rel=1e-4)


def test_read_table(tmp_path):
    path = tmp_path / "measured.csv"
    path.write_text("# F(v, T) of a tip on NaCl\nvelocity, temperature, friction, sem\n"
                    + "".join(f"{v}, {t}, {f}, 0.002\n" for v, t, f in zip(V, T, thermal.sang(V, T, F_C, BETA, V_C))))
    table = thermal.read_table(path)
    assert np.array_equal(table["velocity"], V) and np.array_equal(table["temperature"], T)
    fit = thermal.fit_sang(**table)
    assert fit.values["beta"] == pytest.approx(BETA, rel=1e-6)
    blank = tmp_path / "blank.txt"
    blank.write_text("T v F\n300 1 0.2\n300 10 0.25\n")
    assert thermal.read_table(blank)["sem"] is None


@pytest.mark.parametrize("text, message", [
    ("velocity friction\n1 0.2\n", r"bad\.csv:1: no column 'temperature'"),
    ("velocity temperature friction\n1 300\n", r"bad\.csv:2: 2 values"),
    ("velocity temperature friction\n1 300 x\n", r"bad\.csv:2: not a number"),
    ("velocity temperature friction\n-1 300 0.2\n", r"velocity must be positive; row 1"),
    ("velocity temperature friction\n", r"no header line and data"),
])
def test_read_table_refuses(tmp_path, text, message):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(thermal.TableError, match=message):
        thermal.read_table(path)


def test_bad_points_are_refused():
    with pytest.raises(ValueError, match="velocity must be positive"):
        thermal.fit_sang([0.0, 1, 2, 3], [1, 1, 1, 1], 300.0)
    with pytest.raises(ValueError, match="at least 4 points"):
        thermal.fit_sang([1, 2, 3], [1, 1, 1], 300.0)
    with pytest.raises(ValueError, match="at least 3 points at each temperature"):
        thermal.fit_log([1, 2, 3, 4], [1, 1, 1, 1], [300, 300, 300, 200])
