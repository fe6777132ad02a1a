"""Configurations and computations: the program's numbers to the last bit,
values as Python, the program's checks and messages."""
import h5py
import numpy as np
import pytest

import helpers
from conftest import DATA, INPUTS, interrupted, sigint_at_report

NAF = [INPUTS / "naf.nml", DATA / "small.nml"]


def test_compute_is_the_programs_map_to_the_last_bit(friction, naf_map):
    with friction.Config("afm", files=NAF) as cfg:
        computed = cfg.compute()
    program = helpers.group_datasets(naf_map, "afm")
    assert sorted(computed) == sorted(program)
    for name, values in program.items():
        assert computed[name].shape == values.shape, name
        assert np.array_equal(computed[name], values), name


def test_compute_reports_each_line_and_computes_the_same_map(friction, naf_map):
    """compute(progress=...) reports after each of the map's 10 lines, and
    its numbers are the program's file's, bit for bit, as without it."""
    reports = []
    with friction.Config("afm", files=NAF) as cfg:
        computed = cfg.compute(progress=lambda message, fraction: reports.append((message, fraction)))
    assert reports == [(f"{j} of 10 lines", j / 10) for j in range(1, 11)]
    for name, values in helpers.group_datasets(naf_map, "afm").items():
        assert np.array_equal(computed[name], values), name


def test_ctrl_c_stops_a_compute_and_the_config_computes_on(friction, naf_map):
    """SIGINT during compute() (sent from the first report, on the main
    thread) stops the map after that line: KeyboardInterrupt, after the
    library's status 5; the SIGINT handler is back, and the same Config's
    next compute() is the program's map."""
    import signal
    reports, progress = sigint_at_report(1)
    with friction.Config("afm", files=NAF) as cfg:
        with pytest.raises(KeyboardInterrupt) as caught:
            cfg.compute(progress=progress)
        assert "the map stopped on request after 1 of 10 lines: no result" in interrupted(caught).message
        assert len(reports) == 1
        assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
        computed = cfg.compute()
    for name, values in helpers.group_datasets(naf_map, "afm").items():
        assert np.array_equal(computed[name], values), name


def test_ctrl_c_from_another_thread_stops_a_long_brake_compute(friction):
    """A real SIGINT while the main thread is inside the library, no
    progress asked for: Python's handler runs at the computation's next
    report (its callback is there for this), so a run of 2 million τ
    (about 7 s) stops far before its end instead of when it is done."""
    import os
    import re
    import signal
    import threading
    timer = threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGINT))
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt) as caught:
            friction.brake(values={"brake.t_end": 2.0e6, "brake.dt_out": 1.0})
    finally:
        timer.cancel()
    message = interrupted(caught).message
    reached = re.search(r"at τ = ([0-9.]+) of ([0-9.]+): no result", message)
    assert reached, message
    assert float(reached.group(1)) < 0.5 * float(reached.group(2)), message


def test_a_report_that_raises_stops_the_computation(friction):
    """An exception of the progress callback stops the computation at that
    report (its result would be lost anyway) and is raised after the
    library's status 5."""
    reports = []

    def progress(message, fraction):
        reports.append(message)
        if len(reports) == 3:
            raise ValueError("enough")

    with pytest.raises(ValueError, match="enough") as caught:
        friction.brake(values={"brake.t_end": 40.0, "brake.dt_out": 0.5}, progress=progress)
    assert "brake run stopped on request at τ = " in interrupted(caught).message
    assert len(reports) == 3 and reports[0].startswith("τ = "), reports


def test_afm_line_is_the_files_line_to_the_last_bit(friction, naf_map):
    with h5py.File(naf_map) as f:
        support_x = f["afm/support_x"][()]
        trace, retrace = f["afm/trace/fx"][()], f["afm/retrace/fy"][()]
    with friction.Config("afm", files=NAF) as cfg:
        for j in (0, 3, 9):
            x, fx, _ = cfg.afm_line(j)
            assert np.array_equal(x, support_x)
            assert np.array_equal(fx, trace[j])
            _, _, fy = cfg.afm_line(j, forward=False)
            assert np.array_equal(fy, retrace[j])
    line = friction.afm_line(NAF, line=3)
    assert isinstance(line, friction.Line) and np.array_equal(line.fx, trace[3])


def test_afm_line_with_progress_is_the_line_without(friction, naf_map):
    """afm_line(progress=callable) goes through friction_afm_line_progress:
    the file's line and the plain friction_afm_line's (called here through
    ctypes) to the last bit, and the callable gets the line's end last
    (before it only the library's polls, should the line take 0.1 s)."""
    import ctypes
    with h5py.File(naf_map) as f:
        trace, retrace = f["afm/trace/fx"][()], f["afm/retrace/fy"][()]
    with friction.Config("afm", files=NAF) as cfg:
        for j, forward in ((0, True), (3, False), (9, True)):
            reports = []
            line = cfg.afm_line(j, forward, progress=lambda message, fraction: reports.append((message, fraction)))
            quiet = cfg.afm_line(j, forward)
            plain_x, plain_y = np.zeros(line.fx.size), np.zeros(line.fx.size)
            assert cfg._lib.friction_afm_line(cfg.handle, j, int(forward), plain_x.ctypes.data_as(ctypes.c_void_p),
                                              plain_y.ctypes.data_as(ctypes.c_void_p), plain_x.size, None) == 0
            for got in (line, quiet):
                assert np.array_equal(got.fx, plain_x) and np.array_equal(got.fy, plain_y), j
            assert np.array_equal(line.fx if forward else line.fy, trace[j] if forward else retrace[j]), j
            assert reports[-1] == ("1 of 1 lines", 1.0), reports
            assert all(report == ("started", -1.0) for report in reports[:-1]), reports
        assert np.array_equal(friction.afm_line(NAF, line=3, progress=lambda m, f: None).fx, trace[3])


def test_a_progress_that_raises_at_the_end_of_a_line_returns_nothing(friction, naf_map):
    """An exception of the callable at the line's end ("1 of 1 lines"): the
    line was done, but the call raises it and returns nothing; the Config
    computes the same line again."""
    def progress(message, fraction):
        raise ValueError(f"no thanks: {message}")

    with friction.Config("afm", files=NAF) as cfg:
        with pytest.raises(ValueError, match="no thanks: 1 of 1 lines"):
            cfg.afm_line(2, progress=progress)
        with h5py.File(naf_map) as f:
            assert np.array_equal(cfg.afm_line(2).fx, f["afm/trace/fx"][2])


# A thermal line that takes tens of seconds (the Langevin tip at 0.1 A/s over 9.24 A, some 4e7
# steps, as the C API's capi-thermal-stop): a stop that did not happen inside it would show.
LONG_LINE = {"scan.ny": 1, "scan.length": 9.24, "thermal.temperature": 300.0, "thermal.model": "langevin",
             "scan.velocity": 0.1, "tip.model": "inertial", "thermal.realizations": 1}


def _short_line_after(friction, cfg):
    """The stopped Config computes again: a two-point line, against a fresh Config's."""
    short = {"scan.length": 0.5, "scan.nx": 2, "scan.velocity": 1.0e4}
    for name, value in short.items():
        cfg[name] = value
    with friction.Config("afm", values={**LONG_LINE, **short}) as fresh:
        expected = fresh.afm_line(0)
    got = cfg.afm_line(0)
    assert got.fx.size == 2 and np.isfinite(got.fx).all()
    # the same seed and realizations: the same numbers to the last bit
    assert np.array_equal(got.fx, expected.fx) and np.array_equal(got.fy, expected.fy)


def test_a_progress_that_raises_inside_a_line_stops_it(friction):
    """The callable raising at a poll from inside a long thermal line stops
    the line there: its exception, after the library's status 5, within a
    second of the request (the trip looks every 0.1 s of wall time; the bound
    allows a loaded machine ten times that), no end report, nothing
    returned; the Config computes on."""
    import time
    polls, asked = [], []
    start = time.monotonic()

    def progress(message, fraction):
        polls.append((message, fraction))
        if fraction < 0 and time.monotonic() - start > 0.3:
            asked.append(time.monotonic())
            raise RuntimeError("cancelled")

    with friction.Config("afm", values=LONG_LINE) as cfg:
        with pytest.raises(RuntimeError, match="cancelled") as caught:
            cfg.afm_line(0, progress=progress)
        ended = time.monotonic()
        assert "stopped on request" in interrupted(caught).message
        assert len(asked) == 1 and ended - asked[0] < 1.0, (ended - asked[0], len(polls))
        assert all(poll == ("started", -1.0) for poll in polls), polls
        _short_line_after(friction, cfg)


def test_ctrl_c_stops_a_long_line_without_progress(friction):
    """A real SIGINT while the main thread is inside a long thermal line, no
    progress asked for: the line polls the callback every 0.1 s, Python's
    handler runs there, and the line stops (KeyboardInterrupt after status 5)
    within seconds instead of the tens of seconds of the whole line."""
    import os
    import signal
    import threading
    import time
    timer = threading.Timer(0.3, os.kill, (os.getpid(), signal.SIGINT))
    with friction.Config("afm", values=LONG_LINE) as cfg:
        start = time.monotonic()
        timer.start()
        try:
            with pytest.raises(KeyboardInterrupt) as caught:
                cfg.afm_line(0)
        finally:
            timer.cancel()
        assert time.monotonic() - start < 3.0   # 0.3 s, one poll and the trip's next look; loaded-machine margin
        assert "stopped on request" in interrupted(caught).message
        assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
        _short_line_after(friction, cfg)


GRAPHITE = [INPUTS / "graphite.nml", DATA / "graphite_small.nml"]


def test_a_kept_surface_gives_what_a_new_one_gives(friction, files):
    """A configuration keeps the surface of its last line or computation (the
    graphite net's table) while &surface and the scan stay: its lines are the
    program's to the last bit, a changed tip still gets them from the kept
    table, and a changed surface gets a new one, not the stale one (the
    oracle: a configuration of its own, which builds its table afresh)."""
    path = files("graphite_small", GRAPHITE)
    with h5py.File(path) as f:
        trace = f["afm/trace/fx"][()]
    with friction.Config("afm", files=GRAPHITE) as cfg:
        for j in (0, 2, 1, 2):
            assert np.array_equal(cfg.afm_line(j).fx, trace[j]), j
        assert np.array_equal(cfg.compute()["trace/fx"], trace)
        cfg["tip.kx"] = 0.5
        softer = cfg.afm_line(1).fx
        cfg["surface.epsilon"] = 0.9e-2
        deeper = cfg.afm_line(1).fx
        assert not np.array_equal(deeper, softer)
    with friction.Config("afm", files=GRAPHITE, values={"tip.kx": 0.5}) as fresh:
        assert np.array_equal(fresh.afm_line(1).fx, softer)
    with friction.Config("afm", files=GRAPHITE, values={"tip.kx": 0.5, "surface.epsilon": 0.9e-2}) as fresh:
        assert np.array_equal(fresh.afm_line(1).fx, deeper)


def test_brake_is_the_programs_run_to_the_last_bit(friction, files):
    override = ("&brake t_end = 40.0, dt_out = 0.5 /\n"
                "&analysis spectrum = .false., poincare = .false., lyapunov = .false., rosenstein = .false.,"
                " lyapunov_spectrum = .false., orbit = .false. /\n")
    path = files("brake_40", [INPUTS / "brake.nml"], override)
    run = friction.brake([INPUTS / "brake.nml", path.parent / "brake_40_override.nml"])
    program = helpers.group_datasets(path, "brake")
    trajectory = {k: v for k, v in program.items() if k.count("/") == 0 or k.startswith("events/")}
    assert set(trajectory) == set(run)
    for name, values in trajectory.items():
        assert np.array_equal(run[name], values), name
    assert run["t"][0] == 0.0 and run["t"][-1] == 40.0 and run["t"].size == 81


def test_values_as_python(friction):
    with friction.Config("afm", files=[INPUTS / "naf.nml"]) as cfg:
        assert cfg["scan.nx"] == 128 and isinstance(cfg["scan.nx"], int)
        assert cfg["surface.potential"] == "naf"
        assert cfg["scan.retrace"] is True
        assert cfg["tip.mass"] == 1e-8
        assert cfg.unit("tip.mass") == "kg" and cfg.unit("tip.kx") == "N/m"
        cfg["scan.nx"] = 64
        cfg.set("surface.potential", "hopg").set("scan.retrace", False).set("tip.kx", 2.5)
        assert (cfg.get("scan.nx"), cfg["surface.potential"], cfg["scan.retrace"], cfg["tip.kx"]) == \
            ("64", "hopg", False, 2.5)
        sigma = cfg["surface.sigma"]
        assert isinstance(sigma, list) and len(sigma) == cfg.kinds()["surface.sigma"][1]
        cfg.set("surface.sigma", [1.5, 2.5])
        assert cfg["surface.sigma"][:3] == [1.5, 2.5, sigma[2]]
        assert cfg["surface.sigma(2)"] == 2.5
        assert len(cfg.support_x()) == 64 and cfg.support_x()[-1] == cfg["scan.length"]


def test_text_reads_back(friction, tmp_path):
    with friction.Config("afm", files=[INPUTS / "hopg.nml"], values={"tip.kx": 3.25}) as cfg:
        text = cfg.text()
    (tmp_path / "echo.nml").write_text(text)
    with friction.Config("afm", files=[tmp_path / "echo.nml"]) as again:
        assert again.text() == text and again["tip.kx"] == 3.25


def test_refusals_carry_the_programs_messages(friction, tmp_path):
    with friction.Config("afm") as cfg:
        cfg.set("tip.mass", -1.0e-8)
        with pytest.raises(friction.FrictionError) as caught:
            cfg.check()
        assert caught.value.status == 1
        assert caught.value.message == "&tip: mass = -1.000000E-8: must be > 0 (kg)"
        with pytest.raises(friction.FrictionError, match="nx = 'many': expected an integer"):
            cfg.set("scan.nx", "many")
        with pytest.raises(friction.FrictionError, match="nosuch"):
            cfg.get("tip.nosuch")
    bad = tmp_path / "bad.nml"
    bad.write_text("&tip\n mass = -1.0e-8\n/\n")
    with friction.Config("afm", files=[bad]) as cfg:
        with pytest.raises(friction.FrictionError, match=r"bad\.nml:2: &tip: mass = -1\.000000E-8: must be > 0 \(kg\)"):
            cfg.check()
    with pytest.raises(friction.FrictionError, match="unknown scene|scene"):
        friction.Config("boat")


def test_the_program_refuses_with_the_same_words(friction, program, tmp_path):
    bad = tmp_path / "bad.nml"
    bad.write_text("&tip mass = -1.0e-8 /\n")
    result = helpers.run([program, "-q", "-o", tmp_path / "x.h5", INPUTS / "naf.nml", bad], expect=3)
    with friction.Config("afm", files=[INPUTS / "naf.nml", bad]) as cfg:
        with pytest.raises(friction.FrictionError) as caught:
            cfg.check()
    assert f"friction: error: {caught.value.message}" in result.stderr


def test_a_closed_configuration(friction):
    cfg = friction.Config("brake")
    cfg.close()
    with pytest.raises(ValueError, match="closed"):
        cfg.get("brake.mu")
    assert "closed" in repr(cfg)


def test_threads_read_files_at_once(friction):
    """Configurations read from files on several threads at once (the Fortran
    runtime's file units are the process's: two threads reading at once got
    false "cannot open the file" errors, then corrupted the heap and aborted
    the interpreter).  Every read must succeed and give the one text."""
    import threading

    expected = friction.Config("afm", files=[INPUTS / "naf.nml"]).text()
    failures = []

    def reads():
        try:
            for _ in range(300):
                with friction.Config("afm", files=[INPUTS / "naf.nml"]) as cfg:
                    if cfg.text() != expected:
                        failures.append("a different text")
        except Exception as error:  # noqa: BLE001 - collected and reported below
            failures.append(repr(error))

    threads = [threading.Thread(target=reads) for _ in range(3)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert not failures, failures[:3]


def test_warnings_are_the_programs(friction, program, tmp_path):
    """Config.warnings(): the words the program's input gives on stderr for the
    same values (a file's origin included), returned and never printed."""
    (tmp_path / "slips.nml").write_text("&scan angle = 0.122 /\n&sweep sweep_variable = 'surface.v0', "
                                        "sweep_values = 1.0, 1.6e-19, 3.2e-19 /\n")
    with friction.Config("afm", files=[friction.input_file("naf.nml"), tmp_path / "slips.nml"]) as cfg:
        warnings = cfg.warnings()
        cfg.set("scan.angle", 7.0)
        assert cfg.warnings() == warnings[1:]
        cfg.set("sweep.sweep_variable", "")
        assert cfg.warnings() == []
    done = helpers.run([program, "--print-input", friction.input_file("naf.nml"), tmp_path / "slips.nml"],
                       cwd=tmp_path)
    said = [line.split("friction: warning: ", 1)[1] for line in done.stderr.splitlines() if "warning: " in line]
    assert warnings == said and len(said) == 2
    assert "slips.nml:1: &scan: angle = 0.122" in said[0] and "looks like radians" in said[0]
    assert "slips.nml:2: &sweep: sweep_variable = 'surface.v0': 2 of its 3 values, from 1.6" in said[1]
