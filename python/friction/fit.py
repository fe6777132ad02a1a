"""Fitting the model of the microscope to a measured scan line: the paper's
use of the software (adjust the model to a friction image).

    cfg = friction.Config("afm", values=friction.fit.NAF_LINE)
    result = friction.fit.fit_line(measured_fx, cfg, {"surface.v0": 0.5, ("tip.kx", "tip.ky"): 12.0})
    result.values      # {"surface.v0": 0.8013..., ("tip.kx", "tip.ky"): 6.0157...}

The search is Nelder-Mead over the logarithms of the parameters (positive
by construction), in numpy: scipy is not needed.  Each evaluation is one
line of the C API (friction_afm_line) on this process.
"""
from dataclasses import dataclass, field

import numpy as np

from ._run import Config

__all__ = ["fit_line", "nelder_mead", "FitResult", "example", "NAF_LINE"]

# One line of a NaF map: the scene's defaults (inputs/naf.nml's values) but these.
NAF_LINE = {"surface.potential": "naf", "scan.angle": 0.0, "scan.length": 20.0, "scan.nx": 128, "scan.ny": 1,
            "scan.retrace": False, "integrator.method": "rkf45", "integrator.rtol": 1.0e-6,
            "integrator.atol": 1.0e-7}


def nelder_mead(f, x0, step=0.2, tolerance=1e-6, max_evaluations=400):
    """Minimise f from x0 (standard reflection/expansion/contraction/shrink).
    Returns (x, f(x), evaluations)."""
    n = len(x0)
    simplex = [np.asarray(x0, float)] + [np.asarray(x0, float) + step * np.eye(n)[i] for i in range(n)]
    values = [f(x) for x in simplex]
    evaluations = n + 1
    while evaluations < max_evaluations:
        order = np.argsort(values)
        simplex = [simplex[i] for i in order]
        values = [values[i] for i in order]
        if abs(values[-1] - values[0]) <= tolerance * (abs(values[0]) + 1e-30) and \
                max(np.max(np.abs(x - simplex[0])) for x in simplex[1:]) < 1e-6:
            break
        centroid = np.mean(simplex[:-1], axis=0)
        reflected = centroid + (centroid - simplex[-1])
        f_reflected = f(reflected)
        evaluations += 1
        if f_reflected < values[0]:
            expanded = centroid + 2.0 * (centroid - simplex[-1])
            f_expanded = f(expanded)
            evaluations += 1
            simplex[-1], values[-1] = (expanded, f_expanded) if f_expanded < f_reflected else \
                (reflected, f_reflected)
        elif f_reflected < values[-2]:
            simplex[-1], values[-1] = reflected, f_reflected
        else:
            contracted = centroid + 0.5 * (simplex[-1] - centroid)
            f_contracted = f(contracted)
            evaluations += 1
            if f_contracted < values[-1]:
                simplex[-1], values[-1] = contracted, f_contracted
            else:
                for i in range(1, n + 1):
                    simplex[i] = simplex[0] + 0.5 * (simplex[i] - simplex[0])
                    values[i] = f(simplex[i])
                evaluations += n
    best = int(np.argmin(values))
    return simplex[best], values[best], evaluations


@dataclass
class FitResult:
    """values: the fitted parameters, keyed as `start` was; residual: the sum
    of squared differences (nN^2); rms: its root mean square per sample (nN);
    evaluations: lines computed; line: the fitted model's line."""

    values: dict
    residual: float
    rms: float
    evaluations: int
    line: np.ndarray = field(repr=False)


def _names(key):
    return (key,) if isinstance(key, str) else tuple(key)


def fit_line(measured, config, start, component="fx", line=0, forward=True, step=0.2, tolerance=1e-6,
             max_evaluations=400):
    """Fit parameters of `config` (a friction.Config of scene "afm") so that
    its scan line matches `measured` (nN at the scan.nx support positions).

    start      {parameter: starting value}; a parameter is "group.variable"
               or a tuple of them that share one value (("tip.kx", "tip.ky"));
               values must be positive (the search is over their logarithms)
    component  "fx" or "fy": the force compared
    line, forward  the line of the map and its direction
    step, tolerance, max_evaluations  of the Nelder-Mead search (nelder_mead)
    The configuration is left at the fitted values.  Returns a FitResult."""
    if component not in ("fx", "fy"):
        raise ValueError(f"component must be 'fx' or 'fy', not {component!r}")
    keys = list(start)
    if not keys:
        raise ValueError("start names no parameter")
    x0 = [float(start[k]) for k in keys]
    if min(x0) <= 0:
        raise ValueError("the starting values must be positive (the search is over their logarithms)")
    measured = np.asarray(measured, dtype=float)

    def model(p):
        for key, value in zip(keys, np.exp(p)):
            for name in _names(key):
                config.set(name, float(value))
        return getattr(config.afm_line(line, forward), component)

    def cost(p):
        values = model(p)
        if values.shape != measured.shape:
            raise ValueError(f"the model's line has {values.size} samples, the measured one {measured.size}")
        return float(np.sum((values - measured) ** 2))

    best, residual, evaluations = nelder_mead(cost, np.log(x0), step, tolerance, max_evaluations)
    fitted = model(best)
    return FitResult({k: float(v) for k, v in zip(keys, np.exp(best))}, residual,
                     float(np.sqrt(residual / measured.size)), evaluations, fitted)


def example(true=(0.8, 6.0), start=(0.5, 12.0), noise=0.05, seed=8):
    """The fit of scripts/fit_example.py: a NaF line (NAF_LINE) computed for
    V0 = true[0] eV and k = kx = ky = true[1] N/m, plus Gaussian noise of
    `noise` nN (numpy's default_rng(seed)), fitted from V0 = start[0],
    k = start[1].  Returns (FitResult, measured line)."""
    with Config("afm", values=NAF_LINE) as cfg:
        cfg.set("surface.v0", true[0]).set("tip.kx", true[1]).set("tip.ky", true[1])
        measured = cfg.afm_line(0).fx
        measured = measured + noise * np.random.default_rng(seed).standard_normal(measured.size)
        result = fit_line(measured, cfg, {"surface.v0": start[0], ("tip.kx", "tip.ky"): start[1]})
    return result, measured
