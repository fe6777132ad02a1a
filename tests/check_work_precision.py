#!/usr/bin/env python3
"""Check the files of `work_precision.py --quick` (CTest work_precision.*).

usage: check_work_precision.py DIR

In DIR: work_precision.h5 must hold the quick scenes (naf, brake_switched),
each with the quick methods and the datasets tolerance, error, cpu_time,
rhs_evaluations and status for the quick ladder.  The oracles:

* The reference converged: its difference from itself at a 10x looser
  tolerance (attribute reference_check) is more than 10x below every error
  drawn, and the attribute reference_converged agrees.
* Convergence: for rkf45 and rk8pd the error falls strictly at each
  hundredfold tighter rung (1e-4, 1e-6, 1e-8).  Both steppers adapt their
  step to a local error estimate, so the global error must shrink with the
  tolerance while it stays above the reference's own (checked above).  A
  hundredfold step gives room: the measured factors are 10 to 600.
* The --extra series of tests/data/extra_series.json is stored under
  /naf/extra with its values.
* Every dataset's `units` in both files parses with UDUNITS-2 (cf-units)
  and pint (docs/output.md#units-udunits-strings), and the errors and CPU
  times have theirs (the scene's unit, s).
* failure_map.h5 holds both maps with a category for every method and
  setting, each a known code; every 'ok' point's error is within 100x of
  the asked tolerance (that is what 'ok' means); at NaF damping ratio 1
  (clearly damped) rk8pd neither fails nor is wrong.

Exit 0 when all hold, else 1 with the reasons.
"""
import json
import math
import sys
from pathlib import Path

import h5py
import numpy as np

QUICK_SCENES = ("naf", "brake_switched")
QUICK_METHODS = ("rkf45", "rk8pd", "rk4imp")
QUICK_TOLS = (1e-4, 1e-6, 1e-8)
STATUSES = {"ok", "unresolved", "capped", "killed", "failed", "skipped"}


def main():
    out = Path(sys.argv[1])
    problems = []

    def need(cond, what):
        if not cond:
            problems.append(what)

    with h5py.File(out / "work_precision.h5", "r") as f:
        need(f.attrs["program"] == "work_precision", "root attribute program")
        for scene in QUICK_SCENES:
            need(scene in f, f"group /{scene}")
            if scene not in f:
                continue
            g = f[scene]
            check, converged = float(g.attrs["reference_check"]), bool(g.attrs["reference_converged"])
            drawn = []
            for method in QUICK_METHODS:
                m = g[method]
                tol = m["tolerance"][()]
                need(np.allclose(tol, QUICK_TOLS), f"{scene}/{method}: tolerances {tol}")
                for d in ("error", "cpu_time", "rhs_evaluations", "status", "atol"):
                    need(m[d].shape == tol.shape, f"{scene}/{method}/{d} shape")
                status = [s.decode() if isinstance(s, bytes) else s for s in m["status"][()]]
                need(set(status) <= STATUSES, f"{scene}/{method}: unknown status {status}")
                err = m["error"][()]
                ok = [e for e, s in zip(err, status) if s == "ok"]
                drawn += ok
                need(all(t > 0 for t, s in zip(m["cpu_time"][()], status) if s == "ok"),
                     f"{scene}/{method}: cpu_time must be positive")
                if method in ("rkf45", "rk8pd"):
                    need(status == ["ok"] * 3, f"{scene}/{method}: all rungs must succeed, got {status}")
                    need(all(b < a for a, b in zip(err, err[1:])),
                         f"{scene}/{method}: error must fall as the tolerance tightens: {err}")
            need(drawn and 10 * check < min(drawn),
                 f"{scene}: reference check {check:.2e} not 10x below the smallest error {min(drawn):.2e}")
            need(converged == (10 * check < min(drawn)), f"{scene}: attribute reference_converged")
            need(math.isfinite(check) and check >= 0, f"{scene}: reference_check {check}")
        ex = f.get("naf/extra/external (test)")
        need(ex is not None, "/naf/extra/external (test) from --extra")
        if ex is not None:
            need(np.allclose(ex["error"][()], [1e-4, 1e-6]) and np.allclose(ex["cpu_time"][()], [0.01, 0.1]),
                 "--extra values")

    with h5py.File(out / "failure_map.h5", "r") as f:
        codes = json.loads(f.attrs["categories"])
        for name, param in (("brake_regularized", "epsilon_prime"), ("naf_damping", "damping_ratio")):
            g = f[name]
            methods = [s.decode() if isinstance(s, bytes) else s for s in g["methods"][()]]
            cat = g["category"][()]
            need(cat.shape == (len(methods), g[param].shape[0]), f"{name}: category shape {cat.shape}")
            need(all(str(int(c)) in codes for c in cat.ravel()), f"{name}: unknown category code")
            err, asked = g["error"][()], g["asked_tolerance"][()]
            ok = cat == 0
            need(np.all(err[ok] <= 100 * asked[ok]), f"{name}: an 'ok' point beyond 100x the asked tolerance")
        g = f["naf_damping"]
        methods = [s.decode() if isinstance(s, bytes) else s for s in g["methods"][()]]
        j = list(g["damping_ratio"][()]).index(1.0)
        # ok or slow (timing depends on the machine's load): neither failed nor wrong
        need(g["category"][methods.index("rk8pd"), j] in (0, 1),
             "naf_damping: rk8pd at damping ratio 1 failed or wrong")

    import cf_units
    import pint
    registry = pint.UnitRegistry()
    for name in ("work_precision.h5", "failure_map.h5"):
        with h5py.File(out / name, "r") as f:
            stated = []
            f.visititems(lambda path, obj: stated.append((path, obj.attrs["units"]))
                         if isinstance(obj, h5py.Dataset) and "units" in obj.attrs else None)
            for path, unit in stated:
                unit = unit.decode() if isinstance(unit, bytes) else str(unit)
                try:
                    cf_units.Unit(unit)
                    registry.parse_units(unit)
                except Exception as err:   # either library's refusal, whatever its type
                    need(False, f"{name}: /{path} units {unit!r}: {err}")
            units = dict((path, u.decode() if isinstance(u, bytes) else str(u)) for path, u in stated)
            for path in ("naf/rkf45/error", "naf/rkf45/cpu_time", "naf_damping/c", "naf_damping/error"):
                if name == "work_precision.h5" and path.startswith("naf/") \
                        or name == "failure_map.h5" and path.startswith("naf_damping/"):
                    need(path in units, f"{name}: /{path} has no units")
            need(units.get("naf/rkf45/error", "nN") == "nN" and units.get("naf_damping/c", "N s/m") == "N s/m",
                 f"{name}: units {units}")

    for p in problems:
        print(f"check_work_precision: {p}", file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
