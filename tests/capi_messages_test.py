#!/usr/bin/env python3
"""The namelist and the C API refuse the same values with the same words.

    capi_messages_test.py --binary BIN --library SO --inputs DIR --workdir DIR

Each case is a scene's input files (inputs/naf.nml, ...) and assignments over
them.  The program reads the input files and the assignments written as a
namelist file, bad.nml; the C API (the friction package's Config over the
library) reads the same input files with friction_config_read and sets each
assignment with friction_config_set, then runs friction_config_check.  The
outcomes must be identical: both accept, or both refuse with the same
message, the program's without its "friction: error: bad.nml:LINE: " (the C
API names no place for a value set in memory).  The program runs with
--netlist, which reads and checks the input as a run does but integrates
nothing; a refusal of the netlist writer itself ("--netlist: ...") counts as
accepted input.

The cases:
 1. Listed: every case of tests/cli_test.py's BAD_INPUTS and
    BAD_BRAKE_INPUTS that sets values, all but those that are not about a
    value: a group not closed (file syntax), a missing file, command-line
    errors, and the XYZ net file's contents (read when the surface is built,
    not by the checks).
 2. Generated from the configurations: in each context (NaF, graphite under
    a Lennard-Jones tip, the overdamped and the quasistatic tip; the brake's
    switched and regularized models, in nondimensional and dimensional
    units), every numeric variable that friction_config_names lists for the
    scene's own groups (all but &job and &sweep, whose checks need a sweep
    set up: tests/cli_test.py's bad-sweep-* cases) is set to each of -1, 0
    and 1e300 (an integer to -1 and 0; an array's first element).  The base
    contexts (NaF, switched nondimensional brake) compare every candidate;
    the other contexts compare the candidates whose C API outcome differs
    from the base context's (where the context changes the checks).  The
    candidates the C API accepts (in the other contexts: those it accepts
    and the base context refuses) are also run together, one namelist per
    context, which the program must accept too (a candidate the C API
    refuses in that company is dropped from it and compared on its own).
"""
import argparse
import concurrent.futures
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import cli_test  # noqa: E402  (BAD_INPUTS, BAD_BRAKE_INPUTS)
import helpers  # noqa: E402
from helpers import fail  # noqa: E402

# Listed cases that are not about a value (see the docstring).
# (no-job-brake-group is about a file without &job, which a C API configuration, made for a
# scene, does not have: the C API refuses another scene's group in any file; docs/cli.md.)
NOT_VALUES = {"unclosed-group", "missing-file", "no-arguments", "unknown-option", "unwritable-output",
              "xyz-count", "xyz-field", "xyz-species", "no-job-brake-group"}
CANDIDATES = {"real": ["-1.0", "0.0", "1.0e300"], "integer": ["-1", "0"]}
# (context name, scene, input files, assignments over them); the first of each scene is its base.
DIMENSIONAL = ("brake.nml", "brake_dimensional.nml")
CONTEXTS = [
    ("naf", "afm", ("naf.nml",), []),
    ("graphite", "afm", ("graphite.nml",), []),
    ("overdamped", "afm", ("naf.nml",), [("tip", "model", "'overdamped'")]),
    ("quasistatic", "afm", ("naf.nml",), [("tip", "model", "'quasistatic'")]),
    ("brake", "brake", ("brake.nml",), []),
    ("regularized", "brake", ("brake.nml",), [("brake", "model", "'regularized'")]),
    ("dimensional", "brake", DIMENSIONAL, []),
    ("dimensional-regularized", "brake", DIMENSIONAL, [("brake", "model", "'regularized'")]),
]
PROGRAM_PREFIX = re.compile(r"^friction: error: (bad\.nml:\d+: )?")


def assignments(text):
    """(group, name, value text) of each assignment of a namelist text."""
    masked = re.sub(r"'[^']*'|\"[^\"]*\"", lambda m: "x" * len(m.group()), text)
    found = []
    for group in re.finditer(r"&(\w+)([^/]*)/", masked):
        body_start, body_end = group.start(2), group.end(2)
        names = list(re.finditer(r"([A-Za-z_]\w*(?:\(\d+\))?)\s*=", masked[body_start:body_end]))
        for k, name in enumerate(names):
            start = body_start + name.end()
            end = body_start + names[k + 1].start() if k + 1 < len(names) else body_end
            found.append((group.group(1).lower(), name.group(1).lower(), text[start:end].strip().rstrip(",").strip()))
    return found


def namelist(pairs):
    """A namelist file text of (group, name, value) assignments, one group per line."""
    lines, groups = [], {}
    for group, name, value in pairs:
        groups.setdefault(group, []).append(f"{name} = {value}")
    for group, items in groups.items():
        lines.append(f"&{group} " + ", ".join(items) + " /")
    return "\n".join(lines) + "\n"


class Checker:
    def __init__(self, args):
        self.args = args
        self.fc = helpers.friction_package(args.library)
        self.runs = 0

    def capi(self, scene, base, pairs):
        """The C API's outcome on the input files `base` and the assignments: None (accepted) or the message."""
        with self.fc.Config(scene) as cfg:
            try:
                for path in base:
                    cfg.read(os.path.join(self.args.inputs, path))
                for group, name, value in pairs:
                    cfg.set_text(f"{group}.{name}", value)
                cfg.check()
            except self.fc.FrictionError as error:
                return error.message
        return None

    def program(self, case, base, pairs):
        """The program's outcome on the input files and bad.nml: None (accepted) or the message."""
        workdir = os.path.join(self.args.workdir, case)
        os.makedirs(workdir, exist_ok=True)
        with open(os.path.join(workdir, "bad.nml"), "w") as f:
            f.write(namelist(pairs))
        env = helpers.mpi_env()
        result = subprocess.run([self.args.binary, "-q", "-f", "--netlist", "out.cir"]
                                + [os.path.join(self.args.inputs, path) for path in base] + ["bad.nml"],
                                cwd=workdir, capture_output=True, text=True, env=env, timeout=300)
        ours = [line for line in result.stderr.splitlines() if line.startswith("friction:")]
        if result.returncode == 0 or (ours and ours[0].startswith("friction: error: --netlist:")):
            return None
        if result.returncode != 3 or len(ours) != 1:
            fail(f"{case}: the program exited with {result.returncode}: {result.stderr}")
        return PROGRAM_PREFIX.sub("", ours[0])

    def compare_all(self, cases):
        """cases: (case name, scene, base, pairs, C API outcome); the program on each, in parallel."""
        with concurrent.futures.ThreadPoolExecutor(max_workers=8) as pool:
            outcomes = list(pool.map(lambda c: self.program(c[0], c[2], c[3]), cases))
        for (case, _, base, pairs, capi), program in zip(cases, outcomes):
            if program != capi:
                fail(f"{case} ({' + '.join(base)} + {namelist(pairs).strip()}):\n  program: {program}\n  C API:   {capi}")
        self.runs += len(cases)
        return outcomes


def listed_cases(checker):
    cases = []
    for table, base, scene in [(cli_test.BAD_INPUTS, ("naf.nml",), "afm"),
                               (cli_test.BAD_BRAKE_INPUTS, ("brake.nml",), "brake")]:
        for name, (text, _, _) in table.items():
            if name in NOT_VALUES or text is None:
                continue
            pairs = assignments(text)
            if not pairs:
                fail(f"{name}: no assignment in {text!r}")
            cases.append((f"listed-{scene}-{name}", scene, base, pairs, checker.capi(scene, base, pairs)))
    for case in cases:
        if case[4] is None:
            fail(f"{case[0]}: the C API accepts a value the program's test refuses")
    return cases


def generated_cases(checker):
    cases, accepted_sets, base_outcome = [], [], {}
    for context, scene, base, setting in CONTEXTS:
        with checker.fc.Config(scene) as cfg:
            variables = [(name, kind, size) for name, kind, size, _ in cfg.names()
                         if kind in CANDIDATES and name.split(".")[0] not in ("job", "sweep")]
        accepted = {}
        for name, kind, size in variables:
            group, variable = name.split(".")
            if size > 1:
                variable += "(1)"
            for value in CANDIDATES[kind]:
                pairs = setting + [(group, variable, value)]
                outcome = checker.capi(scene, base, pairs)
                key = (scene, group, variable, value)
                if key not in base_outcome:
                    base_outcome[key] = outcome   # (the first context of a scene is its base)
                elif outcome == base_outcome[key]:
                    continue
                if outcome is None:
                    accepted.setdefault((group, variable), value)
                else:
                    cases.append((f"{context}-{group}-{variable}-{value}", scene, base, pairs, outcome))
        accepted_sets.append((context, scene, base, setting, accepted))
    return cases, accepted_sets


def together(checker, accepted_sets):
    """The candidates each context's C API accepts, in one namelist (those it refuses in company dropped
    and compared alone)."""
    cases = []
    for context, scene, base, setting, accepted in accepted_sets:
        chosen = dict(accepted)
        while True:
            pairs = setting + [(g, v, value) for (g, v), value in chosen.items()]
            outcome = checker.capi(scene, base, pairs)
            blamed = [key for key in chosen if outcome is not None and
                      re.match(rf"^(.*: )?&{key[0]}: {re.escape(key[1].split('(')[0])}\b", outcome)]
            if not blamed:   # accepted, or refused for a value of the input file: compare as it is
                cases.append((f"{context}-together", scene, base, pairs, outcome))
                break
            for key in blamed:
                value = chosen.pop(key)
                alone = setting + [(key[0], key[1], value)]
                cases.append((f"{context}-{key[0]}-{key[1]}-{value}-alone", scene, base, alone,
                              checker.capi(scene, base, alone)))
    return cases


def reason(message):
    """A refusal without its place and value: the check it comes from."""
    return re.sub(r"^(.*?: )?(&\w+: [\w()]+) = .*?: ", r"\2: ", message)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--binary", required=True)
    parser.add_argument("--library", required=True)
    parser.add_argument("--inputs", required=True)
    parser.add_argument("--workdir", required=True)
    args = parser.parse_args()
    shutil.rmtree(args.workdir, ignore_errors=True)
    os.makedirs(args.workdir)
    checker = Checker(args)

    listed = listed_cases(checker)
    checker.compare_all(listed)
    print(f"listed: {len(listed)} bad inputs of cli_test.py, the same message from both")

    generated, accepted_sets = generated_cases(checker)
    refused = [c for c in generated if c[4] is not None]
    checker.compare_all(generated)
    company = together(checker, accepted_sets)
    checker.compare_all(company)
    accepted = sum(len(a[4]) for a in accepted_sets)
    checks = {reason(c[4]) for c in listed + generated + company if c[4] is not None}
    variables = {m.group(1) for m in (re.match(r"(&\w+: \w+)(\(\d+\))?: ", text) for text in checks) if m}
    print(f"generated: {len(refused)} values refused the same way by both, {accepted} accepted by both "
          f"({len(company)} program runs of them)")
    print(f"{checker.runs} program runs; {len(checks)} distinct refusals (variable and reason, values left out) "
          f"of {len(variables)} variables:")
    for text in sorted(checks):
        print("  " + text)
    # A floor, so that generation reaching fewer checks (a renamed input file, a
    # context that stopped applying) fails rather than passing on less.
    if len(checks) < 90:
        fail(f"only {len(checks)} distinct refusals: the generated cases no longer reach the checks")
    print("1 passed, 0 failed")


if __name__ == "__main__":
    main()
