"""The parameter fit: the paper's use of the software (friction.fit)."""
import numpy as np
import pytest

from conftest import INPUTS

# A small NaF image: 6 lines of 32 samples over the paper's 20 x 20 angstrom scan, tight enough
# tolerances for the finite differences' step (docs/fitting.md).
SMALL = {"scan.nx": 32, "scan.ny": 6, "integrator.rtol": 1e-6, "integrator.atol": 1e-7}
NAF_TRUE = {"surface.v0": 0.8, "tip.kx": 6.0, "tip.ky": 6.0}


def _synthetic(friction, files, values, drift, noise_fraction, seed, channels=("trace/fx", "retrace/fx"),
               offset=0.05, calibration=1.0):
    """A "measured" image computed line by line with the support's origin moved by j * drift
    (independently of the fit's own model code), times calibration, plus offset and Gaussian
    noise of noise_fraction times the clean image's standard deviation."""
    with friction.Config("afm", files=files, values=values) as cfg:
        clean = {c: [] for c in channels}
        for j in range(int(cfg["scan.ny"])):
            cfg.set("scan.origin_x", drift[0] * j).set("scan.origin_y", drift[1] * j)
            for c in channels:
                trip, component = c.split("/")
                clean[c].append(getattr(cfg.afm_line(j, trip == "trace"), component))
    clean = {c: np.array(v) for c, v in clean.items()}
    sigma = noise_fraction * np.std(np.concatenate([v.ravel() for v in clean.values()]))
    rng = np.random.default_rng(seed)
    return {c: calibration * v + offset + sigma * rng.standard_normal(v.shape) for c, v in clean.items()}, sigma


def test_the_example_finds_the_nelder_mead_minimum(friction):
    import friction.fit
    result, measured = friction.fit.example()
    # The same minimum as the earlier hand-written Nelder-Mead search (0.8013 eV, 6.0157 N/m, rms
    # 0.0521 nN): a different method, at 0.02 standard errors of each other.
    assert round(result.values["surface.v0"], 4) == 0.8013
    assert round(result.values[("tip.kx", "tip.ky")], 4) == 6.0157
    assert round(result.rms, 4) == 0.0521
    assert result.converged and result.evaluations < 200
    assert 0.002 < result.errors["surface.v0"] < 0.006    # the Fisher prediction below: 0.0036
    assert measured.size == 128 and result.line.size == 128


def test_a_noise_free_line_is_recovered_exactly(friction):
    import friction.fit
    with friction.Config("afm", values=friction.fit.NAF_LINE) as cfg:
        cfg.set("scan.nx", 64).set("surface.v0", 0.7)
        target = cfg.afm_line(0).fx
        result = friction.fit.fit_line(target, cfg, {"surface.v0": 0.4}, tolerance=1e-12)
        assert result.values["surface.v0"] == pytest.approx(0.7, rel=1e-5)
        assert cfg["surface.v0"] == pytest.approx(0.7, rel=1e-5)   # left at the fitted value
        assert np.max(np.abs(result.line - target)) < 1e-3


def test_fit_line_refuses(friction):
    import friction.fit
    with friction.Config("afm", values=friction.fit.NAF_LINE) as cfg:
        with pytest.raises(ValueError, match="component"):
            friction.fit.fit_line(np.zeros(128), cfg, {"surface.v0": 0.5}, component="fz")
        with pytest.raises(ValueError, match="positive"):
            friction.fit.fit_line(np.zeros(128), cfg, {"surface.v0": -0.5})


@pytest.mark.parametrize("scene", ["naf", "hopg"])
def test_a_synthetic_image_is_recovered_within_three_standard_errors(friction, scene):
    import friction.fit
    if scene == "naf":
        files, true, start = [INPUTS / "naf.nml"], NAF_TRUE, {"surface.v0": 0.6, "tip.kx=tip.ky": 8.0}
        values, drift, nuisances = {**SMALL, **true}, (0.02, -0.01), ("offset", "drift_x", "drift_y")
    else:
        # The paper's HOPG (V0 = 0.5 eV, k = 25 N/m, 7 degrees) on 10 x 5 angstrom: 32 samples over 20
        # would alias its 2.46 angstrom period.  Drift along x only: across the lines the sum of
        # squares in drift_y has local minima a start at no drift falls into (docs/fitting.md).
        files, true, start = [INPUTS / "hopg.nml"], {"surface.v0": 0.5, "tip.kx": 25.0, "tip.ky": 25.0}, \
            {"surface.v0": 0.35, "tip.kx=tip.ky": 18.0}
        values = {**SMALL, **true, "scan.length": 10.0, "scan.width": 5.0}
        drift, nuisances = (0.02, 0.0), ("offset", "drift_x")
    measured, sigma = _synthetic(friction, files, values, drift, 0.02, seed=5)
    with friction.Config("afm", files=files, values=values) as cfg:
        result = friction.fit.image(measured, cfg, start, nuisances=nuisances, workers=2)
    assert result.converged, result.reason
    truth = {"surface.v0": true["surface.v0"], "tip.kx=tip.ky": true["tip.kx"], "offset": 0.05,
             "drift_x": drift[0], "drift_y": drift[1]}
    for name in result.names:
        # 3 standard errors: a 0.3 % chance per parameter for a Gaussian estimate.
        assert abs(result.values[name] - truth[name]) < 3 * result.errors[name], (name, result.summary())
    # The noise level within 10 % (its relative standard error is 1/sqrt(2 N) = 3 % for 384 pixels).
    assert result.noise == pytest.approx(sigma, rel=0.1)
    assert result.fitted["trace/fx"].shape == (6, 32) and result.residuals["retrace/fx"].shape == (6, 32)
    p = len(result.names)
    assert result.correlation.shape == (p, p) and np.allclose(np.diag(result.correlation), 1.0)


# Graphite under the Lennard-Jones tip (the lattice sum through its table): the paper's scene with
# damping (ringing after every slip makes the sampled force jump with the parameters) at the paper's
# stiff end, kx = ky = 2.5 N/m, where the tip slides without slips between samples; 4 lines of 32
# samples, tolerances tight enough for the finite differences' step (docs/fitting.md).
GRAPHITE = [INPUTS / "graphite.nml", INPUTS / "graphite_damped.nml", INPUTS / "graphite_stiff.nml"]
GRAPHITE_SMALL = {"scan.nx": 32, "scan.ny": 4, "integrator.rtol": 1e-6, "integrator.atol": 1e-6}


def test_a_graphite_image_through_the_table_is_recovered_within_three_standard_errors(friction, files):
    """The measurement is the program's map (a job on its own process, building its own table),
    plus an offset of 0.01 nN and Gaussian noise of 2 % of the map's spread (seed 3); the fit's
    model is the C API's lines on the workers, each keeping its table across the evaluations.
    From k 30 % off and the support 1 angstrom high, k, the support's height and the offset
    come back within 3 standard errors of the truth."""
    import h5py
    import friction.fit
    override = "&scan nx = 32, ny = 4 /\n&integrator rtol = 1e-6, atol = 1e-6 /\n"
    with h5py.File(files("graphite_fit", GRAPHITE, override)) as f:
        clean = {c: f[f"afm/{c}"][()] for c in ("trace/fx", "retrace/fx")}
        assert f["surface"].attrs["evaluation"] == b"table"     # the lattice sum through its table
    sigma = 0.02 * np.std(np.concatenate([v.ravel() for v in clean.values()]))
    rng = np.random.default_rng(3)
    measured = {c: v + 0.01 + sigma * rng.standard_normal(v.shape) for c, v in clean.items()}
    with friction.Config("afm", files=GRAPHITE, values=GRAPHITE_SMALL) as cfg:
        result = friction.fit.image(measured, cfg, {"tip.kx=tip.ky": 3.25, "tip.support_z": -5.0},
                                    nuisances=("offset",), workers=2)
    assert result.converged, result.reason
    truth = {"tip.kx=tip.ky": 2.5, "tip.support_z": -6.0, "offset": 0.01}
    for name in result.names:
        # 3 standard errors: a 0.3 % chance per parameter for a Gaussian estimate.
        assert abs(result.values[name] - truth[name]) < 3 * result.errors[name], (name, result.summary())
    # The noise level within 13 %: three of its relative standard errors, 1/sqrt(2 x 256) = 4.4 %.
    assert result.noise == pytest.approx(sigma, rel=0.13)


def test_the_scan_origin_is_fitted_with_a_drift(friction):
    """scan.origin_x free beside drift_x: line j starts at the fitted origin plus j x drift (the
    lines were once computed from the configuration's origin, whatever the fit's).  Noise-free,
    from 0.4 angstrom off: the truth to 1e-4 angstrom (the integrator's rtol 1e-6 on a 1 nN force)."""
    import friction.fit
    values = {**SMALL, **NAF_TRUE, "scan.ny": 3}
    with friction.Config("afm", files=[INPUTS / "naf.nml"], values={**values, "scan.origin_x": 0.5}) as cfg:
        measured = np.array([cfg.afm_line(j).fx for j in range(3)])
    with friction.Config("afm", files=[INPUTS / "naf.nml"], values=values) as cfg:
        fit = friction.fit.image(measured, cfg, {"scan.origin_x": 0.9}, nuisances=("drift_x",), workers=1)
    assert fit.values["scan.origin_x"] == pytest.approx(0.5, abs=1e-4)
    assert fit.values["drift_x"] == pytest.approx(0.0, abs=1e-4)


def test_one_process_and_a_pool_give_the_same_fit(friction):
    import friction.fit
    values = {**SMALL, **NAF_TRUE, "scan.ny": 2}
    measured, _ = _synthetic(friction, [INPUTS / "naf.nml"], values, (0.0, 0.0), 0.02, seed=2,
                             channels=("trace/fx",))
    with friction.Config("afm", files=[INPUTS / "naf.nml"], values=values) as cfg:
        fits = [friction.fit.image(measured, cfg, {"surface.v0": 0.7}, nuisances=("offset", "drift_x"), workers=w)
                for w in (1, 2)]
    # Each line is computed alone, from the same configuration: the same bits whoever computes it,
    # in whatever order (with a drift the lines are dealt out by their scan, not by image).
    for fit in fits[1:]:
        assert fit.values == fits[0].values and fit.evaluations == fits[0].evaluations


def test_the_degenerate_pair_and_what_breaks_it(friction):
    import friction.fit
    line = {"scan.nx": 64, "scan.ny": 1, "scan.retrace": False, "scan.origin_y": 1.0, "integrator.rtol": 1e-6,
            "integrator.atol": 1e-7, **NAF_TRUE}
    free = ["surface.v0", "tip.kx=tip.ky"]

    def plan(channels=("trace/fx",), **values):
        with friction.Config("afm", files=[INPUTS / "naf.nml"], values={**line, **values}) as cfg:
            return friction.fit.identifiability(cfg, free, 0.02, channels=channels, workers=1)

    single = plan()
    assert abs(single.correlation[0, 1]) > 0.9 and single.degenerate
    assert single.degenerate[0][:2] == ("surface.v0", "tip.kx=tip.ky")
    # Near the quasi-static limit a deeper corrugation and a stiffer spring give nearly the same
    # line: neither Fy nor a second angle separates them (both stay above 0.9) ...
    assert abs(plan(channels=("trace/fx", "trace/fy")).correlation[0, 1]) > 0.9
    angle = plan(**{"scan.angle": 45.0})
    assert abs(_corr(np.vstack([single.jacobian, angle.jacobian]))) > 0.9
    # ... the dynamics do: a second line 1000 times faster, where the tip's mass and damping count.
    fast = plan(**{"scan.velocity": 4.0e5})
    assert abs(_corr(np.vstack([single.jacobian, fast.jacobian]))) < 0.7


def _corr(jacobian):
    cov = np.linalg.inv(jacobian.T @ jacobian)
    return cov[0, 1] / np.sqrt(cov[0, 0] * cov[1, 1])


def test_identifiability_predicts_the_scatter_of_the_estimates(friction):
    """20 noise realizations of one NaF line fitted: the estimates' standard deviation against the
    Fisher prediction.  With 20 the sample deviation's relative standard error is 1/sqrt(38) = 16 %:
    30 % is about two of them."""
    import friction.fit
    values = {**friction.fit.NAF_LINE, "scan.nx": 64, **NAF_TRUE}
    noise = 0.05
    with friction.Config("afm", values=values) as cfg:
        plan = friction.fit.identifiability(cfg, ["surface.v0", "tip.kx=tip.ky"], noise, workers=1)
        clean = cfg.afm_line(0).fx
        rng = np.random.default_rng(11)
        estimates, errors = [], []
        for _ in range(20):
            fit = friction.fit.image(clean + noise * rng.standard_normal(clean.size), cfg,
                                     {"surface.v0": 0.8, "tip.kx=tip.ky": 6.0}, nuisances=(), workers=1)
            estimates.append([fit.values["surface.v0"], fit.values["tip.kx=tip.ky"]])
            errors.append([fit.errors["surface.v0"], fit.errors["tip.kx=tip.ky"]])
    spread = np.std(estimates, axis=0, ddof=1)
    predicted = np.array([plan.errors["surface.v0"], plan.errors["tip.kx=tip.ky"]])
    assert np.all(np.abs(spread / predicted - 1) < 0.3), (spread, predicted)
    # and each fit's own standard errors (noise estimated from its residuals) agree with the plan's
    assert np.all(np.abs(np.mean(errors, axis=0) / predicted - 1) < 0.3)
    # Each 95 % interval (1.96 standard errors) holds the truth in at least 16 of the 20 fits: the
    # lower end of Binomial(20, 0.95)'s central 99 % (scripts/fit_coverage.py counts 60 and more).
    z = (np.array(estimates) - np.array([0.8, 6.0])) / np.array(errors)
    assert np.all(np.sum(np.abs(z) < 1.959964, axis=0) >= 16), z


def test_profile_likelihood_matches_the_standard_error(friction):
    import friction.fit
    values = {**friction.fit.NAF_LINE, "scan.nx": 64, **NAF_TRUE}
    with friction.Config("afm", values=values) as cfg:
        clean = cfg.afm_line(0).fx
        measured = clean + 0.05 * np.random.default_rng(4).standard_normal(clean.size)
        fit = friction.fit.image(measured, cfg, {"surface.v0": 0.8, "tip.kx=tip.ky": 6.0}, nuisances=(),
                                 workers=1)
        grid, delta = fit.profile("surface.v0", points=5, span=2.0)
    # A locally quadratic profile is (dv / SE)^2: at +-2 SE it is 4 (20 %: the model's curvature).
    assert delta[2] == pytest.approx(0.0, abs=1e-3)
    assert delta[0] == pytest.approx(4.0, rel=0.2) and delta[-1] == pytest.approx(4.0, rel=0.2)
    assert grid[-1] > grid[0]


def test_bad_input_is_refused_clearly(friction):
    import friction.fit
    from friction._image import ImageError
    values = {**SMALL, "scan.ny": 2}
    with friction.Config("afm", files=[INPUTS / "naf.nml"], values=values) as cfg:
        with pytest.raises(ImageError, match=r"channel 'trace/fx' is 3 x 32.*scan 2 x 32 \(scan.ny x scan.nx\)"):
            friction.fit.image({"trace/fx": np.zeros((3, 32))}, cfg, ["surface.v0"], workers=1)
        with pytest.raises(ValueError, match=r"unknown free parameter 'tip.kk'"):
            friction.fit.image({"trace/fx": np.zeros((2, 32))}, cfg, ["tip.kk"], workers=1)
        with pytest.raises(ValueError, match=r"'surface.epsilon' holds 8 values .*: name one, surface.epsilon\(1\)"):
            friction.fit.image({"trace/fx": np.zeros((2, 32))}, cfg, {"surface.epsilon": 0.01}, workers=1)
        with pytest.raises(ValueError, match=r"'surface.sigma\(9\)': surface.sigma has elements 1 .. 8"):
            friction.fit.image({"trace/fx": np.zeros((2, 32))}, cfg, ["surface.sigma(9)"], workers=1)
        with pytest.raises(ValueError, match=r"unknown nuisance 'tilt'"):
            friction.fit.image({"trace/fx": np.zeros((2, 32))}, cfg, ["surface.v0"], nuisances=["tilt"], workers=1)
        with pytest.raises(ImageError, match=r"channel 'trace/fz' is not one of"):
            friction.fit.image({"trace/fz": np.zeros((2, 32))}, cfg, ["surface.v0"], workers=1)
        # NaN pixels: masked, counted and warned about; the fit of the others is unchanged.
        clean = np.array([cfg.afm_line(j).fx for j in range(2)])
        holed = clean.copy()
        holed[1, 5] = np.nan
        with pytest.warns(UserWarning, match="1 pixels are NaN or infinite: masked"):
            fit = friction.fit.image({"trace/fx": holed}, cfg, {"surface.v0": 0.9}, nuisances=(), workers=1)
        assert fit.masked == 1 and np.isnan(fit.residuals["trace/fx"][1, 5])
        assert fit.values["surface.v0"] == pytest.approx(1.0, rel=1e-5)   # the noise-free truth


def test_the_mcmc_sample_agrees_with_the_standard_errors(friction):
    """emcee's sample of one line's posterior (V0, k): its standard deviations against the
    Jacobian's standard errors, which a near-Gaussian posterior shares.  8 walkers x 150 steps,
    a quarter dropped: some 40 independent draws (autocorrelation near 20 steps), a deviation's
    relative standard error near 11 %: 35 % is three of them."""
    pytest.importorskip("emcee")
    import friction.fit
    values = {**friction.fit.NAF_LINE, "scan.nx": 32, **NAF_TRUE}
    with friction.Config("afm", values=values) as cfg:
        clean = cfg.afm_line(0).fx
        measured = clean + 0.05 * np.random.default_rng(9).standard_normal(clean.size)
        fit = friction.fit.image(measured, cfg, {"surface.v0": 0.8, "tip.kx=tip.ky": 6.0}, nuisances=(), workers=1)
        sample = fit.sample(steps=150, walkers=8, seed=1)
    assert sample.shape == (8 * (150 - 150 // 4), 2)
    ratio = np.std(sample, axis=0) / np.array([fit.errors["surface.v0"], fit.errors["tip.kx=tip.ky"]])
    assert np.all(np.abs(ratio - 1) < 0.35), ratio


def test_the_fit_pictures(friction):
    import friction.fit
    import friction.plot
    from friction._image import image_from_arrays
    values = {**SMALL, "scan.ny": 2}
    with friction.Config("afm", files=[INPUTS / "naf.nml"], values=values) as cfg:
        clean = np.array([cfg.afm_line(j).fx for j in range(2)])
        fit = friction.fit.image({"trace/fx": clean + 0.01}, cfg, {"surface.v0": 0.9}, nuisances=("offset",),
                                 workers=1)
    fig = friction.plot.fit_maps(fit)
    assert [ax.get_title() for ax in fig.axes[:3]] == ["trace/fx: measured", "trace/fx: fitted model",
                                                       f"trace/fx: residual (rms {fit.noise:.3g})"]
    np.testing.assert_allclose(fig.axes[0].images[0].get_array(), clean + 0.01)
    with pytest.raises(ValueError, match="no channel 'trace/fy'"):
        friction.plot.fit_maps(fit, "trace/fy")
    images = [image_from_arrays(np.full((2, 3), 1.0 + s), np.full((2, 3), 1.0 - s), metadata={"setpoint": (s, "V")},
                                unit="V") for s in (0.1, 0.3, 0.2)]
    fig = friction.plot.friction_load(images)
    x, y = fig.axes[0].lines[0].get_data()
    assert list(x) == [0.1, 0.2, 0.3] and np.allclose(y, [0.1, 0.2, 0.3])   # friction = s by construction


def test_a_measured_image_is_fitted_along_the_scan_and_its_size_checked(friction):
    """A MeasuredImage's trace and retrace are the force along the scan: at 0 degrees fx, so
    the fit of an image made from fx recovers V0 exactly (noise-free); its size must be the
    configuration's scan; `lines` chooses the lines fitted."""
    import friction.fit
    from friction._image import ImageError, image_from_arrays
    values = {**SMALL, "scan.ny": 4}
    with friction.Config("afm", files=[INPUTS / "naf.nml"], values=values) as cfg:
        trace = np.array([cfg.afm_line(j, True).fx for j in range(4)])
        retrace = np.array([cfg.afm_line(j, False).fx for j in range(4)])
        image = image_from_arrays(trace, retrace, size=(20.0, 20.0), unit="nN")
        fit = friction.fit.image(image, cfg, {"surface.v0": 0.9}, lines=[1, 3], nuisances=(), workers=1)
        assert sorted(fit.fitted) == ["retrace/along", "trace/along"]
        assert fit.fitted["trace/along"].shape == (2, 32)
        assert fit.values["surface.v0"] == pytest.approx(1.0, rel=1e-5)
        np.testing.assert_allclose(fit.fitted["retrace/along"], retrace[[1, 3]], atol=1e-4)
        with pytest.raises(ImageError, match=r"scan is 2000 x 2000 angstrom, the configuration's 20 x 20"):
            friction.fit.image(image_from_arrays(trace, retrace, size=(2000.0, 2000.0)), cfg, ["surface.v0"],
                               workers=1)


def test_compare_is_identifiability_per_scan(friction):
    import friction.fit
    line = {"scan.nx": 32, "scan.ny": 1, "scan.retrace": False, "integrator.rtol": 1e-6, "integrator.atol": 1e-7}
    with friction.Config("afm", files=[INPUTS / "naf.nml"], values=line) as cfg:
        plans = friction.fit.compare(cfg, {"0": {}, "30": {"scan.angle": 30.0, "channels": ("trace/fy",)}},
                                     ["surface.v0"], 0.02, workers=1)
        assert cfg["scan.angle"] == 0.0                       # the configuration is not changed
        alone = friction.fit.identifiability(cfg, ["surface.v0"], 0.02, workers=1)
        cfg.set("scan.angle", 30.0)
        turned = friction.fit.identifiability(cfg, ["surface.v0"], 0.02, channels=("trace/fy",), workers=1)
    assert plans["0"].errors == alone.errors and plans["30"].errors == turned.errors
    # One parameter: SE(ln V0) = noise / |dF/d ln V0|, and SE(V0) = V0 SE(ln V0), V0 = 1 eV (naf.nml).
    jac = alone.jacobian[:, 0]
    assert alone.errors["surface.v0"] == pytest.approx(1.0 * 0.02 / np.sqrt(np.sum(jac ** 2)), rel=1e-12)
