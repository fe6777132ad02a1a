"""Laws of thermally activated friction fitted to friction against velocity
(and temperature), from the program's curves or from measurements.

    import friction.thermal as thermal

    table = thermal.read_table("measured.csv")      # columns velocity, temperature, friction[, sem]
    sang = thermal.fit_sang(**table)                # F_c, beta, v_c with standard errors
    log = thermal.fit_log(**table)                  # F_0 and F_1 per temperature
    print(thermal.compare(**table))                 # both on the same points: chi^2, AIC

The two laws of the literature on atomic stick-slip at a temperature:

- Sang, Dube and Grant (PRL 87, 174301, 2001), from thermally activated
  jumps over a barrier that vanishes as (1 - F/F_c)^(3/2) near the critical
  force:  F = F_c - (beta k_B T ln(v_c / v))^(2/3)  for v < v_c,
  one F_c, beta and v_c for every temperature of the data.
- The logarithmic law of Gnecco et al. (PRL 84, 1172, 2000), from a barrier
  falling linearly with the force:  F = F_0 + F_1 ln v,  its F_0 and F_1
  fitted at each temperature of the data on its own.

Both are fitted by weighted least squares (scipy.optimize.least_squares)
with standard errors from the Jacobian (from the points' own standard errors
when they are given; otherwise scaled by the residuals, as scipy's
curve_fit does without absolute_sigma).  Units: friction in the data's
unit (nN for the program's), velocity in the data's unit (v_c comes out in
it), temperature in K; beta is in friction^(3/2) per eV.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    import os

    from numpy.typing import ArrayLike

__all__ = ["K_B", "LawFit", "sang", "log_law", "fit_sang", "fit_log", "compare", "read_table", "TableError"]

#: Boltzmann's constant, eV/K (CODATA 2018, exact).
K_B = 8.617333262e-5


class TableError(ValueError):
    """A table of measurements that cannot be fitted: the message names the file and what is wrong."""


def sang(velocity: ArrayLike, temperature: ArrayLike, f_c: float, beta: float, v_c: float) -> np.ndarray:
    """Sang et al.'s law F = F_c - (beta k_B T ln(v_c/v))^(2/3) (v < v_c).

    Parameters
    ----------
    velocity : array_like
        Support velocities (any unit; v_c comes out in it).
    temperature : array_like
        K.
    f_c : float
        F_c, in the friction's unit.
    beta : float
        1/eV.
    v_c : float
        In the velocity's unit.

    Returns
    -------
    numpy.ndarray
        F at each velocity.
    """
    v = np.asarray(velocity, float)
    return f_c - (beta * K_B * np.asarray(temperature, float) * np.log(v_c / v)) ** (2.0 / 3.0)


def log_law(velocity: ArrayLike, f_0: float, f_1: float) -> np.ndarray:
    """The logarithmic law F = F_0 + F_1 ln v (v in the data's unit).

    Parameters
    ----------
    velocity : array_like
        Support velocities (any unit; v_c comes out in it).
    f_0 : float
        F_0.
    f_1 : float
        F_1.

    Returns
    -------
    numpy.ndarray
        F at each velocity.
    """
    return f_0 + f_1 * np.log(np.asarray(velocity, float))


@dataclass
class LawFit:
    """A law fitted to points (fit_sang, fit_log make it).

    Parameters
    ----------
    law : str
        'sang' or 'log'.
    values : dict of str to float
        {parameter: estimate}.
    errors : dict of str to float
        {parameter: standard error}.
    covariance : numpy.ndarray
        Of the parameters in the order of values.
    chi2 : float
        The sum of squared weighted residuals.
    dof : int
        The degrees of freedom.
    aic : float
        Akaike's criterion chi2 + 2 k (k parameters): the smaller, the better
        the law describes the same points (with the points' own standard
        errors; without them, n ln(chi2/n) + 2 k).
    residuals : numpy.ndarray
        (friction - law) of each point, in the data's unit.
    converged : bool
        scipy's verdict.
    message : str
        scipy's message.
    temperatures : numpy.ndarray
        The temperatures of the logarithmic law's parameters (K).
    """
    law: str
    values: dict
    errors: dict
    covariance: np.ndarray
    chi2: float
    dof: int
    aic: float
    residuals: np.ndarray
    converged: bool
    message: str
    temperatures: np.ndarray = field(default_factory=lambda: np.zeros(0))

    def predict(self, velocity: ArrayLike, temperature: float | None = None) -> np.ndarray:
        """The fitted law at the given velocities (and temperature, K).

        Parameters
        ----------
        velocity : array_like
            Support velocities (any unit; v_c comes out in it).
        temperature : float, optional
            K; needed for Sang et al.'s law, and for the logarithmic law fitted at several temperatures.

        Returns
        -------
        numpy.ndarray
            The law's friction.

        Raises
        ------
        ValueError
            A temperature missing or not fitted.
        """
        if self.law == "sang":
            if temperature is None:
                raise ValueError("Sang et al.'s law needs the temperature")
            return sang(velocity, temperature, self.values["F_c"], self.values["beta"], self.values["v_c"])
        if temperature is None:
            if self.temperatures.size != 1:
                raise ValueError("the logarithmic law was fitted at several temperatures: give one")
            temperature = self.temperatures[0]
        k = _temperature_index(self.temperatures, temperature)
        return log_law(velocity, self.values[f"F_0[{k}]"], self.values[f"F_1[{k}]"])

    def summary(self) -> str:
        """The estimates with their standard errors, one per line, and the fit's quality.

        Returns
        -------
        str
            The table, one line per parameter.
        """
        lines = [f"{'Sang et al.' if self.law == 'sang' else 'logarithmic'} law: chi2 = {self.chi2:.4g} "
                 f"for {self.dof} degrees of freedom, AIC = {self.aic:.4g}"
                 + ("" if self.converged else f" (NOT CONVERGED: {self.message})")]
        for name, value in self.values.items():
            lines.append(f"  {name:10s} {value:.6g} +- {self.errors[name]:.2g}")
        if self.law == "log":
            lines += [f"  [{k}]: T = {t:g} K" for k, t in enumerate(self.temperatures)]
        return "\n".join(lines)


def _temperature_index(temperatures, temperature):
    k = np.flatnonzero(np.isclose(temperatures, float(temperature), rtol=1e-9, atol=0.0))
    if k.size == 0:
        raise ValueError(f"no fit at T = {temperature:g} K (fitted at {', '.join(f'{t:g}' for t in temperatures)})")
    return int(k[0])


def _points(velocity, friction, temperature, sem):
    v = np.asarray(velocity, float).ravel()
    f = np.asarray(friction, float).ravel()
    t = np.broadcast_to(np.asarray(300.0 if temperature is None else temperature, float), v.shape).astype(float)
    if f.shape != v.shape:
        raise ValueError(f"{v.size} velocities and {f.size} friction values")
    if sem is None:
        s, absolute = np.ones_like(v), False
    else:
        s, absolute = np.broadcast_to(np.asarray(sem, float), v.shape).astype(float), True
        if not np.all(s > 0):
            raise ValueError("every standard error must be positive")
    for name, x in (("velocity", v), ("friction", f), ("temperature", t), ("sem", s)):
        if not np.all(np.isfinite(x)):
            raise ValueError(f"a {name} is not finite")
    if not np.all(v > 0):
        raise ValueError("every velocity must be positive (the laws take its logarithm)")
    if not np.all(t > 0):
        raise ValueError("every temperature must be positive (K)")
    return v, f, t, s, absolute


def _fit(law, residuals, p0, transform, names, f, s, absolute, temperatures=np.zeros(0)):
    from scipy.optimize import least_squares
    result = least_squares(residuals, p0, xtol=1e-12, ftol=1e-12, gtol=1e-12, max_nfev=2000)
    n, k = f.size, len(p0)
    chi2 = float(np.sum(result.fun ** 2))
    dof = n - k
    jac = result.jac
    try:
        cov = np.linalg.inv(jac.T @ jac)
    except np.linalg.LinAlgError:
        cov = np.full((k, k), np.nan)
    if not absolute:
        cov = cov * (chi2 / dof if dof > 0 else np.nan)
    values, gradient = transform(result.x)
    cov = gradient @ cov @ gradient.T
    errors = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    aic = chi2 + 2 * k if absolute else n * math.log(max(chi2, 1e-300) / n) + 2 * k
    fitted_residuals = -result.fun * s
    return LawFit(law, dict(zip(names, map(float, values))), dict(zip(names, map(float, errors))), cov, chi2, dof,
                  float(aic), fitted_residuals, bool(result.success), str(result.message), temperatures)


def fit_sang(velocity: ArrayLike, friction: ArrayLike, temperature: ArrayLike | None = None,
             sem: ArrayLike | None = None) -> LawFit:
    """Sang et al.'s law through the points: F_c, beta, v_c with standard errors.

    velocity, friction: arrays (any velocity unit; v_c comes out in it);
    temperature: K, a number or an array per point (300 K when not given:
    with one temperature only beta k_B T is determined, and beta is given at
    that temperature); sem: the points' standard errors (absolute), or None.
    Internally v_c = v_max exp(e^u) keeps v_c above the fastest point and
    beta = e^b positive; the start is the best of a scan of u, where F_c and
    beta^(2/3) are linear.

    Parameters
    ----------
    velocity : array_like
        Support velocities (any unit; v_c comes out in it).
    friction : array_like
        The mean friction at each.
    temperature : array_like, optional
        K, a number or one per point (300 K when not given).
    sem : array_like, optional
        The points' standard errors (absolute).

    Returns
    -------
    LawFit
        F_c, beta, v_c with standard errors, chi2 and AIC.

    Raises
    ------
    ValueError
        Fewer than 4 points, or a point that is not finite or not positive.
    """
    v, f, t, s, absolute = _points(velocity, friction, temperature, sem)
    if v.size < 4:
        raise ValueError("Sang et al.'s law has 3 parameters: give at least 4 points")
    lv, top = np.log(v), float(np.log(v).max())

    def model(p):
        return p[0] - (math.exp(p[1]) * K_B * t * (top + math.exp(p[2]) - lv)) ** (2.0 / 3.0)

    def residuals(p):
        return (f - model(p)) / s

    def linear(u):
        x = (K_B * t * (top + math.exp(u) - lv)) ** (2.0 / 3.0)
        a = np.vstack([np.ones_like(x), -x]).T / s[:, None]
        fc, c = np.linalg.lstsq(a, f / s, rcond=None)[0]
        return np.array([fc, 1.5 * math.log(c) if c > 0 else 0.0, u])

    # ln v_c - ln v_max from 0.01 to 60 (v_c from 1 % above the fastest point to e^60 times it).
    starts = [linear(u) for u in np.linspace(math.log(0.01), math.log(60.0), 25)]
    p0 = min(starts, key=lambda p: float(np.sum(residuals(p) ** 2)))

    def transform(p):
        beta = math.exp(p[1])
        v_c = math.exp(top + math.exp(p[2]))
        gradient = np.diag([1.0, beta, v_c * math.exp(p[2])])
        return np.array([p[0], beta, v_c]), gradient

    return _fit("sang", residuals, p0, transform, ("F_c", "beta", "v_c"), f, s, absolute)


def fit_log(velocity: ArrayLike, friction: ArrayLike, temperature: ArrayLike | None = None,
            sem: ArrayLike | None = None) -> LawFit:
    """The logarithmic law F = F_0 + F_1 ln v at each temperature of the
    points: parameters F_0[k], F_1[k] for the k-th temperature (sorted),
    with standard errors; `temperatures` of the result lists them.

    Parameters
    ----------
    velocity : array_like
        Support velocities (any unit; v_c comes out in it).
    friction : array_like
        The mean friction at each.
    temperature : array_like, optional
        K, a number or one per point.
    sem : array_like, optional
        The points' standard errors (absolute).

    Returns
    -------
    LawFit
        F_0[k], F_1[k] per temperature with standard errors.

    Raises
    ------
    ValueError
        Fewer than 3 points at a temperature, or a bad point.
    """
    v, f, t, s, absolute = _points(velocity, friction, temperature, sem)
    temperatures = np.unique(t)
    which = np.searchsorted(temperatures, t)
    counts = np.bincount(which, minlength=temperatures.size)
    if np.any(counts < 3):
        bad = temperatures[counts < 3]
        raise ValueError(f"the logarithmic law needs at least 3 points at each temperature "
                         f"(T = {', '.join(f'{x:g}' for x in bad)} K has fewer)")
    lv = np.log(v)
    p0 = np.zeros(2 * temperatures.size)
    for k in range(temperatures.size):
        at = which == k
        slope, intercept = np.polyfit(lv[at], f[at], 1, w=1.0 / s[at])
        p0[2 * k:2 * k + 2] = intercept, slope

    def residuals(p):
        return (f - (p[2 * which] + p[2 * which + 1] * lv)) / s

    def transform(p):
        return p.copy(), np.eye(p.size)

    names = [f"F_{j}[{k}]" for k in range(temperatures.size) for j in (0, 1)]
    return _fit("log", residuals, p0, transform, names, f, s, absolute, temperatures)


def compare(velocity: ArrayLike, friction: ArrayLike, temperature: ArrayLike | None = None,
            sem: ArrayLike | None = None) -> dict[str, Any]:
    """Both laws on the same points: {"sang": LawFit, "log": LawFit,
    "preferred": the law of the smaller AIC}.

    Parameters
    ----------
    velocity : array_like
        Support velocities (any unit; v_c comes out in it).
    friction : array_like
        The mean friction at each.
    temperature : array_like, optional
        K.
    sem : array_like, optional
        Standard errors.

    Returns
    -------
    dict
        {"sang": LawFit, "log": LawFit, "preferred": name}.

    Raises
    ------
    ValueError
        Points either fit refuses.
    """
    fits = {"sang": fit_sang(velocity, friction, temperature, sem),
            "log": fit_log(velocity, friction, temperature, sem)}
    fits["preferred"] = min(("sang", "log"), key=lambda name: fits[name].aic)
    return fits


#: The columns of a table, and the names accepted for each (a header's words, case ignored).
COLUMNS = {"velocity": ("velocity", "v"), "temperature": ("temperature", "t"), "friction": ("friction", "f"),
           "sem": ("sem", "error", "standard_error")}


def read_table(path: str | os.PathLike[str]) -> dict[str, np.ndarray | None]:
    """A table of measured (or computed) friction: text with a header line
    naming the columns velocity, temperature, friction and optionally sem
    (any order; commas or blanks between values; lines starting with # are
    comments).  Returns {"velocity", "temperature", "friction", "sem"} as
    numpy arrays (sem None when absent), ready for fit_sang(**table).
    TableError names the file and line of what is wrong.

    Parameters
    ----------
    path : str or os.PathLike
        The table's file.

    Returns
    -------
    dict
        Arrays "velocity", "temperature", "friction", "sem" (None when absent).

    Raises
    ------
    TableError
        The file and line of what is wrong.
    """
    path = Path(path)
    try:
        text = path.read_text()
    except OSError as err:
        raise TableError(f"{path}: cannot read ({err.strerror or err})") from None
    rows, header, header_line = [], None, 0
    for number, line in enumerate(text.splitlines(), start=1):
        line = line.split("#", 1)[0].strip()
        if not line:
            continue
        words = [w for w in line.replace(",", " ").split()]
        if header is None:
            header, header_line = [w.lower() for w in words], number
            continue
        if len(words) != len(header):
            raise TableError(f"{path}:{number}: {len(words)} values, the header at line {header_line} "
                             f"names {len(header)} columns")
        try:
            rows.append([float(w) for w in words])
        except ValueError:
            raise TableError(f"{path}:{number}: not a number in {line!r}") from None
    if header is None or not rows:
        raise TableError(f"{path}: no header line and data (columns velocity, temperature, friction[, sem])")
    columns = {}
    for key, names in COLUMNS.items():
        found = [i for i, word in enumerate(header) if word in names]
        if found:
            columns[key] = found[0]
        elif key != "sem":
            raise TableError(f"{path}:{header_line}: no column {key!r} in the header ({', '.join(header)})")
    data = np.array(rows)
    table = {key: data[:, i] for key, i in columns.items()}
    table.setdefault("sem", None)
    for key in ("velocity", "temperature") + (("sem",) if table["sem"] is not None else ()):
        bad = np.flatnonzero(~(table[key] > 0))
        if bad.size:
            raise TableError(f"{path}: {key} must be positive; row {bad[0] + 1} of the data has "
                             f"{table[key][bad[0]]:g}")
    if not np.all(np.isfinite(table["friction"])):
        raise TableError(f"{path}: a friction value is not finite")
    return table
