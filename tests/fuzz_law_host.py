#!/usr/bin/env python3
"""The host process of the fuzzing suite's C API law histories (tests/fuzz_test.py, class laws).

Loads the library through the Python package, reads a list of cases as JSON
on stdin, each: a law by name, values set by name (numbers through
friction_law_set_real, text through friction_law_set), the checks, then
one history through friction_law_history straight from ctypes with guard
cells after every array (a states length that may be too short, times and
values that may be NaN, infinite, huge, not increasing), and the same
history through friction.law.Law.history with the values' array of
another length.  Prints a JSON list, for each case: each call's status and message,
whether the guard cells and (after a refusal) the arrays stayed untouched,
whether a history computed is finite, and whether a history accepted had
valid arguments.  A crash of the library kills this process, which the
suite sees as a signal.

    FRICTION_LIBRARY=... fuzz_law_host.py PYTHON_DIR < case.json
"""

import json
import math
import sys

import numpy as np

GUARD = 16
SENTINEL = 12345.678


def outcome(call):
    """[(status, message)] of a call of the package: 0 and '' when it returns."""
    import friction
    try:
        call()
        return [(0, "")]
    except friction.FrictionError as error:
        return [(error.status, str(error))]


def series(case):
    """The times and values of the case, and whether they are valid."""
    n = case["n"]
    t = np.linspace(0.0, 1.0, n)
    kind = case["t"]
    if kind == "decreasing":
        t = t[::-1].copy()
    elif kind == "repeated" and n > 1:
        t[-1] = t[-2]
    elif kind == "nan" and n:
        t[n // 2] = math.nan
    elif kind == "huge":
        t = t * 1e300
    elif kind == "tiny":
        t = t * 1e-300
    a = case["amplitude"]
    u = {"sine": a * np.sin(2.0 * math.pi * 3.0 * t), "ramp": a * t, "nan": np.full(n, math.nan),
         "inf": np.full(n, math.inf), "huge": np.full(n, 1e300), "tiny": np.full(n, 1e-300), "zero": np.zeros(n),
         "step": np.where(np.arange(n) < n // 2, -a, a)}[case["u"]].astype(float)
    if kind in ("huge", "tiny") and case["u"] in ("sine", "ramp"):
        u = a * np.sin(np.linspace(0.0, 6.0, n))
    valid_t = bool(np.all(np.isfinite(t))) and (n < 2 or bool(np.all(np.diff(t) > 0)))
    valid = valid_t and bool(np.all(np.isfinite(u))) and case["displacement"] in (0, 1)
    if case["displacement"] == 1 and n < 2:
        valid = False
    return t, u, valid


def main():
    sys.path.insert(0, sys.argv[1])
    # One process for several cases: the package's import is most of a case's time.
    print(json.dumps([history_case(case) for case in json.load(sys.stdin)]))


def history_case(case):
    import friction
    from friction import _capi
    from friction.law import Law

    report = {"new": [], "sets": [], "check": [], "history": [], "guard_intact": True, "untouched": True,
              "finite": True, "valid": True}
    holder = {}

    def make():
        holder["law"] = Law(case["model"])

    report["new"] = outcome(make)
    law = holder.get("law")
    if law is None:
        return report
    lib = _capi.library()
    for name, value in case["sets"].items():
        report["sets"] += outcome(lambda: law.set(name, value))
    if case["model"] == "table":
        report["sets"] += outcome(lambda: law.set("table_file", case["table"]))
    report["check"] = outcome(law.check)
    count_outcome = outcome(lambda: holder.__setitem__("count", law.state_count))
    count = holder.get("count", 0)
    t, u, valid = series(case)
    n = t.size
    change = case["states_change"]
    states_len = 0 if change is None or count == 0 else max(0, n * count + change)
    valid = valid and (change is None or count == 0 or change >= 0)
    valid = valid and math.isfinite(case["normal"]) and case["normal"] >= 0.0
    force = np.full(n + GUARD, SENTINEL)
    states = np.full(states_len + GUARD, SENTINEL)
    tc, uc = np.ascontiguousarray(t), np.ascontiguousarray(u)

    def history():
        _capi._call(lib.friction_law_history, law.handle, float(case["normal"]), tc.ctypes.data, uc.ctypes.data, n,
                    int(case["displacement"]), force.ctypes.data,
                    None if change is None else states.ctypes.data, states_len)

    if count_outcome[0][0] == 0:
        report["history"] = outcome(history)
        report["guard_intact"] = bool(np.all(force[n:] == SENTINEL) and np.all(states[states_len:] == SENTINEL))
        status = report["history"][0][0]
        if status == 1:
            report["untouched"] = bool(np.all(force == SENTINEL) and np.all(states == SENTINEL))
        if status == 0:
            report["finite"] = bool(np.all(np.isfinite(force[:n])))
            if change is not None:
                report["finite"] = report["finite"] and bool(np.all(np.isfinite(states[:states_len])))
            report["valid"] = valid
        # The package's own check of the lengths: another length is a ValueError, not a call.
        if case["u_change"]:
            longer = np.resize(u, max(0, n + case["u_change"]))
            try:
                law.history(t, longer, normal=1.0)
                report["history"].append((1, "") if longer.size != n else (0, ""))
            except ValueError as error:
                report["history"].append((1, str(error)))
            except friction.FrictionError as error:
                report["history"].append((error.status, str(error)))
    law.close()
    return report


if __name__ == "__main__":
    main()
