"""The parameter fit: the paper's use of the software."""
import numpy as np
import pytest


def test_the_example_recovers_v0_and_k(friction):
    import friction.fit
    result, measured = friction.fit.example()
    assert round(result.values["surface.v0"], 4) == 0.8013
    assert round(result.values[("tip.kx", "tip.ky")], 4) == 6.0157
    assert result.evaluations == 104
    assert round(result.rms, 4) == 0.0521
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
