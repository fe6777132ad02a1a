#!/usr/bin/env python3
"""The program and the shared library never look for libraries in the
current directory.

    runpath_test.py --program BIN --library LIB --workdir DIR

The loader reads an empty entry of a RUNPATH (a leading, trailing or double
colon) as the current directory.  CMake pads a build tree's RUNPATH with one
(room to rewrite it at install) unless told otherwise; a user who then runs
the program in a directory holding a file named like one of its libraries
gets that file loaded, or the program fails to start ("file too short").
The oracle is the loader itself: in a directory holding an empty file named
after every library the program and the library need, `friction --version`
must print the version and a process must load the library; and no entry of
either RUNPATH may be empty or relative (readelf)."""
import argparse
import os
import re
import subprocess
import sys


def fail(message):
    print(f"runpath_test: {message}", file=sys.stderr)
    sys.exit(1)


def dynamic_section(path):
    result = subprocess.run(["readelf", "-d", path], capture_output=True, text=True)
    if result.returncode != 0:
        fail(f"readelf -d {path}: {result.stderr.strip()}")
    return result.stdout


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--program", required=True)
    parser.add_argument("--library", required=True)
    parser.add_argument("--workdir", required=True)
    args = parser.parse_args()
    os.makedirs(args.workdir, exist_ok=True)
    needed = set()
    for path in (args.program, args.library):
        section = dynamic_section(path)
        needed.update(re.findall(r"\(NEEDED\)\s+Shared library: \[([^\]]+)\]", section))
        for entries in re.findall(r"\((?:RUNPATH|RPATH)\)\s+Library r(?:un)?path: \[([^\]]*)\]", section):
            for entry in entries.split(":"):
                if not (entry.startswith("/") or entry.startswith("$ORIGIN")):
                    fail(f"{path}: RUNPATH [{entries}] has the entry {entry!r} (the current directory or a "
                         "relative one)")
    if not needed:
        fail("readelf found no NEEDED libraries: the check would prove nothing")
    # Decoys: empty files named like every library needed.
    for name in needed:
        open(os.path.join(args.workdir, name), "w").close()
    result = subprocess.run([os.path.abspath(args.program), "--version"], cwd=args.workdir,
                            capture_output=True, text=True)
    if result.returncode != 0 or not result.stdout.startswith("friction "):
        fail(f"friction --version beside decoy libraries: exit {result.returncode}: {result.stderr.strip()}")
    # The library, loaded by a fresh process whose current directory holds the decoys.
    probe = ("import ctypes, sys; lib = ctypes.CDLL(sys.argv[1]); buf = ctypes.create_string_buffer(64); "
             "lib.friction_version(buf, ctypes.c_size_t(64)); print(buf.value.decode())")
    result = subprocess.run([sys.executable, "-c", probe, os.path.abspath(args.library)], cwd=args.workdir,
                            capture_output=True, text=True)
    if result.returncode != 0 or not result.stdout.strip():
        fail(f"loading {args.library} beside decoy libraries: exit {result.returncode}: {result.stderr.strip()}")
    print(f"runpath_test: {len(needed)} decoys ignored by the program and the library")


if __name__ == "__main__":
    main()
