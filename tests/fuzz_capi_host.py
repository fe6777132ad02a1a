#!/usr/bin/env python3
"""The host process of the fuzzing suite's C API class (tests/fuzz_test.py).

Loads the library through the Python package, reads one case as JSON on
stdin, and applies it to a configuration handle: values set by name as
namelist text, then the checks, one scan line into arrays of a given length
(with guard cells after them), and the whole scene in memory.  Prints one
JSON object: the status and message of every call, whether the guard cells
stayed untouched and whether every array computed is finite.  A crash of the
library kills this process, which the suite sees as a signal.

    FRICTION_LIBRARY=... fuzz_capi_host.py PYTHON_DIR < case.json
"""

import ctypes
import json
import sys

import numpy as np

GUARD = 16
SENTINEL = 12345.678


def outcome(call):
    """(status, message) of a call of the package: 0 and '' when it returns."""
    import friction
    try:
        call()
        return 0, ""
    except friction.FrictionError as error:
        return error.status, str(error)


def main():
    sys.path.insert(0, sys.argv[1])
    import friction
    from friction import _capi

    case = json.load(sys.stdin)
    report = {"sets": [], "check": None, "line": None, "compute": None, "guard_intact": True, "finite": True}
    config = friction.Config(case["scene"], files=case["files"])
    lib = _capi.library()
    for name, text in case["sets"]:
        # The bytes as given (not UTF-8 when the case says so), straight to the C function.
        raw = text.encode("utf-8", "surrogateescape")
        report["sets"].append(outcome(lambda: _capi._call(lib.friction_config_set, config.handle,
                                                          name.encode("utf-8", "surrogateescape"), raw)))
    report["check"] = outcome(config.check)
    if case["scene"] == "afm" and report["check"][0] == 0:
        nx = int(config.get("scan.nx"))
        n = max(0, nx + case["line_length_change"])
        fx, fy = np.full(n + GUARD, SENTINEL), np.full(n + GUARD, SENTINEL)

        def line():
            _capi._call(lib.friction_afm_line, config.handle, 0, 1, fx.ctypes.data_as(ctypes.c_void_p),
                        fy.ctypes.data_as(ctypes.c_void_p), n)

        report["line"] = outcome(line)
        report["line_n"], report["nx"] = n, nx
        report["guard_intact"] = bool(np.all(fx[n:] == SENTINEL) and np.all(fy[n:] == SENTINEL))
        if report["line"][0] == 0:
            report["finite"] = bool(np.all(np.isfinite(fx[:n])) and np.all(np.isfinite(fy[:n])))
    if report["check"][0] == 0:
        holder = {}

        def compute():
            holder["data"] = config.compute()

        report["compute"] = outcome(compute)
        for value in holder.get("data", {}).values():
            array = np.asarray(value)
            if np.issubdtype(array.dtype, np.floating) and not np.all(np.isfinite(array)):
                report["finite"] = False
    config.close()
    print(json.dumps(report))


if __name__ == "__main__":
    main()
