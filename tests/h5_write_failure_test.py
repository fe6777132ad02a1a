#!/usr/bin/env python3
"""A write of the sweep's table file that fails for want of room closes
cleanly (docs/reliability.md): the failure comes back as the table's error,
and HDF5 prints nothing at exit.  After a chunk write failed for a full disk,
HDF5 1.10 kept the chunk's buffer and, at exit, printed "HDF5: infinite loop
closing library" and the list of its interfaces it could not close.

    h5_write_failure_test.py --binary h5_table_full --workdir DIR

The program (tests/h5_table_full_main.f90) writes eight columns of 200000
doubles, 12.8 MB, and reads them back:
  - with room: every value reads back as written ("ok");
  - under a 1 MB file-size limit (SIGXFSZ ignored through the program's own
    signal set-up): an error naming the file-size limit;
  - on a 1 MB tmpfs, and on a 16 MB tmpfs that this program fills after the
    columns are made (the disk fills during the write): an error saying the
    disk is full.  These need a tmpfs mount (root); without one they are
    skipped and said so.
Each asserts that stderr holds nothing: HDF5 prints its closing loop there.
"""
import argparse
import os
import resource
import subprocess
import sys


def fail(message):
    print(f"FAILED: {message}")
    sys.exit(1)


def run(args, path, *extra, limit_kb=None):
    def limited():
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit_kb * 1024, limit_kb * 1024))

    result = subprocess.run([args.binary, path, *extra], capture_output=True, text=True, timeout=120,
                            preexec_fn=limited if limit_kb else None)
    if result.returncode != 0:
        fail(f"{path}: exit {result.returncode}: {result.stdout}{result.stderr}")
    if result.stderr:
        fail(f"{path}: stderr is not empty (HDF5 did not close cleanly):\n{result.stderr}")
    return result.stdout.strip()


def expect_error(output, path, words):
    if not output.startswith("error: ") or path not in output or words not in output:
        fail(f"expected an error naming {path} and '{words}', got: {output}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--binary", required=True)
    parser.add_argument("--workdir", required=True)
    args = parser.parse_args()
    os.makedirs(args.workdir, exist_ok=True)

    path = os.path.join(args.workdir, "room.h5")
    output = run(args, path)
    if output != "ok":
        fail(f"with room: {output}")
    os.remove(path)

    path = os.path.join(args.workdir, "limited.h5")
    expect_error(run(args, path, limit_kb=1024), path, "file-size limit (ulimit -f)")
    os.remove(path)

    small = os.path.join(args.workdir, "small")
    os.makedirs(small, exist_ok=True)
    for size, mode in (("1m", "plain"), ("16m", "fill")):
        mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", small],
                                 capture_output=True, text=True)
        if mounted.returncode != 0:
            print(f"skipped the full-disk cases: cannot mount a tmpfs here ({mounted.stderr.strip()})")
            break
        try:
            path = os.path.join(small, "full.h5")
            expect_error(run(args, path, mode), path, "the disk is full")
        finally:
            subprocess.run(["umount", small], capture_output=True)
    print("h5-write-failure: every failed write closed cleanly")


if __name__ == "__main__":
    main()
