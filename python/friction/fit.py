"""Fitting the model of the microscope to a measured friction image: the
paper's use of the software (determine the microscope's parameters from an
experimental image), with the uncertainty of each parameter.

    measured = friction.read_image("scan.npz")          # or {"trace/fx": (ny, nx) array, ...}
    cfg = friction.Config("afm", files=["inputs/naf.nml"], values={"scan.nx": 64, "scan.ny": 64})
    result = friction.fit.image(measured, cfg, free={"surface.v0": 0.5, "tip.kx=tip.ky": 12.0})
    result.values["surface.v0"], result.errors["surface.v0"]   # estimate and standard error
    result.correlation          # (p, p) over result.names
    result.converged, result.evaluations, result.reason
    result.fitted, result.residuals                             # {"trace/fx": (ny, nx), ...}
    result.profile("surface.v0")                                # the profile likelihood on request
    result.sample(steps=200)                                    # an emcee sample on request

    plan = friction.fit.identifiability(cfg, free=[...], noise=0.02)   # before the experiment
    plan.errors, plan.correlation, plan.degenerate

The least squares are scipy.optimize.least_squares (trust-region
reflective, with bounds), positive parameters in log space.  Every model
evaluation is a set of scan lines of the C API (friction_afm_line), computed
by a pool of processes, each with its own copy of the configuration; the
Jacobian's finite differences are computed together, one image per free
parameter, and its columns for the offset and calibration are exact.
"""
from __future__ import annotations

import concurrent.futures
import concurrent.futures.process
import math
import multiprocessing
import os
import re
import tempfile
import threading
import warnings
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Mapping, Sequence

import numpy as np

from . import _capi
from ._run import Config

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

    from ._image import MeasuredImage

__all__ = ["image", "identifiability", "compare", "fit_line", "FitResult", "ImageFit", "Identifiability",
           "example", "NAF_LINE", "NUISANCES"]

# One line of a NaF map: the scene's defaults (inputs/naf.nml's values) but these.
NAF_LINE = {"surface.potential": "naf", "scan.angle": 0.0, "scan.length": 20.0, "scan.nx": 128, "scan.ny": 1,
            "scan.retrace": False, "integrator.method": "rkf45", "integrator.rtol": 1.0e-6,
            "integrator.atol": 1.0e-7}

# The instrument's nuisances fitted alongside the model's parameters, with their starting values:
# measured = calibration * model + offset, the support's origin drifting drift_x, drift_y angstrom per line.
NUISANCES = {"offset": 0.0, "calibration": 1.0, "drift_x": 0.0, "drift_y": 0.0}
# Variables that may be zero or negative: fitted as they are, not through their logarithm.
_SIGNED = {"scan.angle", "scan.origin_x", "scan.origin_y", "tip.support_z"}
_CHANNEL = re.compile(r"^(trace|retrace)/(fx|fy|along|across)$")
_ELEMENT = re.compile(r"^([a-z_]+\.[a-z_0-9]+)\((\d+)\)$")   # one element of a list: surface.epsilon(2)


# ---------------------------------------------------------------- model lines, in worker processes

# The worker process's Config (a process, not a thread, per worker: a fit on two threads once got a
# malformed variable list from friction_config_names; a process keeps its library to itself).
_worker = threading.local()


def _worker_config(text, scene):
    """This thread's Config for a configuration's text (kept: a fit asks for it again and again)."""
    key = (scene, text)
    if getattr(_worker, "key", None) != key:
        with tempfile.TemporaryDirectory(prefix="friction-fit-") as folder:
            path = os.path.join(folder, "config.nml")
            with open(path, "w") as file:
                file.write(text)
            _worker.config = Config(scene, files=[path])
        _worker.key = key
        _worker.values = {}   # what this process set last: a call per line for each costs (measured)
    return _worker.config


# What a built surface depends on besides the &surface group: the scan's rectangle (a lattice
# sum's table covers it; a configuration keeps its surface while both stay as they were).
_RECTANGLE = ("scan.origin_x", "scan.origin_y", "scan.angle", "scan.length", "scan.width", "scan.lead_in")


def _lines(text, scene, items, passes):
    """The lines of `items`, [(settings, line, origin)], in their order: [{pass: (fx, fy)}] for
    each pass ("trace", "retrace").  The line is computed with the map's origin at `origin`."""
    cfg = _worker_config(text, scene)
    last = _worker.values
    out = []
    for settings, j, origin in items:
        values = {**settings, "scan.origin_x": origin[0], "scan.origin_y": origin[1]}   # the line's origin
        for name, value in values.items():
            if last.get(name) != float(value):
                cfg.set(name, float(value))
                last[name] = float(value)
        out.append({trip: _capi.Config.afm_line(cfg, int(j), trip == "trace")[:2]   # fx, fy
                    for trip in passes})
    return out


class _Lines:
    """The model's lines for many parameter sets, over a pool of processes
    (workers > 1) or on this process."""

    def __init__(self, config, lines, passes, workers):
        self.text, self.scene = config.text(), config.scene
        self.lines, self.passes = list(lines), tuple(passes)
        self.origin = (float(config.value("scan.origin_x")), float(config.value("scan.origin_y")))
        self.workers = max(1, int(workers))
        # Only a Lennard-Jones net builds a surface worth keeping (its table); the other potentials'
        # lines are computed image by image, each image's settings set once a task.
        self.lattice_sum = str(config.value("surface.potential")).strip().lower() == "lj"
        self.pool = None
        self.images = 0
        self.line_count = 0

    def _items(self, settings_list):
        """(settings, line, origin) for every line of every image, and their groups in the order
        they are computed: for a lattice sum by what its surface depends on (the &surface values
        and the line's scan), so that the lines one built table serves follow each other (the
        images of a Jacobian that move neither the surface nor the scan, a spring constant or
        the tip's height, then share their base image's table line by line when a drift moves
        each line's scan); for the other potentials image by image."""
        items, keys = [], []
        for image, (settings, drift) in enumerate(settings_list):
            start = (settings.get("scan.origin_x", self.origin[0]), settings.get("scan.origin_y", self.origin[1]))
            surface = tuple(sorted((k, v) for k, v in settings.items() if k.startswith("surface.")
                                   or (k in _RECTANGLE and not k.startswith("scan.origin"))))
            for j in self.lines:
                origin = (start[0] + drift[0] * j, start[1] + drift[1] * j)   # line j's origin moves by j * drift
                items.append((settings, j, origin))
                keys.append((surface, origin) if self.lattice_sum else image)
        order = sorted(range(len(items)), key=keys.__getitem__)   # stable: in a group, as given
        groups = []   # runs of one key in that order: the lines one surface serves
        for n in order:
            if groups and keys[groups[-1][-1]] == keys[n]:
                groups[-1].append(n)
            else:
                groups.append([n])
        return items, groups

    def _tasks(self, groups, images):
        """The groups packed into tasks in their order: about two a worker per image, of at least
        4 lines (a task's round trip costs about a line), a group split only when it is larger
        than a task (its surface then built once more)."""
        total = sum(len(g) for g in groups)
        size = math.ceil(total / max(1, min(total // 4, 2 * self.workers * images)))
        tasks, current = [], []
        for group in groups:
            while len(group) > size:
                if current:
                    tasks.append(current)
                    current = []
                tasks.append(group[:size])
                group = group[size:]
            if current and len(current) + len(group) > size:
                tasks.append(current)
                current = []
            current = current + group
        if current:
            tasks.append(current)
        return tasks

    def evaluate(self, settings_list):
        """[(settings, drift)] -> [{pass: (fx, fy)}], the lines in self.lines' order."""
        self.images += len(settings_list)
        self.line_count += len(settings_list) * len(self.lines) * len(self.passes)
        items, groups = self._items(settings_list)
        order = [n for group in groups for n in group]
        if self.workers == 1:
            done = _lines(self.text, self.scene, [items[n] for n in order], self.passes)
        else:
            if self.pool is None:
                # spawn: a fresh interpreter per worker, not a fork of one that may hold MPI or threads.
                self.pool = concurrent.futures.ProcessPoolExecutor(self.workers,
                                                                   mp_context=multiprocessing.get_context("spawn"))
            tasks = self._tasks(groups, len(settings_list))
            order = [n for task in tasks for n in task]
            futures = [self.pool.submit(_lines, self.text, self.scene, [items[n] for n in task], self.passes)
                       for task in tasks]
            try:
                done = [line for future in futures for line in future.result()]
            except concurrent.futures.process.BrokenProcessPool:
                self.close()
                raise RuntimeError("friction.fit: a worker process stopped before its lines were computed. "
                                   "The workers are spawned, each importing the main module again: a script "
                                   "must call friction.fit under `if __name__ == \"__main__\":` (or pass "
                                   "workers=1)") from None
        lines = [None] * len(items)
        for n, line in zip(order, done):
            lines[n] = line
        per = len(self.lines)
        results = []
        for i in range(len(settings_list)):
            mine = lines[i * per:(i + 1) * per]
            results.append({trip: (np.array([line[trip][0] for line in mine]),
                                   np.array([line[trip][1] for line in mine])) for trip in self.passes})
        return results

    def close(self):
        if self.pool is not None:
            self.pool.shutdown()
            self.pool = None


def _default_workers():
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:
        return os.cpu_count() or 1


# ---------------------------------------------------------------- the problem: parameters, data, residuals

def _names(key):
    if isinstance(key, str):
        return tuple(part.strip() for part in key.split("="))
    return tuple(key)


def _label(names):
    return "=".join(names)


@dataclass
class _Parameter:
    label: str
    names: tuple       # the configuration's variables set to this value; () for a nuisance
    start: float
    log: bool
    lower: float
    upper: float


def _channels_of(measured, path=""):
    """{channel: (ny, nx) array} from a MeasuredImage, a dict or an array."""
    from ._image import ImageError, MeasuredImage
    if isinstance(measured, MeasuredImage):
        data = {"trace/along": measured.trace}
        if measured.retrace is not None:
            data["retrace/along"] = measured.retrace
        return data, measured.path or "the measured image"
    if isinstance(measured, dict):
        data = {}
        for key, value in measured.items():
            if not _CHANNEL.match(key):
                raise ImageError(f"the measured image: channel {key!r} is not one of trace|retrace / "
                                 "fx|fy|along|across")
            value = np.asarray(value, dtype=float)
            data[key] = value[None, :] if value.ndim == 1 else value   # one line
        if not data:
            raise ImageError("the measured image has no channel")
        return data, "the measured image"
    array = np.asarray(measured, dtype=float)
    return {"trace/fx": array if array.ndim == 2 else array[None, :]}, "the measured image"


def _check_size(measured, config, where):
    """A measured image's scan size (when its file gives one) must be the configuration's."""
    from ._image import ImageError, MeasuredImage
    if not isinstance(measured, MeasuredImage) or not all(math.isfinite(v) for v in measured.size):
        return
    planned = (float(config.value("scan.length")), float(config.value("scan.width")))
    if any(abs(m - p) > 1e-3 * max(abs(p), 1e-12) for m, p in zip(measured.size, planned)):
        raise ImageError(f"{where}: the image's scan is {measured.size[0]:g} x {measured.size[1]:g} angstrom, the "
                         f"configuration's {planned[0]:g} x {planned[1]:g} (scan.length x scan.width)")


class _Problem:
    """The residuals and their Jacobian for a configuration, free parameters,
    nuisances and a (measured or planned) image."""

    def __init__(self, config, free, data, where, lines, nuisances, bounds, workers, step):
        from ._image import ImageError
        if config.scene != "afm":
            raise ValueError(f"fitting needs a configuration of scene 'afm', not {config.scene!r}")
        self.config = config
        self.where = where
        known = {name for name, *_ in config.names()}
        nx, ny = int(config.value("scan.nx")), int(config.value("scan.ny"))
        self.lines = list(range(ny)) if lines is None else [int(j) for j in lines]
        for j in self.lines:
            if not 0 <= j < ny:
                raise ValueError(f"line {j} out of range: the configuration's scan has lines 0 .. {ny - 1}")
        # ---- free parameters
        if isinstance(free, str):
            free = [free]
        if not isinstance(free, dict):
            free = {key: None for key in free}
        if not free:
            raise ValueError("free names no parameter")
        bounds = dict(bounds or {})
        self.parameters = []
        for key, start in free.items():
            names = _names(key)
            kinds = config.kinds()
            for name in names:
                match = _ELEMENT.match(name)
                base, index = (match.group(1), int(match.group(2))) if match else (name, None)
                if base not in known:
                    raise ValueError(f"unknown free parameter {name!r}: not a variable of scene 'afm' "
                                     "(group.variable, as Config.names() lists them)")
                kind, size = kinds[base][0], kinds[base][1]
                if kind != "real":
                    raise ValueError(f"free parameter {name!r} is not a real number")
                if index is None and size > 1:
                    raise ValueError(f"free parameter {name!r} holds {size} values (a species table): name "
                                     f"one, {name}(1) .. {name}({size})")
                if index is not None and not 1 <= index <= size:
                    raise ValueError(f"free parameter {name!r}: {base} has elements 1 .. {size}")
            label = _label(names)
            value = float(config.value(names[0]) if start is None else start)
            log = names[0] not in _SIGNED
            if log and not value > 0:
                raise ValueError(f"free parameter {label}: the starting value {value} must be positive "
                                 "(it is fitted through its logarithm)")
            low, high = bounds.pop(label, bounds.pop(key, (value / 1e3, value * 1e3) if log else (-np.inf, np.inf)))
            self.parameters.append(_Parameter(label, names, value, log, float(low), float(high)))
        nuisances = dict.fromkeys(nuisances) if not isinstance(nuisances, dict) else dict(nuisances)
        for name, start in nuisances.items():
            if name not in NUISANCES:
                raise ValueError(f"unknown nuisance {name!r}: one of {sorted(NUISANCES)}")
            low, high = bounds.pop(name, (-np.inf, np.inf))
            self.parameters.append(_Parameter(name, (), float(NUISANCES[name] if start is None else start), False,
                                              float(low), float(high)))
        if bounds:
            raise ValueError(f"bounds for {sorted(bounds)}, which are not free")
        self.labels = [p.label for p in self.parameters]
        self.model_parameters = [p for p in self.parameters if p.names or p.label.startswith("drift")]
        # ---- data
        self.data = {}
        for key, array in data.items():
            if array.ndim != 2:
                raise ImageError(f"{where}: channel {key!r} has {array.ndim} dimensions, not 2 (lines x samples)")
            if array.shape[1] != nx or array.shape[0] not in (ny, len(self.lines)):
                raise ImageError(f"{where}: channel {key!r} is {array.shape[0]} x {array.shape[1]} (lines x samples)"
                                 f", the configuration's scan {ny} x {nx} (scan.ny x scan.nx)"
                                 + ("" if lines is None else f" or {len(self.lines)} x {nx} for the lines chosen"))
            self.data[key] = array[self.lines] if array.shape[0] == ny and len(self.lines) != ny else array
        self.channels = sorted(self.data)
        if any(c.startswith("retrace") for c in self.channels) and not bool(config.value("scan.retrace")):
            raise ImageError(f"{where}: a retrace channel is measured but the configuration has scan.retrace off")
        self.mask = {c: np.isfinite(self.data[c]) for c in self.channels}
        self.masked = int(sum(m.size - np.count_nonzero(m) for m in self.mask.values()))
        if self.masked:
            warnings.warn(f"{where}: {self.masked} pixels are NaN or infinite: masked, not fitted", stacklevel=3)
        self.count = int(sum(np.count_nonzero(m) for m in self.mask.values()))
        if self.count <= len(self.parameters):
            raise ImageError(f"{where}: {self.count} valid pixels for {len(self.parameters)} parameters")
        passes = sorted({c.split("/")[0] for c in self.channels}, reverse=True)
        self.engine = _Lines(config, self.lines, passes, workers)
        self.step = float(step)
        self.angle0 = float(config.value("scan.angle"))
        self._cache = {}

    # ---- parameter vectors
    def start(self):
        return np.array([math.log(p.start) if p.log else p.start for p in self.parameters])

    def bounds(self):
        lower = [math.log(p.lower) if p.log else p.lower for p in self.parameters]
        upper = [math.log(p.upper) if p.log else p.upper for p in self.parameters]
        return np.array(lower), np.array(upper)

    def values(self, x):
        return {p.label: (math.exp(v) if p.log else float(v)) for p, v in zip(self.parameters, x)}

    def _setting(self, x):
        values = self.values(x)
        settings = {}
        for p in self.parameters:
            for name in p.names:
                settings[name] = values[p.label]
        return settings, (values.get("drift_x", 0.0), values.get("drift_y", 0.0))

    def _raw(self, results, settings):
        """{channel: (lines, nx)} of the model (no offset or calibration) from the lines' fx, fy."""
        angle = math.radians(settings.get("scan.angle", self.angle0))
        out = {}
        for channel in self.channels:
            trip, component = channel.split("/")
            fx, fy = results[trip]
            out[channel] = {"fx": fx, "fy": fy, "along": fx * math.cos(angle) + fy * math.sin(angle),
                            "across": -fx * math.sin(angle) + fy * math.cos(angle)}[component]
        return out

    def raw_images(self, xs):
        """The model's raw images at each parameter vector of xs (cached by vector)."""
        keys = [np.asarray(x, float).tobytes() for x in xs]
        todo = [(k, x) for k, x in zip(keys, xs) if k not in self._cache]
        if todo:
            settings = [self._setting(x) for _, x in todo]
            for (k, _), setting, result in zip(todo, settings, self.engine.evaluate(settings)):
                self._cache[k] = self._raw(result, setting[0])
        images = [self._cache[k] for k in keys]
        if len(self._cache) > 64:   # the last iterations' images are all a fit asks for again
            self._cache = dict(list(self._cache.items())[-32:])
        return images

    def _affine(self, x):
        values = self.values(x)
        return values.get("calibration", 1.0), values.get("offset", 0.0)

    def model(self, x, raw=None):
        raw = raw or self.raw_images([x])[0]
        scale, offset = self._affine(x)
        return {c: scale * raw[c] + offset for c in self.channels}

    def _flat(self, images):
        return np.concatenate([images[c][self.mask[c]] for c in self.channels])

    def residuals(self, x):
        model = self.model(x)
        return self._flat(model) - self._flat(self.data)

    def _delta(self, i, x):
        p = self.parameters[i]
        return self.step if p.log else self.step * max(1.0, abs(x[i]))

    def jacobian(self, x):
        """Forward differences for the model's parameters and the drifts (all
        their images in one batch), exact columns for offset and calibration."""
        x = np.asarray(x, float)
        varied = [i for i, p in enumerate(self.parameters) if p.names or p.label.startswith("drift")]
        shifted = []
        for i in varied:
            y = x.copy()
            y[i] += self._delta(i, x)
            shifted.append(y)
        images = self.raw_images([x] + shifted)
        base = self._flat(images[0])
        scale, _ = self._affine(x)
        columns = np.empty((base.size, len(self.parameters)))
        for i, image in zip(varied, images[1:]):
            columns[:, i] = scale * (self._flat(image) - base) / self._delta(i, x)
        for i, p in enumerate(self.parameters):
            if p.label == "offset":
                columns[:, i] = 1.0
            elif p.label == "calibration":
                columns[:, i] = base
        return columns

    def close(self):
        self.engine.close()

    def unflatten(self, flat):
        out, at = {}, 0
        for c in self.channels:
            image = np.full(self.data[c].shape, np.nan)
            n = int(np.count_nonzero(self.mask[c]))
            image[self.mask[c]] = flat[at:at + n]
            at += n
            out[c] = image
        return out


def _covariance(jac, sigma):
    """sigma^2 (J^T J)^-1 in the fitted coordinates, and whether J^T J was singular (pseudo-inverse then)."""
    _, s, vt = np.linalg.svd(jac, full_matrices=False)
    singular = s[-1] <= s[0] * 1e-12 if s.size else True
    inverse = np.where(s > s[0] * 1e-12, 1.0 / np.maximum(s, 1e-300) ** 2, 0.0)
    return sigma ** 2 * (vt.T * inverse) @ vt, bool(singular)


def _correlation(cov):
    d = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(d, d)
    return np.where(np.isfinite(corr), corr, 0.0)


def _degenerate(labels, corr, threshold):
    return [(labels[i], labels[j], float(corr[i, j])) for i in range(len(labels)) for j in range(i + 1, len(labels))
            if abs(corr[i, j]) > threshold]


def _value_errors(problem, x, cov):
    """Standard errors of the values: for a log parameter value * SE(log) (the delta method)."""
    values = problem.values(x)
    se = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    return {p.label: (values[p.label] * s if p.log else float(s)) for p, s in zip(problem.parameters, se)}


# ---------------------------------------------------------------- fitting an image

@dataclass
class ImageFit:
    """The fit of an image (friction.fit.image makes it).

    Parameters
    ----------
    names : list of str
        The fitted parameters in order: the free ones (ties joined with
        "=": "tip.kx=tip.ky") then the nuisances.
    values : dict of str to float
        {name: estimate}.
    errors : dict of str to float
        {name: standard error} (from the Jacobian at the minimum, scaled by
        the noise level).
    correlation : numpy.ndarray
        (p, p) over names (of the fitted coordinates: logarithms for
        positive parameters).
    covariance : numpy.ndarray
        (p, p) of the fitted coordinates.
    noise : float
        The noise level: the residuals' rms, sqrt(SSR / (N - p)).
    converged : bool
        scipy's success flag.
    reason : str
        scipy's message.
    status : int
        scipy's status.
    evaluations : int
        Model images computed (those of the coarse first fit included).
    lines_computed : int
        Scan lines computed.
    cost : float
        Half the sum of squared residuals at the minimum.
    fitted : dict of str to numpy.ndarray
        {channel: (lines, nx)} the model (NaN where masked).
    residuals : dict of str to numpy.ndarray
        {channel: (lines, nx)} measured - model (NaN where masked).
    masked : int
        Pixels masked (NaN in the measurement) and not fitted.
    degenerate : list of tuple
        Pairs (a, b, correlation) with |correlation| > 0.9.
    singular : bool
        Whether J^T J was singular (errors from its pseudo-inverse).
    x : numpy.ndarray
        The minimum in the fitted coordinates.
    jacobian : numpy.ndarray
        The Jacobian there.
    _problem : object
        The fit's problem, for profile() and sample().
    """

    names: list
    values: dict
    errors: dict
    correlation: np.ndarray
    covariance: np.ndarray = field(repr=False)
    noise: float = 0.0
    converged: bool = False
    reason: str = ""
    status: int = 0
    evaluations: int = 0
    lines_computed: int = 0
    cost: float = 0.0
    fitted: dict = field(default_factory=dict, repr=False)
    residuals: dict = field(default_factory=dict, repr=False)
    masked: int = 0
    degenerate: list = field(default_factory=list)
    singular: bool = False
    x: np.ndarray = field(default=None, repr=False)
    jacobian: np.ndarray = field(default=None, repr=False)
    _problem: object = field(default=None, repr=False)

    def summary(self) -> str:
        """The estimates as a table of text.

        Returns
        -------
        str
            One row per parameter (estimate, standard error), then the noise and convergence.
        """
        rows = [f"{'parameter':<22} {'estimate':>13} {'std. error':>12}"]
        for name in self.names:
            rows.append(f"{name:<22} {self.values[name]:>13.6g} {self.errors[name]:>12.3g}")
        rows.append(f"noise {self.noise:.4g}; {'converged' if self.converged else 'NOT converged'} after "
                    f"{self.evaluations} images ({self.reason})")
        if self.degenerate:
            rows.append("degenerate: " + ", ".join(f"{a} ~ {b} ({c:+.3f})" for a, b, c in self.degenerate))
        return "\n".join(rows)

    def profile(self, name: str, points: int = 9, span: float = 3.0,
                workers: int | None = None) -> tuple[np.ndarray, np.ndarray]:
        """The profile likelihood of one parameter: at `points` values across
        estimate +- span standard errors (in the fitted coordinate), the
        others refitted.  Returns (values, delta_chi2), delta_chi2 =
        (SSR - SSR_min) / noise^2: the 68 % interval is where it is below 1.

        Parameters
        ----------
        name : str
            One of names.
        points : int
            Values of the parameter.
        span : float
            Standard errors on each side of the estimate.
        workers : int, optional
            Processes computing lines (default: as the fit).

        Returns
        -------
        values : numpy.ndarray
            The parameter's values.
        delta_chi2 : numpy.ndarray
            (SSR - SSR_min) / noise^2 at each.
        """
        problem = self._problem
        i = self.names.index(name)
        if workers is not None:
            problem.engine.workers = workers
        from scipy.optimize import least_squares
        sd = math.sqrt(max(self.covariance[i, i], 0.0))
        grid = self.x[i] + sd * np.linspace(-span, span, points)
        others = [k for k in range(len(self.names)) if k != i]
        lower, upper = problem.bounds()
        out = []
        try:
            for g in grid:
                def fun(y, g=g):
                    x = self.x.copy()
                    x[others] = y
                    x[i] = g
                    return problem.residuals(x)

                def jac(y, g=g):
                    x = self.x.copy()
                    x[others] = y
                    x[i] = g
                    return problem.jacobian(x)[:, others]
                fit = least_squares(fun, self.x[others], jac=jac, bounds=(lower[others], upper[others]),
                                    x_scale="jac")
                out.append(2.0 * fit.cost)
        finally:
            problem.close()
        values = [math.exp(g) if problem.parameters[i].log else g for g in grid]
        return np.array(values), (np.array(out) - 2.0 * self.cost) / self.noise ** 2

    def sample(self, steps: int = 200, walkers: int | None = None, seed: int = 0,
               burn: int | None = None) -> np.ndarray:
        """An MCMC sample of the posterior (emcee's affine-invariant ensemble;
        flat priors within the bounds in the fitted coordinates, Gaussian
        noise of the fitted level).  Returns (steps - burn) * walkers rows of
        the values, columns in the order of names.

        Parameters
        ----------
        steps : int
            Steps of every walker.
        walkers : int, optional
            Walkers (default 2 p + 2).
        seed : int
            Seed of numpy's default_rng (the sample is reproducible).
        burn : int, optional
            Steps discarded (default steps // 4).

        Returns
        -------
        numpy.ndarray
            (steps - burn) * walkers rows of the values, columns in the order of names.

        Raises
        ------
        ImportError
            Without the emcee package.
        """
        try:
            import emcee
        except ImportError:
            raise ImportError("fit's sample() needs the Python package emcee (pip install emcee)") from None
        problem = self._problem
        p = len(self.names)
        walkers = walkers or 2 * p + 2
        lower, upper = problem.bounds()
        rng = np.random.default_rng(seed)
        sd = np.sqrt(np.clip(np.diag(self.covariance), 1e-30, None))
        start = self.x + 0.1 * sd * rng.standard_normal((walkers, p))

        def log_prob(xs):
            xs = np.atleast_2d(xs)
            inside = np.all((xs > lower) & (xs < upper), axis=1)
            out = np.full(len(xs), -np.inf)
            good = [x for x, ok in zip(xs, inside) if ok]
            if good:
                images = problem.raw_images(good)
                data = problem._flat(problem.data)
                values = [-0.5 * np.sum((problem._flat(problem.model(x, raw)) - data) ** 2) / self.noise ** 2
                          for x, raw in zip(good, images)]
                out[inside] = values
            return out

        sampler = emcee.EnsembleSampler(walkers, p, log_prob, vectorize=True)
        sampler.random_state = np.random.RandomState(int(rng.integers(2**31))).get_state()   # reproducible
        try:
            sampler.run_mcmc(start, steps)
        finally:
            problem.close()
        chain = sampler.get_chain(discard=steps // 4 if burn is None else burn, flat=True)
        logs = np.array([q.log for q in problem.parameters])
        return np.where(logs, np.exp(chain), chain)


def image(measured: MeasuredImage | Mapping[str, np.ndarray] | np.ndarray, config: Config,
          free: Mapping[str | tuple[str, ...], float | None] | Sequence[str | tuple[str, ...]],
          lines: Sequence[int] | None = None,
          nuisances: Sequence[str] | Mapping[str, float] = ("offset", "calibration", "drift_x", "drift_y"),
          bounds: Mapping[str, tuple[float, float]] | None = None, workers: int | None = None, step: float = 1e-6,
          max_evaluations: int | None = None, tolerance: float = 1e-6, coarse: int = 8) -> ImageFit:
    """Fit the configuration's parameters to a measured image by least squares.

    scipy's least_squares (trust-region reflective, with bounds), positive
    parameters through their logarithms, the Jacobian by finite differences
    computed together over a pool of processes.

    Parameters
    ----------
    measured : MeasuredImage or dict of str to numpy.ndarray or numpy.ndarray
        A MeasuredImage (trace and retrace compared with the model's force
        along the scan, "trace/along", "retrace/along"), a dict
        {"trace/fx": (ny, nx), "retrace/fy": ..., "trace/along": ...} of any of
        trace|retrace and fx|fy|along|across, or one (ny, nx) array
        ("trace/fx"); NaN pixels are masked (warned, counted in .masked).
    config : friction.Config
        Of scene "afm", whose scan (scan.nx, scan.ny) the image's shape must
        match; not changed.
    free : dict or sequence
        {parameter: start} or a list of parameters (started at the
        configuration's values); a parameter is "group.variable" or tied
        variables sharing one value, "tip.kx=tip.ky" or ("tip.kx", "tip.ky");
        fitted through their logarithm unless the variable may be signed
        (scan.angle, scan.origin_*).
    lines : sequence of int, optional
        The lines fitted (default all); measured may hold all the scan's lines
        or just these.
    nuisances : sequence of str or dict of str to float
        Of NUISANCES, a list (started at 0 offset, calibration 1, no drift) or
        {name: start}: measured = calibration * model + offset, the support
        drifting drift_x, drift_y angstrom per line along the lattice's axes;
        the noise level is always estimated (the residuals' rms).
    bounds : dict of str to (float, float), optional
        {parameter: (low, high)} in the parameter's units; positive parameters
        default to start/1000 .. start*1000.
    workers : int, optional
        Processes computing lines (default: the processors this process may
        use); 1: on this process (spawned processes: a script must guard its top
        level with `if __name__ == "__main__":`, as multiprocessing asks).
    step : float
        The finite differences' step (in log for positive parameters; 1e-6
        wants the integrator's rtol at 1e-4 or below).
    max_evaluations : int, optional
        scipy's max_nfev.
    tolerance : float
        scipy's ftol, xtol and gtol.
    coarse : int
        When more than twice this many lines are fitted, a first fit on this
        many evenly spaced lines, from which the fit of all starts (most
        iterations then cost a few lines); 0: none.

    Returns
    -------
    ImageFit
        The estimates, their standard errors and correlations, the fitted maps.

    Raises
    ------
    ValueError
        A measured image whose shape or channels do not fit the configuration,
        or an unknown parameter or nuisance.
    friction.FrictionError
        A configuration the program refuses, or a failed line.

    Examples
    --------
    >>> fit = friction.fit.image(measured, cfg, free={"surface.v0": 0.5})  # doctest: +SKIP
    >>> fit.values["surface.v0"], fit.errors["surface.v0"]  # doctest: +SKIP
    """
    from scipy.optimize import least_squares
    data, where = _channels_of(measured)
    _check_size(measured, config, where)
    problem = _Problem(config, free, data, where, lines, nuisances, bounds, workers or _default_workers(), step)
    images = lines_computed = 0
    try:
        lower, upper = problem.bounds()
        x0 = np.clip(problem.start(), lower, upper)
        if coarse and len(problem.lines) > 2 * coarse:
            rows = np.unique(np.linspace(0, len(problem.lines) - 1, int(coarse)).round().astype(int))
            with warnings.catch_warnings():   # its masked pixels were reported once, above
                warnings.simplefilter("ignore")
                first = _Problem(config, {p.label: p.start for p in problem.parameters if p.names},
                                 {c: problem.data[c][rows] for c in problem.channels}, where,
                                 [problem.lines[r] for r in rows],
                                 {p.label: p.start for p in problem.parameters if not p.names}, None,
                                 problem.engine.workers, step)
            first.engine.pool, problem.engine.pool = problem.engine.pool, None
            try:
                x0 = least_squares(first.residuals, x0, jac=first.jacobian, bounds=(lower, upper), method="trf",
                                   x_scale="jac", ftol=tolerance, xtol=tolerance, gtol=tolerance,
                                   max_nfev=max_evaluations).x
            finally:
                problem.engine.pool, first.engine.pool = first.engine.pool, None   # the same workers go on
            images, lines_computed = first.engine.images, first.engine.line_count
        fit = least_squares(problem.residuals, x0, jac=problem.jacobian, bounds=(lower, upper), method="trf",
                            x_scale="jac", ftol=tolerance, xtol=tolerance, gtol=tolerance, max_nfev=max_evaluations)
        jac = problem.jacobian(fit.x)
        residual = problem.residuals(fit.x)
    finally:
        problem.close()
    dof = max(problem.count - len(problem.parameters), 1)
    noise = float(np.sqrt(np.sum(residual ** 2) / dof))
    cov, singular = _covariance(jac, noise)
    corr = _correlation(cov)
    fitted = problem.model(fit.x)
    return ImageFit(problem.labels, problem.values(fit.x), _value_errors(problem, fit.x, cov), corr, cov, noise,
                    bool(fit.success), str(fit.message), int(fit.status), images + problem.engine.images,
                    lines_computed + problem.engine.line_count, float(fit.cost),
                    {c: np.where(problem.mask[c], fitted[c], np.nan) for c in problem.channels},
                    {c: np.where(problem.mask[c], problem.data[c] - fitted[c], np.nan) for c in problem.channels},
                    problem.masked, _degenerate(problem.labels, corr, 0.9), singular, fit.x, jac, problem)


# ---------------------------------------------------------------- identifiability before the experiment

@dataclass
class Identifiability:
    """What a planned scan would determine (friction.fit.identifiability makes it).

    Parameters
    ----------
    names : list of str
        The parameters.
    values : dict of str to float
        Their planned (true) values.
    errors : dict of str to float
        {name: standard error} from the Fisher information J^T J / noise^2
        at the planned values.
    relative : dict of str to float
        {name: error / |value|}.
    correlation : numpy.ndarray
        (p, p) over names.
    degenerate : list of tuple
        Pairs (a, b, correlation) with |correlation| above the threshold.
    pixels : int
        The samples the plan measures.
    singular : bool
        Whether the Fisher information was singular.
    jacobian : numpy.ndarray
        The Jacobian at the planned values.
    """

    names: list
    values: dict
    errors: dict
    relative: dict
    correlation: np.ndarray
    degenerate: list
    pixels: int
    singular: bool = False
    jacobian: np.ndarray = field(default=None, repr=False)


def identifiability(config: Config, free: Mapping[str, float | None] | Sequence[str] | str, noise: float,
                    channels: Sequence[str] = ("trace/fx",), lines: Sequence[int] | None = None,
                    nuisances: Sequence[str] | Mapping[str, float] = (), workers: int | None = None,
                    step: float = 1e-6, threshold: float = 0.9) -> Identifiability:
    """The Fisher-information standard errors of the free parameters for a
    planned scan: the configuration (its values are the truth), the
    channels measured (of trace|retrace / fx|fy|along|across), the noise
    level (the measured force's standard deviation, nN) and the nuisances
    fitted alongside (default none).  free and lines as for image().
    Returns an Identifiability.

    Parameters
    ----------
    config : friction.Config
        Of scene "afm": its values are the truth.
    free : dict or sequence of str or str
        The free parameters, as for image().
    noise : float
        The measured force's standard deviation (nN).
    channels : sequence of str
        The channels measured, of trace|retrace / fx|fy|along|across.
    lines : sequence of int, optional
        The lines measured (default all).
    nuisances : sequence of str or dict of str to float
        Fitted alongside, as for image() (default none).
    workers : int, optional
        Processes computing lines.
    step : float
        The finite differences' step.
    threshold : float
        |correlation| above which a pair is degenerate.

    Returns
    -------
    Identifiability
        The standard errors, relative errors and correlations.

    Raises
    ------
    ValueError
        An unknown parameter or channel.
    """
    nx, ny = int(config.value("scan.nx")), int(config.value("scan.ny"))
    rows = ny if lines is None else len(list(lines))
    data = {c: np.zeros((rows, nx)) for c in channels}
    free = {key: None for key in ([free] if isinstance(free, str) else free)} if not isinstance(free, dict) else free
    problem = _Problem(config, free, data, "the planned scan", lines, nuisances, None,
                       workers or _default_workers(), step)
    try:
        jac = problem.jacobian(problem.start())
    finally:
        problem.close()
    cov, singular = _covariance(jac, float(noise))
    corr = _correlation(cov)
    x = problem.start()
    errors = _value_errors(problem, x, cov)
    values = problem.values(x)
    relative = {k: (errors[k] / abs(values[k]) if values[k] else float("inf")) for k in errors}
    return Identifiability(problem.labels, values, errors, relative, corr, _degenerate(problem.labels, corr, threshold),
                           problem.count, singular, jac)


def compare(config: Config, scans: Mapping[str, Mapping[str, Any]], free: Mapping[str, float | None] | Sequence[str],
            noise: float, channels: Sequence[str] = ("trace/fx",), nuisances: Sequence[str] | Mapping[str, float] = (),
            workers: int | None = None) -> dict[str, Identifiability]:
    """Identifiability of several scan choices: scans = {label: {"scan.angle":
    45.0, ...}} (values set over a copy of config; a "channels" entry
    replaces the channels measured).  Returns {label: Identifiability}.

    Parameters
    ----------
    config : friction.Config
        Of scene "afm": its values are the truth.
    scans : dict of str to dict
        {label: {"scan.angle": 45.0, ..., "channels": [...]}}.
    free : dict or sequence of str
        The free parameters, as for image().
    noise : float
        The measured force's standard deviation (nN).
    channels : sequence of str
        The channels measured where a scan names none.
    nuisances : sequence of str or dict of str to float
        Fitted alongside.
    workers : int, optional
        Processes computing lines.

    Returns
    -------
    dict of str to Identifiability
        One per scan.
    """
    out = {}
    for label, values in scans.items():
        values = dict(values)
        chosen = values.pop("channels", channels)
        with _copy(config) as copy:
            for name, value in values.items():
                copy.set(name, value)
            out[label] = identifiability(copy, free, noise, chosen, None, nuisances, workers)
    return out


def _copy(config):
    """A new Config with config's values (through its namelist text)."""
    copy = Config(config.scene)
    with tempfile.TemporaryDirectory(prefix="friction-fit-") as folder:
        path = os.path.join(folder, "config.nml")
        with open(path, "w") as file:
            file.write(config.text())
        copy.read(path)
    return copy


# ---------------------------------------------------------------- one line (the first interface)

@dataclass
class FitResult:
    """The fit of one line (friction.fit.fit_line makes it).

    Parameters
    ----------
    values : dict
        The fitted parameters, keyed as `start` was.
    residual : float
        The sum of squared differences (nN^2).
    rms : float
        Its root mean square per sample (nN).
    evaluations : int
        Lines computed.
    line : numpy.ndarray
        The fitted model's line (nN).
    errors : dict
        Standard errors, keyed as values.
    converged : bool
        scipy's flag.
    reason : str
        scipy's message.
    """

    values: dict
    residual: float
    rms: float
    evaluations: int
    line: np.ndarray = field(repr=False)
    errors: dict = field(default_factory=dict)
    converged: bool = True
    reason: str = ""


def fit_line(measured: ArrayLike, config: Config, start: Mapping[str | tuple[str, ...], float], component: str = "fx",
             line: int = 0, forward: bool = True, step: float = 1e-6, tolerance: float = 1e-10,
             max_evaluations: int = 400) -> FitResult:
    """Fit parameters of a configuration so that one scan line matches a measurement.

    image() for one line and no nuisances, on this process.  The configuration
    is left at the fitted values.

    Parameters
    ----------
    measured : array_like
        nN at the scan.nx support positions.
    config : friction.Config
        Of scene "afm".
    start : dict
        {parameter: starting value}; a parameter is "group.variable" or a tuple
        of them that share one value (("tip.kx", "tip.ky")); values must be
        positive (they are fitted through their logarithms).
    component : str
        "fx" or "fy": the force compared.
    line : int
        The line of the map.
    forward : bool
        Trace (True) or retrace.
    step : float
        The finite differences' step.
    tolerance : float
        scipy least_squares' tolerances.
    max_evaluations : int
        scipy least_squares' max_nfev.

    Returns
    -------
    FitResult
        The fitted values, their errors and the fit's quality.

    Raises
    ------
    ValueError
        An unknown component, no parameter, or a starting value <= 0.
    """
    if component not in ("fx", "fy"):
        raise ValueError(f"component must be 'fx' or 'fy', not {component!r}")
    if not start:
        raise ValueError("start names no parameter")
    if min(float(v) for v in start.values()) <= 0:
        raise ValueError("the starting values must be positive (they are fitted through their logarithms)")
    measured = np.asarray(measured, dtype=float)
    channel = ("trace/" if forward else "retrace/") + component
    free = {(_label(_names(k))): float(v) for k, v in start.items()}
    result = image({channel: measured[None, :]}, config, free, lines=[line], nuisances=(), workers=1, step=step,
                   max_evaluations=max_evaluations, tolerance=tolerance)
    values = {key: result.values[_label(_names(key))] for key in start}
    for key, value in values.items():
        for name in _names(key):
            config.set(name, float(value))
    residual = 2.0 * result.cost
    return FitResult(values, residual, float(np.sqrt(residual / measured.size)), result.lines_computed,
                     result.fitted[channel][0], {key: result.errors[_label(_names(key))] for key in start},
                     result.converged, result.reason)


def example(true: tuple[float, float] = (0.8, 6.0), start: tuple[float, float] = (0.5, 12.0), noise: float = 0.05,
            seed: int = 8) -> tuple[FitResult, np.ndarray]:
    """The fit of scripts/fit_example.py: a NaF line (NAF_LINE) computed for
    V0 = true[0] eV and k = kx = ky = true[1] N/m, plus Gaussian noise of
    `noise` nN (numpy's default_rng(seed)), fitted from V0 = start[0],
    k = start[1].  Returns (FitResult, measured line).

    Parameters
    ----------
    true : tuple of float
        V0 (eV) and k (N/m) the line is computed for.
    start : tuple of float
        V0 and k the fit starts from.
    noise : float
        Standard deviation of the Gaussian noise added (nN).
    seed : int
        Seed of numpy's default_rng.

    Returns
    -------
    result : FitResult
        The fit.
    measured : numpy.ndarray
        The noisy line fitted (nN).
    """
    with Config("afm", values=NAF_LINE) as cfg:
        cfg.set("surface.v0", true[0]).set("tip.kx", true[1]).set("tip.ky", true[1])
        measured = cfg.afm_line(0).fx
        measured = measured + noise * np.random.default_rng(seed).standard_normal(measured.size)
        result = fit_line(measured, cfg, {"surface.v0": start[0], ("tip.kx", "tip.ky"): start[1]})
    return result, measured
