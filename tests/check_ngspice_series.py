#!/usr/bin/env python3
"""Check the ngspice series of `work_precision.py --quick --ngspice` (CTest
work_precision.ngspice).

usage: check_ngspice_series.py DIR

/naf_trace/extra/<ngspice label> in DIR/work_precision.h5 must hold two
points (reltol 1e-6 and 1e-8) measured against the chart's own reference on
the chart's own samples.  The oracles: trap integration is second order, so
a hundredfold tighter reltol must shrink the error at least fivefold
(measured: about 25x); and at reltol 1e-8 the network model must agree with
the kernel's reference within 1e-4 nN (measured 1.5e-5 nN; the netlist
tests assert the same bound on their own grid).  The kernel's rkf45 points
are on the same chart, so both peers share one reference.
"""
import sys
from pathlib import Path

import h5py
import numpy as np


def main():
    path = Path(sys.argv[1]) / "work_precision.h5"
    problems = []
    with h5py.File(path, "r") as f:
        extra = f.get("naf_trace/extra")
        labels = [label for label in (extra or {}) if label.startswith("ngspice")]
        if not labels:
            print(f"FAIL: {path}: no /naf_trace/extra/ngspice* series")
            return 1
        series = extra[labels[0]]
        error, cpu = series["error"][()], series["cpu_time"][()]
        if error.size != 2 or cpu.size != 2:
            problems.append(f"expected 2 points, got {error.size}")
        elif not (np.all(np.isfinite(error)) and np.all(cpu > 0)):
            problems.append(f"errors {error}, times {cpu}")
        else:
            if not error[1] < error[0] / 5:
                problems.append(f"error did not shrink fivefold from reltol 1e-6 to 1e-8: {error}")
            if not error[1] <= 1e-4:
                problems.append(f"error at reltol 1e-8 is {error[1]:.3e} nN > 1e-4 nN")
        if "rkf45" not in f["naf_trace"]:
            problems.append("the kernel's rkf45 series is missing from the chart data")
    for problem in problems:
        print("FAIL: " + problem)
    if not problems:
        print(f"ngspice on the NaF line: errors {error[0]:.2e}, {error[1]:.2e} nN in {cpu[0]:.3f}, {cpu[1]:.3f} s")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
