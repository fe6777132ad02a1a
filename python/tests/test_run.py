"""Jobs: the program's file from Python, with progress."""
import sys

import h5py
import numpy as np
import pytest

from conftest import DATA, INPUTS

NAF = [INPUTS / "naf.nml", DATA / "small.nml"]
TIMINGS = {"wall_time", "compute_time", "created"}


def same_files(a, b):
    """Every dataset and every attribute but the timings equal."""
    def items(path):
        found = {}
        with h5py.File(path) as f:
            def visit(name, item):
                if isinstance(item, h5py.Dataset):
                    found[name] = item[()]
                for key, value in item.attrs.items():
                    if key not in TIMINGS:
                        found[f"{name}@{key}"] = value
            visit("/", f)
            f.visititems(visit)
        return found
    ia, ib = items(a), items(b)
    assert set(ia) == set(ib)
    for key in ia:
        assert np.array_equal(ia[key], ib[key]), key


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


def test_resume_an_interrupted_sweep(friction, program, brake_sweep, tmp_path):
    import helpers
    files = [INPUTS / "brake_sweep.nml", DATA / "sweep_small.nml"]
    out = tmp_path / "part.h5"
    # the program stops after 3 of the 6 points as on SIGTERM (exit 6), leaving checkpoints
    helpers.run([program, "--quiet", "-o", out, *files], expect=6, extra_env={"FRICTION_TEST_STOP_AFTER": "3"})
    part = friction.load(out, scene="sweep")
    assert list(part["sweep/status"].values) == [1, 1, 1, 0, 0, 0]
    assert part.group_attrs["sweep"]["complete"] == 0
    friction.run(files, output=out, resume=True, progress=False)
    resumed, full = friction.load(out), friction.load(brake_sweep)
    assert list(resumed["sweep/computed_by_this_run"].values) == [0, 0, 0, 1, 1, 1]
    assert resumed.group_attrs["sweep"]["complete"] == 1
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
