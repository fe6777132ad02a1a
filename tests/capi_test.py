#!/usr/bin/env python3
"""The C API against the CLI on the same scene, one case per CTest test.

    capi_test.py --binary BIN --capi TEST_CAPI --inputs DIR --workdir DIR afm|brake

afm:   inputs/naf.nml with nx = 16, angle = 10, origin (0.7, 0.3) Å: the CLI's
       first trace and retrace line against `test_capi afm` (friction_afm_line).
brake: inputs/brake.nml to t_end = 40, dt_out = 0.5 against `test_capi brake`
       (friction_brake).
job:   friction_run_job (`test_capi job`) against the CLI on both scenes above:
       every dataset and every attribute of the two files but the wall time
       and the compute times must be equal.
Both run the same kernel, so the numbers must agree to the last bit; the test
allows 1e-12 relative in case a compiler reorders arithmetic.
"""
import argparse
import os
import shutil
import subprocess
import sys

import h5py
import numpy as np

AFM = ("&scan nx = 16, ny = 3, angle = 10.0, origin_x = 0.7, origin_y = 0.3, retrace = .true. /\n")
BRAKE = ("&brake t_end = 40.0, dt_out = 0.5 /\n"
         "&analysis spectrum = .false., poincare = .false., lyapunov = .false., rosenstein = .false. /\n")
TOLERANCE = 1e-12


def fail(message):
    print("FAIL: " + message)
    sys.exit(1)


def run(command, cwd):
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    result = subprocess.run(command, cwd=cwd, capture_output=True, text=True, env=env)
    if result.returncode != 0:
        fail(f"{' '.join(command)} exited with {result.returncode}: {result.stderr}")
    return result.stdout


def compare(name, expected, actual):
    expected, actual = np.asarray(expected), np.asarray(actual)
    if expected.shape != actual.shape:
        fail(f"{name}: shape {actual.shape}, expected {expected.shape}")
    scale = max(1.0, float(np.max(np.abs(expected))))
    difference = float(np.max(np.abs(expected - actual)))
    if not difference <= TOLERANCE * scale:
        fail(f"{name}: max |C API - CLI| = {difference:.3e} > {TOLERANCE * scale:.3e}")
    print(f"{name}: max |C API - CLI| = {difference:.3e} over {expected.size} values")


# Attributes that measure the run rather than compute it.
TIMINGS = {"wall_time", "compute_time", "check_compute_time", "created"}


def file_contents(path):
    """Every dataset and attribute of an HDF5 file, by name."""
    contents = {}

    def visit(name, item):
        if isinstance(item, h5py.Dataset):
            contents[name] = item[()]
        for key, value in item.attrs.items():
            if key not in TIMINGS:
                contents[f"{name}@{key}"] = value

    with h5py.File(path, "r") as f:
        for key, value in f.attrs.items():
            if key not in TIMINGS:
                contents[f"/@{key}"] = value
        f.visititems(visit)
    return contents


def compare_jobs(args):
    for scene, text in [("naf.nml", AFM), ("brake.nml", BRAKE)]:
        override = os.path.join(args.workdir, "override-" + scene)
        with open(override, "w") as f:
            f.write(text)
        inputs = [os.path.join(args.inputs, scene), override]
        run([args.binary, "-q", "-o", "cli.h5", "--force"] + inputs, args.workdir)
        run([args.capi, "job", "capi.h5"] + inputs, args.workdir)
        cli = file_contents(os.path.join(args.workdir, "cli.h5"))
        capi = file_contents(os.path.join(args.workdir, "capi.h5"))
        if sorted(cli) != sorted(capi):
            fail(f"{scene}: the files hold different items: {sorted(set(cli) ^ set(capi))}")
        for name in cli:
            a, b = np.asarray(cli[name]), np.asarray(capi[name])
            if a.shape != b.shape or not np.array_equal(a, b):
                fail(f"{scene}: {name} differs between friction_run_job and the CLI")
        print(f"{scene}: friction_run_job and the CLI wrote the same {len(cli)} datasets and attributes")
    print("1 passed, 0 failed")


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--binary", required=True)
    parser.add_argument("--capi", required=True)
    parser.add_argument("--inputs", required=True)
    parser.add_argument("--workdir", required=True)
    parser.add_argument("case", choices=["afm", "brake", "job"])
    args = parser.parse_args()
    shutil.rmtree(args.workdir, ignore_errors=True)
    os.makedirs(args.workdir)
    if args.case == "job":
        compare_jobs(args)
        return
    override = os.path.join(args.workdir, "override.nml")
    with open(override, "w") as f:
        f.write(AFM if args.case == "afm" else BRAKE)
    scene = "naf.nml" if args.case == "afm" else "brake.nml"
    run([args.binary, "-q", "-o", "cli.h5", os.path.join(args.inputs, scene), override], args.workdir)
    printed = np.loadtxt(run([args.capi, args.case], args.workdir).splitlines(), ndmin=2)
    with h5py.File(os.path.join(args.workdir, "cli.h5"), "r") as f:
        if args.case == "afm":
            for forward, trip in [(1, "trace"), (0, "retrace")]:
                rows = printed[printed[:, 0] == forward]
                for column, quantity in [(2, "fx"), (3, "fy")]:
                    compare(f"{trip} {quantity}", f[f"afm/{trip}/{quantity}"][0, :], rows[:, column])
        else:
            for column, quantity in enumerate(["t", "x", "v", "y", "w"]):
                compare(quantity, f[f"brake/{quantity}"][()], printed[:, column])
    print("1 passed, 0 failed")


if __name__ == "__main__":
    main()
