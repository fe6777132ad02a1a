#!/usr/bin/env python3
"""Check `work_precision.py --add-to` (CTest work_precision.add).

usage: check_work_precision_add.py --script WP --binary BIN --from DIR --workdir DIR

Copies the files of the --quick fixture (DIR: work_precision.h5 and
failure_map.h5) into --workdir, adds rodas4 to them with
`WP --add-to WORKDIR --methods rodas4 --binary BIN`, and checks:

* Nothing measured before is changed: every dataset of the fixture's
  methods is bit for bit the same.
* rodas4 is added to both quick scenes, on the file's ladder, with the
  attribute 'added', and to the root attribute 'methods'.  Its error falls at
  least tenfold at each hundredfold tighter rung on both (an adaptive order-4
  method: the global error shrinks with the tolerance; measured factors 87 to
  1070).  (rodas4 rather than rodas3: at rtol 1e-8 on NaF it takes 0.3 s, and
  rodas3 1.4 s, near the quick ladder's cap of 3 s on a loaded machine.)
* The failure maps list the fixture's methods and then rodas4, and every
  category follows the rule from the stored points alone, computed here
  independently: 'wrong' and the failures as stored, 'slow' an 'ok' point
  more than 10x the fastest 'ok' one of its column, the time cap 'slow'.
* The charts were redrawn after the files were written.

Exit 0 when all hold, else 1 with the reasons.
"""
import argparse
import os
import shutil
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np

QUICK_SCENES = ("naf", "brake_switched")
QUICK_TOLS = (1e-4, 1e-6, 1e-8)
CODES = {"ok": 0, "slow": 1, "failed": 2, "wrong": 3}


def datasets(group, prefix=""):
    out = {}
    for name, item in group.items():
        if isinstance(item, h5py.Group):
            out.update(datasets(item, f"{prefix}{name}/"))
        else:
            out[prefix + name] = item[()]
    return out


def same(a, b):
    """Bit for bit the same dataset: a point the fixture lost to the time cap
    (a loaded machine) keeps NaN for its error and time, and NaN != NaN."""
    a, b = np.asarray(a), np.asarray(b)
    if a.dtype.kind == "f" and b.dtype.kind == "f":
        return a.shape == b.shape and a.tobytes() == b.tobytes()
    return np.array_equal(a, b)


def text(values):
    return [v.decode() if isinstance(v, bytes) else str(v) for v in values]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--script", required=True)
    parser.add_argument("--binary", required=True)
    parser.add_argument("--from", dest="source", required=True)
    parser.add_argument("--workdir", required=True)
    args = parser.parse_args()
    work = Path(args.workdir)
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    for name in ("work_precision.h5", "failure_map.h5"):
        shutil.copy(Path(args.source) / name, work / name)
    with h5py.File(work / "work_precision.h5", "r") as f:
        before = datasets(f)
        methods_before = text(str(f.attrs["methods"]).split(","))
    with h5py.File(work / "failure_map.h5", "r") as f:
        map_before = {name: text(f[name]["methods"][()]) for name in f}
    result = subprocess.run([sys.executable, args.script, "--add-to", str(work), "--methods", "rodas4",
                             "--binary", args.binary], capture_output=True, text=True, timeout=280)
    problems = []

    def need(cond, what):
        if not cond:
            problems.append(what)

    need(result.returncode == 0, f"--add-to exited {result.returncode}: {result.stderr[-2000:]}")
    if result.returncode == 0:
        with h5py.File(work / "work_precision.h5", "r") as f:
            after = datasets(f)
            for key, value in before.items():
                need(key in after and same(after[key], value), f"{key} changed or lost")
            need(text(str(f.attrs["methods"]).split(",")) == methods_before + ["rodas4"],
                 f"root attribute methods: {f.attrs['methods']}")
            for scene in QUICK_SCENES:
                m = f[f"{scene}/rodas4"]
                need("added" in m.attrs, f"{scene}/rodas4: attribute added")
                need(np.allclose(m["tolerance"][()], QUICK_TOLS), f"{scene}/rodas4: tolerances")
                status, err = text(m["status"][()]), m["error"][()]
                need(status == ["ok"] * 3, f"{scene}/rodas4: statuses {status}")
                need(all(b < a / 10 for a, b in zip(err, err[1:])), f"{scene}/rodas4: error must fall: {err}")
        with h5py.File(work / "failure_map.h5", "r") as f:
            for name, methods in map_before.items():
                g = f[name]
                need(text(g["methods"][()]) == methods + ["rodas4"], f"{name}: methods {text(g['methods'][()])}")
                category, time = g["category"][()], g["cpu_time"][()]
                status = [text(row) for row in g["status"][()]]
                for j in range(category.shape[1]):
                    ok_times = [time[i, j] for i in range(category.shape[0]) if status[i][j] == "ok"]
                    fastest = min(ok_times) if ok_times else np.nan
                    for i in range(category.shape[0]):
                        s = status[i][j]
                        want = (CODES["slow"] if s == "ok" and time[i, j] > 10 * fastest else
                                CODES["ok"] if s == "ok" else
                                CODES["slow"] if s in ("capped", "killed") else
                                CODES["wrong"] if s == "wrong" else
                                -1 if s == "no reference" else CODES["failed"])
                        need(category[i, j] == want, f"{name}[{i}, {j}] ({s}): category {category[i, j]}, "
                                                     f"the rule gives {want}")
        newest = os.path.getmtime(work / "failure_map.h5")
        for png in [f"work_precision_{s}.png" for s in QUICK_SCENES] + ["failure_map.png"]:
            need((work / png).exists() and os.path.getmtime(work / png) >= newest, f"{png} not redrawn")
    for p in problems:
        print(f"check_work_precision_add: {p}", file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
