#!/usr/bin/env python3
"""The C API against the program on the same input, one case per CTest test.

    capi_test.py --binary BIN --capi TEST_CAPI --inputs DIR --workdir DIR afm|brake|job

Each scene is an input file of inputs/ with a small override, read by the
program and by friction_config_read in `test_capi`.

afm:   three maps: NaF (inputs/naf.nml; 3 lines of 16 samples at 10 degrees from
       (0.7, 0.3) Å, trace and retrace), HOPG with the quasistatic tip (jumps)
       and graphite under a Lennard-Jones tip (a tip moving in z: fz, tip_z).
       friction_compute must hold exactly the datasets of the file's /afm, and
       friction_afm_line of every line and direction must be that line of
       /afm/trace (/afm/retrace).
brake: inputs/brake.nml to t_end = 40 (dt_out = 0.5): friction_compute must
       hold exactly the datasets of /brake and /brake/events.
job:   friction_run_job, and friction_config_read + friction_run_config, against
       the program on NaF and on the brake: every dataset and every attribute of
       the files but the wall time and the compute times must be equal (the
       `input` attribute included: the configuration's text is the program's).
Both run the same kernel: every number must be equal, to the last bit.
"""
import argparse
import os
import shutil
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import helpers  # noqa: E402
from helpers import fail, file_contents  # noqa: E402

NAF = ("naf.nml", "&scan nx = 16, ny = 3, angle = 10.0, origin_x = 0.7, origin_y = 0.3, retrace = .true. /\n")
HOPG_QUASISTATIC = ("hopg.nml", "&tip model = 'quasistatic' /\n&scan nx = 24, ny = 2, width = 1.0 /\n")
GRAPHITE = ("graphite.nml", "&scan nx = 4, ny = 2, length = 1.0, width = 0.5 /\n")
BRAKE = ("brake.nml", "&brake t_end = 40.0, dt_out = 0.5 /\n"
         "&analysis spectrum = .false., poincare = .false., lyapunov = .false., rosenstein = .false.,"
         " lyapunov_spectrum = .false., orbit = .false. /\n")
# Attributes that measure the run rather than compute it.


def run(command, cwd):
    """The command's standard output; fail() unless it exits 0."""
    return helpers.run(command, cwd).stdout


def inputs(args, scene, name):
    """The scene's input file and its override, written to the work directory."""
    base, text = scene
    override = os.path.join(args.workdir, f"override-{name}.nml")
    with open(override, "w") as f:
        f.write(text)
    return [os.path.join(args.inputs, base), override]


def printed_arrays(text):
    """The arrays `test_capi afm|brake` prints: '# name rows columns', then the values."""
    arrays, lines = {}, text.splitlines()
    k = 0
    while k < len(lines):
        _, name, rows, columns = lines[k].split()
        rows, columns = int(rows), int(columns)
        values = np.array([float(v) for v in lines[k + 1:k + 1 + rows * columns]])
        arrays[name] = values.reshape(rows, columns) if columns > 1 else values
        k += 1 + rows * columns
    return arrays


def same(name, expected, actual):
    expected, actual = np.asarray(expected), np.asarray(actual)
    if expected.shape != actual.shape:
        fail(f"{name}: shape {actual.shape} (C API), {expected.shape} (program)")
    if not np.array_equal(expected, actual):
        difference = np.max(np.abs(expected.astype(float) - actual.astype(float)))
        fail(f"{name}: max |C API - program| = {difference:.3e}, not 0")


def compare_scene(args, scene_name, scene, group):
    files = inputs(args, scene, scene_name)
    out = os.path.join(args.workdir, f"{scene_name}.h5")
    run([args.binary, "-q", "-f", "-o", out] + files, args.workdir)
    program = helpers.group_datasets(out, group)
    capi = printed_arrays(run([args.capi, group] + files, args.workdir))
    computed = {name: value for name, value in capi.items() if not name.startswith("line/")}
    if sorted(computed) != sorted(program):
        fail(f"{scene_name}: friction_compute holds {sorted(computed)}, the file's /{group} {sorted(program)}")
    for name in program:
        same(f"{scene_name} {name}", program[name], computed[name])
    lines = 0
    for name, value in capi.items():
        if name.startswith("line/"):
            _, line, trip, quantity = name.split("/")
            same(f"{scene_name} friction_afm_line {line} {trip} {quantity}",
                 program[f"{trip}/{quantity}"][int(line)], value[0])
            lines += 1
    if group == "afm" and lines != 2 * len(program["support_y"]) * (2 if "retrace/fx" in program else 1):
        fail(f"{scene_name}: {lines} lines printed")
    print(f"{scene_name}: friction_compute equals the file's {len(program)} datasets"
          + (f", friction_afm_line its {lines // 2} line trips" if lines else "") + ", to the last bit")


def compare_jobs(args):
    for name, scene, scene_kind in [("naf", NAF, "afm"), ("brake", BRAKE, "brake")]:
        files = inputs(args, scene, name)
        run([args.binary, "-q", "-o", "cli.h5", "--force"] + files, args.workdir)
        cli = file_contents(os.path.join(args.workdir, "cli.h5"))
        for way, command in [("friction_run_job", [args.capi, "job", "capi.h5"] + files),
                             ("friction_run_job without MPI", [args.capi, "serial-job", "capi.h5"] + files),
                             ("friction_run_config", [args.capi, "config-job", scene_kind, "capi.h5"] + files)]:
            run(command, args.workdir)
            capi = file_contents(os.path.join(args.workdir, "capi.h5"))
            if sorted(cli) != sorted(capi):
                fail(f"{name}: {way} and the program wrote different items: {sorted(set(cli) ^ set(capi))}")
            for item in cli:
                a, b = np.asarray(cli[item]), np.asarray(capi[item])
                if a.shape != b.shape or not np.array_equal(a, b):
                    fail(f"{name}: {item} differs between {way} and the program")
            print(f"{name}: {way} and the program wrote the same {len(cli)} datasets and attributes")


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
    elif args.case == "afm":
        for name, scene in [("naf", NAF), ("hopg-quasistatic", HOPG_QUASISTATIC), ("graphite", GRAPHITE)]:
            compare_scene(args, name, scene, "afm")
    else:
        compare_scene(args, "brake", BRAKE, "brake")
    print("1 passed, 0 failed")


if __name__ == "__main__":
    main()
