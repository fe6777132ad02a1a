"""Jobs: the program's file from Python, with progress."""
import os
import sys

import h5py
import helpers
import numpy as np
import pytest

from conftest import DATA, INPUTS, interrupted, sigint_at_report

NAF = [INPUTS / "naf.nml", DATA / "small.nml"]
TIMINGS = {"wall_time", "compute_time", "created"}


def same_files(a, b, timings=()):
    """Every dataset and every attribute but the timings (and the datasets
    `timings`) equal."""
    def items(path):
        found = {}
        with h5py.File(path) as f:
            def visit(name, item):
                if isinstance(item, h5py.Dataset) and name not in timings:
                    found[name] = item[()]
                for key, value in item.attrs.items():
                    if key not in TIMINGS:
                        found[f"{name}@{key}"] = helpers.attribute_value(f, value)
            visit("/", f)
            f.visititems(visit)
        return found
    ia, ib = items(a), items(b)
    assert set(ia) == set(ib)
    for key in ia:
        # NaN equal to NaN: a sweep point without a periodic orbit has NaN there.
        floats = np.asarray(ia[key]).dtype.kind == "f" and np.asarray(ib[key]).dtype.kind == "f"
        assert np.array_equal(ia[key], ib[key], equal_nan=floats), key


def test_run_writes_the_programs_file_and_reports(friction, naf_map, tmp_path):
    reports = []
    out = friction.run(NAF, output=tmp_path / "naf.h5", progress=lambda m, f: reports.append((m, f)))
    assert out == tmp_path / "naf.h5"
    same_files(out, naf_map)
    progress = [f for _, f in reports if f >= 0]
    assert progress and all(0.0 <= f <= 1.0 for f in progress) and progress[-1] == 1.0
    assert progress == sorted(progress)
    assert reports[-1][0] == "10 of 10 lines"


def test_an_existing_output_needs_force(friction, tmp_path):
    out = tmp_path / "kept.h5"
    out.write_bytes(b"not to be clobbered")
    with pytest.raises(friction.FrictionError, match="exists") as caught:
        friction.run(NAF, output=out, progress=False)
    assert caught.value.status == 3 or caught.value.status == 1
    assert out.read_bytes() == b"not to be clobbered"
    friction.run(NAF, output=out, force=True, progress=False)
    assert friction.load(out, scene="afm")["afm/trace/fx"].shape == (10, 40)


def test_default_output_is_the_first_files_name(friction, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    out = friction.run(NAF, progress=False)
    assert out == tmp_path / "naf.h5" and out.is_file()


def test_progress_bar_with_tqdm(friction, tmp_path, capfd):
    pytest.importorskip("tqdm")
    friction.run(NAF, output=tmp_path / "bar.h5", progress=True)
    err = capfd.readouterr().err
    assert "bar.h5:" in err and "100%" in err and "10 of 10 lines" in err


def test_progress_lines_without_tqdm(friction, tmp_path, capfd, monkeypatch):
    monkeypatch.setitem(sys.modules, "tqdm.auto", None)   # as if tqdm were not installed
    friction.run(NAF, output=tmp_path / "plain.h5", progress=True)
    err = capfd.readouterr().err
    assert "plain.h5: 10 of 10 lines (100 %)" in err


def test_a_failing_callback_is_raised_after_the_job(friction, tmp_path):
    def broken(message, fraction):
        raise RuntimeError("callback broke")
    with pytest.raises(RuntimeError, match="callback broke"):
        friction.run(NAF, output=tmp_path / "cb.h5", progress=broken)
    assert (tmp_path / "cb.h5").is_file()   # the job itself finished


def test_bad_input_names_file_and_line(friction, tmp_path):
    bad = tmp_path / "bad.nml"
    bad.write_text("&scan\n  nx = 1\n/\n")
    with pytest.raises(friction.FrictionError, match=r"bad\.nml:2: &scan: nx = 1") as caught:
        friction.run([INPUTS / "naf.nml", bad], output=tmp_path / "bad.h5", progress=False)
    assert caught.value.status == 1
    assert not (tmp_path / "bad.h5").exists()


def test_config_run_echoes_its_text(friction, tmp_path):
    with friction.Config("afm", files=NAF, values={"scan.ny": 2}) as cfg:
        out = cfg.run(tmp_path / "cfg.h5", progress=False)
        text = cfg.text()
    data = friction.load(out, scene="afm")
    assert data.attrs["input"] == text
    assert data["afm/trace/fx"].shape == (2, 40)


def test_a_sweep_job(friction, afm_sweep, tmp_path):
    out = friction.run([INPUTS / "afm_sweep.nml", DATA / "afm_sweep_small.nml"], output=tmp_path / "sweep.h5",
                       progress=False)
    a, b = friction.load(out, scene="sweep"), friction.load(afm_sweep, scene="sweep")
    assert np.array_equal(a["sweep/mean_friction"].values, b["sweep/mean_friction"].values)


def test_resume_an_interrupted_sweep(friction, stop_program, brake_sweep, tmp_path):
    import helpers
    files = [INPUTS / "brake_sweep.nml", DATA / "sweep_small.nml"]
    out = tmp_path / "part.h5"
    # the program stops after 3 of the 6 points as on SIGTERM (exit 6), leaving checkpoints
    helpers.run([stop_program, "--quiet", "-o", out, *files], expect=6, extra_env={"FRICTION_TEST_STOP_AFTER": "3"})
    part = friction.load(out, scene="sweep")
    assert list(part["sweep/status"].values) == [1, 1, 1, 0, 0, 0]
    assert part["sweep"].attrs["complete"] == 0
    friction.run(files, output=out, resume=True, progress=False)
    resumed, full = friction.load(out), friction.load(brake_sweep)
    assert list(resumed["sweep/computed_by_this_run"].values) == [0, 0, 0, 1, 1, 1]
    assert resumed["sweep"].attrs["complete"] == 1
    for name in ("sweep/maxima", "sweep/lyapunov", "sweep/stick_fraction", "sweep/status"):
        assert np.array_equal(resumed[name].values, full[name].values), name


def test_jobs_on_several_threads_run_one_at_a_time(friction, naf_map, brake_run, tmp_path):
    """Jobs started on several threads at once (ctypes lets them call the
    library together) each write the file a job alone writes: the library
    runs them one after the other.  Before, they shared HDF5 and FFTW's
    planner, reported false errors (a namelist that "cannot be opened", HDF5
    failing to create a dataset) and crashed the interpreter."""
    import threading

    BRAKE = [INPUTS / "brake.nml", DATA / "brake_short.nml"]
    failures = []

    def job(k, files, reference):
        try:
            out = friction.run(files, output=tmp_path / f"job{k}.h5", force=True, progress=False)
            same_files(out, reference)
        except Exception as error:  # noqa: BLE001 - collected and reported below
            failures.append(f"job {k}: {error!r}")

    for _ in range(3):
        threads = [threading.Thread(target=job, args=(k, NAF, naf_map) if k % 2 == 0 else (k, BRAKE, brake_run))
                   for k in range(4)]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
    assert not failures, failures


def test_a_job_from_its_own_callback_is_refused(friction, tmp_path):
    """A job started from the report callback of a job on the same thread
    cannot wait for that job to end: it is refused with a message, not left
    to deadlock, and the outer job finishes."""
    inner = []

    def progress(message, fraction):
        if not inner:
            try:
                friction.run(NAF, output=tmp_path / "inner.h5", progress=False)
                inner.append("ran")
            except friction.FrictionError as error:
                inner.append(str(error))

    out = friction.run(NAF, output=tmp_path / "outer.h5", progress=progress)
    assert out.is_file()
    assert len(inner) == 1 and "already running on this thread" in inner[0], inner
    assert not (tmp_path / "inner.h5").exists()


def test_config_run_never_writes_over_a_file_it_read(friction, tmp_path):
    """Config.run with force=True named the namelist file the configuration
    was read from as its output, and replaced it with HDF5; friction.run
    refuses that, and so must Config.run, leaving the file as it was."""
    own = tmp_path / "own.nml"
    own.write_bytes((DATA / "small.nml").read_bytes())
    before = own.read_bytes()
    with friction.Config("afm", files=[INPUTS / "naf.nml", own]) as cfg:
        with pytest.raises(friction.FrictionError, match="the output is the input file"):
            cfg.run(own, force=True, progress=False)
        assert own.read_bytes() == before
        out = cfg.run(tmp_path / "elsewhere.h5", progress=False)
    assert out.is_file()


def test_ctrl_c_stops_a_map_and_resume_finishes_it(friction, naf_map, tmp_path):
    """SIGINT during a job (here sent from the first progress report, on the
    main thread) stops the map at its next line instead of being swallowed
    by ctypes until the job ends: KeyboardInterrupt, after the job's status
    5, no file, the lines done kept; resume computes the rest, and the file
    equals the uninterrupted run's."""
    import signal
    reports, progress = sigint_at_report(1)
    out = tmp_path / "stopped.h5"
    with pytest.raises(KeyboardInterrupt) as caught:
        friction.run(NAF, output=out, progress=progress)
    assert "checkpointed" in interrupted(caught).message
    assert not out.exists()
    assert len(reports) < 5 and all(message != "10 of 10 lines" for message, _ in reports), reports
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler   # the handler is back
    friction.run(NAF, output=out, resume=True, progress=False)
    same_files(out, naf_map)


def test_ctrl_c_in_a_callback_stops_a_sweep(friction, brake_sweep, tmp_path):
    """A KeyboardInterrupt raised by the report callback itself (as Python
    raises it off the main thread's handler) stops a sweep between points:
    its file holds the points done, and resume finishes it to the
    uninterrupted run's file."""
    from conftest import DATA as data
    files = [INPUTS / "brake_sweep.nml", data / "sweep_small.nml"]
    points = []

    def progress(message, fraction):
        if "points" in message:
            points.append(message)
            raise KeyboardInterrupt

    out = tmp_path / "sweep.h5"
    with pytest.raises(KeyboardInterrupt) as caught:
        friction.run(files, output=out, progress=progress)
    interrupted(caught)
    with h5py.File(out) as handle:
        status = handle["sweep/status"][()]
    assert 0 < (status == 1).sum() < status.size, status
    friction.run(files, output=out, force=True, resume=True, progress=False)
    same_files(out, brake_sweep, timings=("sweep/compute_time", "sweep/computed_by_this_run",
                                          "sweep/peak_memory_per_rank"))


def test_ctrl_c_from_outside_without_a_callback(friction, library, tmp_path):
    """A real SIGINT from another process, with no progress callback: the
    job stops within a line, the script ends with KeyboardInterrupt long
    before the map would have finished, and the lines done are kept."""
    import signal
    import subprocess
    import time
    # 2000 lines: about 3 s of work on this machine; the signal comes 0.5 s after the start.
    (tmp_path / "lines.nml").write_text("&scan ny = 2000 /\n")
    script = tmp_path / "long.py"
    script.write_text(
        "import sys\n"
        f"sys.path.insert(0, {str(INPUTS.parent / 'python')!r})\n"
        "import friction\n"
        "friction.library_version()\n"
        "print('ready', flush=True)\n"
        f"friction.run([{str(INPUTS / 'naf.nml')!r}, 'lines.nml'], output='long.h5', progress=False)\n"
        "print('finished', flush=True)\n")
    env = dict(os.environ, FRICTION_LIBRARY=str(library))
    child = subprocess.Popen([sys.executable, str(script)], cwd=tmp_path, env=env, stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True)
    assert child.stdout.readline().strip() == "ready"
    time.sleep(0.5)
    child.send_signal(signal.SIGINT)
    out, err = child.communicate(timeout=120)
    assert "finished" not in out
    assert child.returncode != 0 and "KeyboardInterrupt" in err and "(status 5)" in err, err
    assert not (tmp_path / "long.h5").exists()
    assert any(path.name.startswith("long.h5") for path in tmp_path.iterdir()), list(tmp_path.iterdir())


def test_arguments_that_c_would_cut_are_refused(friction, tmp_path):
    """An int beyond C's (line 2**40 wrapped to line 0) and text with a NUL
    (cut there: 'scan.nx\\0junk' set scan.nx) are ValueErrors, not another
    call than the one asked."""
    with friction.Config("afm", files=NAF) as cfg:
        with pytest.raises(ValueError, match="beyond a C int"):
            cfg.afm_line(2**40)
        with pytest.raises(ValueError, match="NUL"):
            cfg.set("scan.nx\0junk", 12)
        with pytest.raises(ValueError, match="NUL"):
            cfg.set_text("scan.nx", "12\0 junk")
        with pytest.raises(ValueError, match="NUL"):
            cfg.read(str(tmp_path / "a\0b.nml"))
        assert cfg.get("scan.nx") == "40"
    with pytest.raises(ValueError, match="NUL"):
        friction.run(NAF, output=str(tmp_path / "x\0.h5"), progress=False)
    assert not list(tmp_path.iterdir())


def test_a_process_forked_during_a_job_refuses_jobs_and_reads(friction, tmp_path):
    """fork() while a job runs on another thread (multiprocessing's 'fork'
    beside a job): the child inherited the job lock held by a thread it does
    not have, and its first job waited forever.  Its HDF5 and Fortran runtime
    are the parent's, caught half-way, so the child refuses jobs and file
    reads with a message; the parent's job finishes; a fork between jobs
    runs jobs as before."""
    import threading
    import time
    started, release = threading.Event(), threading.Event()

    def progress(message, fraction):
        started.set()
        release.wait(60)

    def child(label):
        """In the forked child: a job and a read; 0 when both behave as `label` says."""
        code = 1
        try:
            refused = []
            for attempt in (lambda: friction.run(NAF, output=tmp_path / f"{label}.h5", progress=False),
                            lambda: friction.Config("afm").read(INPUTS / "naf.nml")):
                try:
                    attempt()
                    refused.append(False)
                except friction.FrictionError as error:
                    refused.append("forked while a job" in error.message)
            code = 0 if refused == ([True, True] if label == "mid" else [False, False]) else 2
        finally:
            os._exit(code)

    def wait(pid):
        for _ in range(600):
            done, status = os.waitpid(pid, os.WNOHANG)
            if done:
                return os.waitstatus_to_exitcode(status)
            time.sleep(0.1)
        os.kill(pid, 9)
        os.waitpid(pid, 0)
        return "hung"

    job = threading.Thread(target=lambda: friction.run(NAF, output=tmp_path / "parent.h5", progress=progress))
    job.start()
    assert started.wait(60)
    pid = os.fork()
    if pid == 0:
        child("mid")
    release.set()
    job.join(120)
    assert wait(pid) == 0
    assert (tmp_path / "parent.h5").is_file() and not (tmp_path / "mid.h5").exists()
    pid = os.fork()
    if pid == 0:
        child("between")
    assert wait(pid) == 0
    assert (tmp_path / "between.h5").is_file()


def test_ctrl_c_stops_a_brake_trajectory(friction, tmp_path):
    """A brake trajectory (not a sweep) keeps no checkpoints: Ctrl-C stops
    it within a 200th of its range, and nothing is written; before, the
    job ran to its end first (2 million τ here, about 7 s)."""
    long = tmp_path / "long.nml"
    long.write_text("&brake t_end = 2000000.0, dt_out = 1.0 /\n"
                    "&analysis spectrum = .false., poincare = .false., lyapunov = .false. /\n")
    reports, progress = sigint_at_report(2)
    out = tmp_path / "long.h5"
    with pytest.raises(KeyboardInterrupt) as caught:
        friction.run([INPUTS / "brake.nml", long], output=out, progress=progress)
    assert "brake run stopped on request" in interrupted(caught).message
    assert max(fraction for _, fraction in reports) < 0.05, reports   # stopped at the third of 200 pieces
    assert not out.exists() and not list(tmp_path.glob("long.h5*"))
