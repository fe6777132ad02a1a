"""The plots: a Figure with the expected axes, titles and data, and a PNG of
the size asked for (tests/check_png.py checks the file)."""
import struct

import numpy as np
import pytest

import friction
import friction.plot
from check_png import png_problem
from conftest import ROOT


def saved(fig, path, dpi=80):
    """Write the figure; check the PNG and that it is figsize x dpi pixels."""
    fig.savefig(path, dpi=dpi)
    assert png_problem(path, 100, None) is None
    width, height = struct.unpack(">II", path.read_bytes()[16:24])
    w, h = fig.get_size_inches()
    assert abs(width - w * dpi) <= 1 and abs(height - h * dpi) <= 1   # matplotlib truncates
    return path


def titles(fig):
    return [ax.get_title() for ax in fig.axes]


def test_afm_maps(naf_map, tmp_path):
    data = friction.load(naf_map)
    fig = friction.plot.afm_maps(data)
    assert isinstance(fig, friction.plot.Figure)
    assert titles(fig)[:2] == ["$F_x$ (lattice x axis)", "$F_y$ (lattice y axis)"]
    assert len(fig.axes) == 4   # two maps, two colour bars
    assert fig.axes[0].get_xlabel() == "support position along the scan (Å)"
    assert fig.axes[0].get_ylabel() == "line offset across the scan (Å)"
    assert fig.get_suptitle() == "Lateral force maps, trace: NaF(001), scan angle 0°"
    shown = fig.axes[0].images[0].get_array()
    assert np.array_equal(shown, data["afm/trace/fx"].values)
    assert fig.axes[1].images[0].get_clim() == pytest.approx((-np.abs(data["afm/trace/fy"].values).max(),
                                                              np.abs(data["afm/trace/fy"].values).max()))
    saved(fig, tmp_path / "maps.png")
    assert friction.plot.afm_maps(naf_map, trip="retrace").get_suptitle().startswith("Lateral force maps, retrace")
    assert fig._repr_png_().startswith(b"\x89PNG")


def test_friction_loop(naf_map, tmp_path):
    data = friction.load(naf_map)
    fig = friction.plot.friction_loop(data, line=3)
    ax = fig.axes[0]
    assert f"friction = {data['afm/friction'].values[3]:.4g} nN" in ax.get_title()
    assert "Friction loop, line 3" in ax.get_title()
    trace, retrace = ax.lines[0], ax.lines[1]
    assert np.array_equal(trace.get_ydata(), data["afm/trace/f_along"].values[3])
    assert np.array_equal(retrace.get_ydata(), data["afm/retrace/f_along"].values[3])
    assert np.array_equal(trace.get_xdata(), data["afm/support_x"].values)
    saved(fig, tmp_path / "loop.png")
    with pytest.raises(ValueError, match="line 10 out of range: the file has lines 0 .. 9"):
        friction.plot.friction_loop(data, line=10)


def test_lattice_sum_pictures(graphite_map, naf_map, tmp_path):
    data = friction.load(graphite_map)
    net = friction.plot.graphite_net(data)
    assert net.axes[0].get_title().startswith("Crystal net and scan region: Lennard-Jones lattice sum, scan angle 15°")
    assert "150 atoms" in net.axes[0].get_title()
    saved(net, tmp_path / "net.png")
    lines = friction.plot.stacked_lines(data, component="f_along", offset=0.5)
    assert lines.line_offset == 0.5 and "3 scan lines, trace" in lines.axes[0].get_title()
    saved(lines, tmp_path / "lines.png")
    with pytest.raises(friction.FileError, match="not a lattice-sum scene"):
        friction.plot.graphite_net(naf_map)


def test_brake_pictures(brake_run, naf_map, tmp_path):
    data = friction.load(brake_run)
    phase = friction.plot.brake_phase(data, window=(100, 300))
    ax = phase.axes[0]
    assert ax.get_title().startswith("Phase plane, τ ∈ [100, 300] (paper Fig. 12)")
    assert ax.get_xlabel() == "x, block displacement (m)"
    t = data["brake/t"].values
    inside = (t >= 100) & (t <= 300)
    assert np.array_equal(ax.lines[0].get_xdata(), data["brake/x"].values[inside])
    saved(phase, tmp_path / "phase.png")
    # By default the run's second half: the transient (about 1000 τ of 3200 here) is left out.
    default = friction.plot.brake_phase(data).axes[0]
    assert "transient left out" in default.get_title()
    assert np.array_equal(default.lines[0].get_xdata(), data["brake/x"].values[t >= t[0] + 0.5 * (t[-1] - t[0])])
    x = friction.plot.brake_x(data, window=(100, 300))
    assert f"{data['brake/events/t'].size} stick/slip events" in x.axes[0].get_title()
    saved(x, tmp_path / "x.png")
    spectrum = friction.plot.brake_spectrum(data)
    peak = data["brake/spectrum"].attrs["peak_frequency"]
    assert spectrum.axes[0].lines[1].get_xdata()[0] == peak
    assert "(paper Fig. 13)" in spectrum.axes[0].get_title()
    saved(spectrum, tmp_path / "spectrum.png")
    poincare = friction.plot.poincare(data)
    assert f"{data['brake/poincare/strobe_t'].size} points" in poincare.axes[0].get_title()
    saved(poincare, tmp_path / "poincare.png")
    lyapunov = friction.plot.lyapunov(data)
    exponent = data["brake/lyapunov"].attrs["benettin_exponent"]
    assert f"Benettin running estimate: {exponent:.3g} per τ" in lyapunov.axes[0].get_title()
    saved(lyapunov, tmp_path / "lyapunov.png")
    with pytest.raises(ValueError, match="window 5000 6000 is outside the run"):
        friction.plot.brake_phase(data, window=(5000, 6000))
    with pytest.raises(friction.FileError, match="not a friction brake file"):
        friction.plot.brake_phase(naf_map)


def test_orbit_pictures(brake_run, files, tmp_path):
    data = friction.load(brake_run)
    fig = friction.plot.floquet(data)
    mu = data["brake/orbit/floquet_multipliers"].values
    points = fig.axes[0].lines[1]
    assert np.array_equal(points.get_xdata(), mu[:, 0]) and np.array_equal(points.get_ydata(), mu[:, 1])
    assert "Newton steps" in fig.axes[0].get_title()
    saved(fig, tmp_path / "floquet.png")
    with pytest.raises(friction.FileError, match="no /brake/orbit/branch"):
        friction.plot.orbit_branch(data)
    line = files("continuation_short", [ROOT / "inputs" / "brake.nml", ROOT / "inputs" / "brake_continuation.nml",
                                        ROOT / "tests" / "data" / "brake_continuation_short.nml"])
    fig = friction.plot.orbit_branch(friction.load(line))
    assert titles(fig)[0] == "Periodic orbit followed in mu (stick-to-slip section)"
    assert fig.axes[1].get_xlabel() == "mu" and fig.axes[1].get_ylabel() == "largest |μ| of the section map"
    saved(fig, tmp_path / "bifurcation.png")


def test_sweep_pictures(brake_sweep, afm_sweep, tmp_path):
    figures = friction.plot.sweep(brake_sweep)
    assert set(figures) == {"bifurcation", "lyapunov"}
    bifurcation = figures["bifurcation"].axes[0]
    assert bifurcation.get_title() == "bifurcation diagram" and bifurcation.get_xlabel() == "brake.v_dr_prime (m/tau)"
    maxima = friction.load(brake_sweep)["sweep/maxima"]
    assert np.array_equal(np.sort(bifurcation.lines[0].get_ydata()), np.sort(maxima.values))
    for name, fig in figures.items():
        saved(fig, tmp_path / f"{name}.png")
    afm = friction.plot.sweep(afm_sweep)
    assert set(afm) == {"friction"}
    top = afm["friction"].axes[0]
    assert top.get_ylabel() == "mean friction (nN)" and len(top.get_legend().get_texts()) == 2
    assert afm["friction"].axes[1].get_xscale() == "log"
    saved(afm["friction"], tmp_path / "afm_sweep.png")


def test_machine_sweep_pictures(machine_sweep, brake_sweep, tmp_path):
    """A machine sweep: its maxima, and a panel per result it has, each the
    file's numbers; no orbit (NaN) is a gap, not a point."""
    figures = friction.plot.sweep(machine_sweep)
    assert set(figures) == {"bifurcation", "machine"}
    data = friction.load(machine_sweep)
    maxima = figures["bifurcation"].axes[0].lines[0].get_ydata()
    assert np.array_equal(np.sort(maxima), np.sort(data["sweep/maxima"].values))
    axes = figures["machine"].axes
    assert [ax.get_ylabel() for ax in axes] == ["mean friction force (N)", "stick fraction", "stick/slip events",
                                              "Benettin exponent (1/s)", "orbit period (s)", "largest |μ|"]
    assert axes[-1].get_xlabel() == "machine.belt_velocity (m/s)"
    for ax, key in zip(axes, ("force_mean", "stick_fraction", "events", "lyapunov", "orbit_period",
                              "orbit_max_multiplier")):
        wanted = data[f"sweep/{key}"].values.astype(float)
        assert np.array_equal(ax.lines[0].get_ydata(), wanted, equal_nan=True), key
    assert np.isnan(data["sweep/orbit_period"].values[-1])   # steady sliding at 0.3 m/s: no orbit
    for name, fig in figures.items():
        saved(fig, tmp_path / f"machine_{name}.png")
    with pytest.raises(friction.FileError, match="not a machine sweep"):
        friction.plot.sweep_machine(brake_sweep)
    with pytest.raises(friction.FileError, match="not a brake sweep"):
        friction.plot.sweep_lyapunov(machine_sweep)


def test_atlas(brake_atlas, brake_sweep, tmp_path):
    figures = friction.plot.sweep(brake_atlas)
    # 4 values of the second variable: the maps and the lines.
    assert set(figures) == {"atlas", "bifurcation", "lyapunov"}
    top, bottom = figures["atlas"].axes[:2]
    data = friction.load(brake_atlas)
    # The second variable varies fastest: row i is mu_i, column j the j-th belt speed.
    wanted = data["sweep/lyapunov"].values.reshape(3, 4)
    assert np.array_equal(np.asarray(top.collections[0].get_array()).reshape(3, 4), wanted)
    stick = data["sweep/stick_fraction"].values.reshape(3, 4)
    assert np.array_equal(np.asarray(bottom.collections[0].get_array()).reshape(3, 4), stick)
    # Negative log-spaced belt speeds are drawn as magnitudes on a log axis.
    assert bottom.get_xscale() == "log" and bottom.get_xlabel() == "−brake.v_dr_prime (m/tau)"
    assert top.get_yscale() == "linear" and top.get_ylabel() == "brake.mu"
    assert np.allclose(sorted(bottom.get_xlim()), [0.0005 / 2 ** 0.5, 0.004 * 2 ** 0.5], rtol=1e-9)
    saved(figures["atlas"], tmp_path / "atlas.png")
    with pytest.raises(friction.FileError, match="needs a sweep over two variables"):
        friction.plot.atlas(brake_sweep)


def test_work_precision_charts(tmp_path):
    data = friction.load(ROOT / "docs" / "work_precision.h5")
    fig = friction.plot.work_precision(data, "naf")
    ax = fig.axes[0]
    assert ax.get_xscale() == "log" and ax.get_xlabel() == "error: max |F - reference| (nN)"
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "rkf45" in labels and "rk8pd" in labels
    ok = data["naf/rkf45/status"].values == "ok"
    line = next(l for l in ax.lines if l.get_label() == "rkf45")
    assert np.array_equal(line.get_xdata(), data["naf/rkf45/error"].values[ok])
    saved(fig, tmp_path / "wp.png", dpi=90)
    brake = friction.plot.work_precision(data, "brake_regularized")
    assert "ngspice (network model, trap)" in [t.get_text() for t in brake.axes[0].get_legend().get_texts()]
    with pytest.raises(friction.FileError, match="no scene 'boat'"):
        friction.plot.work_precision(data, "boat")
    failure = friction.plot.failure_map(ROOT / "docs" / "failure_map.h5")
    assert len(failure.axes) == 2 and [t.get_text() for t in failure.axes[0].get_xticklabels()][0] == "ε' = 1e+03"
    saved(failure, tmp_path / "failure.png", dpi=90)
