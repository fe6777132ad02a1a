"""Friction laws on their own (docs/laws.md): a law's force along a
prescribed velocity or displacement history, into numpy arrays, and the fit
of a law's parameters to measured forces with their uncertainties.

    from friction.law import Law, fit

    with Law("lugre", sigma2=0.4) as lugre:                 # the &law defaults are Table I's
        force, z = lugre.history(t, v)                      # v in m/s at the times t (s)
        force, z = lugre.history(t, x, displacement=True)   # or a displacement history (m)

    result = fit("lugre", t, v, measured, {"fs": 1.2, "vs": 2e-3}, values={"sigma2": 0.4})
    result.values, result.errors                            # best values and their standard errors

Each history is one call of the C API (friction_law_history) on this
process; the states (LuGre's deflection z, rate and state's age theta) start
in steady sliding at the first velocity.  The fit is SciPy's curve_fit
(Levenberg-Marquardt, or trust-region reflective within bounds) over the
history: the covariance of the parameters is scaled by the residuals' variance
unless `sigma` gives the measurement errors (absolute_sigma).
"""
from __future__ import annotations

import ctypes
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Mapping

import numpy as np

if TYPE_CHECKING:
    import os

    from numpy.typing import ArrayLike

from . import _capi

__all__ = ["Law", "fit", "FitResult", "LAWS"]

LAWS = ("coulomb", "arctan", "stribeck", "karnopp", "dahl", "lugre", "elastoplastic", "rate_state", "table", "gms")


def _full(name):
    return name if "." in name else "law." + name


class Law:
    """A friction law by name with the &law defaults, then `values`.

    Parameters
    ----------
    model : str
        The law's name (LAWS).
    values : dict, optional
        Names of &law ("sigma0") or "group.variable" ("integrator.rtol")
        and their values.
    **more : float or bool or str
        More of them as keywords.

    Raises
    ------
    FrictionError
        An unknown law, name or bad value.
    """

    def __init__(self, model: str, values: Mapping[str, Any] | None = None, **more: Any) -> None:
        self._lib = _capi.library()
        with _capi._ErrorHandle() as err:
            self._handle = self._lib.friction_law_new(_capi._c_text(model, "model"), err.handle)
            if not self._handle:
                err.check(err.status() or 1)
        self.model = model
        for name, value in {**(values or {}), **more}.items():
            self.set(name, value)

    def close(self) -> None:
        """Free the law (also when it is collected); closing twice is harmless.
        """
        if getattr(self, "_handle", None):
            self._lib.friction_law_free(self._handle)
            self._handle = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        self.close()

    @property
    def handle(self) -> int:
        """The C API's handle of the law.

        Returns
        -------
        int
            The handle.

        Raises
        ------
        ValueError
            A closed law.
        """
        if not self._handle:
            raise ValueError("the law is closed")
        return self._handle

    def set(self, name: str, value: float | bool | str) -> None:
        """A number, True/False or text (quoted for you).

        Parameters
        ----------
        name : str
            A &law variable ("sigma0") or "group.variable".
        value : float or bool or str
            Its value.

        Raises
        ------
        friction.FrictionError
            The library's refusal: the program's message, with its status.
        """
        full = _capi._c_text(_full(name), "name")
        if isinstance(value, (int, float, np.floating, np.integer)) and not isinstance(value, (bool, np.bool_)):
            _capi._call(self._lib.friction_law_set_real, self.handle, full, float(value))
        else:
            _capi._call(self._lib.friction_law_set, self.handle, full, _capi._c_text(_capi._item(value), "value"))

    def get(self, name: str) -> str:
        """The value as namelist text ("1.0", "'lugre'").

        Parameters
        ----------
        name : str
            A &law variable or "group.variable".

        Returns
        -------
        str
            The value as namelist text.

        Raises
        ------
        friction.FrictionError
            The library's refusal: the program's message, with its status.
        """
        buf = ctypes.create_string_buffer(8192)
        _capi._call(self._lib.friction_law_get, self.handle, _capi._c_text(_full(name), "name"), buf, len(buf))
        return buf.value.decode()

    def check(self) -> None:
        """The law's checks: FrictionError naming the first bad value.

        Raises
        ------
        friction.FrictionError
            The library's refusal: the program's message, with its status.
        """
        _capi._call(self._lib.friction_law_check, self.handle)

    @property
    def state_count(self) -> int:
        """The number of the law's internal states (0 for a static law).

        Returns
        -------
        int
            The count.

        Raises
        ------
        friction.FrictionError
            The library's refusal: the program's message, with its status.
        """
        with _capi._ErrorHandle() as err:
            count = self._lib.friction_law_state_count(self.handle, err.handle)
            if count < 0:
                err.check(err.status())
        return count

    def history(self, t: ArrayLike, u: ArrayLike, normal: float = 1.0,
                displacement: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """The force (N) at the times t (s) along the velocities u (m/s) or,
        with displacement=True, the displacements u (m); and the states,
        shape (n, state_count).

        Parameters
        ----------
        t : array_like
            Times (s), increasing.
        u : array_like
            Velocities (m/s), or displacements (m) with displacement=True.
        normal : float
            The normal load (N).
        displacement : bool
            Whether u holds displacements.

        Returns
        -------
        force : numpy.ndarray
            The friction force (N), shape (n,).
        states : numpy.ndarray
            The law's states, shape (n, state_count).

        Raises
        ------
        ValueError
            t and u not 1-D arrays of one length.
        friction.FrictionError
            The library's refusal: the program's message, with its status.
        """
        t = np.ascontiguousarray(t, dtype=float)
        u = np.ascontiguousarray(u, dtype=float)
        if t.ndim != 1 or u.shape != t.shape:
            raise ValueError("t and u must be 1-D arrays of one length")
        n = t.size
        count = self.state_count
        force = np.empty(n)
        states = np.empty((n, count))
        _capi._call(self._lib.friction_law_history, self.handle, float(normal), t.ctypes.data, u.ctypes.data, n,
                    1 if displacement else 0, force.ctypes.data, states.ctypes.data if count else None,
                    states.size)
        return force, states


@dataclass
class FitResult:
    """A law's fit to a measured force (friction.law.fit makes it).

    Parameters
    ----------
    values : dict of str to float
        Best values.
    errors : dict of str to float
        Their standard errors (the covariance's diagonal).
    covariance : numpy.ndarray
        Rows and columns in the order of values.
    residuals : numpy.ndarray
        Measured - model (N).
    evaluations : int
        Histories evaluated.
    """
    values: dict
    errors: dict
    covariance: np.ndarray
    residuals: np.ndarray
    evaluations: int


def fit(model: str, t: ArrayLike, u: ArrayLike, force: ArrayLike, start: Mapping[str, float],
        values: Mapping[str, Any] | None = None, normal: float = 1.0, displacement: bool = False,
        sigma: ArrayLike | None = None, bounds: Mapping[str, tuple[float, float]] | None = None) -> FitResult:
    """Fit the &law parameters named in `start` ({name: first guess}) of the
    law `model` to the measured `force` along the history (t, u) (see
    Law.history); `values` fixes other parameters.  `sigma`: the measurement's
    standard errors (absolute), else the residuals' scatter sets the errors.
    `bounds`: {name: (low, high)}.  SciPy's curve_fit does the search.

    Parameters
    ----------
    model : str
        The law's name (LAWS).
    t : array_like
        Times (s).
    u : array_like
        Velocities (m/s) or displacements (m), as Law.history.
    force : array_like
        The measured force (N) at t.
    start : dict of str to float
        {parameter: first guess} of the parameters fitted.
    values : dict, optional
        Other &law parameters, fixed.
    normal : float
        The normal load (N).
    displacement : bool
        Whether u holds displacements.
    sigma : array_like, optional
        The measurement's standard errors (absolute); else the residuals' scatter sets the errors.
    bounds : dict of str to (float, float), optional
        {name: (low, high)}.

    Returns
    -------
    FitResult
        Best values, standard errors, covariance, residuals.

    Raises
    ------
    friction.FrictionError
        The library's refusal: the program's message, with its status.
    RuntimeError
        scipy's curve_fit finds no minimum.

    Examples
    --------
    >>> result = fit("lugre", t, v, force, {"fs": 1.4, "vs": 2e-3})  # doctest: +SKIP
    """
    from scipy.optimize import curve_fit   # only a fit needs SciPy

    names = list(start)
    evaluations = 0
    with Law(model, values) as law:
        def model_force(_, *parameters):
            nonlocal evaluations
            for name, value in zip(names, parameters):
                law.set(name, value)
            evaluations += 1
            return law.history(t, u, normal=normal, displacement=displacement)[0]

        options = {}
        if bounds:   # trust-region reflective, which scales the steps by the Jacobian
            options = {"bounds": ([bounds.get(name, (-np.inf, np.inf))[0] for name in names],
                                  [bounds.get(name, (-np.inf, np.inf))[1] for name in names]),
                       "x_scale": "jac"}
        best, covariance = curve_fit(model_force, np.asarray(t, float), np.asarray(force, float),
                                     p0=[start[name] for name in names], sigma=sigma,
                                     absolute_sigma=sigma is not None, **options)
        residuals = np.asarray(force, float) - model_force(None, *best)
    errors = np.sqrt(np.diag(covariance))
    return FitResult(dict(zip(names, best)), dict(zip(names, errors)), covariance, residuals, evaluations)
