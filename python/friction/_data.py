"""Reading the program's HDF5 files as labelled arrays with units.

    data = friction.load("naf.h5")
    fx = data["afm/trace/fx"]          # an Array: values (ny, nx), dims ("support_y", "support_x")
    fx.units                           # 'nN'
    fx.coords["support_x"].units       # 'angstrom'
    fx.sel(support_y=2.0)              # the line nearest 2 Å across the scan, an Array over support_x
    data.attrs["wall_time"], data.attrs.units["wall_time"]     # 0.047, 's'
    data.group_attrs["afm"]["angle"], data.group_attrs["afm"].units["angle"]
    data.to_xarray()                   # an xarray.Dataset, when xarray is installed

The package's own small labelled-array type rather than xarray (docs/python.md,
"Why not xarray"): load() gives the same objects whatever is installed, with
no dependency beyond numpy and h5py, and to_xarray() hands them to xarray for
those who use it.
"""
import contextlib
from collections.abc import Mapping
from pathlib import Path

import h5py
import numpy as np

__all__ = ["Array", "Attributes", "Dataset", "FileError", "load", "open_output", "text"]


class FileError(ValueError):
    """A file that cannot be read as asked: missing, not HDF5, not a friction
    file of the expected scene, or without the datasets asked for.  The
    message says which (the scripts print it after the file's name)."""


def text(value):
    """HDF5 string attributes come back as (arrays of) bytes; give str."""
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


class Attributes(dict):
    """The attributes of a group: {name: value}, with the units of those that
    have one in .units ({name: unit}, from the file's NAME_units attributes,
    which are not repeated among the values)."""

    def __init__(self, raw=None):
        super().__init__()
        self.units = {}
        raw = dict(raw or {})
        for name, value in raw.items():
            if name.endswith("_units") and name[:-len("_units")] in raw:
                self.units[name[:-len("_units")]] = text(value)
            else:
                self[name] = _python(value)

    def flat(self):
        """The attributes as the file has them: NAME_units beside NAME."""
        out = dict(self)
        out.update({f"{name}_units": unit for name, unit in self.units.items()})
        return out


class Array:
    """A numpy array with named dimensions, coordinates and units.

    values  the numpy array
    dims    a name per dimension ("support_y", "support_x"; "t"; a swept variable)
    coords  {name: Array}: the coordinate of a dimension has the dimension's
            name; others ("brake.mu" of a sweep's maxima) name the dimension
            they run along in their own dims
    units   the dataset's `units` attribute ('nN', 'angstrom', 'm per unit tau'), or None
    name    the dataset's path in the file ("afm/trace/fx")
    attrs   the dataset's other attributes

    numpy functions take it as an array (np.mean(a), np.asarray(a)); a[...]
    indexes the values.  isel() and sel() keep the labels."""

    def __init__(self, values, dims, coords=None, units=None, name=None, attrs=None):
        self.values = np.asarray(values)
        self.dims = tuple(dims)
        if len(self.dims) != self.values.ndim:
            raise ValueError(f"{name}: {len(self.dims)} dimension names for an array of {self.values.ndim}")
        self.coords = dict(coords or {})
        for key, coord in self.coords.items():
            for dim, size in zip(coord.dims, coord.shape):
                if dim in self.dims and self.values.shape[self.dims.index(dim)] != size:
                    raise ValueError(f"{name}: coordinate {key} has {size} values along {dim}, the array "
                                     f"{self.values.shape[self.dims.index(dim)]}")
        self.units = units
        self.name = name
        self.attrs = dict(attrs or {})

    # ---- as an array ----
    def __array__(self, dtype=None, copy=None):
        if dtype is None:
            return self.values
        return self.values.astype(dtype)

    @property
    def shape(self):
        return self.values.shape

    @property
    def ndim(self):
        return self.values.ndim

    @property
    def size(self):
        return self.values.size

    @property
    def dtype(self):
        return self.values.dtype

    def __len__(self):
        return len(self.values)

    def __getitem__(self, key):
        return self.values[key]

    def __iter__(self):
        return iter(self.values)

    @property
    def label(self):
        """"name (units)" for an axis: the last part of the name."""
        short = (self.name or "").rsplit("/", 1)[-1]
        return f"{short} ({self.units})" if self.units else short

    def coord(self, dim):
        """The coordinate of dimension `dim` (an Array), or its indices when it has none."""
        if dim not in self.dims:
            raise KeyError(f"{self.name}: no dimension {dim!r} (dimensions: {', '.join(self.dims)})")
        if dim in self.coords:
            return self.coords[dim]
        return Array(np.arange(self.shape[self.dims.index(dim)]), (dim,), name=dim)

    # ---- selection ----
    def isel(self, indexers=None, **more):
        """By position: isel(support_y=3), isel(t=slice(0, 100)); an integer
        drops its dimension.  indexers: a dict, for names that are not Python
        identifiers ({"brake.mu": 2})."""
        indexers = dict(indexers or {}, **more)
        for dim in indexers:
            if dim not in self.dims:
                raise KeyError(f"{self.name}: no dimension {dim!r} (dimensions: {', '.join(self.dims)})")
        key = tuple(indexers.get(dim, slice(None)) for dim in self.dims)
        dims = tuple(dim for dim, k in zip(self.dims, key) if not isinstance(k, (int, np.integer)))
        coords = {}
        for cname, coord in self.coords.items():
            ckey = tuple(indexers.get(dim, slice(None)) for dim in coord.dims)
            if any(isinstance(k, (int, np.integer)) for k in ckey):
                continue
            coords[cname] = Array(coord.values[ckey], coord.dims, units=coord.units, name=coord.name,
                                  attrs=coord.attrs)
        return Array(self.values[key], dims, coords, self.units, self.name, self.attrs)

    def sel(self, indexers=None, **more):
        """By coordinate value, the nearest: sel(support_y=2.0), sel(t=150.0);
        a pair (low, high) selects the range low <= c <= high."""
        indexers = dict(indexers or {}, **more)
        positions = {}
        for dim, value in indexers.items():
            c = np.asarray(self.coord(dim).values, dtype=float)
            if isinstance(value, tuple) and len(value) == 2:
                inside = np.flatnonzero((c >= value[0]) & (c <= value[1]))
                if inside.size == 0:
                    raise KeyError(f"{self.name}: no {dim} in [{value[0]}, {value[1]}]")
                positions[dim] = slice(int(inside[0]), int(inside[-1]) + 1)
            else:
                positions[dim] = int(np.nanargmin(np.abs(c - float(value))))
        return self.isel(positions)

    # ---- other forms ----
    def to_xarray(self):
        """An xarray.DataArray (needs xarray)."""
        xr = _xarray()
        return xr.DataArray(self.values, dims=self.dims, coords=_xarray_coords(self.coords, self.dims),
                            name=self.name, attrs=_variable_attrs(self))

    def __repr__(self):
        dims = ", ".join(f"{d}: {n}" for d, n in zip(self.dims, self.shape))
        lines = [f"<friction.Array {self.name or ''} ({dims}) {self.dtype}"
                 + (f" [{self.units}]" if self.units else "") + ">"]
        for cname, coord in self.coords.items():
            values = coord.values
            span = f"{values.min():g} .. {values.max():g}" if values.size and values.dtype.kind in "fiu" else ""
            lines.append(f"  {cname} ({', '.join(coord.dims)}): {span}" + (f" [{coord.units}]" if coord.units else ""))
        return "\n".join(lines)


def _xarray():
    try:
        import xarray
    except ImportError:
        raise ImportError("to_xarray() needs xarray: python3 -m pip install xarray "
                          "(friction.load itself does not)") from None
    return xarray


def _variable_attrs(array):
    attrs = {k: v for k, v in array.attrs.items() if not isinstance(v, np.ndarray) or v.dtype != object}
    if array.units is not None:
        attrs["units"] = array.units
    return attrs


def _xarray_name(name, coord, all_dims):
    """A coordinate that runs along another dimension than the one it is named
    after (a sweep's maxima: "brake.v_dr_prime" along "maximum") is renamed
    "<its dimension>_<name>" ("maximum_brake.v_dr_prime"): in xarray a name is
    either a dimension's coordinate or not."""
    if name in all_dims and coord.dims != (name,):
        return f"{coord.dims[0]}_{name}"
    return name


def _xarray_coords(coords, dims, all_dims=None):
    all_dims = set(dims) | set(all_dims or ())
    return {_xarray_name(name, coord, all_dims): (coord.dims, coord.values, _variable_attrs(coord))
            for name, coord in coords.items() if set(coord.dims) <= set(dims)}


class Dataset(Mapping):
    """The contents of one HDF5 file, read whole (the file is closed again).

    data["afm/trace/fx"]   an Array by the dataset's path
    list(data)             the paths of every dataset
    data.attrs             the root's Attributes (program, version, scene, input, ...)
    data.group_attrs       {group path: Attributes} of every group ("afm", "brake/spectrum")
    data.scene, data.version, data.path
    data.to_xarray()       an xarray.Dataset (needs xarray)
    """

    def __init__(self, path, arrays, attrs, group_attrs):
        self.path = Path(path)
        self._arrays = dict(arrays)
        self.attrs = attrs
        self.group_attrs = group_attrs

    def __getitem__(self, name):
        try:
            return self._arrays[name.strip("/")]
        except KeyError:
            raise KeyError(f"{name} (not in {self.path.name})") from None

    def __iter__(self):
        return iter(self._arrays)

    def __len__(self):
        return len(self._arrays)

    @property
    def scene(self):
        """'afm', 'brake' or 'sweep' for the program's files, else None."""
        return self.attrs.get("scene")

    @property
    def version(self):
        """The version of the program that wrote the file."""
        return self.attrs.get("version")

    @property
    def is_friction(self):
        """True for a file the program wrote."""
        return self.attrs.get("program") == "friction"

    def to_xarray(self):
        """Every dataset as a variable of one xarray.Dataset (named by its path),
        with its dimensions, coordinates and units; the root's attributes as the
        dataset's, a group's as "group/name" (NAME_units beside NAME, as in the
        file).  A sweep's maxima have their swept values as the coordinate
        "maximum_<variable>"."""
        xr = _xarray()
        variables, coords = {}, {}
        all_dims = {dim for array in self._arrays.values() for dim in array.dims}
        for name, array in self._arrays.items():
            variables[name] = (array.dims, array.values, _variable_attrs(array))
            coords.update(_xarray_coords(array.coords, array.dims, all_dims))
        for name in coords:
            variables.pop(name, None)
        attrs = self.attrs.flat()
        for group, group_attrs in self.group_attrs.items():
            attrs.update({f"{group}/{k}": v for k, v in group_attrs.flat().items()})
        return xr.Dataset(variables, coords=coords, attrs=attrs)

    def __repr__(self):
        lines = [f"<friction.Dataset {self.path.name}: " + (
            f"friction {self.version}, scene {self.scene}" if self.is_friction else "an HDF5 file") + ">"]
        for name, array in self._arrays.items():
            dims = ", ".join(f"{d}: {n}" for d, n in zip(array.dims, array.shape))
            lines.append(f"  {name} ({dims})" + (f" [{array.units}]" if array.units else ""))
        return "\n".join(lines)


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


def load(path, scene=None):
    """Read a friction output file (any HDF5 file) into a Dataset of labelled arrays.

    The program's layouts get their dimensions and coordinates:
      afm     maps (ny, nx) over ("support_y", "support_x"), the line offset
              across the scan and the support position along it (angstrom);
              /afm/friction over support_y; /surface/atoms over ("atom", "xyz")
      brake   the trajectory over "t"; the events over "event" (their times);
              the spectrum over "frequency"; the Poincare points over "strobe"
              and "section" (their times); the Lyapunov curves over
              "benettin_time" and "rosenstein_time"
      sweep   per point over the swept variable ("brake.v_dr_prime"), or over
              both variables (a grid, the second varying fastest); the brake's
              maxima over "maximum", with the swept values of their point as
              coordinates
    Datasets of other files, or of unknown shape, get dims "<path>_dim_<k>".
    Units come from each dataset's `units` attribute; attributes' units
    (NAME_units) go into Attributes.units.

    scene: 'afm', 'brake' or 'sweep' to require a file the program wrote for
    that scene.  Raises FileError for a missing file, one that is not HDF5,
    or not of the scene asked for."""
    if scene is not None:
        return require(path, scene)
    if isinstance(path, Dataset):
        return path
    path = _check_path(path)
    raw, group_attrs = {}, {}
    try:
        with h5py.File(path, "r") as f:
            root = Attributes(f.attrs)

            def visit(name, item):
                if isinstance(item, h5py.Dataset):
                    raw[name] = (_read_values(item), dict(item.attrs))
                else:
                    group_attrs[name] = Attributes(item.attrs)
            f.visititems(visit)
    except OSError as err:
        raise FileError(f"cannot read as HDF5 ({err})") from None
    except (RuntimeError, KeyError, ValueError, TypeError) as err:
        # A damaged file opens and then fails inside: h5py's own errors
        # (RuntimeError, KeyError, ValueError) said nothing of the file.
        raise FileError(f"the HDF5 file is damaged ({type(err).__name__}: {err})") from None
    arrays = _label(raw, root, group_attrs)
    return Dataset(path, arrays, root, group_attrs)


def _plain(name, values, attrs, dims=None, coords=None):
    attrs = {k: _python(v) for k, v in attrs.items()}
    units = attrs.pop("units", None)
    if dims is None:
        dims = tuple(f"{name}_dim_{k}" for k in range(values.ndim))
    return Array(values, dims, coords, units, name, attrs)


def _label(raw, root, group_attrs):
    """Arrays with the dimensions and coordinates of the program's layouts."""
    arrays = {}
    layouts = []
    if root.get("program") == "friction":
        if "afm/support_x" in raw:
            layouts.append(_afm_layout)
        if "brake/t" in raw:
            layouts.append(_brake_layout)
        if "sweep/values" in raw:
            layouts.append(_sweep_layout)
        if "surface/atoms" in raw:
            layouts.append(_surface_layout)
    for layout in layouts:
        arrays.update(layout(raw, root, group_attrs))
    for name, (values, attrs) in raw.items():
        if name not in arrays:
            arrays[name] = _plain(name, values, attrs)
    return arrays


def _coordinate(raw, name, dim):
    values, attrs = raw[name]
    return _plain(name, values, attrs, dims=(dim,))


def _along(raw, arrays, prefix, coord_name, dim, members):
    """Label the 1-D datasets `members` under prefix with the coordinate `coord_name`."""
    if coord_name not in raw or raw[coord_name][0].ndim != 1:
        return
    coord = _coordinate(raw, coord_name, dim)
    n = coord.size
    for name, (values, attrs) in raw.items():
        if name.startswith(prefix) and members(name[len(prefix):]) and values.shape == (n,):
            arrays[name] = _plain(name, values, attrs, (dim,), {dim: coord})


def _afm_layout(raw, root, group_attrs):
    arrays = {}
    x = _coordinate(raw, "afm/support_x", "support_x")
    y = _coordinate(raw, "afm/support_y", "support_y")
    arrays["afm/support_x"] = Array(x.values, x.dims, {"support_x": x}, x.units, x.name, x.attrs)
    arrays["afm/support_y"] = Array(y.values, y.dims, {"support_y": y}, y.units, y.name, y.attrs)
    for name, (values, attrs) in raw.items():
        if name.startswith(("afm/trace/", "afm/retrace/")) and values.shape == (y.size, x.size):
            arrays[name] = _plain(name, values, attrs, ("support_y", "support_x"),
                                  {"support_y": y, "support_x": x})
    if "afm/friction" in raw and raw["afm/friction"][0].shape == (y.size,):
        values, attrs = raw["afm/friction"]
        arrays["afm/friction"] = _plain("afm/friction", values, attrs, ("support_y",), {"support_y": y})
    return arrays


def _surface_layout(raw, root, group_attrs):
    arrays = {}
    values, attrs = raw["surface/atoms"]
    if values.ndim == 2 and values.shape[1] in (2, 3):
        xyz = Array(np.array(["x", "y", "z"][:values.shape[1]], dtype=object), ("xyz",), name="xyz")
        arrays["surface/atoms"] = _plain("surface/atoms", values, attrs, ("atom", "xyz"), {"xyz": xyz})
        if "surface/species" in raw and raw["surface/species"][0].shape == (values.shape[0],):
            species, sattrs = raw["surface/species"]
            arrays["surface/species"] = _plain("surface/species", species, sattrs, ("atom",))
    return arrays


def _brake_layout(raw, root, group_attrs):
    arrays = {}
    _along(raw, arrays, "brake/", "brake/t", "t", lambda rest: "/" not in rest)
    _along(raw, arrays, "brake/events/", "brake/events/t", "event", lambda rest: True)
    _along(raw, arrays, "brake/spectrum/", "brake/spectrum/frequency", "frequency", lambda rest: True)
    _along(raw, arrays, "brake/poincare/", "brake/poincare/strobe_t", "strobe",
           lambda rest: rest.startswith("strobe_"))
    _along(raw, arrays, "brake/poincare/", "brake/poincare/section_t", "section",
           lambda rest: rest.startswith("section_"))
    _along(raw, arrays, "brake/lyapunov/", "brake/lyapunov/benettin_time", "benettin_time",
           lambda rest: rest.startswith("benettin_"))
    _along(raw, arrays, "brake/lyapunov/", "brake/lyapunov/rosenstein_time", "rosenstein_time",
           lambda rest: rest.startswith("rosenstein_"))
    return arrays


def _sweep_layout(raw, root, group_attrs):
    arrays = {}
    values, vattrs = raw["sweep/values"]
    n = values.size
    var1 = root.get("sweep_variable") or "values"
    var2 = root.get("sweep_variable2")
    sweep = group_attrs.get("sweep", {})
    shape1, shape2 = int(sweep.get("shape", n)), int(sweep.get("shape2", 1))
    two = bool(var2) and "sweep/values2" in raw and shape1 * shape2 == n and shape2 > 0
    if two:
        values2, v2attrs = raw["sweep/values2"]
        c1 = _plain("sweep/values", values[::shape2], vattrs, (var1,))
        c2 = _plain("sweep/values2", values2[:shape2], v2attrs, (var2,))
        dims, coords, shape = (var1, var2), {var1: c1, var2: c2}, (shape1, shape2)
        # every point's values, for the maxima
        point_coords = {var1: _plain("sweep/values", values, vattrs, ("point",)),
                        var2: _plain("sweep/values2", values2, v2attrs, ("point",))}
    else:
        c1 = _plain("sweep/values", values, vattrs, (var1,))
        dims, coords, shape = (var1,), {var1: c1}, (n,)
        point_coords = {var1: _plain("sweep/values", values, vattrs, ("point",))}
    for name, (data, attrs) in raw.items():
        if name.startswith("sweep/") and data.shape == (n,):
            arrays[name] = _plain(name, data.reshape(shape), attrs, dims, coords)
    if "sweep/maxima" in raw and "sweep/maxima_count" in raw:
        counts = np.asarray(raw["sweep/maxima_count"][0]).astype(int).ravel()
        maxima, mattrs = raw["sweep/maxima"]
        if counts.size == n and counts.sum() == maxima.size and (counts >= 0).all():
            mcoords = {key: Array(np.repeat(c.values, counts), ("maximum",), units=c.units, name=c.name,
                                  attrs=c.attrs) for key, c in point_coords.items()}
            arrays["sweep/maxima"] = _plain("sweep/maxima", maxima, mattrs, ("maximum",), mcoords)
    if "sweep/peak_memory_per_rank" in raw:
        data, attrs = raw["sweep/peak_memory_per_rank"]
        if data.ndim == 1:
            arrays["sweep/peak_memory_per_rank"] = _plain("sweep/peak_memory_per_rank", data, attrs, ("rank",))
    return arrays


@contextlib.contextmanager
def open_output(path, scene, what):
    """Open a friction output file of the given scene with h5py, for reading.

    path: a file name; scene: 'afm', 'brake' or 'sweep', also the group that
    must exist; what: how to call the file in messages ('force-map', 'brake').
    Missing datasets (KeyError), unreadable files (OSError) and unexpected
    data (TypeError, ValueError) inside the block become FileError.
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
    """`data` (a Dataset or a file name) loaded, and a friction file of `scene`;
    FileError otherwise, as open_output words it."""
    what = what or WHAT.get(scene, scene)
    data = load(data)
    if not data.is_friction or data.scene != scene or scene not in data.group_attrs:
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

