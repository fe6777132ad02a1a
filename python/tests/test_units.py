"""Every unit the program's files state parses with UDUNITS-2 (cf-units: what
netCDF's tools and the CF conventions read) and with pint (what xarray's
unit support reads), and both agree on its size (docs/output.md#units).

One file of every scene and kind: a map, a lattice-sum map with its table, a
thermal map, the brake with every diagnostic, the brake in SI units, the
brake with a law in SI and in its own units, a continuation, the machine
with its diagnostics, the machine's periodic orbit and continuation, a
brake sweep, an AFM sweep and a machine sweep with its orbits.  Checked:
every dataset's `units`, every attribute `NAME_units` and each column's
unit in a `column_units`; a unit in the brake's
time τ (`units_tau`, `NAME_units_tau`, `column_units_tau`) is its `units`
at τ = 1, and with the SI brake's `time_scale` (τ in s) it converts to SI.
"""
import math

import h5py
import numpy as np
import pytest

import cf_units   # UDUNITS-2 (the wheel carries the library); scripts/install-deps installs it
import pint

from conftest import DATA, INPUTS

BRAKE_SHORT = [INPUTS / "brake.nml", DATA / "brake_short.nml"]
NO_TANGENTS = "&analysis lyapunov = .false., lyapunov_spectrum = .false., orbit = .false. /\n"

# name: (input files, override namelist text)
KINDS = {
    "map": ([INPUTS / "naf.nml", DATA / "small.nml"], ""),
    "graphite": ([INPUTS / "graphite.nml", DATA / "graphite_small.nml"], ""),
    "thermal": ([INPUTS / "naf_thermal_temperature.nml"], "&thermal realizations = 2 /\n"),
    "brake": (BRAKE_SHORT, ""),
    "brake_si": ([INPUTS / "brake.nml", INPUTS / "brake_dimensional.nml", DATA / "brake_short.nml"], ""),
    "brake_law_si": ([INPUTS / "brake_lugre.nml"],
                     "&brake t_end = 60.0 /\n&analysis window_start = 10.0, window_end = 60.0 /\n"),
    # The arctan law in the brake's own units: its parameters are ε' and δ' (tau/m), not SI.
    "brake_law": (BRAKE_SHORT, "&brake model = 'law' /\n&law model = 'arctan' /\n" + NO_TANGENTS),
    "continuation": ([INPUTS / "brake.nml", INPUTS / "brake_continuation.nml",
                      DATA / "brake_continuation_short.nml"], ""),
    "machine": ([INPUTS / "machine_lugre.nml"], ""),
    # The orbit's point and equilibrium (column_units), its branch; and a machine sweep with its orbits.
    "machine_orbit": ([INPUTS / "machine_orbit.nml"], ""),
    "machine_sweep": ([INPUTS / "machine_orbit.nml"],
                      "&analysis continuation = '' /\n&sweep sweep_variable = 'machine.belt_velocity', "
                      "sweep_spacing = 'list', sweep_values = 0.0026, 0.3 /\n"),
    "brake_sweep": ([INPUTS / "brake_sweep.nml", DATA / "sweep_small.nml"], ""),
    "afm_sweep": ([INPUTS / "afm_sweep.nml", DATA / "afm_sweep_small.nml"], ""),
}


def stated_units(path):
    """(where, unit) of every dataset's `units` and every attribute NAME_units,
    and {where: (unit, unit in τ, columns' units in τ)} where a τ form is beside it."""
    units, tau_forms = [], {}

    def text(value):
        return value.decode() if isinstance(value, bytes) else str(value)

    def visit(name, obj):
        for key, value in obj.attrs.items():
            where = f"/{name}@{key}"
            # A group's `units` is not a unit: /brake's is &brake's variable (the parameter set).
            if key == "column_units":
                # A dataset whose columns differ in unit (/machine/orbit/point): each column's.
                units.extend((f"{where}[{i}]", column.strip()) for i, column in enumerate(text(value).split(",")))
            elif key.endswith("_units") or (key == "units" and isinstance(obj, h5py.Dataset)):
                units.append((where, text(value)))
                tau = obj.attrs.get(key + "_tau")
                columns = obj.attrs.get("column_units_tau") if key == "units" else None
                if tau is not None or columns is not None:
                    tau_forms[where] = (text(value), None if tau is None else text(tau),
                                        None if columns is None else text(columns))
            elif key.endswith("_tau"):
                unit_key = "units" if key == "column_units_tau" else key[:-4]
                assert unit_key in obj.attrs, f"{path.name}: {where} without {unit_key}"

    with h5py.File(path, "r") as f:
        visit("", f)
        f.visititems(visit)
        time_scale = f["brake"].attrs.get("time_scale") if "brake" in f else None
    return units, tau_forms, time_scale


@pytest.fixture(scope="module", params=sorted(KINDS))
def kind_file(request, files):
    inputs, override = KINDS[request.param]
    return request.param, files(f"units_{request.param}", inputs, override)


def si_factor_pint(registry, unit):
    """(factor, SI base unit text) of unit in pint."""
    q = registry.Quantity(1.0, registry.parse_units(unit)).to_base_units()
    return q.magnitude, "1" if q.dimensionless else f"{q.units:C}"


def test_every_unit_parses_in_udunits_and_pint(kind_file):
    kind, path = kind_file
    units, _, _ = stated_units(path)
    assert units, f"{kind}: no units found in {path}"
    registry = pint.UnitRegistry()
    bad = []
    for where, unit in units:
        try:
            udunits = cf_units.Unit(unit)
        except ValueError as exc:
            bad.append(f"{where} = {unit!r}: UDUNITS: {exc}")
            continue
        try:
            factor, base = si_factor_pint(registry, unit)
        except (pint.errors.PintError, ValueError, TypeError, AttributeError) as exc:
            bad.append(f"{where} = {unit!r}: pint: {exc}")
            continue
        # Both read the same size: UDUNITS converts one `unit` into pint's SI base unit by pint's
        # factor, to 1e-5 (UDUNITS's electronvolt is CODATA 1986's, 6e-7 off the exact 2019 value
        # pint has; a wrong meaning, a factor 2π, 1024/1000 or a prefix, is far beyond it).
        try:
            converted = udunits.convert(1.0, cf_units.Unit(base.replace("**", "^")))
        except ValueError as exc:
            bad.append(f"{where} = {unit!r}: UDUNITS cannot convert it to pint's {base!r}: {exc}")
            continue
        if not math.isclose(converted, factor, rel_tol=1e-5):
            bad.append(f"{where} = {unit!r}: 1 {unit} is {converted} {base} in UDUNITS, {factor} in pint")
    assert not bad, f"{kind} ({path.name}):\n" + "\n".join(bad)


def test_units_in_tau_are_their_units_at_tau_one(kind_file):
    kind, path = kind_file
    _, tau_forms, time_scale = stated_units(path)
    if kind.startswith("brake") or kind == "continuation":
        assert tau_forms, f"{kind}: no unit in tau"
    else:
        assert not tau_forms, f"{kind}: units in tau outside the brake: {sorted(tau_forms)[:3]}"
    dimensionless = pint.UnitRegistry()
    dimensionless.define("tau = 1")       # the convention: τ is a pure number
    for where, (unit, tau, columns) in tau_forms.items():
        forms = ([tau] if tau else []) + ([c.strip() for c in columns.split(",")] if columns else [])
        assert any("tau" in form for form in forms), f"{where}: {forms} have no tau"
        for form in forms:
            ratio = dimensionless.Quantity(1.0, form).to(unit).magnitude
            assert math.isclose(ratio, 1.0, rel_tol=1e-15), f"{where}: {form!r} at tau = 1 is not {unit!r}"
    if time_scale is not None:
        # With &brake units = 'dimensional' a unit τ is time_scale seconds: the velocity in SI.
        si = pint.UnitRegistry()
        si.define(f"tau = {float(time_scale)!r} * second")
        with h5py.File(path, "r") as f:
            v = f["brake/v"]
            speed = si.Quantity(np.asarray(v[:5]), v.attrs["units_tau"].decode()).to("m/s").magnitude
            assert np.allclose(speed, v[:5] / time_scale, rtol=1e-15, atol=0.0)


def test_the_law_in_the_brakes_own_units(files):
    """With units = 'nondimensional' the law's parameters are in the brake's units (docs/laws.md):
    the arctan law's epsilon is ε' in tau/m, not &law's SI s/m."""
    path = files("units_brake_law", *KINDS["brake_law"])
    with h5py.File(path, "r") as f:
        law = f["brake/law"].attrs
        assert law["epsilon_units_tau"].decode() == "tau/m" and law["epsilon_units"].decode() == "1/m"
    path = files("units_brake_law_si", *KINDS["brake_law_si"])
    with h5py.File(path, "r") as f:
        law = f["brake/law"].attrs
        assert law["fs_units"].decode() == "N" and "fs_units_tau" not in law
