#!/usr/bin/env python3
"""Run a command and pass only if it exits with the expected code.

usage: expect_exit.py CODE [--stderr REGEX] -- COMMAND [ARG ...]

Passes (exit 0) when COMMAND exits with CODE, its stderr matches REGEX (if
given) and holds no Python traceback; else fails (exit 1).  The command's
output is echoed.  For the error paths of the scripts, where CTest's
WILL_FAIL would accept any failure, a crash included.
"""

import argparse
import re
import subprocess
import sys


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("code", type=int)
    parser.add_argument("--stderr", metavar="REGEX")
    argv = sys.argv[1:]
    if "--" not in argv:
        parser.error("put -- before the command")
    split = argv.index("--")
    args = parser.parse_args(argv[:split])
    command = argv[split + 1:]
    if not command:
        parser.error("no command after --")
    try:
        run = subprocess.run(command, capture_output=True, text=True)
    except OSError as err:
        print(f"expect_exit.py: cannot run {command[0]}: {err}", file=sys.stderr)
        return 1
    sys.stdout.write(run.stdout)
    sys.stdout.write(run.stderr)
    problems = []
    if run.returncode != args.code:
        problems.append(f"exit code {run.returncode}, expected {args.code}")
    if "Traceback (most recent call last)" in run.stderr:
        problems.append("a Python traceback on stderr")
    if args.stderr and not re.search(args.stderr, run.stderr):
        problems.append(f"stderr does not match {args.stderr!r}")
    for problem in problems:
        print(f"expect_exit.py: {problem}", file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
