#!/usr/bin/env python3
"""Regression tests of issue 15 (docs/reliability.md): nothing crashes, nothing
is silently wrong, nothing is lost.  One case per CTest test:

    hardening_test.py --binary BIN --mpiexec MPIEXEC --inputs DIR --workdir DIR CASE

Each case reproduces a defect once found and asserts the outcome: the exit
code, one `friction: error:` message with the words that explain it, the
files left (existing ones never damaged), and the output's values.
"""
import argparse
import os
import shutil
import signal
import stat
import subprocess
import sys
import time

import h5py
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from helpers import file_contents  # noqa: E402

SMALL = "&scan nx = 16, ny = 4 /\n"
NO_DIAGNOSTICS = ("&analysis spectrum = .false., poincare = .false., lyapunov = .false., rosenstein = .false.,"
                  " lyapunov_spectrum = .false., orbit = .false. /\n")
SWEEP = ("&brake mu = 0.5, mu_s = 0.59, t_end = 300.0, dt_out = 0.1 /\n"
         "&analysis window_start = 50.0, window_end = 300.0, lyapunov_transient = 50.0,"
         " poincare = .false., rosenstein = .false. /\n"
         "&sweep sweep_variable = 'brake.v_dr_prime', sweep_spacing = 'linear',"
         " sweep_from = -0.004, sweep_to = -0.001, sweep_count = 5 /\n")
GRAPHITE_SMALL = "&scan nx = 12, ny = 3, length = 2.0 /\n"
ABORTS = ("Fortran runtime error", "Error allocating", "Backtrace", "Segmentation fault", "SIGSEGV",
          "infinite loop closing library",
          "Error termination", "Program received signal")


class Skip(Exception):
    pass


def fail(message):
    print("FAILED: " + message)
    sys.exit(1)


def run(args, cmd, expect=0, env=None, timeout=600, stdin=None):
    full_env = dict(os.environ)
    full_env.update(env or {})
    result = subprocess.run(cmd, cwd=args.workdir, capture_output=True, text=True, env=full_env,
                            timeout=timeout, input=stdin, errors="replace")
    for word in ABORTS:
        if word in result.stderr:
            fail(f"{' '.join(cmd)}: a runtime abort or signal ({word!r}):\n{result.stderr}")
    if result.returncode < 0 or result.returncode > 6:
        fail(f"{' '.join(cmd)}: exit {result.returncode}, outside the documented codes:\n{result.stderr}")
    if expect is not None and result.returncode != expect:
        fail(f"{' '.join(cmd)} exited {result.returncode}, expected {expect}\n"
             f"stdout: {result.stdout}\nstderr: {result.stderr}")
    if result.returncode not in (0, 6):
        # One message: "friction: error: ..." (usage errors: "friction: ..." and the usage line).
        prefix = "friction:" if result.returncode == 2 else "friction: error:"
        errors = [line for line in result.stderr.splitlines() if line.startswith(prefix)]
        if len(errors) != 1:
            fail(f"{' '.join(cmd)}: expected one 'friction: error:' line, got:\n{result.stderr}")
    return result


def friction(args, *rest, ranks=None, expect=0, env=None, timeout=600, stdin=None):
    # (An interrupted run: the test build of the program that stops on cue.)
    binary = args.stop_binary if "FRICTION_TEST_STOP_AFTER" in (env or {}) else args.binary
    cmd = [binary, "--quiet", *rest]
    if ranks is not None:
        forward = [item for name in (env or {}) for item in ("-x", name)]
        cmd = [args.mpiexec, "-n", str(ranks), *forward, *cmd]
    return run(args, cmd, expect, env, timeout, stdin)


def write(args, name, text, mode="w"):
    path = os.path.join(args.workdir, name)
    with open(path, mode) as handle:
        handle.write(text)
    return path


def path(args, name):
    return os.path.join(args.workdir, name)


def inputs(args, name):
    return os.path.join(args.inputs, name)


def contains(result, *words):
    for word in words:
        if word not in result.stderr:
            fail(f"the message lacks {word!r}: {result.stderr!r}")


def listing(directory):
    return sorted(os.listdir(directory))


# ---- defect 1: --force replaces only a regular file, never an input ----

def case_force_device(args):
    """A device node, a pipe and a directory at the output path are never
    replaced, with or without --force (a device node is made here with mknod
    when permitted; /dev/null itself is never put at risk)."""
    write(args, "small.nml", SMALL)
    targets = {"fifo": os.mkfifo, "dir": os.mkdir}
    try:
        os.mknod(path(args, "null"), 0o666 | stat.S_IFCHR, os.makedev(1, 3))
        targets["null"] = None
    except (PermissionError, OSError):
        print("note: mknod not permitted; the device-node case is covered by the fifo")
    for name, make in targets.items():
        if make is not None:
            make(path(args, name))
        for force in ([], ["-f"]):
            result = friction(args, *force, "-o", name, inputs(args, "naf.nml"), "small.nml", expect=3,
                              timeout=60)
            contains(result, name)
            mode = os.lstat(path(args, name)).st_mode
            if not {"fifo": stat.S_ISFIFO, "dir": stat.S_ISDIR, "null": stat.S_ISCHR}[name](mode):
                fail(f"{name} was replaced by {oct(mode)}")
    if [f for f in listing(args.workdir) if ".tmp" in f]:
        fail(f"temporary files left: {listing(args.workdir)}")


def case_force_own_input(args):
    """-f -o mine.nml mine.nml small.nml is an error and leaves mine.nml as
    it was; so is an output that names the XYZ net a namelist reads."""
    mine = write(args, "mine.nml", open(inputs(args, "naf.nml")).read())
    before = open(mine).read()
    write(args, "small.nml", SMALL)
    result = friction(args, "-f", "-o", "mine.nml", "mine.nml", "small.nml", expect=3)
    contains(result, "mine.nml", "input file")
    if open(mine).read() != before:
        fail("the input file was changed")
    # The same file under another name (./mine.nml) is the same file.
    friction(args, "-f", "-o", "./mine.nml", "mine.nml", "small.nml", expect=3)
    # A file named inside a namelist: the XYZ net.
    shutil.copy(inputs(args, "graphite_defects.xyz"), path(args, "net.xyz"))
    xyz_before = open(path(args, "net.xyz")).read()
    write(args, "net.nml", "&surface net = 'file', net_file = 'net.xyz' /\n" + GRAPHITE_SMALL)
    result = friction(args, "-f", "-o", "net.xyz", inputs(args, "graphite.nml"),
                      inputs(args, "graphite_defects.nml"), "net.nml", expect=3)
    contains(result, "net.xyz", "input file")
    if open(path(args, "net.xyz")).read() != xyz_before:
        fail("the XYZ net was changed")
    # The default output of an input named like an output: x.h5 -> x.h5.
    shutil.copy(mine, path(args, "x.h5"))
    friction(args, "-f", "x.h5", "small.nml", expect=3)


def case_force_symlink(args):
    """A symbolic link at the output path is neither followed nor replaced,
    with or without --force (docs/reliability.md); a dangling one neither."""
    write(args, "small.nml", SMALL)
    write(args, "target.h5", "precious")
    os.symlink("target.h5", path(args, "link.h5"))
    os.symlink("nowhere.h5", path(args, "dangling.h5"))
    for name in ("link.h5", "dangling.h5"):
        for force in ([], ["-f"]):
            result = friction(args, *force, "-o", name, inputs(args, "naf.nml"), "small.nml", expect=3)
            contains(result, name, "symbolic link")
            if not os.path.islink(path(args, name)):
                fail(f"{name} is no longer a link")
    if open(path(args, "target.h5")).read() != "precious" or os.path.exists(path(args, "nowhere.h5")):
        fail("a link's target was written")
    # A regular file is replaced with --force (and only with it).
    write(args, "plain.h5", "old")
    friction(args, "-o", "plain.h5", inputs(args, "naf.nml"), "small.nml", expect=3)
    friction(args, "-f", "-o", "plain.h5", inputs(args, "naf.nml"), "small.nml")
    with h5py.File(path(args, "plain.h5"), "r") as handle:
        if handle["afm/trace/fx"].shape != (4, 16):
            fail("the forced output is not the map")


def case_empty_output(args):
    """-o '' is a usage error (exit 2)."""
    write(args, "small.nml", SMALL)
    result = run(args, [args.binary, "-o", "", inputs(args, "naf.nml"), "small.nml"], expect=2)
    contains(result, "-o")


# ---- defect 2: no overwrite at the moment of publishing ----

def case_publish_race(args):
    """A file that appears at the output path while a run computes (another
    run finished first) is not overwritten without --force: the run fails
    with exit 5, the other file is intact, and this run's result is kept
    under its temporary name, complete."""
    write(args, "sweep.nml", SWEEP.replace("sweep_count = 5", "sweep_count = 12").replace("300.0", "600.0", 1))
    process = subprocess.Popen([args.binary, "--quiet", "-o", "out.h5", inputs(args, "brake.nml"), "sweep.nml"],
                               cwd=args.workdir, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    first = path(args, "out.h5.ckpt")
    deadline = time.monotonic() + 120
    while not os.path.exists(first) and process.poll() is None and time.monotonic() < deadline:
        time.sleep(0.01)
    write(args, "out.h5", "the other run's file")
    _, stderr = process.communicate(timeout=300)
    if process.returncode != 5:
        fail(f"the run exited {process.returncode}, expected 5: {stderr}")
    if "appeared while this run computed" not in stderr or "kept as" not in stderr:
        fail(f"message: {stderr!r}")
    if open(path(args, "out.h5")).read() != "the other run's file":
        fail("the other run's file was overwritten")
    kept = [f for f in listing(args.workdir) if f.startswith("out.h5.tmp-")]
    if len(kept) != 1:
        fail(f"expected this run's file kept, found {listing(args.workdir)}")
    with h5py.File(path(args, kept[0]), "r") as handle:
        if not np.all(handle["sweep/status"][()] == 1):
            fail("the kept file is not complete")


# ---- defect 3: a full disk ----

def small_tmpfs(args, size="64k"):
    directory = path(args, "small")
    os.makedirs(directory, exist_ok=True)
    result = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", directory],
                            capture_output=True, text=True)
    if result.returncode != 0:
        raise Skip(f"cannot mount a small tmpfs here (needs root): {result.stderr.strip()}")
    return directory


def unmount(directory):
    subprocess.run(["umount", directory], capture_output=True)


def fill(directory):
    """Fill a file system to its last byte."""
    descriptor = os.open(os.path.join(directory, "filler"), os.O_WRONLY | os.O_CREAT | os.O_APPEND)
    try:
        while True:
            os.write(descriptor, b"\0" * 4096)
    except OSError:
        pass
    try:
        while True:
            os.write(descriptor, b"\0")
    except OSError:
        pass
    os.close(descriptor)


def case_disk_full(args):
    """The output on a full disk: exit 5 with one message that names the
    output (not the removed temporary file), no crash at MPI_Finalize (no
    HDF5 handle left open), on 1 and 2 ranks, for maps of sizes around what
    fits on a 4 MB tmpfs (the data's writes fail, the file is cut and closed);
    on a 64 kB one the run stops before computing.  Nothing is left on the
    small disk; an existing file there is intact."""
    directory = small_tmpfs(args, "4m")
    try:
        write(args, "small/existing.h5", "keep me")
        outcomes = set()
        for nx, ny, ranks in ((4096, 16, None), (4096, 16, 2), (2048, 16, None), (3000, 16, 2), (2600, 16, None),
                              (1024, 16, None), (8192, 4, None)):
            write(args, "med.nml", f"&scan nx = {nx}, ny = {ny} /\n")
            result = friction(args, "-o", "small/out.h5", inputs(args, "naf.nml"), "med.nml", ranks=ranks,
                              expect=None)
            outcomes.add(result.returncode)
            if result.returncode == 0:
                with h5py.File(path(args, "small/out.h5"), "r") as handle:
                    if handle["afm/trace/fx"].shape != (ny, nx) or not np.all(np.isfinite(handle["afm/trace/fx"])):
                        fail("a map written on the small disk is incomplete")
                os.remove(path(args, "small/out.h5"))
                continue
            if result.returncode != 5:
                fail(f"nx = {nx}, ny = {ny}: exit {result.returncode}, expected 0 or 5: {result.stderr}")
            contains(result, "small/out.h5")
            if ".tmp-" in result.stderr:
                fail(f"the message cites the removed temporary file: {result.stderr}")
            if listing(directory) != ["existing.h5"]:
                fail(f"files left on the full disk: {listing(directory)}")
        if outcomes != {0, 5}:
            fail(f"expected maps that fit and maps that do not, got exit codes {outcomes}")
        if open(path(args, "small/existing.h5")).read() != "keep me":
            fail("the existing file was damaged")
    finally:
        unmount(directory)
    # The reproduction: a 64 kB disk, a 128 x 16 map.
    directory = small_tmpfs(args, "64k")
    try:
        write(args, "med.nml", "&scan nx = 128, ny = 16 /\n")
        result = friction(args, "-o", "small/out.h5", inputs(args, "naf.nml"), "med.nml", expect=5)
        contains(result, "small/out.h5", "disk is full")
        if listing(directory):
            fail(f"files left: {listing(directory)}")
    finally:
        unmount(directory)


def case_checkpoint_full(args):
    """The disk fills during a sweep: exit 5 with a message that says the
    disk is full, no crash.  Either the checkpoint (one HDF5 file) stays
    whole (its writes landed in space it had taken: it is kept, and --resume
    with room again computes nothing), or a write of it failed: it cannot be
    trusted, is removed, the message names it, and --resume computes every
    point.  Nothing else is left on the disk."""
    # (4 MB: room for the checkpoint's 1 MB reserve and the 1 MB to spare.)
    directory = small_tmpfs(args, "4m")
    try:
        write(args, "sweep.nml", SWEEP.replace("t_end = 300.0", "t_end = 1500.0").replace("sweep_count = 5",
                                                                                         "sweep_count = 8"))
        process = subprocess.Popen([args.binary, "-o", "small/s.h5", inputs(args, "brake.nml"), "sweep.nml"],
                                   cwd=args.workdir, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        first = os.path.join(directory, "s.h5.ckpt")
        deadline = time.monotonic() + 120
        while not os.path.exists(first) and process.poll() is None and time.monotonic() < deadline:
            time.sleep(0.01)
        fill(directory)
        _, stderr = process.communicate(timeout=600)
        for word in ABORTS:
            if word in stderr:
                fail(f"abort: {stderr}")
        if process.returncode != 5:
            fail(f"exit {process.returncode}, expected 5: {stderr}")
        if "disk is full" not in stderr:
            fail(f"the message does not say the disk is full: {stderr}")
        kept = "s.h5.ckpt" in listing(directory)
        if not kept and "s.h5.ckpt" not in stderr:
            fail(f"the checkpoint was removed and the message does not say so: {stderr}")
        if listing(directory) != sorted(["filler"] + ["s.h5.ckpt"] * kept):
            fail(f"files left on the full disk: {listing(directory)}")
        os.remove(os.path.join(directory, "filler"))
        friction(args, "--resume", "-o", "small/s.h5", inputs(args, "brake.nml"), "sweep.nml")
        with h5py.File(path(args, "small/s.h5"), "r") as handle:
            computed = handle["sweep/computed_by_this_run"][()]
            if not np.all(computed == (0 if kept else 1)) or not np.all(handle["sweep/status"][()] == 1):
                fail(f"the resume computed {computed} with the checkpoint {'kept' if kept else 'removed'}")
    finally:
        unmount(directory)


# ---- defect 4: --resume verifies the whole input and every checkpoint ----

def interrupted_sweep(args):
    write(args, "sweep.nml", SWEEP)
    friction(args, "-o", "part.h5", inputs(args, "brake.nml"), "sweep.nml", expect=6,
             env={"FRICTION_TEST_STOP_AFTER": "2"})
    checkpoints = sorted(f for f in listing(args.workdir) if ".ckpt" in f)
    if checkpoints != ["part.h5.ckpt"]:
        fail(f"checkpoints {checkpoints}: expected one for the sweep")


def case_resume_changed(args):
    """--resume refuses checkpoints of another input: a changed &brake mu, or
    another sweep_variable with the same values (exit 3, nothing computed,
    the files as they were); with the same input it completes the sweep."""
    interrupted_sweep(args)
    before = {f: open(path(args, f), "rb").read() for f in listing(args.workdir)}
    write(args, "mu.nml", "&brake mu = 0.45 /\n")
    result = friction(args, "--resume", "-o", "part.h5", inputs(args, "brake.nml"), "sweep.nml", "mu.nml",
                      expect=3)
    contains(result, "part.h5.ckpt", "another input")
    # Another variable over the same values (delta_prime: the brake runs with it).
    write(args, "var.nml", "&sweep sweep_variable = 'brake.delta_prime' /\n")
    result = friction(args, "--resume", "-o", "part.h5", inputs(args, "brake.nml"), "sweep.nml", "var.nml",
                      expect=None)
    if result.returncode != 3 or "another input" not in result.stderr:
        fail(f"another sweep variable was resumed: {result.returncode} {result.stderr}")
    after = {f: open(path(args, f), "rb").read() for f in listing(args.workdir) if f in before}
    if after != before:
        fail("a refused resume changed files")
    friction(args, "--resume", "-o", "part.h5", inputs(args, "brake.nml"), "sweep.nml")
    with h5py.File(path(args, "part.h5"), "r") as handle:
        if list(handle["sweep/computed_by_this_run"][()]) != [0, 0, 1, 1, 1]:
            fail(f"computed {handle['sweep/computed_by_this_run'][()]}")
        if handle["sweep"].attrs["complete"] != 1:
            fail("not complete")


def case_resume_damaged(args):
    """A checkpoint that lost its end, or whose first bytes are overwritten,
    is refused as damaged (exit 3, nothing computed); removed, every point is
    computed again."""
    interrupted_sweep(args)
    name = path(args, "part.h5.ckpt")
    data = open(name, "rb").read()
    open(name, "wb").write(data[:len(data) // 2])
    result = friction(args, "--resume", "-o", "part.h5", inputs(args, "brake.nml"), "sweep.nml", expect=3)
    contains(result, "part.h5.ckpt", "damaged")
    open(name, "wb").write(b"\0" * 8 + data[8:])
    result = friction(args, "--resume", "-o", "part.h5", inputs(args, "brake.nml"), "sweep.nml", expect=3)
    contains(result, "damaged")
    os.remove(name)
    friction(args, "--resume", "-o", "part.h5", inputs(args, "brake.nml"), "sweep.nml")
    with h5py.File(path(args, "part.h5"), "r") as handle:
        if list(handle["sweep/computed_by_this_run"][()]) != [1, 1, 1, 1, 1]:
            fail(f"computed {handle['sweep/computed_by_this_run'][()]}")


# ---- defect 11: a long map survives a time limit ----

MAP = "&scan nx = 24, ny = 7, checkpoint_interval = 0.0 /\n"
THERMAL_MAP = ("&scan nx = 16, ny = 5, checkpoint_interval = 0.0 /\n"
               "&thermal temperature = 300.0, realizations = 2, seed = 3 /\n")


VERIFY = "&verify check = .true. /\n"


def verify_resumed(args):
    """MAP with &verify on 2 ranks (4 and 3 lines), stopped by the test hook
    after 5 lines of each rank's, the check's counted after the map's: both
    ranks finish their map and stop in the check (exit 6, the message says
    so, no file, every line of the map checkpointed); --resume runs the check
    alone and writes the uninterrupted file."""
    write(args, "stopped.nml", MAP + VERIFY)
    files = [inputs(args, "naf.nml"), "stopped.nml"]
    friction(args, "-o", "stopped_whole.h5", *files, ranks=2)
    result = friction(args, "-o", "stopped.h5", *files, ranks=2, expect=6, env={"FRICTION_TEST_STOP_AFTER": "5"})
    contains(result, "interrupted in its &verify run", "--resume")
    checkpoints = sorted(f for f in listing(args.workdir) if f.startswith("stopped.h5.line-"))
    if len(checkpoints) != 7 or os.path.exists(path(args, "stopped.h5")):
        fail(f"stopped in the check: {checkpoints} and {'a' if os.path.exists(path(args, 'stopped.h5')) else 'no'} "
             "file; expected the 7 lines and no file")
    friction(args, "--resume", "-o", "stopped.h5", *files, ranks=2)
    whole = same_as_uninterrupted(args, "stopped")
    if "afm/verify@max_difference" not in whole:
        fail("the resumed check's file has no /afm/verify")


def same_as_uninterrupted(args, name):
    """fail() unless NAME.h5, resumed, equals NAME_whole.h5 in every dataset
    and every attribute but the timings, and no checkpoint is left; returns
    the contents."""
    whole, resumed = file_contents(path(args, f"{name}_whole.h5")), file_contents(path(args, f"{name}.h5"))
    if sorted(whole) != sorted(resumed):
        fail(f"{name}: the resumed file holds {sorted(set(whole) ^ set(resumed))} the other does not")
    for key in whole:
        if not np.array_equal(np.asarray(whole[key]), np.asarray(resumed[key]), equal_nan=np.asarray(whole[key]).dtype.kind == "f"):
            fail(f"{name}: {key} differs between the uninterrupted and the resumed map")
    left = [f for f in listing(args.workdir) if ".ckpt" in f]
    if left:
        fail(f"checkpoints left after the map completed: {left}")
    return whole


def map_resumed(args, name, text, ranks):
    """An uninterrupted map, then the same map stopped after 2 lines of each
    rank (exit 6, no file, a checkpoint per line done) and resumed: the
    resumed file equals the uninterrupted one in every dataset and every
    attribute but the timings (the integrator's counts included), and the
    checkpoints are gone."""
    write(args, f"{name}.nml", text)
    files = [inputs(args, "naf.nml"), f"{name}.nml"]
    friction(args, "-o", f"{name}_whole.h5", *files, ranks=ranks)
    result = friction(args, "-o", f"{name}.h5", *files, ranks=ranks, expect=6,
                      env={"FRICTION_TEST_STOP_AFTER": "2"})
    contains(result, "map interrupted", "--resume")
    if os.path.exists(path(args, f"{name}.h5")):
        fail("an interrupted map wrote its output")
    checkpoints = sorted(f for f in listing(args.workdir) if f.startswith(f"{name}.h5.line-"))
    if len(checkpoints) != 2 * ranks:
        fail(f"{len(checkpoints)} line checkpoints after 2 lines on each of {ranks} ranks: {checkpoints}")
    friction(args, "--resume", "-o", f"{name}.h5", *files, ranks=ranks)
    same_as_uninterrupted(args, name)
    return files


def case_map_resume(args):
    """A NaF map on 2 ranks, and the same at 300 K with 2 realizations (the
    standard errors and the slips in the checkpoints), and with &verify,
    resume to the uninterrupted file; so does a map stopped in its &verify
    run; a checkpoint of another input or a damaged one is refused (exit 3,
    naming it)."""
    files = map_resumed(args, "map", MAP, 2)
    map_resumed(args, "warm", THERMAL_MAP, 2)
    map_resumed(args, "checked", MAP + VERIFY, 2)
    verify_resumed(args)
    os.remove(path(args, "map.h5"))
    friction(args, "-o", "map.h5", *files, expect=6, env={"FRICTION_TEST_STOP_AFTER": "1"})
    write(args, "v0.nml", "&surface v0 = 1.1 /\n")
    result = friction(args, "--resume", "-o", "map.h5", *files, "v0.nml", expect=3)
    contains(result, "map.h5.line-1.ckpt", "another input")
    name = path(args, "map.h5.line-1.ckpt")
    text = open(name).read()
    write(args, "map.h5.line-1.ckpt", text[:len(text) - 40])
    result = friction(args, "--resume", "-o", "map.h5", *files, expect=3)
    contains(result, "map.h5.line-1.ckpt", "damaged")
    os.remove(name)
    friction(args, "--resume", "-o", "map.h5", *files)


def case_map_signal(args):
    """SIGTERM during a map that checkpoints every line: exit 6, no output,
    the lines done kept; --resume completes it to the uninterrupted file."""
    write(args, "long.nml", "&scan nx = 64, ny = 400, checkpoint_interval = 0.0 /\n")
    files = [inputs(args, "naf.nml"), "long.nml"]
    process = subprocess.Popen([args.binary, "--quiet", "-o", "cut.h5", *files], cwd=args.workdir,
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and not any(".ckpt" in f for f in listing(args.workdir)):
        time.sleep(0.05)
    process.send_signal(signal.SIGTERM)
    _, stderr = process.communicate(timeout=120)
    if process.returncode == 0:
        raise Skip("the map finished before the signal (a fast machine)")
    if process.returncode != 6 or "map interrupted" not in stderr:
        fail(f"SIGTERM during a map: exit {process.returncode}: {stderr}")
    if os.path.exists(path(args, "cut.h5")):
        fail("an interrupted map wrote its output")
    kept = [f for f in listing(args.workdir) if f.startswith("cut.h5.line-")]
    if not kept:
        fail("no line kept")
    friction(args, "--resume", "-o", "cut.h5", *files)
    friction(args, "-o", "whole.h5", *files)
    whole, resumed = file_contents(path(args, "whole.h5")), file_contents(path(args, "cut.h5"))
    differing = [key for key in whole if not np.array_equal(np.asarray(whole[key]), np.asarray(resumed.get(key)))]
    if differing:
        fail(f"the resumed map differs from the uninterrupted one in {differing}")
    print(f"{len(kept)} of 400 lines kept at the signal; the resumed map equals the uninterrupted one")


def case_brake_signal(args):
    """SIGINT during a long brake trajectory (not a sweep): it stops within a
    200th of its range with exit 6 and a message, and writes nothing.
    Before, the signal's default action killed the program without a word
    (and in a Python host Ctrl-C waited for the whole trajectory)."""
    write(args, "long.nml", "&brake t_end = 2000000.0, dt_out = 1.0 /\n" + NO_DIAGNOSTICS)   # about 7 s
    process = subprocess.Popen([args.binary, "-o", "long.h5", inputs(args, "brake.nml"), "long.nml"],
                               cwd=args.workdir, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    # The first progress line (after 2 s) says the run is integrating: signal then.
    first = process.stderr.readline()
    started = time.monotonic()
    process.send_signal(signal.SIGINT)
    _, stderr = process.communicate(timeout=120)
    stderr = first + stderr
    stopped = time.monotonic() - started
    if process.returncode == 0:
        raise Skip("the trajectory finished before the signal (a fast machine)")
    if process.returncode != 6 or "brake run stopped on request" not in stderr or "no file written" not in stderr:
        fail(f"SIGINT during a brake run: exit {process.returncode}: {stderr}")
    if [f for f in listing(args.workdir) if f.startswith("long.h5")]:
        fail(f"a stopped brake run left files: {listing(args.workdir)}")
    print(f"stopped {stopped:.2f} s after the signal: {stderr.strip().splitlines()[-1]}")


def case_sweep_signal_last(args):
    """A stop request after the last point stops nothing: the file says
    complete (status all done, complete = 1) and the run exits 0."""
    write(args, "sweep.nml", SWEEP)
    friction(args, "-o", "s.h5", inputs(args, "brake.nml"), "sweep.nml", env={"FRICTION_TEST_STOP_AFTER": "5"})
    with h5py.File(path(args, "s.h5"), "r") as handle:
        if handle["sweep"].attrs["complete"] != 1 or not np.all(handle["sweep/status"][()] == 1):
            fail("a sweep with every point done is not complete")


# ---- defect 8 and 10: empty datasets ----

def case_brake_no_events(args):
    """A valid brake run without events writes empty event datasets (exit 0),
    with the diagnostics off or a belt at rest."""
    for extra in ("&brake t_end = 1.0 /\n", "&brake t_end = 5.0, v_dr_prime = 0.0 /\n"):
        write(args, "short.nml", extra + NO_DIAGNOSTICS)
        friction(args, "-f", "-o", "b.h5", inputs(args, "brake.nml"), "short.nml")
        with h5py.File(path(args, "b.h5"), "r") as handle:
            for name in ("t", "kind", "x", "v", "y", "w"):
                data = handle[f"brake/events/{name}"]
                if data.shape != (0,) or "units" not in data.attrs:
                    fail(f"/brake/events/{name}: shape {data.shape}")
            if not np.all(np.isfinite(handle["brake/x"][()])):
                fail("non-finite trajectory")


# ---- defect 6: input the parser must not accept ----

OVERFLOW = [("tip", "mass"), ("tip", "kx"), ("tip", "cx"), ("scan", "velocity"), ("surface", "v0")]


def case_overflowing_literals(args):
    """1e400 (and -1e400, 1e-400) are input errors naming the variable,
    not Infinity (or 0) and a run that exits 0 or 4."""
    write(args, "small.nml", SMALL)
    for group, name in OVERFLOW:
        for value in ("1e400", "-1.0d+999", "1e-400"):
            write(args, "bad.nml", f"&{group} {name} = {value} /\n")
            result = friction(args, inputs(args, "naf.nml"), "small.nml", "bad.nml", expect=3)
            contains(result, "bad.nml:1", f"&{group}", name, "out of range")
    if [f for f in listing(args.workdir) if f.endswith(".h5")]:
        fail("bad input wrote a file")


def case_tolerance_bounds(args):
    """rtol = atol = 1e300 is bad input (it gave forces of 1e181 nN); so are
    rtol >= 1 and atol > 1, and h_min above the first step: an explicit
    h_start is an input error, the automatic one is raised to h_min and
    never silently ignored."""
    write(args, "small.nml", SMALL)
    for text, words in (("&integrator rtol = 1e300, atol = 1e300 /\n", ["rtol", "< 1"]),
                        ("&integrator rtol = 1.0 /\n", ["rtol", "< 1"]),
                        ("&integrator atol = 2.0 /\n", ["atol", "<= 1"]),
                        ("&integrator h_min = 1e-3, h_start = 1e-6 /\n", ["h_min", "h_start"])):
        write(args, "bad.nml", text)
        result = friction(args, inputs(args, "naf.nml"), "small.nml", "bad.nml", expect=3)
        contains(result, "bad.nml:1", "&integrator", *words)
    write(args, "bad.nml", "&verify check = .true., check_rtol = 5.0 /\n")
    result = friction(args, inputs(args, "brake.nml"), "bad.nml", expect=3)
    contains(result, "check_rtol")
    # h_min larger than the automatic first step: used, so the run fails on it.
    write(args, "hmin.nml", "&integrator h_min = 1e-3 /\n")
    result = friction(args, inputs(args, "naf.nml"), "small.nml", "hmin.nml", expect=4)
    contains(result, "h_min")


def case_long_line(args):
    """A namelist line of 100 000 characters reads (the limit is 16 Mi)."""
    write(args, "long.nml", "&scan nx = 16," + " " * 100000 + "ny = 4, velocity = 400.0 /\n")
    friction(args, "-o", "l.h5", inputs(args, "naf.nml"), "long.nml")
    with h5py.File(path(args, "l.h5"), "r") as handle:
        if handle["afm/trace/fx"].shape != (4, 16):
            fail("the long line was not read")
    # A value list spread over one long line, and a file without a final newline.
    write(args, "nonl.nml", "&scan nx = 16, ny = 4 /")
    friction(args, "-o", "n.h5", inputs(args, "naf.nml"), "nonl.nml")


def case_input_not_text(args):
    """What is not a text file is bad input at once (exit 3, no file), never
    a read without end: a device (/dev/zero fed the reader forever), a
    directory (read as an empty namelist), and the same as an XYZ net file;
    a line without end in a pipe stops at the 16 Mi limit."""
    write(args, "small.nml", SMALL)
    for name, word in (("/dev/zero", "device"), ("/dev/null", "device"), (args.workdir, "directory")):
        result = friction(args, inputs(args, "naf.nml"), name, "small.nml", expect=3, timeout=60)
        contains(result, name, word)
        write(args, "net.nml", f"&surface net = 'file', net_file = '{name}' /\n" + GRAPHITE_SMALL)
        result = friction(args, inputs(args, "graphite.nml"), "net.nml", expect=3, timeout=60)
        contains(result, name, word)
    # A pipe of 20 Mi characters without a line end.
    result = friction(args, inputs(args, "naf.nml"), "/dev/stdin", stdin="&scan nx = 16," + " " * (20 << 20),
                      expect=3, timeout=60)
    contains(result, "/dev/stdin:1", "longer than 16 Mi")
    if [f for f in listing(args.workdir) if f.endswith(".h5")]:
        fail("bad input wrote a file")


def case_input_size(args):
    """Large inputs take time in proportion to their size: 200 000
    assignments in one file and a list of 300 000 values read in seconds
    (the scan and the value lists were quadratic: 20 000 assignments took
    8 s, 80 000 values 47 s, so these would take minutes; the timeout is
    60 s).  A repeat count beyond the 10 million values a list holds is bad
    input, not 16 GB of bounds; and a message shows a long value cut."""
    write(args, "many.nml", "&scan " + " ".join(["nx = 16,"] * 200000) + " ny = 4 /\n")
    result = friction(args, "--print-input", inputs(args, "naf.nml"), "many.nml", timeout=60)
    if "nx = 16" not in result.stdout:
        fail("the last of many assignments was not read")
    values = ", ".join(f"{10.0 + 1e-5 * k:.5f}" for k in range(300000))
    write(args, "list.nml", f"&sweep sweep_variable = 'tip.kx', sweep_values = {values} /\n")
    result = friction(args, "--print-input", inputs(args, "naf.nml"), "list.nml", timeout=60)
    if "12.99999" not in result.stdout:
        fail("the last of the sweep's values was not echoed")
    write(args, "repeat.nml", "&sweep sweep_variable = 'tip.kx', sweep_values = 2000000000*10.0 /\n")
    result = friction(args, inputs(args, "naf.nml"), "repeat.nml", expect=3, timeout=60)
    contains(result, "repeat.nml:1", "sweep_values", "the most a list holds")
    write(args, "scalar.nml", "&tip kx = " + ", ".join(["10.0"] * 100000) + " /\n")
    result = friction(args, inputs(args, "naf.nml"), "scalar.nml", expect=3, timeout=60)
    contains(result, "scalar.nml:1", "kx", "more characters)", "more values than the 1 elements")
    if len(result.stderr) > 1000:
        fail(f"the message carries the whole value: {len(result.stderr)} characters")
    if [f for f in listing(args.workdir) if f.endswith(".h5")]:
        fail("bad input wrote a file")


def case_stdin(args):
    """A pipe as input: works on one rank; on two ranks (only rank 0 reads
    the pipe) a clear input error, exit 3, and no hang."""
    friction(args, "-o", "one.h5", inputs(args, "naf.nml"), "/dev/stdin", stdin=SMALL, timeout=120)
    with h5py.File(path(args, "one.h5"), "r") as handle:
        if handle["afm/trace/fx"].shape != (4, 16):
            fail("the piped input was not used")
    result = friction(args, "-o", "two.h5", inputs(args, "naf.nml"), "/dev/stdin", ranks=2, stdin=SMALL,
                      expect=3, timeout=120)
    contains(result, "/dev/stdin", "regular file")


def case_garbage_input(args):
    """Random bytes, a NUL, and non-UTF-8 text in a quoted value are input
    errors (exit 3), never an abort."""
    rng = np.random.default_rng(15)
    write(args, "small.nml", SMALL)
    for k in range(5):
        write(args, f"g{k}.nml", bytes(rng.integers(0, 256, 2000, dtype=np.uint8)), mode="wb")
        result = friction(args, inputs(args, "naf.nml"), f"g{k}.nml", "small.nml", expect=3)
        contains(result, f"g{k}.nml")
    write(args, "utf.nml", b"&surface potential = 'lj', species = 'C\xff' /\n", mode="wb")
    result = friction(args, inputs(args, "graphite.nml"), "utf.nml", expect=3)
    contains(result, "species", "UTF-8")
    write(args, "nul.nml", b"&scan nx = 1\x006 /\n", mode="wb")
    friction(args, inputs(args, "naf.nml"), "nul.nml", expect=3)


# ---- defect 5: sizes ----

def case_huge_sizes(args):
    """Sizes checked in 64 bits before allocating: nx = 1e9 (2.9e11 bytes,
    nx * ny >= 2**31) and a map that fits the dataset limit but not memory
    are input errors stating the memory; an XYZ file announcing 2e9 atoms
    too.  No runtime abort."""
    result = friction(args, inputs(args, "naf.nml"), write(args, "a.nml", "&scan nx = 1000000000 /\n"), expect=3)
    contains(result, "a.nml:1", "nx", "2147483647", "TB")
    result = friction(args, inputs(args, "naf.nml"), write(args, "b.nml", "&scan nx = 200000000, ny = 10 /\n"),
                      expect=3)
    contains(result, "memory", "GB")
    result = friction(args, inputs(args, "naf.nml"), write(args, "c.nml", "&scan nx = 2147483647, ny = 1 /\n"),
                      expect=3)
    contains(result, "memory")
    write(args, "huge.xyz", "2000000000\nhuge\nC 0 0 0\n")
    write(args, "d.nml", "&surface net = 'file', net_file = 'huge.xyz' /\n" + GRAPHITE_SMALL)
    result = friction(args, inputs(args, "graphite.nml"), "d.nml", expect=3)
    contains(result, "huge.xyz")


def net_lines(args):
    lines = open(inputs(args, "graphite_defects.xyz")).read().splitlines()
    n = int(lines[0])
    return lines[2:2 + n]


def write_net(args, name, atoms):
    write(args, name, f"{len(atoms)}\n{name}\n" + "\n".join(atoms) + "\n")


def case_lj_far_atom(args):
    """A stray atom at 1e5 or 1e6 Å: no cell list of gigabytes (the run is
    quick and small), the cutoff not shrunk, the forces as without it."""
    atoms = net_lines(args)
    write_net(args, "base.xyz", atoms)
    runs = {}
    for label, extra in (("base", []), ("far5", ["C 100000.0 0.0 0.0"]),
                         ("far6", ["C 1000000.0 -1000000.0 0.0"])):
        write_net(args, f"{label}.xyz", atoms + extra)
        write(args, f"{label}.nml", f"&surface net = 'file', net_file = '{label}.xyz' /\n" + GRAPHITE_SMALL)
        start = time.monotonic()
        friction(args, "-o", f"{label}.h5", inputs(args, "graphite.nml"), inputs(args, "graphite_defects.nml"),
                 f"{label}.nml", timeout=120)
        elapsed = time.monotonic() - start
        with h5py.File(path(args, f"{label}.h5"), "r") as handle:
            runs[label] = (handle["surface"].attrs["cutoff"], handle["afm/trace/fx"][()], elapsed)
    for label in ("far5", "far6"):
        if runs[label][0] < runs["base"][0] - 1e-12:
            fail(f"{label}: the far atom shrank the cutoff {runs[label][0]} < {runs['base'][0]}")
        if runs[label][2] > 10 * runs["base"][2] + 5:
            fail(f"{label}: {runs[label][2]:.1f} s against {runs['base'][2]:.1f} s without the far atom")
        # With the same cutoff the far atom changes nothing.  (Compared where
        # the map is static: the contact height and each line's first sample,
        # the tip at rest.  Further on, a slip taken between samples turns
        # the rounding of a differently ordered sum into visible differences.)
        write(args, f"{label}-cut.nml", "&surface net = 'file', net_file = 'base.xyz', "
              f"cutoff = {float(runs[label][0])!r} /\n" + GRAPHITE_SMALL)
        friction(args, "-o", f"{label}-cut.h5", inputs(args, "graphite.nml"), inputs(args, "graphite_defects.nml"),
                 f"{label}-cut.nml")
        with h5py.File(path(args, f"{label}-cut.h5"), "r") as cut, \
                h5py.File(path(args, f"{label}.h5"), "r") as far:
            for name in ("contact_height", "support_height"):
                if abs(cut["afm"].attrs[name] - far["afm"].attrs[name]) > 1e-9:
                    fail(f"{label}: {name} {far['afm'].attrs[name]} against {cut['afm'].attrs[name]}")
            for name in ("fx", "fy", "fz", "tip_z"):
                difference = np.max(np.abs(cut[f"afm/trace/{name}"][:, 0] - far[f"afm/trace/{name}"][:, 0]))
                if difference > 1e-9:
                    fail(f"{label}: {name} at rest differs by {difference} from the net without the far atom")
            if not np.all(np.isfinite(far["afm/trace/fx"][()])):
                fail(f"{label}: non-finite forces")


def case_lj_geometry(args):
    """Nets on which the tip has no contact are errors, not a scan 6 Å below
    the layer: a single atom away from the origin, tiny sigma, tiny a, a
    support pushed 1e6 Å into the layer; duplicate atoms are an error
    naming both lines."""
    write(args, "one.xyz", "1\none\nC 0.0 0.0 0.0\n")
    cases = {
        "one": ("&surface net = 'file', net_file = 'one.xyz' /\n", ["contact"]),
        "sigma": ("&surface shells = 4, sigma = 0.01 /\n", ["contact"]),
        "a": ("&surface shells = 4, a = 0.1 /\n", ["contact"]),
        "support": ("&tip support_z = -1e6 /\n", ["support_z", "layer"]),
    }
    for label, (text, words) in cases.items():
        scan = GRAPHITE_SMALL
        if label == "one":   # the scan beside the atom, 3 Å away
            scan = "&scan nx = 12, ny = 3, length = 2.0, origin_x = 3.0, origin_y = 0.0 /\n"
        write(args, f"{label}.nml", scan + text)
        result = friction(args, "-o", f"{label}.h5", inputs(args, "graphite.nml"), f"{label}.nml", expect=3)
        contains(result, *words)
    atoms = net_lines(args)
    write_net(args, "dup.xyz", atoms + [atoms[5]] * 3)
    write(args, "dup.nml", "&surface net = 'file', net_file = 'dup.xyz' /\n" + GRAPHITE_SMALL)
    result = friction(args, "-o", "dup.h5", inputs(args, "graphite.nml"), inputs(args, "graphite_defects.nml"),
                      "dup.nml", expect=3)
    contains(result, "dup.xyz:", "line 8", "position of the atom")
    # A moderate load still scans (the shipped support_z is -6 Å).
    write(args, "ok.nml", GRAPHITE_SMALL)
    friction(args, "-o", "ok.h5", inputs(args, "graphite.nml"), "ok.nml")
    with h5py.File(path(args, "ok.h5"), "r") as handle:
        if not np.all(handle["afm/trace/tip_z"][()] > 0.5 * 2.4945):
            fail("the tip scanned inside the layer")



def case_lj_off_edge(args):
    """A scan that runs off the flake is an error at the first sample with no
    atoms under the tip, not a map of a tip hanging below the layer: the
    paper's flake (600 atoms, 9 shells, under 25 Å from its middle) scanned
    30 Å from its middle, so the last samples have no atom within the
    cutoff below them and the load (support_z = -6 Å) pulls the tip under
    the layer.  The table is built (the scan's middle lies on the flake);
    the check runs at every sample, on 1 and on 2 ranks (exit 3, bad input,
    naming where the tip was, nothing written)."""
    write(args, "edge.nml", "&scan nx = 12, ny = 1, length = 30.0, width = 0.0, origin_x = 0.0, "
          "origin_y = 0.0, retrace = .false. /\n")
    for ranks in (1, 2):
        out = f"edge{ranks}.h5"
        result = friction(args, "-o", out, inputs(args, "graphite.nml"), "edge.nml", ranks=ranks, expect=3)
        contains(result, "the tip went below the layer of atoms at (", "trace", "off the edge of the net",
                 "support_z")
        if "evaluation = 'table'" in result.stderr:
            fail(f"the table was not built for the scan: {result.stderr}")
        if os.path.exists(path(args, out)):
            fail(f"{out} was written for a scan that failed")

# ---- issue 40: nothing crashes, hangs or lies, round three ----

def case_element_index(args):
    """An element index that is not a whole number from 1 on (0, -1, 2^31,
    'a', 1.5, 1:2, 2147483650) was applied to another element: sigma(0) set
    sigma(1), species(2147483650) replaced 'C'.  Each is now bad input naming
    the file, line, group and variable, as --set already refused them."""
    for index in ("0", "-1", "2147483648", "a", "1.5", "1:2", " 0 "):
        over = write(args, "over.nml", f"&surface\n  sigma({index}) = 5.0\n/\n")
        result = friction(args, "--print-input", inputs(args, "graphite.nml"), over, expect=3)
        contains(result, "over.nml:2:", "&surface", f"sigma({index})", "whole number")
        if result.stdout:
            fail(f"sigma({index}): --print-input printed an input: {result.stdout[:200]!r}")
    over = write(args, "over.nml", "&surface species(2147483650) = 'N' /\n")
    result = friction(args, "--print-input", inputs(args, "graphite.nml"), over, expect=3)
    contains(result, "over.nml:1:", "&surface", "species(2147483650)")
    # The oracle for the accepted form: sigma(1) = 5.0 sets the one element.
    over = write(args, "over.nml", "&surface sigma( 1 ) = 5.0 /\n")
    result = friction(args, "--print-input", inputs(args, "graphite.nml"), over)
    if "sigma = 5.0" not in result.stdout.replace("5.00000000000000", "5.0"):
        line = [text for text in result.stdout.splitlines() if "sigma" in text]
        fail(f"sigma(1) = 5.0 did not set sigma: {line}")


def case_text_outside_group(args):
    """Text outside a group was dropped without a word, and the default
    128 x 128 map ran with exit 0: an assignment after the closing '/', a
    group without its '&', the $scan ... $end form.  Each is bad input
    naming the line; nothing is written."""
    texts = {
        "after": ("&scan nx = 8 /\nny = 3\n", "after.nml:2:", "outside a group"),
        "no-ampersand": ("scan nx = 8, ny = 3 /\n", "no-ampersand.nml:1:", "outside a group"),
        "dollar": ("$scan nx = 8, ny = 3 $end\n", "dollar.nml:1:", "$group ... $end"),
        "quoted": ("&scan nx = 8 / 'ny = 3'\n", "quoted.nml:1:", "outside a group"),
    }
    for name, (text, where, words) in texts.items():
        over = write(args, name + ".nml", text)
        result = friction(args, "-o", name + ".h5", inputs(args, "naf.nml"), over, expect=3)
        contains(result, where, words)
        if os.path.exists(path(args, name + ".h5")):
            fail(f"{name}: an output was written for bad input")
    # Comments and blank lines between groups stay allowed.
    over = write(args, "fine.nml", "! a comment\n\n&scan nx = 8, ny = 2 /   ! after\n\t\n")
    result = friction(args, "--print-input", inputs(args, "naf.nml"), over)
    if "nx = 8" not in result.stdout:
        fail("a comment between groups stopped the reading of &scan")


def leftovers(args, prefix):
    """Temporary files of an output: OUTPUT.tmp-PID, OUTPUT.ckpt.new, *.ckpt.tmp."""
    return [f for f in listing(args.workdir) if f.startswith(prefix) and (".tmp" in f or f.endswith(".new"))]


def case_stderr_closed(args):
    """A closed stderr (`friction ... 2>&1 | true`) killed the program with
    SIGPIPE at its first progress line (exit 141, no file).  It is now an
    I/O error: the map stops at its next line as on a stop request, keeps
    its lines' checkpoints, leaves no temporary file, and exits 5.  A short
    run that writes its file and then cannot say so exits 5 too."""
    write(args, "long.nml", "&scan nx = 64, ny = 8192, checkpoint_interval = 0.0 /\n")
    reader, writer = os.pipe()
    os.close(reader)   # the pipe's reader is gone before the run starts, as `| true` leaves it
    started = time.monotonic()
    result = subprocess.run([args.binary, "-o", "o.h5", inputs(args, "naf.nml"), "long.nml"], cwd=args.workdir,
                            stdout=writer, stderr=writer, timeout=120)
    os.close(writer)
    seconds = time.monotonic() - started
    if result.returncode != 5:
        fail(f"stderr closed: exit {result.returncode}, expected 5 (141 is death by SIGPIPE)")
    if os.path.exists(path(args, "o.h5")) or leftovers(args, "o.h5"):
        fail(f"stderr closed: files left {listing(args.workdir)}")
    kept = [f for f in listing(args.workdir) if f.startswith("o.h5.line-")]
    print(f"stopped {seconds:.1f} s after the start (its first progress line is due after 2 s), "
          f"{len(kept)} of 8192 lines kept")
    reader, writer = os.pipe()
    os.close(reader)
    write(args, "short.nml", SMALL)
    result = subprocess.run([args.binary, "-o", "short.h5", inputs(args, "naf.nml"), "short.nml"],
                            cwd=args.workdir, stdout=writer, stderr=writer, timeout=120)
    os.close(writer)
    if result.returncode != 5 or not os.path.exists(path(args, "short.h5")) or leftovers(args, "short.h5"):
        fail(f"a short run with stderr closed: exit {result.returncode}, files {listing(args.workdir)}")


def limited(kilobytes):
    import resource
    return lambda: resource.setrlimit(resource.RLIMIT_FSIZE, (kilobytes * 1024, kilobytes * 1024))


def case_file_size_limit(args):
    """`ulimit -f 40` killed a map with SIGXFSZ and a runtime backtrace and
    left OUTPUT.tmp-PID; a sweep left OUTPUT.ckpt.new.  A file-size limit is
    now an I/O error like a full disk: exit 5, one message, nothing left."""
    write(args, "map.nml", "&scan nx = 64, ny = 64 /\n")
    result = subprocess.run([args.binary, "--quiet", "-o", "o.h5", inputs(args, "naf.nml"), "map.nml"],
                            cwd=args.workdir, capture_output=True, text=True, timeout=120, preexec_fn=limited(40))
    if result.returncode != 5 or [w for w in ABORTS if w in result.stderr]:
        fail(f"a map under ulimit -f 40: exit {result.returncode}: {result.stderr}")
    if os.path.exists(path(args, "o.h5")) or leftovers(args, "o.h5"):
        fail(f"a map under ulimit -f 40 left {listing(args.workdir)}")
    # A limit above the 1 MB the run asks to spare before computing, below
    # the 2.4 MB map: the dataset that would pass it is refused before it
    # is written (a write past the limit left a file HDF5 could not close).
    result = subprocess.run([args.binary, "--quiet", "-o", "o.h5", inputs(args, "naf.nml")], cwd=args.workdir,
                            capture_output=True, text=True, timeout=120, preexec_fn=limited(1500))
    if result.returncode != 5 or [w for w in ABORTS if w in result.stderr] or "ulimit -f" not in result.stderr:
        fail(f"a 128 x 128 map under ulimit -f 1500: exit {result.returncode}: {result.stderr}")
    if os.path.exists(path(args, "o.h5")) or leftovers(args, "o.h5"):
        fail(f"a map under ulimit -f 1500 left {listing(args.workdir)}")
    write(args, "sweep.nml", SWEEP)
    result = subprocess.run([args.binary, "--quiet", "-o", "sw.h5", inputs(args, "brake.nml"), "sweep.nml"],
                            cwd=args.workdir, capture_output=True, text=True, timeout=120, preexec_fn=limited(40))
    if result.returncode != 5 or [w for w in ABORTS if w in result.stderr]:
        fail(f"a sweep under ulimit -f 40: exit {result.returncode}: {result.stderr}")
    if leftovers(args, "sw.h5") or os.path.exists(path(args, "sw.h5")):
        fail(f"a sweep under ulimit -f 40 left {listing(args.workdir)}")
    contains(result, "friction: error:")


def case_print_input_errors(args):
    """--print-input ignored write errors: exit 0 with nothing written to a
    closed stdout or /dev/full.  Both are I/O errors now (exit 5)."""
    with open("/dev/full", "w") as full:
        result = subprocess.run([args.binary, "--print-input", inputs(args, "naf.nml")], cwd=args.workdir,
                                stdout=full, stderr=subprocess.PIPE, text=True, timeout=60)
    if result.returncode != 5 or "standard output" not in result.stderr:
        fail(f"--print-input > /dev/full: exit {result.returncode}: {result.stderr}")
    result = subprocess.run([args.binary, "--print-input", inputs(args, "naf.nml")], cwd=args.workdir,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, timeout=60,
                            preexec_fn=lambda: os.close(1))
    if result.returncode != 5 or "standard output" not in result.stderr:
        fail(f"--print-input >&-: exit {result.returncode}: {result.stderr}")
    # The oracle: the same with a working stdout exits 0 and prints the groups.
    result = friction(args, "--print-input", inputs(args, "naf.nml"))
    if "&scan" not in result.stdout:
        fail("--print-input printed no &scan")


def case_sweep_checksum(args):
    """A sweep checkpoint carries a checksum of each point's row: a status of
    65537, a result changed to 12345.678 or one flipped bit of a result was
    resumed into the output with exit 0.  Each is refused as damaged (exit
    3, naming the point) and the checkpoint is kept as it was; the
    undamaged checkpoint resumes."""
    interrupted_sweep(args)
    name = path(args, "part.h5.ckpt")
    original = open(name, "rb").read()
    partial = open(path(args, "part.h5"), "rb").read()   # the interrupted run's file, with its pending points

    def damage(column, change):
        open(name, "wb").write(original)
        with h5py.File(name, "r+") as handle:
            data = handle[column][()]
            data[0] = change(data[0])
            handle[column][...] = data
        damaged = open(name, "rb").read()
        result = friction(args, "--resume", "-o", "part.h5", inputs(args, "brake.nml"), "sweep.nml", expect=3)
        contains(result, "part.h5.ckpt", "damaged", "point 1")
        if "disk" in result.stderr:
            fail(f"a damaged checkpoint reported as a disk problem: {result.stderr}")
        if not os.path.exists(name) or open(name, "rb").read() != damaged:
            fail("a refused checkpoint was removed or changed")
        if open(path(args, "part.h5"), "rb").read() != partial:
            fail("a refused resume changed the output")

    damage("status", lambda x: 65537)
    damage("result1", lambda x: 12345.678)
    damage("result1", lambda x: np.frombuffer((np.float64(x).view(np.int64) ^ 1).tobytes(), np.float64)[0])
    open(name, "wb").write(original)
    friction(args, "--resume", "-o", "part.h5", inputs(args, "brake.nml"), "sweep.nml")
    with h5py.File(path(args, "part.h5"), "r") as handle:
        if list(handle["sweep/computed_by_this_run"][()]) != [0, 0, 1, 1, 1]:
            fail(f"computed {handle['sweep/computed_by_this_run'][()]}")


def case_sweep_too_large(args):
    """sweep_count = 1e8 stopped by SIGTERM filled a disk with 48 MB free
    with pending rows, lost its computed points and segfaulted at exit;
    2147483647 did the same.  A sweep whose file cannot fit beside the output
    is refused before computing (exit 3, naming &sweep and sweep_count),
    nothing left; on a 48 MB tmpfs (root only), and on this disk for a count
    too large for it."""
    write(args, "huge.nml", SWEEP.replace("sweep_count = 5", "sweep_count = 2147483647"))
    free = shutil.disk_usage(args.workdir).free
    if free > 8 * 2147483647 * 36:
        raise Skip(f"the disk has {free} bytes free, room for 2147483647 points")
    result = friction(args, "-o", "h.h5", inputs(args, "brake.nml"), "huge.nml", expect=3)
    contains(result, "&sweep", "sweep_count = 2147483647", "free")
    if [f for f in listing(args.workdir) if f.startswith("h.h5")]:
        fail(f"a refused sweep left {listing(args.workdir)}")
    small = small_tmpfs(args, "48m")
    try:
        write(args, "huge.nml", SWEEP.replace("sweep_count = 5", "sweep_count = 100000000"))
        result = friction(args, "-o", "small/h.h5", inputs(args, "brake.nml"), "huge.nml", expect=3)
        contains(result, "&sweep", "sweep_count = 100000000", "free")
        if os.listdir(small):
            fail(f"a refused sweep left {os.listdir(small)}")
        # The oracle: the 5-point sweep fits there and runs.
        write(args, "fits.nml", SWEEP)
        friction(args, "-o", "small/f.h5", inputs(args, "brake.nml"), "fits.nml")
    finally:
        unmount(small)


def case_runtime_aborts(args):
    """Accepted values that aborted in the runtime: continuation_points =
    2147483647 (allocating 64 GB) is bad input; a linear sweep of tip.kx from
    -1.7e308 to 1.7e308 ("Nonnegative width required in format") runs its
    points (the middle one is 0, exactly) without an abort or a checkpoint
    left."""
    result = friction(args, "-o", "o.h5", inputs(args, "brake.nml"), "--set", "brake.t_end=400",
                      "--set", "analysis.orbit=.true.", "--set", "analysis.continuation='mu'",
                      "--set", "analysis.continuation_end=0.5", "--set", "analysis.continuation_points=2147483647",
                      expect=3)
    contains(result, "&analysis", "continuation_points")
    write(args, "kx.nml", "&sweep sweep_variable = 'tip.kx', sweep_spacing = 'linear', sweep_from = -1.7e308,"
          " sweep_to = 1.7e308, sweep_count = 3 /\n&scan nx = 8, ny = 1 /\n")
    result = friction(args, "-o", "s.h5", inputs(args, "naf.nml"), "kx.nml", expect=None)
    if result.returncode not in (0, 4):
        fail(f"the kx sweep: exit {result.returncode}: {result.stderr}")
    if [f for f in listing(args.workdir) if ".ckpt" in f or ".tmp" in f]:
        fail(f"the kx sweep left {listing(args.workdir)}")
    with h5py.File(path(args, "s.h5"), "r") as handle:
        values = handle["sweep/values"][()]
        if list(values) != [-1.7e308, 0.0, 1.7e308]:
            fail(f"the sweep's values {values}, expected -1.7e308, 0, 1.7e308")


def case_endless_loops(args):
    """lyapunov_spectrum_renormalise = 1e-300 with max_wall_time = 3 never
    ended and ignored SIGTERM; 1e-13 and lyapunov_renormalise = 1e-300 (an
    exponent of 0.0 from zero samples) were accepted.  Each is bad input now,
    naming the variable."""
    for name in ("lyapunov_spectrum_renormalise", "lyapunov_renormalise"):
        for value in ("1e-300", "1e-13"):
            result = friction(args, "--print-input", inputs(args, "brake.nml"), "--set", f"analysis.{name}={value}",
                              "--set", "analysis.lyapunov_spectrum=.true.", "--set", "analysis.lyapunov=.true.",
                              expect=3)
            contains(result, f"&analysis: {name}", "renormalisation intervals")
    # Newton's steps are each a run to the section: 2**31 - 1 of them is refused too.
    result = friction(args, "--print-input", inputs(args, "brake.nml"), "--set",
                      "analysis.orbit_max_iterations=2147483647", expect=3)
    contains(result, "&analysis: orbit_max_iterations", "<= 1000")


def signalled(args, command, words, delay, limit):
    """Run command, send SIGTERM after `delay` seconds (inside its long
    loop), and check it ends within `limit` seconds of the signal with exit
    6 and `words` in its message; returns the seconds it took."""
    process = subprocess.Popen(command, cwd=args.workdir, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(delay)
    if process.poll() is not None:
        fail(f"{command}: ended (exit {process.returncode}) before the signal: the loop is not long enough "
             f"to test: {process.stderr.read()}")
    sent = time.monotonic()
    process.send_signal(signal.SIGTERM)
    try:
        _, stderr = process.communicate(timeout=120)
    except subprocess.TimeoutExpired:
        process.kill()
        fail(f"{command}: no end 120 s after SIGTERM")
    took = time.monotonic() - sent
    if process.returncode != 6 or any(word not in stderr for word in words):
        fail(f"SIGTERM: exit {process.returncode}, expected 6 with {words}: {stderr}")
    if took > limit:
        fail(f"SIGTERM: ended {took:.2f} s after the signal, more than {limit} s")
    return took


def case_stop_long_loops(args):
    """A stop request ends each long loop of a brake run within one of its
    pieces: the Lyapunov spectrum's renormalisations, Benettin's intervals,
    the continuation's points.  Each run integrates a short trajectory
    (0.1 s), then spends its time in the loop (tens of seconds to its end);
    SIGTERM comes 3 s after the start, and the run must end with exit 6
    within 5 s (a piece takes milliseconds; the margin is the machine's
    load).  Before, the loops ran to their end (837 s for the spectrum of
    the issue)."""
    quiet = ("&analysis spectrum = .false., poincare = .false., rosenstein = .false., lyapunov = .false.,"
             " lyapunov_spectrum = .false., orbit = .false.,\n")
    runs = {
        "spectrum": ("lyapunov_spectrum = .true., lyapunov_spectrum_renormalise = 0.0002,"
                     " lyapunov_spectrum_transient = 0.0 /\n", "the Lyapunov spectrum"),
        "benettin": ("lyapunov = .true., lyapunov_renormalise = 0.0002, lyapunov_transient = 0.0 /\n",
                     "the Lyapunov exponent"),
        "continuation": ("orbit = .true., continuation = 'mu', continuation_end = 0.3,"
                         " continuation_points = 20000 /\n", "the continuation"),
    }
    for name, (text, words) in runs.items():
        write(args, name + ".nml", "&brake t_end = 1000.0, dt_out = 0.5 /\n" + quiet + text)
        took = signalled(args, [args.binary, "-o", name + ".h5", inputs(args, "brake.nml"), name + ".nml"],
                         ["stopped on request", words], 3.0, 5.0)
        if [f for f in listing(args.workdir) if f.startswith(name + ".h5")]:
            fail(f"{name}: a stopped run left {listing(args.workdir)}")
        print(f"{name}: ended {took:.2f} s after SIGTERM")


def case_misleading_messages(args):
    """Messages that named no variable or blamed the wrong thing: ax =
    1e-300 failed as a NaN at t = 0; a tiny Langevin time_step, welch_segments
    and lyapunov_d0 = 1e300 (blamed on the pad lifting off) named no file,
    line or variable; thermal.temperature = 1e300 ran (forces of 1e148 nN).
    Each is bad input naming the file, line, group and variable now.  Two
    ranks reading a pipe were told to give 'a regular file or a pipe'."""
    cases = [
        ("naf.nml", "&surface ax = 1e-300 /\n", "&surface: ax"),
        ("naf_thermal_temperature.nml", "&thermal model = 'langevin', time_step = 1e-30 /\n", "&thermal: time_step"),
        ("naf_thermal_temperature.nml", "&thermal temperature = 1e300 /\n", "&thermal: temperature"),
        ("brake.nml", "&analysis welch_segments = 100000 /\n", "&analysis: welch_segments"),
        ("brake.nml", "&analysis lyapunov_d0 = 1e300 /\n", "&analysis: lyapunov_d0"),
    ]
    for base, text, words in cases:
        write(args, "bad.nml", text)
        result = friction(args, "-o", "bad.h5", inputs(args, base), "bad.nml", expect=3)
        contains(result, "bad.nml:1:", words)
        if os.path.exists(path(args, "bad.h5")):
            fail(f"{text.strip()}: an output was written")
    write(args, "small.nml", SMALL)
    result = friction(args, "-o", "pipe.h5", inputs(args, "naf.nml"), "/dev/stdin", ranks=2, expect=3,
                      stdin=open(path(args, "small.nml")).read())
    contains(result, "/dev/stdin", "rank 0", "regular file")
    if "or a pipe" in result.stderr:
        fail(f"two ranks reading a pipe were told to give a pipe: {result.stderr}")


CASES = {name[len("case_"):].replace("_", "-"): function for name, function in globals().items()
         if name.startswith("case_")}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--binary", required=True)
    parser.add_argument("--stop-binary", required=True, help="the program with a reporter that stops on cue")
    parser.add_argument("--mpiexec", required=True)
    parser.add_argument("--inputs", required=True)
    parser.add_argument("--workdir", required=True)
    parser.add_argument("case", choices=sorted(CASES))
    args = parser.parse_args()
    if os.path.ismount(os.path.join(args.workdir, "small")):
        unmount(os.path.join(args.workdir, "small"))
    shutil.rmtree(args.workdir, ignore_errors=True)
    os.makedirs(args.workdir)
    try:
        CASES[args.case](args)
    except Skip as reason:
        print(f"SKIPPED: {reason}")
        sys.exit(77)
    print("1 passed, 0 failed")


if __name__ == "__main__":
    main()
