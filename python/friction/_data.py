"""Reading the program's HDF5 files as xarray trees with units.

    data = friction.load("naf.h5")          # an xarray.DataTree
    fx = data["afm/trace/fx"]               # a DataArray over ("support_y", "support_x")
    fx.attrs["units"]                       # 'nN'
    fx["support_x"].attrs["units"]          # 'angstrom'
    fx.sel(support_y=2.0, method="nearest") # the line nearest 2 Å across the scan
    data.attrs["wall_time"], data.attrs["wall_time_units"]     # 0.047, 's'
    data["afm"].attrs["angle"], data["afm"].attrs["angle_units"]

The files' layouts (which dataset runs along which other) are the program's
own, so load() names the dimensions and coordinates that the files do not
yet mark themselves; xarray does the rest.
"""
from __future__ import annotations

import contextlib
import os
from pathlib import Path
from typing import Any, Iterator

import h5py
import numpy as np
import xarray as xr

__all__ = ["FileError", "groups", "load", "open_output", "paths", "text"]


class FileError(ValueError):
    """A file that cannot be read as asked: missing, not HDF5, not a friction
    file of the expected scene, or without the datasets asked for.  The
    message says which (the scripts print it after the file's name)."""


def text(value: Any) -> str:
    """HDF5 string attributes come back as (arrays of) bytes; give str.

    Parameters
    ----------
    value : bytes or str or numpy.ndarray
        An attribute's value.

    Returns
    -------
    str
        The text.
    """
    if isinstance(value, np.ndarray) and value.shape == ():
        value = value[()]
    return value.decode() if isinstance(value, bytes) else str(value)


def _python(value):
    """An attribute's value as plain Python: str, int, float, bool or a numpy array."""
    if isinstance(value, np.ndarray):
        if value.shape == ():
            return _python(value[()])
        if value.dtype.kind in "SO":
            return np.array([text(v) for v in value.ravel()], dtype=object).reshape(value.shape)
        return value
    if isinstance(value, (bytes, np.bytes_)):
        return value.decode()
    if isinstance(value, np.bool_):
        return bool(value)
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.floating):
        return float(value)
    return value


#: HDF5's bookkeeping of dimension scales: the dimensions and coordinates say it.
SCALE_ATTRIBUTES = {"CLASS", "NAME", "DIMENSION_LIST", "REFERENCE_LIST", "coordinates"}


def _attrs(raw):
    """An HDF5 object's attributes as plain Python values (text decoded);
    an attribute's unit stays beside it as NAME_units, as in the file.  The
    dimension scales' bookkeeping (SCALE_ATTRIBUTES) is not read: its object
    references, when damaged, can keep HDF5 reading for ever, and the
    layouts below name the same dimensions."""
    if raw is None:
        return {}
    return {name: _python(raw[name]) for name in raw.keys() if name not in SCALE_ATTRIBUTES}


def paths(tree: xr.DataTree) -> list[str]:
    """The path of every array in a loaded file ("afm/trace/fx", "brake/t"),
    coordinates included, in the file's order of groups.

    Parameters
    ----------
    tree : xarray.DataTree
        A loaded file (friction.load).

    Returns
    -------
    list of str
        The paths.
    """
    out = []
    for node in tree.subtree:
        prefix = node.path.strip("/")
        own = node.to_dataset(inherit=False)
        out += [f"{prefix}/{name}" if prefix else str(name) for name in own.variables]
    return out


def groups(tree: xr.DataTree) -> dict[str, Any]:
    """{group path: its attributes} of every group of a loaded file ("afm",
    "brake/spectrum"); the root's are tree.attrs.

    Parameters
    ----------
    tree : xarray.DataTree
        A loaded file (friction.load).

    Returns
    -------
    dict
        {group path: attributes}.
    """
    return {node.path.strip("/"): node.attrs for node in tree.subtree if node.path != "/"}


def _check_path(path):
    path = Path(path)
    if not path.exists():
        raise FileError("no such file")
    if not path.is_file():
        raise FileError("not a regular file")
    return path


def _read_values(dataset):
    values = dataset[()]
    if isinstance(values, np.ndarray) and values.dtype.kind in "SO":
        values = np.array([text(v) for v in values.ravel()], dtype=object).reshape(values.shape)
    elif isinstance(values, (bytes, np.bytes_)):
        values = np.array(text(values), dtype=object)
    return np.asarray(values)


def load(path: str | os.PathLike[str] | xr.DataTree, scene: str | None = None) -> xr.DataTree:
    """Read a friction output file (any HDF5 file) into an xarray.DataTree:
    a node per group, a variable per dataset (named by the dataset), the
    root's and each group's attributes as the node's attrs.

    The program's layouts name the dimensions and coordinates, as the files'
    own HDF5 dimension scales do (docs/output.md; a sweep's points become the
    grid of its variables):
      afm     maps (ny, nx) over ("support_y", "support_x"), the line offset
              across the scan and the support position along it (angstrom),
              coordinates of /afm that /afm/trace and /afm/retrace inherit;
              /afm/friction over support_y; /afm/slips over "slip";
              /surface/atoms over ("atom", "xyz")
      brake   the trajectory over "t"; the events over "event" with their
              times t as coordinate; the spectrum over "frequency"; the
              Poincare points over "strobe_t" and "section_t"; the Lyapunov
              curves over "benettin_time", "rosenstein_time" and
              "exponents_time"
      machine the run over "t"; the events over "event" with their times t;
              the spectrum over "frequency"; the Lyapunov curve over "time"
      sweep   per point over the swept variable ("brake.v_dr_prime"), or over
              both variables (a grid, the second varying fastest); the brake's
              maxima over "maximum", with the swept values of their point as
              the coordinates "maximum_<variable>"
    Other datasets get dims "<path>_dim_<k>".  Units are each variable's
    attrs["units"]; an attribute's unit is the attribute NAME_units.

    scene: 'afm', 'brake' or 'sweep' to require a file the program wrote for
    that scene.  Raises FileError for a missing file, one that is not HDF5,
    or not of the scene asked for.

    Parameters
    ----------
    path : str or os.PathLike or xarray.DataTree
        The file (a tree is returned as it is).
    scene : str, optional
        'afm', 'brake' or 'sweep': require a file of that scene.

    Returns
    -------
    xarray.DataTree
        The file, read whole (the file is closed).

    Raises
    ------
    FileError
        A missing file, one that is not HDF5, or not of the scene asked for.

    Examples
    --------
    >>> data = friction.load("naf.h5")  # doctest: +SKIP
    >>> data["afm/trace/fx"].attrs["units"]  # doctest: +SKIP
    'nN'
    """
    if scene is not None:
        return require(path, scene)
    if isinstance(path, xr.DataTree):
        return path
    path = _check_path(path)
    raw, group_attrs = {}, {"": {}}
    try:
        with h5py.File(path, "r") as f:
            group_attrs[""] = _attrs(f.attrs)

            def visit(name, item):
                if isinstance(item, h5py.Dataset):
                    raw[name] = (_read_values(item), _attrs(item.attrs))
                else:
                    group_attrs[name] = _attrs(item.attrs)
            f.visititems(visit)
    except OSError as err:
        raise FileError(f"cannot read as HDF5 ({err})") from None
    except (RuntimeError, KeyError, ValueError, TypeError) as err:
        # A damaged file opens and then fails inside: h5py's own errors
        # (RuntimeError, KeyError, ValueError) said nothing of the file.
        raise FileError(f"the HDF5 file is damaged ({type(err).__name__}: {err})") from None
    labels = _label(raw, group_attrs[""], group_attrs)
    nodes = {name: {"data": {}, "coords": {}} for name in group_attrs}
    for name, (values, attrs) in raw.items():
        group, _, short = name.rpartition("/")
        nodes.setdefault(group, {"data": {}, "coords": {}})
        dims, role = labels.get(name, (tuple(f"{name}_dim_{k}" for k in range(values.ndim)), "data"))
        reshaped = values.reshape([n for n in labels.get(name + "#shape", values.shape)])
        nodes[group][role][short] = xr.Variable(dims, reshaped, attrs)
    for name, (dims, values, attrs) in labels.get("#extra", {}).items():
        group, _, short = name.rpartition("/")
        nodes[group]["coords"][short] = xr.Variable(dims, values, attrs)
    datasets = {"/" + group: xr.Dataset(node["data"], coords=node["coords"], attrs=group_attrs.get(group, {}))
                for group, node in nodes.items()}
    try:
        return xr.DataTree.from_dict(datasets)
    except ValueError as err:
        raise FileError(f"unexpected data in the file ({err})") from None


def _label(raw, root, group_attrs):
    """{dataset path: (dims, "data" or "coords")} of the program's layouts;
    "<path>#shape" where a dataset is reshaped and "#extra" for coordinates
    the file does not hold as datasets."""
    labels = {}
    if root.get("program") == "friction":
        if "afm/support_x" in raw and "afm/support_y" in raw:
            _afm_layout(raw, labels)
        if "brake/t" in raw:
            _brake_layout(raw, labels)
        if "sweep/values" in raw:
            _sweep_layout(raw, root, group_attrs, labels)
        if "surface/atoms" in raw:
            _surface_layout(raw, labels)
        if "machine/t" in raw:
            _machine_layout(raw, labels)
    return labels


def _along(raw, labels, prefix, coord_name, dim, members):
    """The 1-D datasets `members` under prefix run along dim, whose
    coordinate is the dataset coord_name."""
    if coord_name not in raw or raw[coord_name][0].ndim != 1:
        return
    n = raw[coord_name][0].size
    for name, (values, _) in raw.items():
        rest = name[len(prefix):]
        if name.startswith(prefix) and "/" not in rest and members(rest) and values.shape == (n,):
            labels[name] = ((dim,), "data")
    labels[coord_name] = ((dim,), "coords")


def _afm_layout(raw, labels):
    ny, nx = raw["afm/support_y"][0].size, raw["afm/support_x"][0].size
    labels["afm/support_x"] = (("support_x",), "coords")
    labels["afm/support_y"] = (("support_y",), "coords")
    for name, (values, _) in raw.items():
        if name.startswith(("afm/trace/", "afm/retrace/")) and values.shape == (ny, nx):
            labels[name] = (("support_y", "support_x"), "data")
    for name in ("afm/friction", "afm/friction_sem"):
        if name in raw and raw[name][0].shape == (ny,):
            labels[name] = (("support_y",), "data")
    slips = [name for name in raw if name.startswith("afm/slips/") and raw[name][0].ndim == 1]
    if slips and len({raw[name][0].size for name in slips}) == 1:
        labels.update({name: (("slip",), "data") for name in slips})


def _surface_layout(raw, labels):
    values = raw["surface/atoms"][0]
    if values.ndim == 2 and values.shape[1] in (2, 3):
        labels["surface/atoms"] = (("atom", "xyz"), "data")
        labels.setdefault("#extra", {})["surface/xyz"] = (
            ("xyz",), np.array(["x", "y", "z"][:values.shape[1]], dtype=object), {})
        if "surface/species" in raw and raw["surface/species"][0].shape == (values.shape[0],):
            labels["surface/species"] = (("atom",), "data")


def _brake_layout(raw, labels):
    _along(raw, labels, "brake/", "brake/t", "t", lambda rest: True)
    _along(raw, labels, "brake/events/", "brake/events/t", "event", lambda rest: True)
    _along(raw, labels, "brake/spectrum/", "brake/spectrum/frequency", "frequency", lambda rest: True)
    _along(raw, labels, "brake/poincare/", "brake/poincare/strobe_t", "strobe_t",
           lambda rest: rest.startswith("strobe_"))
    _along(raw, labels, "brake/poincare/", "brake/poincare/section_t", "section_t",
           lambda rest: rest.startswith("section_"))
    for curve in ("benettin", "rosenstein"):
        _along(raw, labels, "brake/lyapunov/", f"brake/lyapunov/{curve}_time", f"{curve}_time",
               lambda rest, curve=curve: rest.startswith(f"{curve}_"))
    _along(raw, labels, "brake/orbit/branch/", "brake/orbit/branch/parameter", "parameter", lambda rest: True)
    _along(raw, labels, "brake/orbit/branch/", "brake/orbit/branch/section_parameter", "section_parameter",
           lambda rest: rest.startswith("section_"))
    _exponents_history(raw, labels, "brake/lyapunov/")


def _exponents_history(raw, labels, prefix):
    """The QR spectrum's running estimates along their times (exponents_time, exponent)."""
    history = prefix + "exponents_history"
    if prefix + "exponents_time" in raw and history in raw:
        n = raw[prefix + "exponents_time"][0].size
        if raw[history][0].ndim == 2 and raw[history][0].shape[0] == n:
            labels[prefix + "exponents_time"] = (("exponents_time",), "coords")
            labels[history] = (("exponents_time", "exponent"), "data")


def _machine_layout(raw, labels):
    _along(raw, labels, "machine/", "machine/t", "t", lambda rest: True)
    _along(raw, labels, "machine/events/", "machine/events/t", "event", lambda rest: True)
    _along(raw, labels, "machine/spectrum/", "machine/spectrum/frequency", "frequency", lambda rest: True)
    _along(raw, labels, "machine/lyapunov/", "machine/lyapunov/time", "time", lambda rest: rest == "estimate")
    _along(raw, labels, "machine/poincare/", "machine/poincare/strobe_t", "strobe_t",
           lambda rest: rest.startswith("strobe_"))
    _along(raw, labels, "machine/poincare/", "machine/poincare/section_t", "section_t",
           lambda rest: rest.startswith("section_"))
    _exponents_history(raw, labels, "machine/lyapunov/")
    _along(raw, labels, "machine/orbit/branch/", "machine/orbit/branch/parameter", "parameter", lambda rest: True)
    _along(raw, labels, "machine/orbit/branch/", "machine/orbit/branch/section_parameter", "section_parameter",
           lambda rest: rest.startswith("section_"))


def _sweep_layout(raw, root, group_attrs, labels):
    values, vattrs = raw["sweep/values"]
    n = values.size
    var1 = root.get("sweep_variable") or "values"
    var2 = root.get("sweep_variable2")
    sweep = group_attrs.get("sweep", {})
    shape1, shape2 = int(sweep.get("shape", n)), int(sweep.get("shape2", 1))
    two = bool(var2) and "sweep/values2" in raw and shape1 * shape2 == n and shape2 > 0
    extra = labels.setdefault("#extra", {})
    if var1 == "values":
        return
    if two:
        values2, v2attrs = raw["sweep/values2"]
        dims, shape = (var1, var2), (shape1, shape2)
        extra[f"sweep/{var1}"] = ((var1,), values[::shape2], vattrs)
        extra[f"sweep/{var2}"] = ((var2,), values2[:shape2], v2attrs)
        per_point = {var1: (values, vattrs), var2: (values2, v2attrs)}
    else:
        dims, shape = (var1,), (n,)
        extra[f"sweep/{var1}"] = ((var1,), values, vattrs)
        per_point = {var1: (values, vattrs)}
    for name, (data, _) in raw.items():
        if name.startswith("sweep/") and data.shape == (n,):
            labels[name] = (dims, "data")
            labels[name + "#shape"] = shape
    if "sweep/maxima" in raw and "sweep/maxima_count" in raw:
        counts = np.asarray(raw["sweep/maxima_count"][0]).astype(int).ravel()
        maxima = raw["sweep/maxima"][0]
        if counts.size == n and counts.sum() == maxima.size and (counts >= 0).all():
            labels["sweep/maxima"] = (("maximum",), "data")
            for key, (point_values, attrs) in per_point.items():
                extra[f"sweep/maximum_{key}"] = (("maximum",), np.repeat(point_values, counts), attrs)
    if "sweep/peak_memory_per_rank" in raw and raw["sweep/peak_memory_per_rank"][0].ndim == 1:
        labels["sweep/peak_memory_per_rank"] = (("rank",), "data")


@contextlib.contextmanager
def open_output(path: str | os.PathLike[str], scene: str, what: str) -> Iterator[h5py.File]:
    """Open a friction output file of the given scene with h5py, for reading.

    path: a file name; scene: 'afm', 'brake' or 'sweep', also the group that
    must exist; what: how to call the file in messages ('force-map', 'brake').
    Missing datasets (KeyError), unreadable files (OSError) and unexpected
    data (TypeError, ValueError) inside the block become FileError.

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    scene : str
        'afm', 'brake' or 'sweep', also the group that must exist.
    what : str
        How to call the file in messages.

    Yields
    ------
    h5py.File
        The open file.

    Raises
    ------
    FileError
        A file that is not of the scene, or fails inside the block.
    """
    path = _check_path(path)
    try:
        with h5py.File(path, "r") as f:
            if (text(f.attrs.get("program", b"")) != "friction"
                    or text(f.attrs.get("scene", b"")) != scene or scene not in f):
                raise FileError(f"not a friction {what} file "
                                f"(needs program = 'friction', scene = '{scene}', group /{scene})")
            yield f
    except FileError:
        raise
    except KeyError as err:
        raise FileError(f"incomplete friction {what} file ({err})") from None
    except OSError as err:
        raise FileError(f"cannot read as HDF5 ({err})") from None
    except (TypeError, ValueError) as err:
        raise FileError(f"unexpected data in the file ({err})") from None


WHAT = {"afm": "force-map", "brake": "brake", "sweep": "sweep"}


def require(data, scene, what=None):
    """`data` (a loaded file or a file name) loaded, and a friction file of `scene`;
    FileError otherwise, as open_output words it."""
    what = what or WHAT.get(scene, scene)
    data = load(data)
    if (data.attrs.get("program") != "friction" or data.attrs.get("scene") != scene
            or scene not in data.children):
        raise FileError(f"not a friction {what} file "
                        f"(needs program = 'friction', scene = '{scene}', group /{scene})")
    return data


@contextlib.contextmanager
def reading(what):
    """Missing datasets or attributes and unexpected data inside the block become FileError."""
    try:
        yield
    except FileError:
        raise
    except KeyError as err:
        raise FileError(f"incomplete friction {what} file ({err.args[0] if err.args else err})") from None
    except (TypeError, ValueError, IndexError) as err:
        raise FileError(f"unexpected data in the file ({err})") from None

