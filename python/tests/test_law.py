"""friction.law: the C API's friction laws from Python, against oracles that
are not the library's output: closed forms, SciPy's PchipInterpolator, and a
fit that recovers the parameters it was simulated with."""
import numpy as np
import pytest
from scipy.interpolate import PchipInterpolator

import friction
from friction.law import Law, fit


def stribeck(v, fc=1.0, fs=1.5, vs=1e-3, exponent=2.0):
    return fc + (fs - fc) * np.exp(-np.abs(v / vs) ** exponent)


def test_lugre_steady_state_through_the_c_api():
    # From steady sliding at each velocity (the history's start) the force stays g(v) sgn v + σ2 v.
    with Law("lugre", sigma2=0.4) as lugre:
        assert lugre.state_count == 1
        for v in (1e-4, 3e-3, -2e-2):
            t = np.linspace(0.0, 1.0, 11)
            force, z = lugre.history(t, np.full_like(t, v))
            expected = np.sign(v) * stribeck(v) + 0.4 * v
            np.testing.assert_allclose(force, expected, rtol=1e-12)
            np.testing.assert_allclose(z[:, 0], np.sign(v) * stribeck(v) / 1e5, rtol=1e-12)


def test_rate_state_steady_friction():
    # μ_ss = μ0 + (a - b) ln(V/v0) for a normal load of 2 N; the asinh form is the logarithm to e^-120.
    with Law("rate_state", evolution="slip") as law:
        for v in (1e-8, 1e-6, 1e-3, 1.0):
            force, theta = law.history([0.0, 1.0], [v, v], normal=2.0)
            np.testing.assert_allclose(force, 2.0 * (0.6 + (0.010 - 0.015) * np.log(v / 1e-6)), rtol=1e-12)
            np.testing.assert_allclose(theta[:, 0], 1e-5 / v, rtol=1e-12)


def test_table_law_is_scipys_pchip_in_log_velocity(tmp_path):
    # Rows irregular in ln v, rising then falling (the limiter acts at the turn and the ends); the
    # force between them is SciPy's PchipInterpolator of (ln v, F), times the scale, and the
    # first or last row's force outside (extrapolation 'constant').
    v = np.array([1e-6, 3e-6, 2e-5, 1e-4, 4e-4, 1e-3, 5e-3, 2e-2, 1e-1])
    f = np.array([1.20, 1.24, 1.31, 1.33, 1.30, 1.18, 1.05, 1.02, 1.10])
    table = tmp_path / "curve.txt"
    table.write_text("# v (m/s)  F (N)\n" + "".join(f"{float(a)!r} {float(b)!r}\n" for a, b in zip(v, f)))
    probe = np.logspace(-7, 0, 701)
    with Law("table", table_file=str(table), scale=3.0) as law:
        law.check()
        force, _ = law.history(probe, probe)
    inside = (probe > v[0]) & (probe < v[-1])
    expected = 3.0 * PchipInterpolator(np.log(v), f)(np.log(probe[inside]))
    np.testing.assert_allclose(force[inside], expected, rtol=1e-13)
    np.testing.assert_allclose(force[probe <= v[0]], 3.0 * f[0], rtol=1e-15)
    np.testing.assert_allclose(force[probe >= v[-1]], 3.0 * f[-1], rtol=1e-15)


def test_bad_values_are_refused_by_name():
    with Law("lugre", sigma0=-1.0) as law:
        with pytest.raises(friction.FrictionError, match=r"&law: sigma0 = -1.0.*must be > 0"):
            law.check()
    with pytest.raises(friction.FrictionError, match="unknown friction law 'bristles'"):
        Law("bristles")
    with Law("stribeck") as law:
        with pytest.raises(friction.FrictionError, match="unknown variable 'sigma9'"):
            law.set("sigma9", 1.0)


def test_fit_recovers_the_stribeck_curve_of_lugre():
    # LuGre forces along a slow velocity sweep from 1e-4 to 1e-1 m/s (quasi-steady: the bristles relax
    # in g/(σ0 v) <= 0.15 s against 33 s per decade) with Gaussian noise of 2 mN, seed fixed: the fit of
    # F_s, v_s and σ2 (each within 5 %: the sweep determines them)
    # lands within 4 standard errors of the values simulated (a chance of 6e-5 per parameter), and
    # the errors agree with the noise (the residuals' scatter within 10 % of 2 mN for 400 points).
    t = np.linspace(0.0, 100.0, 400)
    v = 10.0 ** (-4.0 + 3.0 * t / 100.0)
    truth = {"fs": 1.3, "vs": 2e-3, "sigma2": 0.4}
    with Law("lugre", truth) as law:
        clean, _ = law.history(t, v)
    rng = np.random.default_rng(37)
    measured = clean + rng.normal(0.0, 2e-3, t.size)
    result = fit("lugre", t, v, measured, {"fs": 1.5, "vs": 1e-3, "sigma2": 0.1})
    for name, value in truth.items():
        assert abs(result.values[name] - value) < 4.0 * result.errors[name], (name, result.values, result.errors)
        assert result.errors[name] < 0.05 * value
    assert abs(np.std(result.residuals) / 2e-3 - 1.0) < 0.1


def test_machine_scene_computes_through_the_c_api():
    # The Coulomb belt oscillator (docs/laws.md, Mechanisms) through Config.compute: break-away at
    # t = 2.5 s + n (1.5π + 2) s, the closed form's cycle, to the event tolerance and the integration's.
    values = {"machine.stiffness": 1.0, "machine.belt_velocity": 0.2, "machine.v0": 0.2, "machine.t_end": 20.0,
              "law.model": "coulomb", "law.mu": 0.3, "law.mu_s": 0.5}
    with friction.Config("machine", values=values) as cfg:
        run = cfg.compute()
    breakaway = run["events/t"][run["events/kind"] == 1]
    np.testing.assert_allclose(breakaway, 2.5 + np.arange(breakaway.size) * (1.5 * np.pi + 2.0), atol=1e-8)
    assert breakaway.size == 3
