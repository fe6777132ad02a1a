#!/usr/bin/env python3
"""Speed against accuracy: work-precision charts and a failure map for friction.

For each scene (NaF, HOPG, graphite, the brake's regularized law and its
switched model) every GSL stepper and the library's Rosenbrock steppers
(rodas3, rodas4) climb a ladder of tolerances;
each run's error against a far tighter reference is set against its CPU time.
Writes, into --out (default: the current directory):

  work_precision.h5             a group per scene, a group per method with the
                                datasets tolerance, atol, error, cpu_time
                                (median of the repeats), rhs_evaluations,
                                status, message; the reference and its own
                                convergence check as the scene's attributes
  work_precision_<scene>.png    error against CPU time, log-log, a line per method
  failure_map.h5, failure_map.png
                                at one asked tolerance, every method against
                                the brake's epsilon_prime (1e3 ... 1e9) and the
                                NaF tip's damping ratio (2 ... 0): ok, slow,
                                failed, or silently wrong

What is measured:

* Error, on what users look at.  AFM: the lateral force along the scan line
  (/afm/trace/f_along and /afm/retrace/f_along), largest |F - F_ref| in nN,
  on a reduced run: NaF and HOPG 8 lines (ny = 8) of 64 samples over the
  input file's 20 x 20 Å area, trace and retrace (enough work, 10 to 100 ms,
  that the 3 ms of input and set-up in wall_time do not dominate); graphite
  with inputs/graphite_damped.nml (damping ratio 0.2: the undamped tip is
  chaotic and no tolerance resolves its line), the paper's whole 24 x 128
  map, trace and retrace, through the surface table (its build, about
  0.11 s, is in every run's time; on a short scan it would be most of it).  Brake: x,
  largest |x - x_ref| in m over the window tau in [100, 1000] (the paper's
  Fig. 13 window) on an output grid of 1 tau.
* CPU time: what the program records about the integration, from the output
  file: /brake compute_time (the integration alone) and, for the AFM, the root
  attribute wall_time on one rank (input, set-up and integration, without
  MPI start-up and the write).  The median of --repeats runs (one run when
  the first takes over 2 s).  The command line, not the C API, because it has
  the max_wall_time guard, the right-hand-side counts and the graphite net.
* Reference: rk8pd far tighter than the ladder (AFM rtol = atol = 1e-12,
  graphite 1e-11, brake rtol 1e-13 / 1e-14 for the switched model), checked
  against itself at a tolerance 10x looser.  That difference is recorded as
  the scene's attribute reference_check and must lie 10x below the smallest
  error plotted (attribute reference_converged); a point whose error is
  within 10x of reference_check is kept in the file with status 'unresolved'
  and not drawn.
* Each run carries max_wall_time = --cap seconds in its namelist; a stepper
  that hits it is recorded as 'capped' and is not tried at tighter
  tolerances.  A run that does not stop on its own is killed 60 s after the
  cap ('killed').  Any other error exit is 'failed' with the program's message.

Failure map categories at the asked tolerance (rtol = 1e-6): 'failed' (error
exit other than the time cap), 'wrong' (success reported but the error is
more than 100x the asked tolerance expressed in the measured quantity:
atol + rtol max|x_ref| in m for the brake, k atol + rtol max|F_ref| in nN
for the tip, k in nN/Å), 'slow' (more than 10x the CPU time of the fastest method that
is neither failed nor wrong; the time cap counts as slow), else 'ok'.

The printed ranking behind method = 'auto' (docs/speed.md): at each rung, the
methods not silently wrong at that rtol, ordered by the CPU time they need
to reach the asked tolerance (log-log interpolation between rungs).

--extra FILE adds series measured elsewhere (e.g. a circuit simulator) to the
charts: a JSON list of {"scene": "<scene>", "label": "...", "error": [...],
"cpu_time": [...]} in the units of that scene's chart.  They are drawn dashed
in black and stored under /<scene>/extra/<label>.

--add-to DIR measures only the --methods given and adds them to the files
in DIR (work_precision.h5 and failure_map.h5), measured as the file was (its
scenes, ladders, repeats and cap), replacing those methods' earlier series;
what depends on all the methods together is computed again (the failure
map's 'slow', the ranking behind 'auto', the best method per error level)
and DIR's charts are redrawn.  The added groups carry the attribute 'added'
(when, and the program's source revision).

Usage (normally through scripts/work_precision, which builds first):

    python3 scripts/work_precision.py [--quick] [--out DIR] [--extra FILE]
                                      [--repeats N] [--cap S] [--binary PATH]
                                      [--scenes a,b] [--methods a,b] [--no-failure-map]
    python3 scripts/work_precision.py --add-to DIR --methods a,b [--scenes a,b] [--no-failure-map]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

try:
    import h5py
    import numpy as np
except ImportError as exc:  # pragma: no cover - environment problem
    sys.exit(f"work_precision: {exc}; run scripts/install-deps")

sys.path.insert(0, str(Path(__file__).resolve().parent))
# The charts are drawn by the package (python/friction/plot.py) from the files written here.
sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "python"))
import friction.plot  # noqa: E402
import benchmark_afm  # noqa: E402  (the AFM runner: env, snapshot, attributes)
import benchmark_brake  # noqa: E402  (the brake runner: namelist, compute_time, x(t))
import ngspice_compare  # noqa: E402  (the paper's network model in ngspice, as a peer)

ROOT = Path(__file__).resolve().parent.parent
INPUTS = ROOT / "inputs"
GSL_METHODS = benchmark_brake.METHODS  # all 11 GSL step types
METHODS = GSL_METHODS + ("rodas3", "rodas4")  # and the library's two Rosenbrock steppers
QUICK_METHODS = ("rkf45", "rk8pd", "rk4imp")
QUICK_TOLS = (1e-4, 1e-6, 1e-8)
REPEAT_BELOW = 2.0  # s: repeat runs faster than this (median), one run above
BRAKE_WINDOW = (100.0, 1000.0)
FAILURE_RTOL = 1e-6
EPSILON_PRIMES = tuple(10.0 ** k for k in range(3, 10))
DAMPING_RATIOS = (2.0, 1.0, 0.3, 0.1, 0.01, 0.0)
CATEGORIES = ("ok", "slow", "failed", "wrong")  # codes 0..3; -1: no reference
LEVELS = (1e-6, 1e-9)
REFERENCE_CAP = 300.0  # s: max_wall_time of the reference runs  # error levels reported in the summary (nN or m)


def log(msg: str) -> None:
    print(f"work_precision: {msg}", file=sys.stderr, flush=True)


def ladder(first: int, last: int) -> tuple[float, ...]:
    return tuple(10.0 ** -k for k in range(first, last + 1))


# --------------------------------------------------------------------------
# One run of a setting and what it gives
# --------------------------------------------------------------------------


@dataclass
class Point:
    """One setting of one method: status, error, median time, cost."""

    method: str
    rtol: float
    atol: float
    status: str  # ok, unresolved, capped, killed, failed, skipped
    message: str = ""
    error: float = math.nan
    time: float = math.nan
    rhs: int = 0
    times: list = field(default_factory=list)
    scale: float = math.nan  # the asked tolerance in the measured quantity


def classify_failure(message: str) -> str:
    if "max_wall_time" in message:
        return "capped"
    if message.startswith("killed"):
        return "killed"
    return "failed"


class AfmScene:
    """A reduced AFM run of one input file; error on f_along in nN."""

    kind = "afm"

    def __init__(self, name, input_names, reduce, tols, ref_tol, title, what):
        self.name, self.input_names, self.reduce_text = name, input_names, reduce
        self.tols, self.ref_tol, self.title, self.what = tols, ref_tol, title, what
        self.unit = "nN"
        self.quantity = "lateral force along the line, f_along"
        self.time_source = "root attribute wall_time, 1 rank"

    def setup(self, fr: benchmark_afm.Friction, cap: float, extra: str = "", tag: str = ""):
        self.fr, self.cap, self.extra, self.tag = fr, cap, extra, tag or self.name
        text = (INPUTS / self.input_names[0]).read_text()
        k = re.search(r"^\s*kx\s*=\s*([-+0-9.eEdD]+)", text, re.M)
        # 1 N/m times 1 Å is 0.1 nN: the force of an error of 1 Å in u.
        self.k_nn_per_a = float(k.group(1)) * 0.1
        self.base = [fr.inputs / n for n in self.input_names]
        self.base.append(fr.override(f"{self.tag}_reduce", self.reduce_text))
        if extra:
            self.base.append(fr.override(f"{self.tag}_extra", extra))

    def run(self, method, rtol, atol, cap=None):
        cap = cap or self.cap
        o = self.fr.override(
            f"{self.tag}_{method}_{rtol:g}",
            f"&integrator method = '{method}', rtol = {rtol!r}, atol = {atol!r}, "
            f"max_steps = 2000000000, max_wall_time = {cap!r} /")
        try:
            r = self.fr.run(self.base + [o], 1, timeout=cap + 60.0)
        except subprocess.TimeoutExpired:
            return None, f"killed: still running {cap + 60:g} s after its start"
        except RuntimeError as exc:
            msg = [ln for ln in str(exc).splitlines() if "error:" in ln]
            return None, (msg[-1].split("error:", 1)[1].strip() if msg else str(exc).splitlines()[0])
        with h5py.File(r.path, "r") as f:
            q = [f["afm/trace/f_along"][()].ravel()]
            if "afm/retrace/f_along" in f:
                q.append(f["afm/retrace/f_along"][()].ravel())
        r.path.unlink()
        return {"q": np.concatenate(q), "time": r.wall, "rhs": r.rhs}, ""

    def atol_for(self, rtol):
        return rtol

    def scale(self, ref_q, rtol, atol):
        return self.k_nn_per_a * atol + rtol * float(np.max(np.abs(ref_q)))

    @staticmethod
    def error(q, ref_q):
        return float(np.max(np.abs(q - ref_q)))


class BrakeScene:
    """The paper's brake to tau = 1000; error on x over the window, in m."""

    kind = "brake"

    def __init__(self, name, model, tols, ref_rtol, title):
        self.name, self.model, self.tols, self.ref_tol, self.title = name, model, tols, ref_rtol, title
        self.unit = "m"
        self.quantity = f"x over tau in [{BRAKE_WINDOW[0]:g}, {BRAKE_WINDOW[1]:g}]"
        self.what = f"tau in [0, {BRAKE_WINDOW[1]:g}], output every 1 tau"
        self.time_source = "/brake attribute compute_time"

    def setup(self, fr: benchmark_brake.Friction, cap: float, extra: str = "", tag: str = ""):
        self.fr, self.extra, self.cap = fr, extra, cap

    def run(self, method, rtol, atol, cap=None):
        kw = {"event_tolerance": min(1e-10, rtol / 10)} if self.model == "switched" else {}
        self.fr.max_wall = cap or self.cap
        r = self.fr.run(self.model, method, rtol, atol, BRAKE_WINDOW[1], 1.0, brake_vars=self.extra, **kw)
        if not r.ok:
            return None, r.message
        window = r.t >= BRAKE_WINDOW[0] - 1e-9
        return {"q": r.x[window], "time": r.compute_time, "rhs": r.rhs}, ""

    def atol_for(self, rtol):
        return rtol / 100

    @staticmethod
    def scale(ref_q, rtol, atol):
        return atol + rtol * float(np.max(np.abs(ref_q)))

    @staticmethod
    def error(q, ref_q):
        if q.shape != ref_q.shape:
            raise RuntimeError("output grids differ")
        return float(np.max(np.abs(q - ref_q)))


def make_scenes(quick: bool) -> dict:
    afm_tols = QUICK_TOLS if quick else ladder(3, 10)
    return {
        "naf": AfmScene("naf", ("naf.nml",), "&scan nx = 64, ny = 8 /", afm_tols, 1e-12,
                        "NaF, 8 lines, trace + retrace", "inputs/naf.nml, ny = 8, nx = 64"),
        "hopg": AfmScene("hopg", ("hopg.nml",), "&scan nx = 64, ny = 8 /", afm_tols, 1e-12,
                         "HOPG, 8 lines at 7°, trace + retrace", "inputs/hopg.nml, ny = 8, nx = 64"),
        # the failure map's NaF case: the first line alone
        "naf_line": AfmScene("naf_line", ("naf.nml",), "&scan nx = 64, ny = 1 /", afm_tols, 1e-12,
                             "NaF, one line, trace + retrace", "inputs/naf.nml, ny = 1, nx = 64"),
        # The line the SPICE netlist models (line 0, trace): ngspice's peer chart.
        "naf_trace": AfmScene("naf_trace", ("naf.nml",), "&scan nx = 64, ny = 1, retrace = .false. /", afm_tols,
                              1e-12, "NaF, line 0, trace only (the SPICE netlist's line)",
                              "inputs/naf.nml, ny = 1, nx = 64, trace only"),
        # Damped (ratio 0.2): the paper's undamped tip is chaotic, and its line
        # force is not determined to better than about 0.06 nN at any tolerance
        # (rk8pd at 1e-11 against 1e-10; docs/speed.md).  The paper's whole
        # map: through the surface table (the default) every run pays its
        # build (about 0.11 s), which a short scan would let dominate.
        "graphite": AfmScene("graphite", ("graphite.nml", "graphite_damped.nml"),
                             "&scan nx = 128, ny = 24 /",
                             QUICK_TOLS if quick else ladder(3, 10), 1e-11,
                             "graphite (Lennard-Jones, 600 atoms, surface table), damping ratio 0.2, "
                             "24 lines, trace + retrace",
                             "inputs/graphite.nml + graphite_damped.nml, the paper's 24 x 128 map"),
        "brake_regularized": BrakeScene("brake_regularized", "regularized",
                                        QUICK_TOLS if quick else ladder(3, 11), 1e-13,
                                        "brake, regularized law (ε' = 3.5121e7)"),
        "brake_switched": BrakeScene("brake_switched", "switched",
                                     QUICK_TOLS if quick else ladder(3, 11), 1e-14,
                                     "brake, switched model"),
    }


def measure(scene, method, rtol, atol, repeats, ref_q=None, cap=None) -> Point:
    out, msg = scene.run(method, rtol, atol, cap)
    if out is None:
        return Point(method, rtol, atol, classify_failure(msg), msg)
    times = [out["time"]]
    if out["time"] < REPEAT_BELOW:
        for _ in range(repeats - 1):
            again, msg = scene.run(method, rtol, atol, cap)
            if again is None:  # did not repeat: report it rather than hide it
                return Point(method, rtol, atol, classify_failure(msg), "repeat: " + msg)
            times.append(again["time"])
    p = Point(method, rtol, atol, "ok", error=math.nan, time=statistics.median(times),
              rhs=out["rhs"], times=times)
    p.q = out["q"]
    if ref_q is not None:
        p.error = scene.error(out["q"], ref_q)
        p.scale = scene.scale(ref_q, rtol, atol)
    return p


def reference(scene):
    """The reference run and its own convergence check (10x looser)."""
    rtol = scene.ref_tol
    ref = measure(scene, "rk8pd", rtol, scene.atol_for(rtol), 1, cap=REFERENCE_CAP)
    chk = measure(scene, "rk8pd", rtol * 10, scene.atol_for(rtol * 10), 1, cap=REFERENCE_CAP)
    if ref.status != "ok" or chk.status != "ok":
        bad = ref if ref.status != "ok" else chk
        raise RuntimeError(f"{scene.name}: reference rk8pd {bad.rtol:g} {bad.status}: {bad.message}")
    return ref, scene.error(chk.q, ref.q)


# --------------------------------------------------------------------------
# Work-precision
# --------------------------------------------------------------------------


def run_scene(scene, methods, repeats) -> dict:
    log(f"{scene.name}: reference")
    ref, check = reference(scene)
    log(f"{scene.name}: reference rk8pd {scene.ref_tol:g} in {ref.time:.3f} s; "
        f"vs 10x looser: {check:.2e} {scene.unit}")
    rows = {}
    for method in methods:
        pts, stop = [], None
        for rtol in scene.tols:
            atol = scene.atol_for(rtol)
            if stop:
                pts.append(Point(method, rtol, atol, "skipped", f"not tried: {stop}"))
                continue
            p = measure(scene, method, rtol, atol, repeats, ref.q)
            if p.status == "ok" and p.error <= 10 * check:
                p.status = "unresolved"
                p.message = f"error within 10x of the reference's own ({check:.1e})"
            if p.status in ("capped", "killed"):
                stop = f"{p.status} at rtol {rtol:g}"
            log(f"  {scene.name} {method:7s} rtol {rtol:.0e}: {p.status:10s} "
                + (f"error {p.error:.2e} {scene.unit}, {p.time:.4f} s, {p.rhs} rhs" if p.status in
                   ("ok", "unresolved") else p.message[:100]))
            pts.append(p)
        rows[method] = pts
    res = {"scene": scene, "ref": ref, "check": check, "rows": rows}
    res["smallest"], res["converged"] = resolution(rows, check)
    return res


def resolution(rows, check) -> tuple[float, bool]:
    """The smallest error drawn (of the 'ok' points) and whether the
    reference's own check lies 10x below it."""
    ok_errors = [p.error for pts in rows.values() for p in pts if p.status == "ok"]
    smallest = min(ok_errors) if ok_errors else math.nan
    return smallest, bool(ok_errors) and 10 * check < smallest


# ngspice's reltol ladders (the charts' own rtol ladders, less the loosest rungs,
# where trap integration misses slips: docs/netlist.md).
NGSPICE_LADDERS = {"naf_trace": [10.0 ** -k for k in range(4, 11)],
                   "brake_regularized": [10.0 ** -k for k in range(4, 12)]}
NGSPICE_QUICK = {"naf_trace": [1e-6, 1e-8]}  # --quick --ngspice: seconds, for the test


def ngspice_series(res, fr_inputs: Path, binary: Path, workdir: Path, ladders: dict) -> dict:
    """The scene's netlist in ngspice along a reltol ladder, each rung's error
    measured against the chart's own reference on the chart's own samples;
    ngspice's vntol = chgtol = abstol is the chart's atol for that rtol.  CPU
    time is ngspice's reported transient analysis time."""
    scene, ref = res["scene"], res["ref"]
    if scene.kind == "brake":
        inputs = [fr_inputs / "brake.nml",
                  write_override(workdir, "ngspice_brake",
                                         f"&brake model = 'regularized', t_end = {BRAKE_WINDOW[1]!r}, "
                                         "dt_out = 1.0 /\n")]
        t = np.arange(ref.q.size) * 1.0 + BRAKE_WINDOW[0]
        window = BRAKE_WINDOW
    else:
        inputs = [fr_inputs / "naf.nml", write_override(workdir, "ngspice_naf", scene.reduce_text + "\n")]
        text = (fr_inputs / "naf.nml").read_text()
        velocity = float(re.search(r"^\s*velocity\s*=\s*([-+0-9.eE]+)", text, re.M).group(1))
        length = float(re.search(r"^\s*length\s*=\s*([-+0-9.eE]+)", text, re.M).group(1))
        t = np.arange(ref.q.size) * (length / (ref.q.size - 1)) / velocity
        window = None
    errors, times = [], []
    for reltol in ladders[scene.name]:
        row = ngspice_compare.ngspice_work_precision(inputs, [reltol], t, ref.q, binary=binary,
                                                      atol=scene.atol_for(reltol), window=window,
                                                      repeats=1, workdir=workdir / "ngspice")[0]
        log(f"  {scene.name} ngspice reltol {reltol:.0e}: error {row['error']:.2e} {scene.unit}, "
            f"{row['cpu_time']:.4f} s")
        errors.append(row["error"])
        times.append(row["cpu_time"])
    return {"label": "ngspice (network model, trap)", "error": errors, "cpu_time": times,
            "reltol": ladders[scene.name]}


def write_override(workdir: Path, name: str, text: str) -> Path:
    path = workdir / f"{name}.nml"
    path.write_text(text)
    return path


def time_to_reach(points, level):
    """CPU time a method needs for error <= level: log-log interpolation
    between its ladder points (ok ones, loosest first); None if never."""
    pts = [p for p in points if p.status == "ok" and p.error > 0]
    prev = None
    for p in pts:
        if p.error <= level:
            if prev is None or prev.error <= level:
                return p.time
            f = (math.log(level) - math.log(prev.error)) / (math.log(p.error) - math.log(prev.error))
            return math.exp(math.log(prev.time) + f * (math.log(p.time) - math.log(prev.time)))
        prev = p
    return None


def best_at(rows, level):
    """(method, time) of the fastest method at error <= level, or None."""
    cands = [(t, m) for m, pts in rows.items() if (t := time_to_reach(pts, level)) is not None]
    return (min(cands)[1], min(cands)[0]) if cands else None


def auto_evidence(res) -> list:
    """For each asked tolerance rtol of the ladder, the candidates for
    method = 'auto', best first: the methods that at rtol itself are not
    silently wrong (error within 100x the asked tolerance atol + rtol x
    scale, in the measured quantity: the failure map's rule), ranked by the
    CPU time they need to reach that asked tolerance (time_to_reach)."""
    scene, rows, out = res["scene"], res["rows"], []
    for rtol in scene.tols:
        level = scene.scale(res["ref"].q, rtol, scene.atol_for(rtol))
        cands = []
        for m, pts in rows.items():
            p = next((p for p in pts if p.rtol == rtol), None)
            if p is None or p.status not in ("ok", "unresolved") or p.error > 100 * level:
                continue
            t = time_to_reach(pts, level)
            if t is not None:
                cands.append((t, m))
        cands.sort()
        out.append({"rtol": rtol, "level": level, "ranking": [[m, t] for t, m in cands]})
    return out


def with_units(dataset, units: str, long_name: str = "") -> None:
    """A dataset's unit as a UDUNITS string that pint also reads (docs/output.md#units-udunits-strings),
    and its description in long_name."""
    dataset.attrs["units"] = units
    if long_name:
        dataset.attrs["long_name"] = long_name


def write_extra(e, ex, unit: str) -> None:
    """One series measured elsewhere as the group extra/<label>."""
    s = e.create_group(ex["label"])
    with_units(s.create_dataset("error", data=np.asarray(ex["error"], dtype=float)), unit)
    with_units(s.create_dataset("cpu_time", data=np.asarray(ex["cpu_time"], dtype=float)), "s")


def write_scene(f: h5py.File, res, extras) -> None:
    scene = res["scene"]
    g = f.create_group(scene.name)
    a = g.attrs
    a["title"] = scene.title
    a["run"] = scene.what
    a["quantity"] = scene.quantity
    a["unit"] = scene.unit
    a["error"] = f"max |q - q_ref| over the samples, {scene.unit}"
    a["cpu_time"] = f"{scene.time_source}, median of the repeats, s"
    a["reference_method"] = "rk8pd"
    a["reference_rtol"] = scene.ref_tol
    a["reference_atol"] = scene.atol_for(scene.ref_tol)
    a["reference_time"] = res["ref"].time
    a["reference_check_rtol"] = scene.ref_tol * 10
    a["reference_check"] = res["check"]
    for method, pts in res["rows"].items():
        write_method(g, method, pts, scene.unit)
    if extras:
        e = g.create_group("extra")
        for ex in extras:
            write_extra(e, ex, scene.unit)
    write_derived(g, res)


def write_method(g, method: str, pts, unit: str) -> None:
    """One method's ladder as the group /<scene>/<method>; unit: the error's."""
    m = g.create_group(method)
    with_units(m.create_dataset("tolerance", data=np.array([p.rtol for p in pts])), "1", "rtol")
    # (atol is in the units of each integrated state: a mix, so no one unit)
    m.create_dataset("atol", data=np.array([p.atol for p in pts])).attrs["long_name"] = \
        "atol, in the units of each integrated state"
    with_units(m.create_dataset("error", data=np.array([p.error for p in pts])), unit,
               "max |q - q_ref| over the samples")
    with_units(m.create_dataset("cpu_time", data=np.array([p.time for p in pts])), "s")
    with_units(m.create_dataset("rhs_evaluations", data=np.array([p.rhs for p in pts], dtype=np.int64)), "1")
    m.create_dataset("status", data=[p.status for p in pts], dtype=h5py.string_dtype())
    m.create_dataset("message", data=[p.message for p in pts], dtype=h5py.string_dtype())


def strings(values) -> list:
    """HDF5 strings (bytes or str) as str."""
    return [v.decode() if isinstance(v, bytes) else str(v) for v in values]


def read_method(m, method: str) -> list:
    """A method's ladder back from its group (write_method)."""
    text = [strings(m[d][()]) for d in ("status", "message")]
    return [Point(method, float(rtol), float(atol), status, message, error=float(error), time=float(time),
                  rhs=int(rhs))
            for rtol, atol, error, time, rhs, status, message in zip(
                m["tolerance"][()], m["atol"][()], m["error"][()], m["cpu_time"][()], m["rhs_evaluations"][()],
                *text)]


def write_derived(g, res) -> None:
    """What the scene's attributes say of all its methods together: the
    smallest error drawn, whether the reference resolves it, the ranking
    behind method = 'auto' and the best method at the error levels."""
    res["smallest"], res["converged"] = resolution(res["rows"], res["check"])
    a = g.attrs
    a["smallest_error"] = res["smallest"]
    a["reference_converged"] = res["converged"]
    ev = auto_evidence(res)
    a["auto_evidence"] = json.dumps(ev)
    levels = {}
    for level in LEVELS:
        b = best_at(res["rows"], level)
        r = time_to_reach(res["rows"].get("rkf45", []), level)
        levels[f"{level:g}"] = {"best": b[0] if b else None, "time": b[1] if b else None,
                                "rkf45_time": r}
    a["best_at_levels"] = json.dumps(levels)
    res["levels"], res["evidence"] = levels, ev


# --------------------------------------------------------------------------
# Failure map
# --------------------------------------------------------------------------


def failure_column(scene, methods, label) -> dict:
    """Every method at FAILURE_RTOL on one setting, categorised."""
    rtol, atol = FAILURE_RTOL, scene.atol_for(FAILURE_RTOL)
    try:
        ref, check = reference(scene)
    except RuntimeError as exc:
        log(f"failure map {label}: no reference ({exc})")
        return {"label": label, "ref_check": math.nan, "points": [
            Point(m, rtol, atol, "no reference", str(exc)) for m in methods], "codes": [-1] * len(methods)}
    pts = [measure(scene, m, rtol, atol, 1, ref.q) for m in methods]
    for p in pts:
        # Wrong only where the reference resolves it: its own difference
        # (10x looser) must stay 10x below the error called wrong.
        if p.status == "ok" and p.error > 100 * p.scale and p.error > 10 * check:
            p.status = "wrong"
    codes = category_codes(pts)
    for p, code in zip(pts, codes):
        log(f"  failure map {label} {p.method:7s}: {CATEGORIES[code]:6s} "
            + (f"error {p.error:.1e} (100x asked {100 * p.scale:.1e}), {p.time:.4f} s"
               if p.status in ("ok", "wrong") else p.message[:90]))
    return {"label": label, "ref_check": check, "points": pts, "codes": codes}


def category_codes(pts) -> list:
    """The failure map's category of each method's point at one setting
    (status 'wrong' already given): slow is relative to the fastest method
    that is neither failed nor wrong, so it depends on all the methods."""
    good = [p.time for p in pts if p.status == "ok"]
    best = min(good) if good else math.nan
    codes = []
    for p in pts:
        if p.status == "no reference":
            codes.append(-1)
        elif p.status == "ok" and p.time > 10 * best:
            codes.append(1)
        elif p.status == "ok":
            codes.append(0)
        elif p.status in ("capped", "killed"):
            codes.append(1)
        elif p.status == "wrong":
            codes.append(3)
        else:
            codes.append(2)
    return codes


def failure_maps(afm_fr, brake_fr, methods, cap, quick) -> list:
    maps = []
    eps = (1e5, 1e7) if quick else EPSILON_PRIMES
    scene = make_scenes(quick)["brake_regularized"]
    cols = []
    for e in eps:
        scene.setup(brake_fr, cap, extra=f"epsilon_prime = {e!r}")
        cols.append(failure_column(scene, methods, f"ε' = {e:.0e}"))
    maps.append({"name": "brake_regularized", "parameter": "epsilon_prime", "values": eps,
                 "title": f"brake, regularized law: x over τ ∈ [{BRAKE_WINDOW[0]:g}, {BRAKE_WINDOW[1]:g}], "
                          f"rtol {FAILURE_RTOL:g}, atol {FAILURE_RTOL / 100:g}",
                 "unit": "m", "columns": cols})
    zetas = (1.0, 0.0) if quick else DAMPING_RATIOS
    scene = make_scenes(quick)["naf_line"]
    text = (INPUTS / "naf.nml").read_text()
    mass = float(re.search(r"^\s*mass\s*=\s*([-+0-9.eE]+)", text, re.M).group(1))
    kx = float(re.search(r"^\s*kx\s*=\s*([-+0-9.eE]+)", text, re.M).group(1))
    ky = float(re.search(r"^\s*ky\s*=\s*([-+0-9.eE]+)", text, re.M).group(1))
    cols, cs = [], []
    for z in zetas:
        cx, cy = z * 2 * math.sqrt(mass * kx), z * 2 * math.sqrt(mass * ky)
        cs.append(cx)
        scene.setup(afm_fr, cap, extra=f"&tip cx = {cx!r}, cy = {cy!r} /", tag=f"naf_zeta{z:g}")
        cols.append(failure_column(scene, methods, f"ζ = {z:g}"))
    maps.append({"name": "naf_damping", "parameter": "damping_ratio", "values": zetas, "c": cs,
                 "title": f"NaF line: lateral force, rtol = atol = {FAILURE_RTOL:g}; "
                          f"damping ratio ζ = c / (2 √(m k))",
                 "unit": "nN", "columns": cols})
    return maps


def write_failure_maps(path: Path, maps, methods, meta) -> None:
    with h5py.File(path, "w") as f:
        for k, v in meta.items():
            f.attrs[k] = v
        f.attrs["categories"] = json.dumps({"-1": "no reference", **{str(i): c for i, c in enumerate(CATEGORIES)}})
        f.attrs["rules"] = ("failed: error exit other than the time cap; wrong: success but error > 100x "
                            "the asked tolerance in the measured quantity; slow: > 10x the time of the "
                            "fastest method neither failed nor wrong, or stopped by max_wall_time; ok: else")
        f.attrs["rtol"] = FAILURE_RTOL
        for mp in maps:
            g = f.create_group(mp["name"])
            g.attrs["title"] = mp["title"]
            g.attrs["unit"] = mp["unit"]
            g.create_dataset(mp["parameter"], data=np.array(mp["values"], dtype=float))
            if "c" in mp:
                with_units(g.create_dataset("c", data=np.array(mp["c"])), "N s/m", "cx; cy likewise from ky")
            write_map_points(g, mp["parameter"], methods, mp["columns"], mp["unit"])


MAP_POINT_DATA = ("methods", "category", "error", "cpu_time", "asked_tolerance", "status", "message",
                  "reference_check")


def write_map_points(g, parameter: str, methods, cols, unit: str) -> None:
    """A failure map's points (methods x settings) and categories; unit: the error's."""
    for d in MAP_POINT_DATA:
        if d in g:
            del g[d]
    g.create_dataset("methods", data=list(methods), dtype=h5py.string_dtype())
    g.create_dataset("category", data=np.array([c["codes"] for c in cols], dtype=np.int8).T)
    g.create_dataset("error", data=np.array([[p.error for p in c["points"]] for c in cols]).T)
    g.create_dataset("cpu_time", data=np.array([[p.time for p in c["points"]] for c in cols]).T)
    g.create_dataset("asked_tolerance", data=np.array([[p.scale for p in c["points"]] for c in cols]).T)
    g.create_dataset("status", data=np.array([[p.status for p in c["points"]] for c in cols],
                                              dtype=object).T, dtype=h5py.string_dtype())
    g.create_dataset("message", data=np.array([[p.message for p in c["points"]] for c in cols],
                                               dtype=object).T, dtype=h5py.string_dtype())
    g.create_dataset("reference_check", data=np.array([c["ref_check"] for c in cols]))
    for d, units in (("error", unit), ("cpu_time", "s"), ("asked_tolerance", "1"), ("reference_check", unit)):
        with_units(g[d], units)
    for d in ("category", "error", "cpu_time", "status"):
        g[d].attrs["axes"] = f"methods x {parameter}"


def read_map_columns(g, parameter: str) -> tuple[list, list]:
    """A failure map's methods and its columns of points back from the file
    (write_map_points)."""
    def text(d):
        return [strings(row) for row in g[d][()]]
    methods = strings(g["methods"][()])
    status, message = text("status"), text("message")
    error, time, asked = g["error"][()], g["cpu_time"][()], g["asked_tolerance"][()]
    cols = []
    for j in range(g[parameter].shape[0]):
        pts = [Point(m, FAILURE_RTOL, math.nan, status[i][j], message[i][j], error=float(error[i, j]),
                     time=float(time[i, j]), scale=float(asked[i, j])) for i, m in enumerate(methods)]
        cols.append({"points": pts, "ref_check": float(g["reference_check"][j]),
                     "codes": [int(c) for c in g["category"][:, j]]})
    return methods, cols


# --------------------------------------------------------------------------


def load_extras(path: Path | None, scenes) -> dict:
    if path is None:
        return {}
    try:
        data = json.loads(path.read_text())
        out = {}
        for ex in data:
            if ex["scene"] not in scenes:
                raise ValueError(f"unknown scene '{ex['scene']}' (known: {', '.join(scenes)})")
            if "/" in str(ex["label"]) or not str(ex["label"]):
                raise ValueError(f"label '{ex['label']}': must be nonempty, without '/' (an HDF5 group name)")
            if len(ex["error"]) != len(ex["cpu_time"]) or not ex["error"]:
                raise ValueError(f"{ex['label']}: error and cpu_time need the same, nonzero length")
            out.setdefault(ex["scene"], []).append(
                {"label": str(ex["label"]), "error": [float(v) for v in ex["error"]],
                 "cpu_time": [float(v) for v in ex["cpu_time"]]})
        return out
    except (OSError, ValueError, KeyError, TypeError) as exc:
        sys.exit(f"work_precision: --extra {path}: {exc}")


def replot(path: Path, out: Path, extras: dict) -> int:
    """Redraw the charts of a work_precision.h5 without measuring again; the
    --extra series (and any already in the file) are added to the file and
    drawn.  The measured data are not changed."""
    scenes = make_scenes(False)
    replotted = []
    with h5py.File(path, "r+") as f:
        for name in f:
            if name not in scenes:
                continue
            g = f[name]
            for ex in extras.get(name, []):
                e = g.require_group("extra")
                if ex["label"] in e:
                    del e[ex["label"]]
                write_extra(e, ex, scenes[name].unit)
            replotted.append((name, len(g.get("extra", {}))))
    data = friction.load(path)
    for name, count in replotted:
        save(friction.plot.work_precision(data, name), out / f"work_precision_{name}.png")
        log(f"replotted {name} ({count} extra series)")
    return 0


def save(figure, path: Path) -> None:
    """The charts' resolution: 90 dpi."""
    figure.savefig(path, dpi=90)


def add_to(directory: Path, results, maps, methods, meta) -> tuple[list, list, list]:
    """Add the methods measured now to the files in directory (replacing
    their earlier series), and recompute what depends on all the methods
    together: the scenes' derived attributes and the failure map's
    categories.  Returns the merged results, maps and methods."""
    stamp = f"{meta['created']}, {meta['source']}"
    merged_results = []
    with h5py.File(directory / "work_precision.h5", "r+") as f:
        known = [m for m in str(f.attrs["methods"]).split(",") if m]
        all_methods = known + [m for m in methods if m not in known]
        for res in results:
            g = f[res["scene"].name]
            before = float(g.attrs["reference_check"])
            if not (res["check"] <= 2 * before and before <= 2 * res["check"]):
                log(f"{res['scene'].name}: the reference's own check is {res['check']:.2e} now against "
                    f"{before:.2e} in the file: the program's reference has changed (the added series are "
                    "measured against today's)")
            for method, pts in res["rows"].items():
                if method in g:
                    del g[method]
                write_method(g, method, pts, res["scene"].unit)
                g[method].attrs["added"] = stamp
            rows = {m: read_method(g[m], m) for m in all_methods if m in g}
            merged = dict(res, rows=rows)
            write_derived(g, merged)
            merged_results.append(merged)
        f.attrs["methods"] = ",".join(all_methods)
    merged_maps = []
    if maps:
        with h5py.File(directory / "failure_map.h5", "r+") as f:
            for mp in maps:
                g = f[mp["name"]]
                if not np.allclose(g[mp["parameter"]][()], mp["values"]):
                    raise RuntimeError(f"failure map {mp['name']}: the file's {mp['parameter']} values differ "
                                       "from this run's (a --quick file and a full run?)")
                old_methods, old_cols = read_map_columns(g, mp["parameter"])
                map_methods = [m for m in old_methods if m not in methods] + list(methods)
                cols = []
                for old, new in zip(old_cols, mp["columns"]):
                    pts = [p for p in old["points"] if p.method not in methods] + new["points"]
                    cols.append(dict(new, points=pts, codes=category_codes(pts)))
                write_map_points(g, mp["parameter"], map_methods, cols, mp["unit"])
                merged_maps.append(dict(mp, columns=cols, methods=map_methods))
            f.attrs["added"] = f"{','.join(methods)}: {stamp}"
    return merged_results, merged_maps, all_methods


def summary_table(results) -> str:
    lines = ["| scene | error level | best method | time | rkf45 time | rkf45 / best |",
             "|---|---|---|---|---|---|"]
    for res in results:
        s = res["scene"]
        for lv, v in res["levels"].items():
            if v["best"] is None:
                lines.append(f"| {s.name} | {lv} {s.unit} | not reached | | | |")
                continue
            r = v["rkf45_time"]
            lines.append(f"| {s.name} | {lv} {s.unit} | {v['best']} | {v['time'] * 1e3:.2f} ms | "
                         + (f"{r * 1e3:.2f} ms | {r / v['time']:.1f} |" if r else "not reached | |"))
    tols = sorted({t for res in results for t in res["scene"].tols}, reverse=True)
    lines += ["", "Candidates for method = 'auto' at each asked rtol: not silently wrong at that rtol,",
              "ranked by the CPU time to reach its asked tolerance (atol + rtol max|q_ref|); ms:",
              "", "| scene | " + " | ".join(f"{t:.0e}" for t in tols) + " |",
              "|---|" + "---|" * len(tols)]
    for res in results:
        cells = {e["rtol"]: e for e in res["evidence"]}
        lines.append(f"| {res['scene'].name} | " + " | ".join(
            (", ".join(f"{m} {t * 1e3:.0f}" for m, t in cells[t]["ranking"][:3])
             if t in cells and cells[t]["ranking"] else "-") for t in tols) + " |")
    return "\n".join(lines)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter,
                                epilog="See the module docstring (or docs/speed.md).")
    p.add_argument("--quick", action="store_true",
                   help=f"naf and brake_switched, {', '.join(QUICK_METHODS)}, rtol "
                        f"{', '.join(f'{t:g}' for t in QUICK_TOLS)}, one run each, a small failure map")
    p.add_argument("--out", type=Path, default=Path("."), help="output directory (default: .)")
    p.add_argument("--extra", type=Path, metavar="FILE",
                   help='series measured elsewhere, drawn dashed on their scene\'s chart and stored '
                        'under /<scene>/extra: a JSON list of {"scene": ..., "label": ..., '
                        '"error": [...], "cpu_time": [...]} in the chart\'s units (nN or m, s)')
    p.add_argument("--repeats", type=int, default=None, help="runs per timing (default 3; 1 with --quick)")
    p.add_argument("--cap", type=float, default=None, help="max_wall_time per run, s (default 10; 3 with --quick)")
    p.add_argument("--scenes", help="comma-separated subset of the scenes")
    p.add_argument("--methods", help="comma-separated subset of the methods")
    p.add_argument("--no-failure-map", action="store_true", help="skip the failure map")
    p.add_argument("--ngspice", action="store_true",
                   help="also chart the paper's network model in ngspice (friction --netlist) on its two "
                        "scenes, brake_regularized and naf_trace (added to the scenes run)")
    p.add_argument("--add-to", type=Path, metavar="DIR",
                   help="measure only --methods and add them to DIR's work_precision.h5 and failure_map.h5 "
                        "(replacing their earlier series; the file's scenes, ladders, repeats and cap), "
                        "recompute what depends on all methods, and redraw DIR's charts")
    p.add_argument("--replot", type=Path, metavar="H5",
                   help="measure nothing: redraw the charts of this work_precision.h5 into --out, adding "
                        "the --extra series to the file")
    p.add_argument("--binary", type=Path, default=ROOT / "build" / "friction",
                   help="the friction executable (default: build/friction)")
    args = p.parse_args(argv)
    if args.replot:
        if not args.replot.exists():
            p.error(f"--replot {args.replot}: no such file")
        args.out.mkdir(parents=True, exist_ok=True)
        return replot(args.replot, args.out, load_extras(args.extra, make_scenes(False)))
    repeats = args.repeats or (1 if args.quick else 3)
    cap = args.cap or (3.0 if args.quick else 10.0)
    in_file = None
    if args.add_to:
        wp = args.add_to / "work_precision.h5"
        if not wp.exists():
            p.error(f"--add-to {args.add_to}: no work_precision.h5 there")
        if not args.methods:
            p.error("--add-to needs --methods (the methods to add)")
        if args.ngspice or args.extra:
            p.error("--add-to adds measured methods only (no --ngspice, no --extra)")
        with h5py.File(wp, "r") as f:
            # Measured as the file was: its ladders, repeats and cap.
            args.quick = bool(f.attrs["quick"])
            repeats, cap = int(f.attrs["repeats"]), float(f.attrs["max_wall_time"])
            in_file = [n for n in f if n in make_scenes(args.quick)]
        if not (args.add_to / "failure_map.h5").exists():
            args.no_failure_map = True
        args.out = args.add_to
    scenes = make_scenes(args.quick)
    names = (args.scenes.split(",") if args.scenes else in_file if in_file is not None else
             (["naf", "brake_switched"] if args.quick else
              [n for n in scenes if n not in ("naf_line", "naf_trace")]))
    if in_file is not None and any(n not in in_file for n in names):
        p.error(f"--add-to: the file has the scenes {', '.join(in_file)} only")
    if args.ngspice:
        if not shutil.which("ngspice"):
            p.error("--ngspice: no ngspice on PATH (scripts/install-deps installs it)")
        ladders = NGSPICE_QUICK if args.quick else NGSPICE_LADDERS
        names += [n for n in ladders if n not in names]
    methods = tuple(args.methods.split(",")) if args.methods else (QUICK_METHODS if args.quick else METHODS)
    for n in names:
        if n not in scenes:
            p.error(f"unknown scene '{n}' (known: {', '.join(scenes)})")
    for m in methods:
        if m not in METHODS:
            p.error(f"unknown method '{m}' (known: {', '.join(METHODS)})")
    if not args.binary.exists():
        p.error(f"{args.binary}: no such program (run scripts/build)")
    extras = load_extras(args.extra, scenes)
    for n in extras:
        if n not in names:
            log(f"--extra: scene '{n}' is not run this time; its series are left out")
    args.out.mkdir(parents=True, exist_ok=True)

    t0 = time.perf_counter()
    workdir = Path(tempfile.mkdtemp(prefix="friction-wp-"))
    try:
        snapshot = benchmark_afm.snapshot_program(args.binary, workdir)
        shutil.copytree(INPUTS, workdir / "inputs")
        afm_fr = benchmark_afm.Friction(snapshot, [], workdir)
        brake_fr = benchmark_brake.Friction(snapshot, workdir, cap)
        results = []
        for n in names:
            s = scenes[n]
            s.setup(afm_fr if s.kind == "afm" else brake_fr, cap)
            results.append(run_scene(s, methods, repeats))
            if args.ngspice and n in ladders:
                extras.setdefault(n, []).append(ngspice_series(results[-1], workdir / "inputs", snapshot, workdir,
                                                               ladders))
        maps = [] if args.no_failure_map else failure_maps(afm_fr, brake_fr, methods, cap, args.quick)
    except RuntimeError as exc:
        log(str(exc))
        return 1
    finally:
        shutil.rmtree(workdir, ignore_errors=True)
    total = time.perf_counter() - t0

    meta = {"program": "work_precision", "created": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
            "source": benchmark_afm.git_state(), "quick": args.quick, "repeats": repeats,
            "max_wall_time": cap, "seconds": total}
    if args.add_to:
        try:
            results, maps, methods = add_to(args.add_to, results, maps, methods, meta)
        except RuntimeError as exc:
            log(str(exc))
            return 1
    else:
        with h5py.File(args.out / "work_precision.h5", "w") as f:
            for k, v in meta.items():
                f.attrs[k] = v
            f.attrs["methods"] = ",".join(methods)
            for res in results:
                write_scene(f, res, extras.get(res["scene"].name, []))
        if maps:
            write_failure_maps(args.out / "failure_map.h5", maps, methods, meta)
    charts = friction.load(args.out / "work_precision.h5")
    for res in results:
        name = res["scene"].name
        save(friction.plot.work_precision(charts, name), args.out / f"work_precision_{name}.png")
    if maps:
        save(friction.plot.failure_map(args.out / "failure_map.h5"), args.out / "failure_map.png")

    print("# Speed against accuracy\n")
    for res in results:
        s = res["scene"]
        print(f"- {s.name}: {s.what}; reference rk8pd rtol {s.ref_tol:g} ({res['ref'].time:.3f} s), "
              f"vs 10x looser {res['check']:.1e} {s.unit}; smallest error drawn {res['smallest']:.1e} "
              f"{s.unit}; converged: {res['converged']}")
    print()
    print(summary_table(results))
    for mp in maps:
        print(f"\nFailure map: {mp['title']}\n")
        print("| method | " + " | ".join(c["label"] for c in mp["columns"]) + " |")
        print("|---|" + "---|" * len(mp["columns"]))
        for i, m in enumerate(mp.get("methods", methods)):
            print(f"| {m} | " + " | ".join(
                (CATEGORIES[c["codes"][i]] if c["codes"][i] >= 0 else "no ref")
                + (f" {c['points'][i].time * 1e3:.1f} ms" if c["points"][i].status in ("ok", "wrong") else
                   f" ({c['points'][i].status})" if c["points"][i].status in ("capped", "killed") else "")
                for c in mp["columns"]) + " |")
    print(f"\n(took {total:.0f} s; files in {args.out})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
