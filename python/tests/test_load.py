"""load(): the datasets with their coordinates and units, read independently with h5py."""

import h5py
import numpy as np
import pytest
import xarray as xr

import friction
from conftest import DATA, ROOT


def raw(path, name):
    with h5py.File(path) as f:
        return f[name][()], {k: v for k, v in f[name].attrs.items()}


def test_a_map(naf_map):
    data = friction.load(naf_map)
    assert isinstance(data, xr.DataTree)
    assert data.attrs["scene"] == "afm" and data.attrs["program"] == "friction"
    fx = data["afm/trace/fx"]
    values, attrs = raw(naf_map, "afm/trace/fx")
    assert np.array_equal(fx.values, values) and fx.attrs["units"] == attrs["units"].decode() == "nN"
    assert fx.dims == ("support_y", "support_x") and fx.shape == (10, 40)
    x, _ = raw(naf_map, "afm/support_x")
    y, _ = raw(naf_map, "afm/support_y")
    # the map's coordinates are /afm's, inherited by /afm/trace
    assert np.array_equal(fx["support_x"].values, x) and fx["support_x"].attrs["units"] == "angstrom"
    assert np.array_equal(fx["support_y"].values, y) and fx["support_y"].attrs["units"] == "angstrom"
    assert data["afm/friction"].dims == ("support_y",)
    assert data["afm/trace/tip_x"].attrs["units"] == "angstrom"
    # xarray's selection by coordinate
    line = fx.sel(support_y=y[3] + 0.1, method="nearest")
    assert line.dims == ("support_x",) and np.array_equal(line.values, values[3])
    part = fx.sel(support_x=slice(5.0, 10.0))
    assert np.array_equal(part["support_x"].values, x[(x >= 5.0) & (x <= 10.0)])
    assert np.array_equal(fx.isel(support_y=2, support_x=slice(0, 4)).values, values[2, :4])
    # attributes as in the file, a unit beside its value (NAME_units)
    assert data.attrs["wall_time_units"] == "s" and isinstance(data.attrs["nranks"], int)
    afm = data["afm"].attrs
    assert afm["angle"] == 0.0 and afm["angle_units"] == "degree" and afm["kx_units"] == "N/m"
    assert afm["potential"] == "naf"
    assert "afm/trace/fx" in friction.paths(data) and "afm/support_x" in friction.paths(data)
    assert friction.groups(data)["afm/trace"] == {}


def test_a_brake_run(brake_run):
    data = friction.load(brake_run, scene="brake")
    t, _ = raw(brake_run, "brake/t")
    x = data["brake/x"]
    assert x.dims == ("t",) and np.array_equal(x["t"].values, t) and x.attrs["units"] == "m"
    v = data["brake/v"].attrs    # UDUNITS at τ = 1, and in τ (docs/output.md#units-udunits-strings)
    assert v["units"] == "m" and v["units_tau"] == "m/tau" and data["brake/stick"].dims == ("t",)
    events = data["brake/events/kind"]
    et, _ = raw(brake_run, "brake/events/t")
    assert events.dims == ("event",) and np.array_equal(events["t"].values, et)
    spectrum = data["brake/spectrum/amplitude"]
    f, _ = raw(brake_run, "brake/spectrum/frequency")
    assert spectrum.dims == ("frequency",) and np.array_equal(spectrum["frequency"].values, f)
    assert spectrum["frequency"].attrs["units"] == "1" and spectrum["frequency"].attrs["units_tau"] == "1/tau"
    assert data["brake/poincare/strobe_x"].dims == ("strobe_t",)
    st, _ = raw(brake_run, "brake/poincare/strobe_t")
    assert np.array_equal(data["brake/poincare/strobe_x"]["strobe_t"].values, st)
    assert data["brake/poincare/section_y"].dims == ("section_t",)
    assert data["brake/lyapunov/benettin_estimate"].dims == ("benettin_time",)
    assert data["brake/lyapunov/rosenstein_divergence"].dims == ("rosenstein_time",)
    brake = data["brake"].attrs
    assert brake["v_dr_prime"] == -0.002788 and brake["v_dr_prime_units"] == "m"
    assert brake["v_dr_prime_units_tau"] == "m/tau"
    assert data["brake/spectrum"].attrs["peak_frequency_units_tau"] == "1/tau"


def test_a_machine_run_with_its_maps_and_spectrum(program, tmp_path):
    """The machine's Poincaré maps along their times and its QR spectrum's history."""
    import subprocess
    path = tmp_path / "machine.h5"
    subprocess.run([str(program), "--quiet", "-o", str(path), str(ROOT / "inputs" / "machine_coulomb.nml"),
                    "--set", "analysis.poincare=.true.", "--set", "analysis.strobe_period=1.0",
                    "--set", "analysis.lyapunov=.false.", "--set", "analysis.lyapunov_spectrum=.true.",
                    "--set", "analysis.lyapunov_spectrum_transient=10"], check=True)
    data = friction.load(path, scene="machine")
    st, _ = raw(path, "machine/poincare/strobe_t")
    strobe = data["machine/poincare/strobe_x"]
    assert strobe.dims == ("strobe_t",) and np.array_equal(strobe["strobe_t"].values, st)
    assert data["machine/poincare/section_v"].dims == ("section_t",)
    history = data["machine/lyapunov/exponents_history"]
    et, _ = raw(path, "machine/lyapunov/exponents_time")
    assert history.dims == ("exponents_time", "exponent") and np.array_equal(history["exponents_time"].values, et)
    assert history.attrs["units"] == "1/s" and data["machine/lyapunov/exponents"].size == 2


def test_a_brake_sweep(brake_sweep):
    data = friction.load(brake_sweep, scene="sweep")
    values, vattrs = raw(brake_sweep, "sweep/values")
    lyap = data["sweep/lyapunov"]
    assert lyap.dims == ("brake.v_dr_prime",) and lyap.attrs["units_tau"] == "1/tau"
    assert np.array_equal(lyap["brake.v_dr_prime"].values, values)
    assert lyap["brake.v_dr_prime"].attrs["units_tau"] == vattrs["units_tau"].decode() == "m/tau"
    maxima = data["sweep/maxima"]
    counts, _ = raw(brake_sweep, "sweep/maxima_count")
    assert maxima.dims == ("maximum",) and maxima.size == counts.sum()
    assert np.array_equal(maxima["maximum_brake.v_dr_prime"].values, np.repeat(values, counts))


def test_an_afm_sweep_is_a_grid(afm_sweep):
    data = friction.load(afm_sweep)
    friction_values, _ = raw(afm_sweep, "sweep/mean_friction")
    v0, _ = raw(afm_sweep, "sweep/values")
    velocity, _ = raw(afm_sweep, "sweep/values2")
    grid = data["sweep/mean_friction"]
    assert grid.dims == ("surface.v0", "scan.velocity") and grid.shape == (5, 2)
    for i in range(5):
        for j in range(2):
            assert grid.values[i, j] == friction_values[i * 2 + j]
            assert grid["surface.v0"].values[i] == v0[i * 2 + j]
            assert grid["scan.velocity"].values[j] == velocity[i * 2 + j]
    assert grid["surface.v0"].attrs["units"] == "eV" and grid["scan.velocity"].attrs["units"] == "angstrom/s"
    assert grid.sel({"scan.velocity": 100.0}).dims == ("surface.v0",)


def test_a_lattice_sum_map(graphite_map):
    data = friction.load(graphite_map)
    atoms = data["surface/atoms"]
    assert atoms.dims == ("atom", "xyz") and list(atoms["xyz"].values) == ["x", "y", "z"]
    assert data["surface/species"].dims == ("atom",)
    assert data["afm/trace/fz"].dims == ("support_y", "support_x")
    assert data["surface"].attrs["species_names"] == "C"


def test_other_hdf5_files():
    data = friction.load(ROOT / "docs" / "work_precision.h5")
    assert data.attrs["program"] != "friction"
    status = data["naf/rkf45/status"]
    assert status.dims == ("naf/rkf45/status_dim_0",) and status.values[0] in ("ok", "unresolved", "capped")
    assert data["naf"].attrs["unit"] == "nN"


def test_files_it_cannot_read(tmp_path, naf_map):
    with pytest.raises(friction.FileError, match="no such file"):
        friction.load(tmp_path / "none.h5")
    with pytest.raises(friction.FileError, match="cannot read as HDF5"):
        friction.load(DATA / "small.nml")
    with pytest.raises(friction.FileError, match="not a friction brake file"):
        friction.load(naf_map, scene="brake")
    with pytest.raises(KeyError, match="afm/trace/nothing"):
        friction.load(naf_map)["afm/trace/nothing"]


def test_a_damaged_file(tmp_path, brake_run):
    """A file damaged inside (bits flipped past its superblock) raised
    h5py's RuntimeError, KeyError or ValueError; every damage is the
    package's FileError, or loads (a flip in the data's own bytes)."""
    import random
    data = bytes(open(brake_run, "rb").read())
    raised = set()
    for seed in range(40):
        rng = random.Random(seed)
        damaged = bytearray(data)
        for _ in range(20):
            at = rng.randrange(len(damaged))
            damaged[at] ^= 1 << rng.randrange(8)
        path = tmp_path / f"damaged-{seed}.h5"
        path.write_bytes(bytes(damaged))
        try:
            friction.load(path)
        except friction.FileError as err:
            raised.add(str(err).split(" (")[0])
    # The 40 fixed seeds reach a file that opens and fails inside (any other
    # exception fails the test where it is raised).
    assert "the HDF5 file is damaged" in raised, raised


def test_a_tree_is_loaded_once(naf_map):
    data = friction.load(naf_map)
    assert friction.load(data) is data


def test_xarray_opens_the_files_themselves(naf_map, brake_run, brake_sweep, afm_sweep):
    """The files carry their coordinates as HDF5 dimension scales, so xarray
    opens them without this package (engine h5netcdf): a map's axes, the
    trajectory's time, the spectrum's frequencies, the events' numbers and
    times, a sweep's points with their swept values (a grid by xarray's
    unstack), with the values h5py reads."""
    import h5netcdf  # noqa: F401  (xarray's engine; scripts/install-deps installs it)
    tree = xr.open_datatree(naf_map, engine="h5netcdf", phony_dims="sort")
    fx = tree["afm/trace/fx"]
    values, _ = raw(naf_map, "afm/trace/fx")
    x, _ = raw(naf_map, "afm/support_x")
    y, _ = raw(naf_map, "afm/support_y")
    assert fx.dims == ("support_y", "support_x") and np.array_equal(fx.values, values)
    assert np.array_equal(fx["support_x"].values, x) and np.array_equal(fx["support_y"].values, y)
    assert fx.attrs["units"] == "nN" and fx["support_x"].attrs["units"] == "angstrom"
    assert tree["afm/friction"].dims == ("support_y",)
    brake = xr.open_datatree(brake_run, engine="h5netcdf", phony_dims="sort")
    t, _ = raw(brake_run, "brake/t")
    assert brake["brake/x"].dims == ("t",) and np.array_equal(brake["brake/x"]["t"].values, t)
    f, _ = raw(brake_run, "brake/spectrum/frequency")
    assert np.array_equal(brake["brake/spectrum/amplitude"]["frequency"].values, f)
    kind = brake["brake/events/kind"]
    et, _ = raw(brake_run, "brake/events/t")
    assert kind.dims == ("event",) and np.array_equal(kind["t"].values, et)
    assert np.array_equal(kind["event"].values, np.arange(1, et.size + 1))
    assert brake["brake/poincare/strobe_x"].dims == ("strobe_t",)
    # a sweep: every per-point column over the points' numbers, the swept values as coordinates
    sweep = xr.open_datatree(brake_sweep, engine="h5netcdf", phony_dims="sort")
    values, _ = raw(brake_sweep, "sweep/values")
    lyapunov = sweep["sweep/lyapunov"]
    assert lyapunov.dims == ("point",) and np.array_equal(lyapunov["values"].values, values)
    assert np.array_equal(lyapunov["point"].values, np.arange(1, values.size + 1))
    grid = xr.open_datatree(afm_sweep, engine="h5netcdf", phony_dims="sort")["sweep"].to_dataset()
    v0, _ = raw(afm_sweep, "sweep/values")
    velocity, _ = raw(afm_sweep, "sweep/values2")
    friction_values, _ = raw(afm_sweep, "sweep/mean_friction")
    unstacked = grid.set_index(point=["values", "values2"]).unstack("point")["mean_friction"]
    assert unstacked.sel(values=v0[3], values2=velocity[3]).item() == friction_values[3]
