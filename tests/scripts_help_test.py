#!/usr/bin/env python3
"""Every script in scripts/ answers --help (the shell ones -h too) without side effects.

    scripts_help_test.py --scripts DIR --workdir DIR

Each script (shell ones with bash, Python ones with python3; afm_maps.gp
and C sources are not commands) runs with --help from an empty working
directory (HOME elsewhere: matplotlib's font cache is not the script's doing), and a PATH whose first folder holds
stand-ins for the programs a script would use to act: apt-get, sudo,
dpkg-query, cmake, ninja, make, mpirun, mpiexec, srun, gfortran, ngspice,
gnuplot, h5dump.  A stand-in records its call and fails.  The script must
exit 0 within 60 s, print something, call no stand-in and leave the
working directory empty.  Four at a time (most of the time is Python
importing numpy and matplotlib; -h of a Python script is argparse's own).
"""
import argparse
import concurrent.futures
import os
import shutil
import stat
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from helpers import fail  # noqa: E402

ACTING = ["apt-get", "sudo", "dpkg-query", "cmake", "ninja", "make", "mpirun", "mpiexec", "srun", "gfortran",
          "ngspice", "gnuplot", "h5dump"]
NOT_COMMANDS = {".gp", ".c"}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scripts", type=Path, required=True)
    parser.add_argument("--workdir", type=Path, required=True)
    args = parser.parse_args()
    shutil.rmtree(args.workdir, ignore_errors=True)
    stand_ins = args.workdir / "bin"
    stand_ins.mkdir(parents=True)
    for name in ACTING:
        path = stand_ins / name
        path.write_text(f"#!/bin/sh\necho \"{name} $*\" >> \"$STAND_IN_LOG\"\nexit 97\n")
        path.chmod(path.stat().st_mode | stat.S_IXUSR)
    scripts = sorted(p for p in args.scripts.iterdir() if p.is_file() and p.suffix not in NOT_COMMANDS)
    runs = []
    for script in scripts:
        first = script.read_text(errors="replace").split("\n", 1)[0]
        interpreter = "python3" if "python" in first or script.suffix == ".py" else "bash"
        for option in ("--help", "-h") if interpreter == "bash" else ("--help",):
            runs.append((script, interpreter, option))

    def check(number, script, interpreter, option):
        where = f"{script.name} {option}"
        cwd = args.workdir / f"cwd{number}"
        cwd.mkdir()
        calls = args.workdir / f"calls{number}.log"
        env = dict(os.environ, HOME=str(args.workdir / "home"), PATH=f"{stand_ins}{os.pathsep}{os.environ['PATH']}",
                   MPLBACKEND="Agg", PYTHONDONTWRITEBYTECODE="1", STAND_IN_LOG=str(calls))
        try:
            result = subprocess.run([interpreter, str(script.resolve()), option], cwd=cwd, env=env,
                                    capture_output=True, text=True, timeout=60)
        except subprocess.TimeoutExpired:
            return [f"{where}: still running after 60 s"]
        found = []
        if result.returncode != 0:
            found.append(f"{where}: exit {result.returncode}: {result.stderr.strip()[-300:]}")
        elif not result.stdout.strip():
            found.append(f"{where}: printed nothing on stdout")
        if calls.exists():
            found.append(f"{where}: ran {calls.read_text().strip()!r}")
        left = sorted(str(p.relative_to(cwd)) for p in cwd.rglob("*"))
        if left:
            found.append(f"{where}: left {left[:5]} in the working directory")
        return found

    with concurrent.futures.ThreadPoolExecutor(4) as pool:
        problems = [p for found in pool.map(lambda item: check(item[0], *item[1]), enumerate(runs)) for p in found]
    if problems:
        fail(f"{len(problems)} problems:\n  " + "\n  ".join(problems))
    print(f"{len(scripts)} scripts answer --help ({len(runs)} runs) without side effects")


if __name__ == "__main__":
    main()
