#!/usr/bin/env python3
"""scripts/friction.slurm without a cluster: srun is a stand-in that logs
its arguments, answers `srun --mpi=list`, and starts the program once as
task 0 of a 2-task step that no MPI launch reached (SLURM_STEP_NUM_TASKS=2,
SLURM_PROCID=0, no PMIx variables): what a plain srun does where the site's
MPI needs --mpi=pmix.

    slurm_script_test.py --script scripts/friction.slurm --binary build/friction
                         --inputs inputs --workdir DIR

Checks: the script asks for --mpi=pmix when srun lists it, for pmi2 when
only that is listed, for srun's default with FRICTION_SRUN_MPI= (empty);
it passes --resume and writes the array task's output; --help prints its
header and runs nothing; and the program warns that the tasks are not one
MPI job, naming their number and the remedy.
"""
import argparse
import os
import shutil
import stat
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from helpers import fail, mpi_env, require  # noqa: E402

FAKE_SRUN = """#!/bin/bash
if [[ $1 == --mpi=list ]]; then
  printf 'MPI plugin types are...\\n\\tnone\\n%s' "$FAKE_SRUN_PLUGINS"
  exit 0
fi
printf '%s\\n' "$*" >> "$FAKE_SRUN_LOG"
command=()
for a in "$@"; do [[ $a == --mpi=* ]] || command+=("$a"); done
SLURM_STEP_NUM_TASKS=2 SLURM_PROCID=0 exec "${command[@]}"
"""


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    for option in ("--script", "--binary", "--inputs", "--workdir"):
        parser.add_argument(option, required=True)
    args = parser.parse_args()
    work = Path(args.workdir)
    shutil.rmtree(work, ignore_errors=True)
    (work / "bin").mkdir(parents=True)
    srun = work / "bin" / "srun"
    srun.write_text(FAKE_SRUN)
    srun.chmod(srun.stat().st_mode | stat.S_IXUSR)
    shutil.copytree(args.inputs, work / "inputs")
    (work / "sweep").mkdir()
    # A small map, so each run takes well under a second.
    (work / "sweep" / "00.nml").write_text("&scan nx = 16, ny = 4 /\n")
    log = work / "srun.log"
    base = mpi_env({"PATH": f"{work / 'bin'}{os.pathsep}{os.environ['PATH']}",
                    "FRICTION": os.path.abspath(args.binary), "FAKE_SRUN_LOG": str(log),
                    "SLURM_ARRAY_TASK_ID": "0"})
    for key in list(base):
        if key.startswith(("PMIX_", "PMI_", "OMPI_COMM_WORLD", "OMPI_UNIVERSE", "SLURM_STEP", "SLURM_PROCID")):
            del base[key]

    help_run = subprocess.run(["bash", args.script, "--help"], env=base, cwd=work, capture_output=True,
                              text=True, timeout=60)
    require(help_run.returncode == 0 and "srun --mpi=list" in help_run.stdout and not log.exists(),
            f"--help prints the header and runs nothing: {help_run.returncode} {help_run.stderr}")

    cases = [("pmix", "\tpmi2\n\tpmix\n", "--mpi=pmix"), ("pmi2", "\tpmi2\n", "--mpi=pmi2"),
             ("default", "\tpmix\n", None)]
    for name, plugins, expected in cases:
        env = dict(base, FAKE_SRUN_PLUGINS=plugins)
        if name == "default":
            env["FRICTION_SRUN_MPI"] = ""
        log.unlink(missing_ok=True)
        output = work / "results" / "hopg-00.h5"
        output.unlink(missing_ok=True)
        result = subprocess.run(["bash", args.script], env=env, cwd=work, capture_output=True, text=True,
                                timeout=300)
        if result.returncode != 0:
            fail(f"{name}: friction.slurm exited {result.returncode}:\n{result.stderr}")
        line = log.read_text().strip()
        words = line.split()
        mpi = [w for w in words if w.startswith("--mpi=")]
        require(mpi == ([expected] if expected else []), f"{name}: srun {line}")
        require("--resume" in words and "results/hopg-00.h5" in words, f"{name}: srun {line}")
        require(output.is_file(), f"{name}: the array task's output {output}")
        require("Slurm started 2 tasks, but they are not one MPI job" in result.stderr
                and "srun --mpi=pmix" in result.stderr, f"{name}: the program's warning:\n{result.stderr}")
        print(f"{name}: srun {line}")
    print("1 passed, 0 failed")


if __name__ == "__main__":
    main()
