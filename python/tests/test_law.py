"""friction.law: the C API's friction laws from Python, against oracles that
are not the library's output: closed forms, SciPy's PchipInterpolator, and a
fit that recovers the parameters it was simulated with."""
from pathlib import Path

import h5py
import numpy as np
import pytest
from scipy.integrate import solve_ivp
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


SWEEP = Path(__file__).resolve().parents[2] / "tests" / "data" / "naf_thermal_velocity_sweep.h5"


def write_sweep(path, values, friction, status, variable="scan.velocity"):
    """A file in the layout of the program's sweeps (docs/sweeps.md)."""
    with h5py.File(path, "w") as f:
        f["sweep/values"] = np.asarray(values, dtype=float)
        f["sweep/values"].attrs["units"] = np.bytes_("angstrom/s")
        f["sweep/values"].attrs["variable"] = np.bytes_(variable)
        f["sweep/mean_friction"] = np.asarray(friction, dtype=float)
        f["sweep/mean_friction"].attrs["units"] = np.bytes_("nN")
        f["sweep/status"] = np.asarray(status, dtype=np.int32)


def test_table_from_the_microscopes_sweep_file():
    # A sweep of scan.velocity over inputs/naf_thermal_velocity.nml (NaF at 300 K, the thermal
    # reduced model, 4 velocities from 0.01 to 10 angstrom/s, made by the program): its rows are
    # the velocities in m/s and the mean friction in N, times the scale, interpolated as a text
    # table's (SciPy's PchipInterpolator in ln v).
    with h5py.File(SWEEP) as f:
        v = f["sweep/values"][:] * 1e-10
        fr = f["sweep/mean_friction"][:] * 1e-9
    contacts = 1.0e6
    probe = np.logspace(np.log10(v[0]) - 1, np.log10(v[-1]) + 1, 301)
    with Law("table", table_file=str(SWEEP), scale=contacts) as law:
        law.check()
        force, _ = law.history(probe, probe)
        at_rows, _ = law.history(v, v)
    inside = (probe > v[0]) & (probe < v[-1])
    np.testing.assert_allclose(force[inside], contacts * PchipInterpolator(np.log(v), fr)(np.log(probe[inside])),
                               rtol=1e-13)
    np.testing.assert_allclose(at_rows, contacts * fr, rtol=1e-13)
    np.testing.assert_allclose(force[probe <= v[0]], contacts * fr[0], rtol=1e-15)


def test_sweep_table_reproduces_a_closed_form_law(tmp_path):
    # F(v) = F0 + F1 ln(1 + v/v1), the shape of thermally activated friction, sampled at 4 velocities
    # a decade from 1e-3 to 1e3 angstrom/s, given as a sweep's list in a shuffled order with one
    # failed point: the table reproduces the law (scaled) to the interpolation's error.  That error
    # is the monotone cubic's on these rows, which SciPy's PchipInterpolator of the same rows has
    # too (measured: 5.1e-5 of F at most, where the curve bends; the law and SciPy 3e-16 apart); the
    # bound is it, plus rounding.
    f0, f1, v1 = 0.2, 0.05, 0.3                      # nN, nN, angstrom/s
    grid = np.logspace(-3, 3, 25)
    closed = lambda a: f0 + f1 * np.log1p(a / v1)    # noqa: E731 (angstrom/s -> nN)
    order = np.random.default_rng(3).permutation(grid.size)
    values = np.append(grid[order], 5.0)
    friction_nn = np.append(closed(grid[order]), np.nan)
    status = np.append(np.ones(grid.size, dtype=np.int32), 2)
    path = tmp_path / "curve.h5"
    write_sweep(path, values, friction_nn, status)
    probe = np.logspace(-3, 3, 601)[1:-1] * 1e-10     # m/s, inside the rows
    with Law("table", table_file=str(path), scale=200.0) as law:
        law.check()
        force, _ = law.history(probe, probe)
    exact = 200.0 * closed(probe * 1e10) * 1e-9
    pchip = 200.0 * PchipInterpolator(np.log(grid * 1e-10), closed(grid) * 1e-9)(np.log(probe))
    bound = np.max(np.abs(pchip - exact))
    error = np.max(np.abs(force - exact))
    assert error <= bound * (1 + 1e-9) + 1e-15 * np.max(exact), (error, bound)
    assert bound < 1e-4 * np.max(exact)


def test_sweep_table_refusals(tmp_path):
    other = tmp_path / "other.h5"
    write_sweep(other, [1.0, 2.0], [0.1, 0.2], [1, 1], variable="surface.v0")
    with Law("table", table_file=str(other)) as law:
        with pytest.raises(friction.FrictionError, match=r"&law: table_file = .*a sweep of 'surface.v0'"):
            law.check()
    few = tmp_path / "few.h5"
    write_sweep(few, [1.0, 2.0], [0.1, 0.2], [1, 2])
    with Law("table", table_file=str(few)) as law:
        with pytest.raises(friction.FrictionError, match="1 points done; a table needs at least 2"):
            law.check()


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


def test_gms_hysteresis_loop_against_radau():
    # The Generalized Maxwell-Slip law (the 4 default elements, Table I's Stribeck curve) under
    # x = A sin(2πft) from rest, A beyond every element's break-away deflection and the peak speed
    # 2 v_s, so that elements stick, slip while the curve falls and relax at the rate C.  The
    # oracle: the same equations written here, each interval (constant velocity) integrated by
    # SciPy's Radau at rtol 1e-11, an element's switch from stick to slip located as a terminal
    # event (the right-hand side is smooth between switches).  The library integrates at rtol 1e-9
    # of each element's break-away deflection, a bound of 1.5e-9 N on each element's force; measured
    # 1.2e-11 N, and 1e-8 N leaves room for the entry band (1e-5 of a limit over 1e-5 of its
    # deflection, gone within a sample) without letting a wrong branch (0.1 N) pass.
    k = np.array([4e4, 3e4, 2e4, 1e4])
    w = np.array([0.1, 0.2, 0.3, 0.4])
    c, sigma2 = 20.0, 0.4
    scale = w * 1.5 / k

    def interval(z, v, t0, t1):
        s = np.sign(v)
        limit = w * stribeck(v)
        slipping = (v != 0) & (k * z * s >= limit)
        while True:
            def rhs(_, y):
                return np.where(slipping, c / k * (s - k * y * scale / limit), v) / scale
            events = []
            for i in np.flatnonzero(~slipping) if v != 0 else []:
                def reaches(_, y, i=i):
                    return k[i] * y[i] * scale[i] * s - limit[i]
                reaches.terminal, reaches.direction = True, 1
                events.append((i, reaches))
            sol = solve_ivp(rhs, (t0, t1), z / scale, method="Radau", rtol=1e-11, atol=1e-13,
                            events=[e for _, e in events] or None)
            z = sol.y[:, -1] * scale
            if sol.status != 1:
                return z
            for (i, _), hit in zip(events, sol.t_events):
                if hit.size:
                    slipping[i] = True
                    z[i] = s * limit[i] / k[i]
                    t0 = hit[0]

    amplitude, frequency = 1e-4, 3.2
    t = np.linspace(0.0, 1.25 / frequency, 501)
    x = amplitude * np.sin(2 * np.pi * frequency * t)
    with Law("gms", sigma2=sigma2, attraction=c) as law:
        assert law.state_count == 4
        # A rest sample first: the states start at rest (steady sliding at velocity 0).
        force, states = law.history(np.concatenate([[-1e-3], t]), np.concatenate([[0.0], x]), displacement=True)
    force, states = force[1:], states[1:]
    z = np.zeros(4)
    expected = [0.0]
    for i in range(1, t.size):
        v = (x[i] - x[i - 1]) / (t[i] - t[i - 1])
        z = interval(z, v, t[i - 1], t[i])
        expected.append(np.sum(k * z) + sigma2 * v)
    np.testing.assert_allclose(force[1:], expected[1:], rtol=0, atol=1e-8)
    # A loop, not a curve: at x = 0 the force on the way up and on the way down differ by about 2 F_s.
    assert force[np.argmin(np.abs(x[200:300])) + 200] < -1.0 < 1.0 < force[np.argmin(np.abs(x[350:450])) + 350]
