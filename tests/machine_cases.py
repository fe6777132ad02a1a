"""What the machine scene's oracle scripts (machine_oracles.py,
machine_orbit_oracles.py, machine_chaos.py) share: running the program on
inputs with --set values, checking refused inputs, and the command line
that picks one case.

    from machine_cases import run_program, check_refusals, case_main
"""
import argparse
import subprocess
from pathlib import Path


def run_program(args, name, files, sets):
    """The program on `files` (in --inputs) with --set key=value for each of
    `sets`, writing DIR/name.h5 (DIR the --workdir); its path."""
    out = Path(args.workdir) / f"{name}.h5"
    command = [args.binary, "--quiet", "--force", "-o", str(out)] + [str(Path(args.inputs) / f) for f in files]
    for key, value in sets.items():
        command += ["--set", f"{key}={value}"]
    subprocess.run(command, check=True)
    return out


def check_refusals(args, cases, label, scene="machine"):
    """For each (groups, line, names, why) of `cases`: an input of `scene` (the
    machine's unless named) of the groups (after its &job) is refused with exit code 3, the message naming
    the file, the line and `names`, saying `why`, and no file is written."""
    work = Path(args.workdir)
    for i, (groups, line, names, why) in enumerate(cases):
        path = work / f"bad{i}.nml"
        path.write_text(f"! a refused value\n&job\n  scene = '{scene}'\n/\n" + groups)
        out = work / f"bad{i}.h5"
        result = subprocess.run([args.binary, "-o", str(out), str(path)], capture_output=True, text=True)
        print(f"{label}: exit {result.returncode}: {result.stderr.strip()}")
        assert result.returncode == 3, result
        assert f"{path}:{line}: {names}" in result.stderr and why in result.stderr, result.stderr
        assert not out.exists()


def case_main(doc, cases, extra=()):
    """Runs the case named on the command line (--binary, --inputs, --workdir,
    each option of `extra`, CASE), `cases` mapping names to functions of the
    arguments."""
    parser = argparse.ArgumentParser(description=doc.split("\n")[0])
    parser.add_argument("--binary", required=True)
    for option in extra:
        parser.add_argument(option, required=True)
    parser.add_argument("--inputs", required=True)
    parser.add_argument("--workdir", required=True)
    parser.add_argument("case", choices=list(cases))
    args = parser.parse_args()
    Path(args.workdir).mkdir(parents=True, exist_ok=True)
    cases[args.case](args)
    return 0
