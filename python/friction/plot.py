"""The project's pictures as functions: each takes a file's data (the
xarray.DataTree of friction.load, or a file name) and returns a matplotlib Figure.

    data = friction.load("naf.h5")
    fig = friction.plot.afm_maps(data)          # Fx and Fy maps (the paper's Fig. 7b/8b)
    fig.savefig("naf_maps.png", dpi=150)

AFM maps:     afm_maps, friction_loop
lattice sums: graphite_net (Fig. 9a), stacked_lines (Fig. 9b)
brake:        brake_phase (Fig. 12), brake_x, brake_spectrum (Fig. 13),
              poincare (Fig. 14), lyapunov, floquet, orbit_branch
sweeps:       sweep (every chart of a sweep file), bifurcation, sweep_lyapunov,
              sweep_friction, sweep_machine
speed:        work_precision, failure_map (files of scripts/work_precision)
thermal:      friction_velocity (rows of scripts/thermal_velocity.py), sang_fit,
              friction_temperature (rows of scripts/thermal_temperature.py), temperature_fit
fits:         fit_maps (friction.fit.image's maps), fit_corner (an MCMC sample),
              friction_load (measured images against their setpoint)

The figures are matplotlib.figure.Figure objects outside pyplot: nothing is
shown or kept open behind the caller's back, and no display is needed.  In a
notebook a figure shows as a cell's value.  A file that is not what a
function draws raises friction.FileError, as the scripts report it.
"""
from __future__ import annotations

import io
import math
import os
import warnings
from typing import TYPE_CHECKING, Any, Mapping, Sequence, Union

import numpy as np
from matplotlib import colormaps
from matplotlib.cm import ScalarMappable
from matplotlib.collections import LineCollection
from matplotlib.colors import ListedColormap, Normalize
from matplotlib.figure import Figure as _Figure
from matplotlib.patches import Polygon, Rectangle

from ._data import FileError, groups, load, paths, reading, require

if TYPE_CHECKING:
    import xarray as xr
    from numpy.typing import ArrayLike

    from ._image import MeasuredImage
    from .fit import ImageFit

#: What the plots take: a loaded file (friction.load) or a file's path.
DataLike = Union["xr.DataTree", str, "os.PathLike[str]"]

__all__ = ["afm_maps", "friction_loop", "graphite_net", "stacked_lines", "brake_phase", "brake_x",
           "brake_spectrum", "poincare", "lyapunov", "floquet", "orbit_branch", "sweep", "bifurcation",
           "sweep_lyapunov", "atlas", "sweep_friction", "sweep_machine", "work_precision", "failure_map", "friction_velocity",
           "sang_fit", "friction_temperature", "temperature_fit", "fit_maps", "fit_corner", "friction_load",
           "Figure"]


class Figure(_Figure):
    """A matplotlib Figure that shows itself as a PNG in a notebook."""

    def _repr_png_(self):
        buffer = io.BytesIO()
        self.savefig(buffer, format="png")
        return buffer.getvalue()


def _figure(**kwargs):
    return Figure(**kwargs)


POTENTIAL_LABELS = {"naf": "NaF(001)", "hopg": "HOPG", "lj": "Lennard-Jones lattice sum"}


def _describe_scan(potential, angle):
    name = POTENTIAL_LABELS.get(potential, potential)
    return f"{name}, scan angle {angle:g}°"


# --------------------------------------------------------------------------
# AFM maps
# --------------------------------------------------------------------------


def _scan(data):
    """The map, its axes and the line friction of an AFM file, checked."""
    data = require(data, "afm", "force-map")
    with reading("force-map"):
        afm = groups(data)["afm"]
        scan = {"potential": str(afm["potential"]), "angle": float(afm["angle"]),
                "x": data["afm/support_x"].values, "y": data["afm/support_y"].values,
                "friction": data["afm/friction"].values if "afm/friction" in paths(data) else None}
        for trip in ("trace", "retrace"):
            if f"afm/{trip}/fx" in paths(data):
                scan[trip] = {q: data[f"afm/{trip}/{q}"].values for q in ("fx", "fy", "f_along")}
    if "trace" not in scan:
        raise FileError("no /afm/trace group")
    shape = (scan["y"].size, scan["x"].size)
    for trip in ("trace", "retrace"):
        for name, values in scan.get(trip, {}).items():
            if values.shape != shape:
                raise FileError(f"/afm/{trip}/{name} has shape {values.shape}, expected (ny, nx) = {shape}")
    return scan


def _pixel_extent(x, y):
    """imshow extent with pixel centres on the support positions (Å)."""
    dx = (x[-1] - x[0]) / (x.size - 1) if x.size > 1 else 1.0
    dy = (y[-1] - y[0]) / (y.size - 1) if y.size > 1 else dx
    return [x[0] - dx / 2, x[-1] + dx / 2, y[0] - dy / 2, y[-1] + dy / 2]


def afm_maps(data: DataLike, trip: str = "trace", cmap: str = "RdBu_r") -> Figure:
    """Fx and Fy maps side by side over the scanned area (the paper's Fig. 7b/8b):
    the support position along the scan against the line offset across it
    (Å); colour scale symmetric about 0 nN.  trip: 'trace' or 'retrace'.

    Parameters
    ----------
    data : xarray.DataTree or str or os.PathLike
        The file's data (friction.load) or its path.
    trip : str
        'trace' or 'retrace'.
    cmap : str
        A matplotlib colour map.

    Returns
    -------
    Figure
        The figure (matplotlib, outside pyplot).

    Raises
    ------
    friction.FileError
        A file that is not of the kind drawn, or lacks what the picture needs.
    ValueError
        An unknown trip.

    Examples
    --------
    >>> fig = friction.plot.afm_maps(friction.load("naf.h5"))  # doctest: +SKIP
    """
    scan = _scan(data)
    if trip not in scan:
        raise FileError(f"no /afm/{trip}: the run had retrace off")
    extent = _pixel_extent(scan["x"], scan["y"])
    fig = _figure(figsize=(11, 4.8), layout="constrained")
    axes = fig.subplots(1, 2)
    for ax, key, label in zip(axes, ("fx", "fy"), ("$F_x$", "$F_y$")):
        values = scan[trip][key]
        finite = np.abs(values[np.isfinite(values)])
        limit = float(finite.max()) if finite.size and finite.max() > 0 else 1.0
        image = ax.imshow(values, origin="lower", extent=extent, aspect="equal",
                          interpolation="nearest", cmap=cmap, vmin=-limit, vmax=limit)
        ax.set_title(f"{label} (lattice {key[1]} axis)")
        ax.set_xlabel("support position along the scan (Å)")
        ax.set_ylabel("line offset across the scan (Å)")
        fig.colorbar(image, ax=ax, shrink=0.9, label=f"{label} (nN)")
    fig.suptitle(f"Lateral force maps, {trip}: {_describe_scan(scan['potential'], scan['angle'])}")
    return fig


def friction_loop(data: DataLike, line: int | None = None) -> Figure:
    """Trace and retrace f_along of one line against the support position:
    the friction loop, with the line's friction (/afm/friction) in the title.
    line: 0 .. ny-1 (default: the middle line, ny // 2).

    Parameters
    ----------
    data : xarray.DataTree or str or os.PathLike
        The file's data (friction.load) or its path.
    line : int, optional
        The line, 0 .. ny - 1; default the middle line, ny // 2.

    Returns
    -------
    Figure
        The figure (matplotlib, outside pyplot).

    Raises
    ------
    friction.FileError
        A file that is not of the kind drawn, or lacks what the picture needs.
    ValueError
        A line out of range.
    """
    scan = _scan(data)
    if "retrace" not in scan or scan["friction"] is None:
        raise FileError("no /afm/retrace: the run had retrace off (no friction loop)")
    ny = scan["y"].size
    line = ny // 2 if line is None else int(line)
    if not 0 <= line < ny:
        raise ValueError(f"line {line} out of range: the file has lines 0 .. {ny - 1}")
    x = scan["x"]
    trace = scan["trace"]["f_along"][line]
    retrace = scan["retrace"]["f_along"][line]
    friction = scan["friction"][line]
    fig = _figure(figsize=(8, 4.8), layout="constrained")
    ax = fig.subplots()
    ax.fill_between(x, retrace, trace, color="0.88", label="loop")
    ax.plot(x, trace, "-", color="tab:red", label="trace (→)")
    ax.plot(x, retrace, "-", color="tab:blue", label="retrace (←)")
    ax.axhline(0.0, color="0.5", linewidth=0.6)
    ax.set_xlabel("support position along the scan (Å)")
    ax.set_ylabel("$F_\\parallel$, force along the scan (nN)")
    ax.set_xlim(x[0], x[-1])
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small")
    ax.set_title(f"Friction loop, line {line} (offset {scan['y'][line]:.3g} Å), "
                 f"{_describe_scan(scan['potential'], scan['angle'])}\nfriction = {friction:.4g} nN")
    return fig


# --------------------------------------------------------------------------
# Lattice sums (graphite): the net and stacked lines
# --------------------------------------------------------------------------

COMPONENTS = {
    "fx": ("$F_x$", "force along the lattice x axis"),
    "fy": ("$F_y$", "force along the lattice y axis"),
    "fz": ("$F_z$", "vertical force"),
    "f_along": ("$F_\\parallel$", "force along the scan"),
    "f_across": ("$F_\\perp$", "force across the scan"),
}
BOND_FACTOR = 1.2  # bonds: pairs closer than this x the nearest-neighbour distance
NN_SAMPLE = 400  # atoms whose nearest neighbour sets the nearest-neighbour distance


def _lattice(data):
    """The scan, the tip path and the net of a lattice-sum file, checked."""
    data = require(data, "afm", "force-map")
    if "surface/atoms" not in paths(data):
        raise FileError("not a lattice-sum scene: no /surface/atoms (for NaF/HOPG maps use plot_afm.py)")
    with reading("force-map"):
        afm = groups(data)["afm"]
        surface = groups(data).get("surface", {})
        lattice = {
            "potential": str(afm.get("potential", "?")),
            "angle": float(afm["angle"]),
            "origin": np.array([float(afm["origin_x"]), float(afm["origin_y"])]),
            "x": np.asarray(data["afm/support_x"].values, dtype=float),
            "y": np.asarray(data["afm/support_y"].values, dtype=float),
            "atoms": np.asarray(data["surface/atoms"].values, dtype=float),
            "species": (np.asarray(data["surface/species"].values, dtype=int)
                        if "surface/species" in paths(data) else None),
            "species_names": [s.strip() for s in str(surface.get("species_names", "")).split(",")],
            "cutoff": float(surface["cutoff"]) if "cutoff" in surface else None,
            "trips": {},
        }
        for trip in ("trace", "retrace"):
            quantities = {q: np.asarray(data[f"afm/{trip}/{q}"].values, dtype=float)
                          for q in (*COMPONENTS, "tip_x", "tip_y") if f"afm/{trip}/{q}" in paths(data)}
            if quantities:
                lattice["trips"][trip] = quantities

    atoms = lattice["atoms"]
    if atoms.ndim != 2 or atoms.shape[1] not in (2, 3) or atoms.shape[0] < 1:
        raise FileError(f"/surface/atoms has shape {atoms.shape}, expected (natoms, 3)")
    if not np.all(np.isfinite(atoms)):
        raise FileError("/surface/atoms holds non-finite positions")
    names = [n for n in lattice["species_names"] if n] or ["atom"]
    lattice["species_names"] = names
    species = lattice["species"]
    if species is None:
        lattice["species"] = np.ones(atoms.shape[0], dtype=int)
    elif species.shape != (atoms.shape[0],):
        raise FileError(f"/surface/species has shape {species.shape}, expected (natoms,) = ({atoms.shape[0]},)")
    elif species.size and (species.min() < 1 or species.max() > len(names)):
        raise FileError(f"/surface/species holds indices {species.min()} .. {species.max()}, "
                        f"but species_names lists {len(names)}")
    if lattice["x"].ndim != 1 or lattice["y"].ndim != 1 or lattice["x"].size < 1 or lattice["y"].size < 1:
        raise FileError("/afm/support_x and /afm/support_y must be nonempty 1-D arrays")
    if "trace" not in lattice["trips"]:
        raise FileError("no /afm/trace group")
    shape = (lattice["y"].size, lattice["x"].size)
    for trip, values in lattice["trips"].items():
        for name, array in values.items():
            if array.shape != shape:
                raise FileError(f"/afm/{trip}/{name} has shape {array.shape}, expected (ny, nx) = {shape}")
    return lattice


def scan_axes(angle_deg):
    """Unit vectors along (u) and across (n) the scan in the lattice frame."""
    t = np.radians(angle_deg)
    return np.array([np.cos(t), np.sin(t)]), np.array([-np.sin(t), np.cos(t)])


def scan_region(lattice):
    """Corners of the area covered by the support: origin, +L u, +L u + W n, +W n."""
    u, n = scan_axes(lattice["angle"])
    x0, x1 = lattice["x"].min(), lattice["x"].max()
    y0, y1 = lattice["y"].min(), lattice["y"].max()
    o = lattice["origin"]
    return np.array([o + x0 * u + y0 * n, o + x1 * u + y0 * n, o + x1 * u + y1 * n, o + x0 * u + y1 * n])


def nearest_neighbour_distance(xyz):
    """Typical nearest-neighbour distance: the median over (a sample of) the atoms.

    A median rather than the minimum, so one misplaced atom does not shrink
    the bonds of the whole net.  None for a single atom or coincident atoms.
    """
    count = xyz.shape[0]
    if count < 2:
        return None
    sample = xyz[np.unique(np.linspace(0, count - 1, min(count, NN_SAMPLE)).astype(int))]
    nearest = np.empty(sample.shape[0])
    for k, p in enumerate(sample):
        d2 = np.sum((xyz - p) ** 2, axis=1)
        d2 = d2[d2 > 1e-12]  # itself (and exact duplicates)
        nearest[k] = np.sqrt(d2.min()) if d2.size else np.inf
    d = float(np.median(nearest))
    return d if np.isfinite(d) and d > 0 else None


def bonds(xyz, cutoff):
    """Index pairs (i, j), i < j, of atoms closer than cutoff (scipy's k-d tree), in lexical order."""
    count = xyz.shape[0]
    if count < 2 or not cutoff or cutoff <= 0:
        return np.empty((0, 2), dtype=int)
    from scipy.spatial import cKDTree
    # query_pairs keeps distances <= r: the next float below cutoff keeps the strict "closer than".
    pairs = cKDTree(np.asarray(xyz, float)).query_pairs(np.nextafter(cutoff, 0.0), output_type="ndarray")
    if pairs.size == 0:
        return np.empty((0, 2), dtype=int)
    pairs = np.sort(pairs.astype(int), axis=1)
    return pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))]


def graphite_net(data: DataLike, margin: float = 5.0, whole: bool = False, tip_line: int | None = 0) -> Figure:
    """The crystal net of a lattice-sum map (the paper's Fig. 9a): atoms by
    species, bonds (pairs closer than 1.2 x the nearest-neighbour distance),
    the scan region and the tip's path on trace line `tip_line` (None: no
    path); zoomed to the scan region plus `margin` Å, or the whole net.

    Parameters
    ----------
    data : xarray.DataTree or str or os.PathLike
        The file's data (friction.load) or its path.
    margin : float
        Angstrom around the scan region shown.
    whole : bool
        Show the whole net instead.
    tip_line : int or None
        The trace line whose tip path is drawn; None for none.

    Returns
    -------
    Figure
        The figure (matplotlib, outside pyplot).

    Raises
    ------
    friction.FileError
        A file that is not of the kind drawn, or lacks what the picture needs.
    """
    lattice = _lattice(data)
    xyz = lattice["atoms"]
    species = lattice["species"]
    names = lattice["species_names"]
    region = scan_region(lattice)
    ny = lattice["y"].size
    if tip_line is not None and not 0 <= tip_line < ny:
        raise ValueError(f"tip line {tip_line} out of range: the file has lines 0 .. {ny - 1}")
    tip = None
    if tip_line is not None:
        trace = lattice["trips"]["trace"]
        if "tip_x" in trace and "tip_y" in trace:
            tip = np.column_stack((trace["tip_x"][tip_line], trace["tip_y"][tip_line]))

    if whole:
        lo = np.minimum(xyz[:, :2].min(axis=0), region.min(axis=0))
        hi = np.maximum(xyz[:, :2].max(axis=0), region.max(axis=0))
        pad = 0.03 * float(max(hi - lo)) + 1.0
        lo, hi = lo - pad, hi + pad
    else:
        shown = region
        if tip is not None:
            shown = np.vstack((region, tip[np.all(np.isfinite(tip), axis=1)]))
        lo, hi = shown.min(axis=0) - margin, shown.max(axis=0) + margin

    d_nn = nearest_neighbour_distance(xyz)
    bond_cut = BOND_FACTOR * d_nn if d_nn else None
    # Only the atoms in view (and a bond length around it) are drawn.
    reach = bond_cut or 0.0
    visible = np.all((xyz[:, :2] >= lo - reach) & (xyz[:, :2] <= hi + reach), axis=1)
    pts, spc = xyz[visible], species[visible]

    width, height = hi - lo
    aspect = float(np.clip(height / width if width > 0 else 1.0, 0.3, 2.0))
    fig = _figure(figsize=(7.0, 6.2 * aspect + 1.4), layout="constrained")
    ax = fig.subplots()
    pairs = bonds(pts, bond_cut)
    if pairs.size:
        segments = np.stack((pts[pairs[:, 0], :2], pts[pairs[:, 1], :2]), axis=1)
        ax.add_collection(LineCollection(segments, colors="0.55", linewidths=0.6, zorder=1))
    marker = float(np.clip(3000.0 / max(pts.shape[0], 1), 1.0, 30.0))
    colours = colormaps["tab10"]
    for k, name in enumerate(names, start=1):
        mine = spc == k
        count = int(np.sum(species == k))
        if count == 0:
            continue
        ax.scatter(pts[mine, 0], pts[mine, 1], s=marker, color=colours((k - 1) % 10),
                   edgecolors="none", zorder=2, label=f"{name} ({count} atoms)")

    ax.add_patch(Polygon(region, closed=True, fill=False, edgecolor="tab:red",
                         linewidth=1.6, zorder=3, label="scan region (support)"))
    u, _ = scan_axes(lattice["angle"])
    arrow = 0.25 * (lattice["x"].max() - lattice["x"].min()) or 1.0
    o = region[0]
    ax.annotate("", xy=o + arrow * u, xytext=o, zorder=4,
                arrowprops=dict(arrowstyle="-|>", color="tab:red", linewidth=1.6))
    if tip is not None:
        ax.plot(tip[:, 0], tip[:, 1], "-", color="black", linewidth=1.0, zorder=4,
                label=f"tip path, trace line {tip_line}")
        ax.plot(tip[0, 0], tip[0, 1], "o", color="black", markersize=3, zorder=4)

    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_aspect("equal")
    ax.set_xlabel("x (Å)")
    ax.set_ylabel("y (Å)")
    note = f"{xyz.shape[0]} atoms"
    if d_nn:
        note += f", nearest neighbours {d_nn:.3f} Å"
    if lattice["cutoff"]:
        note += f", cutoff {lattice['cutoff']:.3g} Å"
    ax.set_title(f"Crystal net and scan region: {_describe_scan(lattice['potential'], lattice['angle'])}\n{note}",
                 fontsize="medium")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.08), ncols=3, fontsize="small",
              markerscale=max(1.0, 4.0 / np.sqrt(marker)), frameon=False)
    return fig


def stacked_lines(data: DataLike, trip: str = "trace", component: str = "fx", offset: float | None = None) -> Figure:
    """The scan lines stacked as in the paper's Fig. 9b: one force component
    against the support position, line j shifted up by j x offset nN
    (default: 1.2 x the largest peak-to-peak of the lines), labelled with its
    offset across the scan.  The offset used is the figure's attribute
    `line_offset`.

    Parameters
    ----------
    data : xarray.DataTree or str or os.PathLike
        The file's data (friction.load) or its path.
    trip : str
        'trace' or 'retrace'.
    component : str
        The force dataset drawn: 'fx', 'fy', 'fz', 'f_along' or 'f_across'.
    offset : float, optional
        nN between lines; default 1.2 times the largest peak-to-peak.

    Returns
    -------
    Figure
        The figure (matplotlib, outside pyplot).

    Raises
    ------
    friction.FileError
        A file that is not of the kind drawn, or lacks what the picture needs.
    ValueError
        An unknown trip or component.
    """
    lattice = _lattice(data)
    if trip not in lattice["trips"]:
        raise FileError(f"no /afm/{trip}: the run had retrace off")
    if component not in lattice["trips"][trip]:
        raise FileError(f"no /afm/{trip}/{component} in the file")
    x, y = lattice["x"], lattice["y"]
    values = lattice["trips"][trip][component]
    ny = y.size
    if offset is None:
        with warnings.catch_warnings():  # all-NaN lines: no peak-to-peak, no warning
            warnings.simplefilter("ignore", RuntimeWarning)
            ptp = np.nanmax(values, axis=1) - np.nanmin(values, axis=1)
        ptp = ptp[np.isfinite(ptp)]
        offset = 1.2 * float(ptp.max()) if ptp.size and ptp.max() > 0 else 1.0
    symbol, meaning = COMPONENTS[component]

    fig = _figure(figsize=(8, min(4.0 + 0.35 * ny, 12.0)), layout="constrained")
    ax = fig.subplots()
    cmap = colormaps["viridis"]
    span = (y.max() - y.min()) or 1.0
    norm = Normalize(y.min(), y.min() + span)
    step = max(1, int(np.ceil(ny / 30)))  # at most ~30 labels
    for j in range(ny):
        base = j * offset
        colour = cmap(norm(y[j]))
        ax.axhline(base, color="0.85", linewidth=0.5, zorder=1)
        ax.plot(x, values[j] + base, "-", color=colour, linewidth=1.0, zorder=2)
        if j % step == 0 or j == ny - 1:
            ax.annotate(f"{y[j]:.2f} Å", xy=(1.0, base), xycoords=("axes fraction", "data"),
                        xytext=(4, 0), textcoords="offset points", va="center",
                        fontsize="x-small", color=colour)
    if x.size > 1:
        ax.set_xlim(x.min(), x.max())
    direction = "→" if trip == "trace" else "←"
    ax.set_xlabel(f"support position along the scan (Å), {trip} {direction}")
    ax.set_ylabel(f"{symbol} (nN), line j shifted up by j × {offset:.3g} nN")
    ax.set_ylim(-offset, (ny - 1) * offset + offset)
    sm = ScalarMappable(norm=norm, cmap=cmap)
    bar = fig.colorbar(sm, ax=ax, shrink=0.5, aspect=15, pad=0.09)
    bar.set_label("line offset across the scan (Å)", fontsize="small")
    ax.set_title(f"{symbol}, {meaning}, {ny} scan lines, {trip}: "
                 f"{_describe_scan(lattice['potential'], lattice['angle'])}", fontsize="medium")
    fig.line_offset = offset
    return fig


# --------------------------------------------------------------------------
# The brake
# --------------------------------------------------------------------------


def _brake_run(data):
    """The trajectory, events and parameters of a brake file, checked."""
    data = require(data, "brake", "brake")
    with reading("brake"):
        run = {name: data[f"brake/{name}"].values for name in ("t", "x", "v", "y", "w", "stick")}
        brake = groups(data)["brake"]
        run["model"] = str(brake["model"])
        run["v_dr"] = float(brake["v_dr_prime"])
        run["method"] = str(data.attrs.get("method", "?"))
        run["event_t"] = data["brake/events/t"].values
        run["event_kind"] = data["brake/events/kind"].values
    n = run["t"].size
    for name in ("x", "v", "y", "w", "stick"):
        if run[name].shape != (n,):
            raise FileError(f"/brake/{name} has shape {run[name].shape}, expected ({n},)")
    if n < 2:
        raise FileError("the run has fewer than two output points")
    return run


def _describe_brake(run):
    return f"{run['model']} model ({run['method']}), $v'_{{dr}}$ = {run['v_dr']:g} m"


def _window(run, window):
    """The time window; None: the run's second half, which leaves out the
    transient (about 1000 τ of the 3200 at the paper's parameters) so a
    periodic orbit is drawn as the closed curve it is."""
    if window is None:
        window = (run["t"][0] + 0.5 * (run["t"][-1] - run["t"][0]), run["t"][-1])
    t0, t1 = window
    if not t0 < t1:
        raise ValueError("the window (t0, t1) needs t0 < t1")
    if np.count_nonzero((run["t"] >= t0) & (run["t"] <= t1)) < 2:
        raise ValueError(f"window {t0:g} {t1:g} is outside the run (τ from {run['t'][0]:g} to {run['t'][-1]:g})")
    return t0, t1


def brake_phase(data: DataLike, window: tuple[float, float] | None = None) -> Figure:
    """The phase plane (x, x') over the time window (default: the run's second
    half, after the transient; the paper's Fig. 12 is tau in [100, 1000],
    inside the transient); stick points in their own colour, the belt
    velocity dashed.

    Parameters
    ----------
    data : xarray.DataTree or str or os.PathLike
        The file's data (friction.load) or its path.
    window : tuple of float, optional
        The time window (tau_start, tau_end); default the run's second half.

    Returns
    -------
    Figure
        The figure (matplotlib, outside pyplot).

    Raises
    ------
    friction.FileError
        A file that is not of the kind drawn, or lacks what the picture needs.
    ValueError
        A window outside the run.
    """
    run = _brake_run(data)
    t0, t1 = _window(run, window)
    inside = (run["t"] >= t0) & (run["t"] <= t1)
    x, v, stick = run["x"][inside], run["v"][inside], run["stick"][inside] == 1
    fig = _figure(figsize=(8, 5.6), layout="constrained")
    ax = fig.subplots()
    ax.plot(x, v, "-", color="tab:blue", linewidth=0.6, label="slip and stick (trajectory)")
    if stick.any():
        ax.plot(x[stick], v[stick], ".", color="tab:red", markersize=2.5,
                label=f"stick: x' = v'$_{{dr}}$ ({stick.mean():.1%} of the points)")
    ax.axhline(run["v_dr"], color="0.4", linestyle="--", linewidth=0.8,
               label=f"belt velocity v'$_{{dr}}$ = {run['v_dr']:g}")
    ax.set_xlabel("x, block displacement (m)")
    ax.set_ylabel("x', block velocity (m per unit τ)")
    second_half = ", the run's second half: transient left out" if window is None else ""
    ax.set_title(f"Phase plane, τ ∈ [{t0:g}, {t1:g}] (paper Fig. 12){second_half}\n{_describe_brake(run)}")
    ax.legend(loc="best", fontsize="small")
    return fig


def brake_x(data: DataLike, window: tuple[float, float] | None = None) -> Figure:
    """x(tau): the whole run above, the last 30 tau of the window below, where
    stick shows as straight stretches of slope v'_dr.

    Parameters
    ----------
    data : xarray.DataTree or str or os.PathLike
        The file's data (friction.load) or its path.
    window : tuple of float, optional
        The time window (tau_start, tau_end); default the run's second half.

    Returns
    -------
    Figure
        The figure (matplotlib, outside pyplot).

    Raises
    ------
    friction.FileError
        A file that is not of the kind drawn, or lacks what the picture needs.
    ValueError
        A window outside the run.
    """
    run = _brake_run(data)
    window = _window(run, window)
    t, x, stick = run["t"], run["x"], run["stick"] == 1
    fig = _figure(figsize=(11, 7), layout="constrained")
    whole, zoom = fig.subplots(2, 1)
    zoom_from = max(window[0], window[1] - 30.0)
    for ax, (t0, t1) in ((whole, (t[0], t[-1])), (zoom, (zoom_from, window[1]))):
        inside = (t >= t0) & (t <= t1)
        ax.plot(t[inside], x[inside], "-", color="tab:blue", linewidth=0.6, label="x(τ)")
        part = inside & stick
        if part.any():
            ax.plot(t[part], x[part], ".", color="tab:red", markersize=1.5 if ax is whole else 3, label="stick")
        ax.set_xlim(t0, t1)
        ax.set_ylabel("x, block displacement (m)")
    zoom.set_xlabel("τ = t √(k1/m)")
    whole.legend(loc="upper right", fontsize="small")
    n_events = run["event_t"].size
    whole.set_title(f"Block displacement, {_describe_brake(run)}\n{n_events} stick/slip events, "
                    f"{stick.mean():.1%} of the points in stick; below: τ ∈ [{zoom_from:g}, {window[1]:g}]")
    return fig


def _diagnostics(data):
    """The /brake/spectrum, /brake/poincare and /brake/lyapunov groups present."""
    data = require(data, "brake", "brake")
    d = {}
    with reading("brake"):
        brake = groups(data)["brake"]
        d["model"] = str(brake["model"])
        d["v_dr"] = float(brake["v_dr_prime"])
        present = groups(data)
        if "brake/spectrum" in present:
            s = present["brake/spectrum"]
            d["spectrum"] = {"frequency": data["brake/spectrum/frequency"].values,
                             "amplitude": data["brake/spectrum/amplitude"].values,
                             "amplitude_units": _unit_of(data["brake/spectrum/amplitude"].attrs),
                             "series": str(s["series"]), "window": str(s["window"]),
                             **{k: float(s[k]) for k in ("peak_frequency", "resolution", "window_start",
                                                         "window_end")}}
        if "brake/poincare" in present:
            p = present["brake/poincare"]
            d["poincare"] = {name.rsplit("/", 1)[1]: data[name].values for name in paths(data)
                             if name.startswith("brake/poincare/")}
            d["poincare"]["period"] = float(p["strobe_period"])
            d["poincare"]["section"] = str(p["section"])
        if "brake/lyapunov" in present:
            d["lyapunov"] = {name.rsplit("/", 1)[1]: data[name].values for name in paths(data)
                             if name.startswith("brake/lyapunov/")}
            d["lyapunov"]["attrs"] = present["brake/lyapunov"]
    if not any(k in d for k in ("spectrum", "poincare", "lyapunov")):
        raise FileError("no chaos diagnostics in the file (run friction with an &analysis group)")
    return d


def _need(d, part):
    if part not in d:
        raise FileError(f"no /brake/{part} in the file (run friction with &analysis {part} = .true.)")
    return d[part]


def brake_spectrum(data: DataLike) -> Figure:
    """The amplitude spectrum of the analysed variable over its window (the
    paper's Fig. 13), with the peak frequency and the bin width.

    Parameters
    ----------
    data : xarray.DataTree or str or os.PathLike
        The file's data (friction.load) or its path.

    Returns
    -------
    Figure
        The figure (matplotlib, outside pyplot).

    Raises
    ------
    friction.FileError
        A file that is not of the kind drawn, or lacks what the picture needs.
    """
    d = _diagnostics(data)
    s = _need(d, "spectrum")
    fig = _figure(figsize=(8, 5), layout="constrained")
    ax = fig.subplots()
    ax.semilogy(s["frequency"], np.maximum(s["amplitude"], 1e-300), "-", linewidth=0.8)
    ax.axvline(s["peak_frequency"], color="tab:red", linestyle="--", linewidth=0.8,
               label=f"peak {s['peak_frequency']:.6f} ± {s['resolution'] / 2:.6f} (bin {s['resolution']:.6f})")
    ax.axvline(0.143433, color="0.5", linestyle=":", linewidth=0.8, label="paper: 0.143433")
    ax.set_xlim(0, min(1.0, s["frequency"][-1]))
    ax.set_xlabel("frequency (cycles per unit τ)")
    ax.set_ylabel(_with_unit(f"amplitude of {s['series']}", s.get("amplitude_units")))
    ax.set_title(f"Spectrum of {s['series']}, τ ∈ [{s['window_start']:g}, {s['window_end']:g}], "
                 f"{s['window']} window (paper Fig. 13)\n{d['model']} model")
    ax.legend(fontsize="small")
    return fig


def poincare(data: DataLike) -> Figure:
    """The stroboscopic map (x, x') at the strobe period (the paper's Fig. 14),
    beside the true section (x, y).

    Parameters
    ----------
    data : xarray.DataTree or str or os.PathLike
        The file's data (friction.load) or its path.

    Returns
    -------
    Figure
        The figure (matplotlib, outside pyplot).

    Raises
    ------
    friction.FileError
        A file that is not of the kind drawn, or lacks what the picture needs.
    """
    d = _diagnostics(data)
    p = _need(d, "poincare")
    fig = _figure(figsize=(12, 5), layout="constrained")
    strobe, section = fig.subplots(1, 2)
    # Coloured by time, so the transient from the initial state and the convergence
    # (or not) onto the attractor show, rather than one cloud of every point.
    points = strobe.scatter(p["strobe_x"], p["strobe_v"], c=p["strobe_t"], s=6, cmap="viridis")
    strobe.set_title(f"Stroboscopic map, period {p['period']:.6g} τ (paper Fig. 14)\n{p['strobe_t'].size} points")
    # On the stick-to-slip section x' = v'_dr: (x, y) shows what changes.
    section.scatter(p["section_x"], p["section_y"], c=p["section_t"], s=6, cmap="viridis",
                    vmin=points.norm.vmin, vmax=points.norm.vmax)
    section.set_title(f"Section: {p['section']} (x, y)\n{p['section_t'].size} points")
    fig.colorbar(points, ax=[strobe, section], label="τ of the point")
    section.set_ylabel("y, crank arm tip displacement (m)")
    strobe.set_ylabel("x', block velocity (m per unit τ)")
    for ax in (strobe, section):
        ax.set_xlabel("x, block displacement (m)")
    return fig


def lyapunov(data: DataLike) -> Figure:
    """The running Benettin estimate (from the equations) and the Rosenstein
    divergence curve with its fit range and slope (from the series).

    Parameters
    ----------
    data : xarray.DataTree or str or os.PathLike
        The file's data (friction.load) or its path.

    Returns
    -------
    Figure
        The figure (matplotlib, outside pyplot).

    Raises
    ------
    friction.FileError
        A file that is not of the kind drawn, or lacks what the picture needs.
    """
    d = _diagnostics(data)
    g = _need(d, "lyapunov")
    a = g["attrs"]
    fig = _figure(figsize=(12, 5), layout="constrained")
    flow, series = fig.subplots(1, 2)
    if "benettin_estimate" in g:
        flow.plot(g["benettin_time"], g["benettin_estimate"], "-", linewidth=0.8)
        flow.axhline(0, color="0.5", linewidth=0.6)
        flow.set_title(f"Benettin running estimate: {float(a['benettin_exponent']):.3g} per τ\n"
                       f"renormalised every {float(a['benettin_renormalise']):g} τ, "
                       f"d0 = {float(a['benettin_d0']):g}, transient {float(a['benettin_transient']):g} τ")
        flow.set_xlabel("measuring time (τ)")
        flow.set_ylabel("λ estimate (1/τ)")
    else:
        flow.set_axis_off()
    if "rosenstein_divergence" in g:
        t, curve = g["rosenstein_time"], g["rosenstein_divergence"]
        k0, k1 = int(a["rosenstein_fit_start"]), int(a["rosenstein_fit_end"])
        lam = float(a["rosenstein_exponent"])
        series.plot(t, curve, "-", linewidth=0.8, label="mean ln divergence")
        # The slope means an exponent only where the curve is straight over the fit range:
        # R² of a straight line there; below 0.98 (curvature visible by eye) no line is drawn.
        tk, ck = t[k0:k1 + 1], curve[k0:k1 + 1]
        r2 = (np.corrcoef(tk, ck)[0, 1] ** 2) if tk.size > 2 and np.ptp(ck) > 0 else 0.0
        series.axvspan(tk[0], tk[-1], color="0.9", zorder=0, label=f"fit range (R² = {r2:.3f})")
        if r2 >= 0.98:
            series.plot(tk, curve[k0] + lam * (tk - t[k0]), "--", color="tab:red",
                        label=f"fit: λ = {lam:.3g} per τ ({float(a['rosenstein_log2_per_sample']):.3g} log2/sample)")
        else:
            series.plot([], [], " ", label=f"no linear region: the fit's slope {lam:.3g} per τ is not an exponent")
        series.set_title(f"Rosenstein: m = {int(a['rosenstein_dimension'])}, delay {int(a['rosenstein_delay'])}, "
                         f"Theiler {int(a['rosenstein_theiler'])} samples of "
                         f"{float(a['rosenstein_sample_spacing']):g} τ")
        series.set_xlabel("time after the pairing (τ)")
        series.set_ylabel("⟨ln distance⟩")
        series.legend(fontsize="small")
    else:
        series.set_axis_off()
    return fig


def _orbit(data):
    """The /brake/orbit group: attributes and datasets (branch ones under 'branch/')."""
    data = require(data, "brake", "brake")
    with reading("brake"):
        if "brake/orbit" not in groups(data):
            raise FileError("no /brake/orbit in the file (run friction with &analysis orbit = .true.)")
        o = {name[len("brake/orbit/"):]: data[name].values for name in paths(data) if name.startswith("brake/orbit/")}
        o["attrs"] = groups(data)["brake/orbit"]
        if "brake/orbit/branch" in groups(data):
            o["variable"] = str(groups(data)["brake/orbit/branch"]["variable"])
            names = str(groups(data)["brake/orbit/bifurcations"]["kind_names"])
            o["kind_names"] = {int(code): name.strip() for code, name in
                               (item.split("=") for item in names.split(","))}
    return o


def floquet(data: DataLike) -> Figure:
    """The periodic orbit's Floquet multipliers in the complex plane with the
    unit circle (the stick's exact 0 and the trivial 1 included).

    Parameters
    ----------
    data : xarray.DataTree or str or os.PathLike
        The file's data (friction.load) or its path.

    Returns
    -------
    Figure
        The figure (matplotlib, outside pyplot).

    Raises
    ------
    friction.FileError
        A file that is not of the kind drawn, or lacks what the picture needs.
    """
    o = _orbit(data)
    a = o["attrs"]
    fig = _figure(figsize=(5.5, 5.5), layout="constrained")
    ax = fig.subplots()
    angle = np.linspace(0, 2 * np.pi, 361)
    ax.plot(np.cos(angle), np.sin(angle), color="0.5", linewidth=0.8, label="unit circle")
    if int(a["found"]) == 1:
        mu = o["floquet_multipliers"]
        ax.plot(mu[:, 0], mu[:, 1], "o", color="tab:red", label="multipliers")
        title = (f"period {float(a['period']):.6g} τ, {int(a['iterations'])} Newton steps, "
                 f"residual {float(a['residual']):.1e}")
        reach = max(1.2, 1.1 * np.max(np.hypot(mu[:, 0], mu[:, 1])))
    else:
        title = f"no orbit: {a['reason']}"
        reach = 1.2
    ax.set_xlim(-reach, reach)
    ax.set_ylim(-reach, reach)
    ax.set_aspect("equal")
    ax.set_xlabel("Re μ")
    ax.set_ylabel("Im μ")
    ax.set_title(f"Floquet multipliers of the periodic orbit\n{title}", fontsize="medium")
    ax.legend(fontsize="small")
    return fig


def orbit_branch(data: DataLike) -> Figure:
    """The bifurcation diagram along a continuation line: the attractor's x at
    its slip onsets (dots), the followed orbit's slip onset x (solid where
    stable, dashed where unstable), the detected bifurcations; below, the
    largest |μ| of the section map against 1.

    Parameters
    ----------
    data : xarray.DataTree or str or os.PathLike
        The file's data (friction.load) or its path.

    Returns
    -------
    Figure
        The figure (matplotlib, outside pyplot).

    Raises
    ------
    friction.FileError
        A file that is not of the kind drawn, or lacks what the picture needs.
    """
    o = _orbit(data)
    if "branch/parameter" not in o:
        raise FileError("no /brake/orbit/branch in the file (run friction with &analysis continuation)")
    p = o["branch/parameter"]
    found = o["branch/found"] == 1
    x = o["branch/point"][:, 0]
    modulus = o["branch/max_modulus"]
    fig = _figure(figsize=(8, 7), layout="constrained")
    top, bottom = fig.subplots(2, 1, sharex=True, height_ratios=[2, 1])
    top.plot(o["branch/section_parameter"], o["branch/section_x"], ".", markersize=1.5, color="0.4",
             label="attractor: x at slip onsets")
    kinds = np.asarray(o.get("bifurcations/kind", []), dtype=int)
    where = np.asarray(o.get("bifurcations/parameter", []), dtype=float)
    jumps = where[kinds == 4]
    # One segment per pair of neighbours with orbits on one branch (no
    # discontinuity between them): solid if stable at both ends.
    for k in range(1, p.size):
        if not (found[k - 1] and found[k]) or np.any((jumps - p[k - 1]) * (jumps - p[k]) < 0):
            continue
        stable = modulus[k - 1] < 1 and modulus[k] < 1
        style = {"linestyle": "-" if stable else "--", "color": "tab:blue" if stable else "tab:orange"}
        top.plot(p[k - 1:k + 1], x[k - 1:k + 1], **style)
        bottom.plot(p[k - 1:k + 1], modulus[k - 1:k + 1], **style)
    top.plot(p[found], x[found], ".", color="k", markersize=3)
    top.plot([], [], "-", color="tab:blue", label="orbit, stable")
    top.plot([], [], "--", color="tab:orange", label="orbit, unstable")
    bottom.axhline(1.0, color="0.5", linewidth=0.8)
    colours = {1: "tab:red", 2: "tab:purple", 3: "tab:green", 4: "0.6"}
    seen = set()
    for kind, at in zip(o.get("bifurcations/kind", []), o.get("bifurcations/parameter", [])):
        name = o["kind_names"].get(int(kind), str(kind))
        for ax in (top, bottom):
            ax.axvline(at, color=colours.get(int(kind), "k"), linestyle=":", linewidth=1,
                       label=None if ax is bottom or name in seen else f"{name.replace('_', ' ')}")
        seen.add(name)
        top.annotate(f"{name.replace('_', ' ')}\n{at:.4g}", (at, 1.0), xycoords=("data", "axes fraction"),
                     rotation=90, va="top", ha="right", fontsize="x-small")
    missing = p[~found]
    if missing.size:
        top.plot(missing, np.full(missing.size, np.nanmin(o["branch/section_x"]) if o["branch/section_x"].size
                                  else 0.0), "x", color="tab:red", label="no orbit found")
    top.set_ylabel("x at slip onset (m)")
    # The section the orbit was found on: stick_to_slip, creep_band_exit for a law without exact stick, or
    # band_hold_end for a law with a band (Karnopp's).
    section = str(o["attrs"].get("section", "stick_to_slip")).replace("_", "-")
    top.set_title(f"Periodic orbit followed in {o['variable']} ({section} section)", fontsize="medium")
    top.legend(fontsize="x-small", loc="lower left")
    bottom.set_xlabel(o["variable"])
    bottom.set_ylabel("largest |μ| of the section map")
    return fig


# --------------------------------------------------------------------------
# Sweeps
# --------------------------------------------------------------------------


def _sweep(data):
    """The per-point datasets of /sweep (flat, in the order of the points), checked."""
    data = require(data, "sweep", "sweep")
    with reading("sweep"):
        s = {"scene": str(data.attrs.get("sweep_scene", "brake")), "variable": str(data.attrs["sweep_variable"])}
        keys = ["values", "status"]
        if s["scene"] == "brake":
            keys += ["maxima", "maxima_offset", "maxima_count", "lyapunov", "stick_fraction"]
        elif s["scene"] == "machine":
            keys += ["maxima", "maxima_offset", "maxima_count", "force_mean", "stick_fraction", "events",
                     "lyapunov", "orbit_found", "orbit_period", "orbit_max_multiplier"]
        else:
            keys += ["mean_friction", "max_force"]
        missing = [key for key in keys if f"sweep/{key}" not in paths(data)]
        if missing:
            raise FileError("/sweep lacks " + ", ".join(missing))
        s.update({key: np.ravel(data[f"sweep/{key}"].values) for key in keys})
        if "sweep_variable2" in data.attrs:
            s["variable2"] = str(data.attrs["sweep_variable2"])
            s["values2"] = np.ravel(data["sweep/values2"].values)
        # Axis labels with the swept variables' units, which /sweep/values and values2 carry.
        s["label"] = _with_unit(s["variable"], _unit_of(data["sweep/values"].attrs))
        if "variable2" in s:
            s["label2"] = _with_unit(s["variable2"], _unit_of(data["sweep/values2"].attrs))
    n = s["values"].size
    if any(s[key].size != n for key in keys if key != "maxima"):
        raise FileError("per-point datasets of different lengths")
    if s["scene"] in ("brake", "machine") and s["maxima_count"].sum() != s["maxima"].size:
        raise FileError("maxima_count does not add up to the maxima")
    return s


def _unit_of(attrs):
    """A dataset's unit for a label: in the brake's time τ where it has one
    (`units_tau`, 'm/tau'), else its UDUNITS `units` ('m', 'eV')."""
    return attrs.get("units_tau", attrs.get("units"))


def _with_unit(name, unit):
    """'brake.v_dr_prime (m/tau)'; a pure number's unit ('1', none) is not shown."""
    unit = "" if unit is None else str(unit)
    return f"{name} ({unit})" if unit and unit != "1" else name


def _series(s):
    """(label, mask) per value of the second variable; one series without."""
    if "values2" not in s:
        return [(None, np.ones(s["values"].size, bool))]
    return [(f"{s['variable2']} = {value:g}", s["values2"] == value) for value in np.unique(s["values2"])]


def _mark_failed(ax, s):
    failed = s["status"] == 2
    for k, value in enumerate(np.unique(s["values"][failed])):
        ax.axvline(value, color="r", lw=0.8, alpha=0.5, label="failed" if k == 0 else None)


def _log_scale(values):
    """A log axis for positive values spread over more than a decade."""
    values = values[np.isfinite(values)]
    return values.size > 1 and values.min() > 0 and values.max() / values.min() > 10


def _brake_sweep(data):
    s = _sweep(data)
    if s["scene"] != "brake":
        raise FileError(f"not a brake sweep (sweep_scene = '{s['scene']}': use sweep)")
    return s


def _maxima_sweep(data):
    """A sweep with the local maxima of x per point: the brake's or the machine's."""
    s = _sweep(data)
    if s["scene"] not in ("brake", "machine"):
        raise FileError(f"not a brake or machine sweep (sweep_scene = '{s['scene']}': use sweep_friction)")
    return s


def bifurcation(data: DataLike) -> Figure:
    """A brake or machine sweep's bifurcation diagram: the local maxima of x
    after the transient (the machine's: over the second half of each run)
    against the swept parameter; failed points as red lines.

    Parameters
    ----------
    data : xarray.DataTree or str or os.PathLike
        The file's data (friction.load) or its path.

    Returns
    -------
    Figure
        The figure (matplotlib, outside pyplot).

    Raises
    ------
    friction.FileError
        A file that is not of the kind drawn, or lacks what the picture needs.
    """
    s = _maxima_sweep(data)
    fig = _figure(figsize=(7, 4.5))
    ax = fig.subplots()
    for k, (label, mask) in enumerate(_series(s)):
        counts = np.where(mask, s["maxima_count"], 0)
        keep = np.repeat(mask, s["maxima_count"])
        parameter = np.repeat(s["values"], counts)
        ax.plot(parameter, s["maxima"][keep], ".", markersize=2, color="k" if label is None else f"C{k}", alpha=0.6)
        if label is not None:
            ax.plot([], [], "o", color=f"C{k}", label=label)
    _mark_failed(ax, s)
    if _log_scale(s["values"]):
        ax.set_xscale("log")
    ax.set_xlabel(s["label"])
    ax.set_ylabel("local maxima of x after the transient (m)" if s["scene"] == "brake"
                  else "local maxima of x, second half of the run (m)")
    ax.set_title("bifurcation diagram")
    if ax.get_legend_handles_labels()[0]:
        ax.legend()
    fig.tight_layout()
    return fig


def sweep_lyapunov(data: DataLike) -> Figure:
    """A brake sweep's Benettin exponent and stick fraction against the parameter.

    Parameters
    ----------
    data : xarray.DataTree or str or os.PathLike
        The file's data (friction.load) or its path.

    Returns
    -------
    Figure
        The figure (matplotlib, outside pyplot).

    Raises
    ------
    friction.FileError
        A file that is not of the kind drawn, or lacks what the picture needs.
    """
    s = _brake_sweep(data)
    done = s["status"] == 1
    fig = _figure(figsize=(7, 6))
    top, bottom = fig.subplots(2, 1, sharex=True)
    top.axhline(0.0, color="0.6", lw=0.8)
    for k, (label, mask) in enumerate(_series(s)):
        keep = done & mask
        top.plot(s["values"][keep], s["lyapunov"][keep], "o-", ms=3, color=f"C{k}", label=label)
        bottom.plot(s["values"][keep], s["stick_fraction"][keep], "o-", ms=3, color=f"C{k}")
    top.set_ylabel("Benettin exponent (1/τ)")
    bottom.set_ylabel("stick fraction")
    bottom.set_xlabel(s["label"])
    if "values2" in s:
        top.legend(fontsize="small")
    fig.tight_layout()
    return fig


def _grid_axis(values, name):
    """(coordinates, label, log) of one axis of a 2-D sweep: a geometric
    axis of negative values (belt velocities) is drawn as its magnitude on
    a log scale."""
    if values.size > 2 and np.all(values < 0):
        ratio = values[1:] / values[:-1]
        if np.allclose(ratio, ratio[0], rtol=1e-6) and not np.isclose(ratio[0], 1.0):
            return -values, f"−{name}", True
    if values.size > 2 and np.all(values > 0):
        ratio = values[1:] / values[:-1]
        if np.allclose(ratio, ratio[0], rtol=1e-6) and not np.isclose(ratio[0], 1.0):
            return values, name, True
    return values, name, False


def _edges(centres, log):
    """Cell edges around grid centres (geometric means on a log axis)."""
    c = np.log(centres) if log else centres
    if c.size == 1:
        e = np.array([c[0] - 0.5, c[0] + 0.5])
    else:
        inner = 0.5 * (c[1:] + c[:-1])
        e = np.concatenate([[2 * c[0] - inner[0]], inner, [2 * c[-1] - inner[-1]]])
    return np.exp(e) if log else e


def atlas(data: DataLike) -> Figure:
    """A two-variable brake sweep as maps: the Benettin exponent (chaos where
    it is positive) and the stick fraction over the grid; failed or pending
    points are grey.

    Parameters
    ----------
    data : xarray.DataTree or str or os.PathLike
        The file's data (friction.load) or its path.

    Returns
    -------
    Figure
        The figure (matplotlib, outside pyplot).

    Raises
    ------
    friction.FileError
        A file that is not of the kind drawn, or lacks what the picture needs.
    """
    s = _brake_sweep(data)
    if "values2" not in s:
        raise FileError("an atlas needs a sweep over two variables (sweep_variable2)")
    n1 = np.unique(s["values"]).size
    n2 = np.unique(s["values2"]).size
    if n1 * n2 != s["values"].size:
        raise FileError("the sweep's points do not form a grid")
    # The second variable varies fastest (docs/sweeps.md).
    v1 = s["values"].reshape(n1, n2)[:, 0]
    v2 = s["values2"].reshape(n1, n2)[0, :]
    x, xlabel, xlog = _grid_axis(v2, s["label2"])
    y, ylabel, ylog = _grid_axis(v1, s["label"])
    done = (s["status"] == 1).reshape(n1, n2)
    fig = _figure(figsize=(7, 8.5))
    top, bottom = fig.subplots(2, 1, sharex=True)
    exponent = np.where(done, s["lyapunov"].reshape(n1, n2), np.nan)
    finite = exponent[np.isfinite(exponent)]
    bound = max(float(np.max(np.abs(finite))) if finite.size else 1.0, 1e-12)
    cmap = colormaps["RdBu_r"].with_extremes(bad="0.7")
    image = top.pcolormesh(_edges(x, xlog), _edges(y, ylog), np.ma.masked_invalid(exponent), cmap=cmap,
                           vmin=-bound, vmax=bound, shading="flat")
    fig.colorbar(image, ax=top, label="Benettin exponent (1/τ)")
    top.set_title("largest Lyapunov exponent: chaos where red")
    stick = np.where(done, s["stick_fraction"].reshape(n1, n2), np.nan)
    grey = colormaps["viridis"].with_extremes(bad="0.7")
    image = bottom.pcolormesh(_edges(x, xlog), _edges(y, ylog), np.ma.masked_invalid(stick), cmap=grey,
                              vmin=0.0, vmax=1.0, shading="flat")
    fig.colorbar(image, ax=bottom, label="stick fraction")
    for ax in (top, bottom):
        ax.set_ylabel(ylabel)
        if ylog:
            ax.set_yscale("log")
        if xlog:
            ax.set_xscale("log")
    bottom.set_xlabel(xlabel)
    fig.tight_layout()
    return fig


def sweep_friction(data: DataLike) -> Figure:
    """An AFM sweep's mean friction and maximum lateral force against the
    parameter, a line per value of a second variable.

    Parameters
    ----------
    data : xarray.DataTree or str or os.PathLike
        The file's data (friction.load) or its path.

    Returns
    -------
    Figure
        The figure (matplotlib, outside pyplot).

    Raises
    ------
    friction.FileError
        A file that is not of the kind drawn, or lacks what the picture needs.
    """
    s = _sweep(data)
    if s["scene"] != "afm":
        raise FileError(f"not an AFM sweep (sweep_scene = '{s['scene']}': use sweep)")
    done = s["status"] == 1
    fig = _figure(figsize=(7, 6.5))
    top, bottom = fig.subplots(2, 1, sharex=True)
    for k, (label, mask) in enumerate(_series(s)):
        keep = done & mask
        top.plot(s["values"][keep], s["mean_friction"][keep], "o-", ms=3, color=f"C{k}", label=label)
        bottom.plot(s["values"][keep], s["max_force"][keep], "o-", ms=3, color=f"C{k}")
    for ax in (top, bottom):
        _mark_failed(ax, s)
    if _log_scale(s["values"]):
        bottom.set_xscale("log")
    if _log_scale(s["mean_friction"][done]):
        top.set_yscale("log")
    top.set_ylabel("mean friction (nN)")
    top.set_title("half the width of the friction loop, over the map")
    bottom.set_ylabel("maximum lateral force (nN)")
    bottom.set_xlabel(s["label"])
    if top.get_legend_handles_labels()[0]:
        top.legend(fontsize="small")
    fig.tight_layout()
    return fig


def sweep_machine(data: DataLike) -> Figure:
    """A machine sweep's results against the parameter, a line per value of
    a second variable: the mean friction force and the stick fraction over
    the second half of each run; the stick/slip events when any point has
    some (set-valued laws, Karnopp's); Benettin's exponent when `lyapunov` was on (any
    point nonzero); and with `&analysis orbit`, where any point found its
    periodic orbit, the orbit's period and the largest multiplier |μ| of its
    section map (the unit circle dashed: stable below).  Points without an
    orbit (NaN) are gaps; failed points are red lines.

    Parameters
    ----------
    data : xarray.DataTree or str or os.PathLike
        The file's data (friction.load) or its path.

    Returns
    -------
    Figure
        The figure (matplotlib, outside pyplot).

    Raises
    ------
    friction.FileError
        A file that is not of the kind drawn, or lacks what the picture needs.
    """
    s = _sweep(data)
    if s["scene"] != "machine":
        raise FileError(f"not a machine sweep (sweep_scene = '{s['scene']}': use sweep)")
    done = s["status"] == 1
    found = done & (s["orbit_found"] == 1)
    panels = [("force_mean", "mean friction force (N)", done), ("stick_fraction", "stick fraction", done)]
    if np.any(s["events"][done] > 0):
        panels.append(("events", "stick/slip events", done))
    if np.any(s["lyapunov"][done] != 0.0):
        panels.append(("lyapunov", "Benettin exponent (1/s)", done))
    if np.any(found):
        panels += [("orbit_period", "orbit period (s)", found), ("orbit_max_multiplier", "largest |μ|", found)]
    fig = _figure(figsize=(7, 1.9 * len(panels) + 1.0))
    axes = np.atleast_1d(fig.subplots(len(panels), 1, sharex=True))
    for ax, (key, ylabel, shown) in zip(axes, panels):
        for k, (label, mask) in enumerate(_series(s)):
            # NaN (no orbit at a point) breaks the line instead of joining its neighbours across it
            y = np.where(shown & mask, s[key].astype(float), np.nan)[mask]
            ax.plot(s["values"][mask], y, "o-", ms=3, color=f"C{k}", label=label)
        if key == "lyapunov":
            ax.axhline(0.0, color="0.6", lw=0.8)
        if key == "orbit_max_multiplier":
            ax.axhline(1.0, color="0.4", lw=0.8, ls="--")
            if _log_scale(np.append(s[key][shown], 1.0)):   # stick-slip orbits' multipliers lie near 0
                ax.set_yscale("log")
        ax.set_ylabel(ylabel)
        _mark_failed(ax, s)
    if _log_scale(s["values"]):
        axes[-1].set_xscale("log")
    axes[0].set_title("machine sweep: the second half of each run")
    axes[-1].set_xlabel(s["label"])
    if axes[0].get_legend_handles_labels()[0]:
        axes[0].legend(fontsize="small")
    fig.tight_layout()
    return fig


def sweep(data: DataLike) -> dict[str, Figure]:
    """Every chart of a sweep file: {"bifurcation": Figure, "lyapunov": Figure}
    for a brake sweep, and "atlas" (maps) when it has a second variable (only
    the maps when that has more than 8 values: a line each would not read);
    {"friction": Figure} for an AFM sweep; {"bifurcation": Figure, "machine":
    Figure} for a machine sweep (sweep_machine).

    Parameters
    ----------
    data : xarray.DataTree or str or os.PathLike
        The file's data (friction.load) or its path.

    Returns
    -------
    dict of str to Figure
        The charts by name.

    Raises
    ------
    friction.FileError
        A file that is not of the kind drawn, or lacks what the picture needs.
    """
    data = require(data, "sweep", "sweep")
    s = _sweep(data)
    if s["scene"] == "brake":
        if "values2" not in s:
            return {"bifurcation": bifurcation(data), "lyapunov": sweep_lyapunov(data)}
        figures = {"atlas": atlas(data)}
        if np.unique(s["values2"]).size <= 8:
            figures.update({"bifurcation": bifurcation(data), "lyapunov": sweep_lyapunov(data)})
        return figures
    if s["scene"] == "machine":
        return {"bifurcation": bifurcation(data), "machine": sweep_machine(data)}
    return {"friction": sweep_friction(data)}


# --------------------------------------------------------------------------
# Speed against accuracy (files of scripts/work_precision)
# --------------------------------------------------------------------------

STYLE = {"rk2": ("tab:gray", "o"), "rk4": ("tab:brown", "s"), "rkf45": ("tab:blue", "o"),
         "rkck": ("tab:cyan", "^"), "rk8pd": ("tab:red", "D"), "rk1imp": ("tab:olive", "v"),
         "rk2imp": ("tab:pink", "<"), "rk4imp": ("tab:green", ">"), "bsimp": ("tab:purple", "p"),
         "msadams": ("gold", "h"), "msbdf": ("tab:orange", "*"), "rodas3": ("darkblue", "P"),
         "rodas4": ("darkgreen", "X"), "switched": ("k", "x")}


def work_precision(data: DataLike, scene: str) -> Figure:
    """The work-precision chart of one scene of a work_precision.h5: error
    against CPU time, log-log, a line per method (its 'ok' points), the
    series measured elsewhere dashed, the reference's own check dotted.

    Parameters
    ----------
    data : xarray.DataTree or str or os.PathLike
        The file's data (friction.load) or its path.
    scene : str
        The scene's group in the file ('naf', 'brake_switched', ...).

    Returns
    -------
    Figure
        The figure (matplotlib, outside pyplot).

    Raises
    ------
    friction.FileError
        A file that is not of the kind drawn, or lacks what the picture needs.
    """
    data = load(data)
    if scene not in groups(data):
        known = sorted(g for g in groups(data) if "/" not in g)
        raise FileError(f"no scene {scene!r} in the file (scenes: {', '.join(known)})")
    with reading("work-precision"):
        attrs = groups(data)[scene]
        methods = sorted({name.split("/")[1] for name in paths(data)
                          if name.startswith(f"{scene}/") and name.count("/") == 2 and name.split("/")[1] != "extra"},
                         key=lambda m: list(STYLE).index(m) if m in STYLE else len(STYLE))
        check = float(attrs["reference_check"])
        unit = str(attrs["unit"])
        fig = _figure(figsize=(7.5, 5.2))
        ax = fig.subplots()
        for method in methods:
            status = np.asarray(data[f"{scene}/{method}/status"].values)
            ok = status == "ok"
            if not ok.any():
                continue
            color, marker = STYLE.get(method, ("k", "."))
            ax.loglog(data[f"{scene}/{method}/error"].values[ok], data[f"{scene}/{method}/cpu_time"].values[ok],
                      marker=marker, color=color, label=method, lw=1.2, ms=5)
        extras = sorted({name.split("/")[2] for name in paths(data) if name.startswith(f"{scene}/extra/")})
        for label in extras:
            ax.loglog(data[f"{scene}/extra/{label}/error"].values, data[f"{scene}/extra/{label}/cpu_time"].values,
                      "k--", marker="+", label=label)
        ax.axvline(check, color="0.6", ls=":", lw=1)
        ax.text(check, ax.get_ylim()[1], " reference\n self-check", va="top", fontsize=7, color="0.4")
        quantity = "x" if scene.startswith("brake") else "F"
        ax.set_xlabel(f"error: max |{quantity} - reference| ({unit})")
        ax.set_ylabel("CPU time (s, median)")
        ax.set_title(f"{attrs['title']}\n{attrs['quantity']}; {attrs['run']}", fontsize=9)
        ax.grid(True, which="major", alpha=0.3)
        ax.legend(fontsize=7, ncol=2, loc="best")
        fig.tight_layout()
    return fig


FAILURE_COLOURS = ["#dddddd", "#4daf4a", "#ffd92f", "#e41a1c", "#984ea3"]  # none, ok, slow, failed, wrong
PARAMETER_LABELS = {"epsilon_prime": lambda v: f"ε' = {v:.0e}", "damping_ratio": lambda v: f"ζ = {v:g}"}


def failure_map(data: DataLike) -> Figure:
    """The failure maps of a failure_map.h5: every method against each
    setting of a parameter, ok, slow, failed or silently wrong, with the CPU
    time in ms.

    Parameters
    ----------
    data : xarray.DataTree or str or os.PathLike
        The file's data (friction.load) or its path.

    Returns
    -------
    Figure
        The figure (matplotlib, outside pyplot).

    Raises
    ------
    friction.FileError
        A file that is not of the kind drawn, or lacks what the picture needs.
    """
    data = load(data)
    maps = [g for g in groups(data) if "/" not in g]
    if not maps:
        raise FileError("no failure maps in the file")
    with reading("failure-map"):
        first = maps[0]
        methods = list(data[f"{first}/methods"].values)
        fig = _figure(figsize=(5.5 * len(maps), 0.42 * len(methods) + 2.2))
        axes = np.atleast_1d(fig.subplots(1, len(maps)))
        cmap = ListedColormap(FAILURE_COLOURS)
        for ax, name in zip(axes, maps):
            attrs = groups(data)[name]
            parameter = next(p for p in PARAMETER_LABELS if f"{name}/{p}" in paths(data))
            values = data[f"{name}/{parameter}"].values
            labels = [PARAMETER_LABELS[parameter](v) for v in values]
            category = np.asarray(data[f"{name}/category"].values, dtype=int)
            status = data[f"{name}/status"].values
            cpu = data[f"{name}/cpu_time"].values
            ax.imshow(category + 1, cmap=cmap, vmin=0, vmax=4, aspect="auto")
            ax.set_yticks(range(len(methods)), methods, fontsize=8)
            ax.set_xticks(range(len(labels)), labels, fontsize=7, rotation=30)
            for j in range(len(labels)):
                for i in range(len(methods)):
                    st = status[i, j]
                    txt = {"capped": "cap", "killed": "kill"}.get(st, "")
                    if st in ("ok", "wrong") and math.isfinite(cpu[i, j]):
                        txt = f"{cpu[i, j] * 1e3:.0f}" if cpu[i, j] >= 0.01 else f"{cpu[i, j] * 1e3:.1f}"
                    ax.text(j, i, txt, ha="center", va="center", fontsize=6)
            ax.set_title(attrs["title"], fontsize=8)
        handles = [Rectangle((0, 0), 1, 1, color=FAILURE_COLOURS[i + 1]) for i in range(4)]
        fig.legend(handles, ["ok", "slow (>10x best, or time cap)", "fails with an error",
                             "silently wrong (>100x asked)"], loc="lower center", ncol=4, fontsize=8)
        fig.text(0.01, 0.01, "numbers: CPU time in ms", fontsize=7)
        fig.tight_layout(rect=(0, 0.07, 1, 1))
    return fig


def sang_fit(velocity: ArrayLike, friction: ArrayLike, sem: ArrayLike,
             temperature: float = 300.0) -> tuple[float, float, float]:
    """Sang, Dube and Grant's law F = F_c - B [ln(v_c/v)]^(2/3) (PRL 87,
    174301, 2001) through the points, weighted by their standard errors
    (friction.thermal.fit_sang at one temperature, where only
    B = (beta k_B T)^(2/3) is determined).  Returns (F_c, B, v_c), v_c in
    the units of velocity.

    Parameters
    ----------
    velocity : array_like
        Support velocities (angstrom/s).
    friction : array_like
        Mean friction at each (nN).
    sem : array_like
        Its standard errors (nN).
    temperature : float
        K.

    Returns
    -------
    tuple of float
        (F_c, B, v_c): nN, nN, angstrom/s.
    """
    from . import thermal
    fit = thermal.fit_sang(velocity, friction, temperature, sem)
    b = (fit.values["beta"] * thermal.K_B * temperature) ** (2.0 / 3.0)
    return fit.values["F_c"], float(b), fit.values["v_c"]


def friction_velocity(rows: Sequence[Mapping[str, Any]]) -> Figure:
    """The mean friction against the support velocity with error bars (one
    standard error), a series per model ('kramers', 'langevin'), and
    Sang et al.'s law fitted through the reduced model's points below
    3 Å/s (where its jumps are thermal).  rows: dicts with model, velocity
    (Å/s), friction and sem (nN), as scripts/thermal_velocity.py gives.

    Parameters
    ----------
    rows : sequence of dict
        Points with model, velocity (angstrom/s), friction and sem (nN).

    Returns
    -------
    Figure
        The figure (matplotlib, outside pyplot).
    """
    fig = _figure(figsize=(6.4, 4.4))
    ax = fig.add_subplot()
    styles = {"kramers": ("o", "tab:blue", "reduced model (Kramers KMC)"),
              "langevin": ("s", "tab:red", "Langevin tip")}
    for model, (marker, colour, label) in styles.items():
        pts = sorted((r["velocity"], r["friction"], r["sem"]) for r in rows if r["model"] == model)
        if not pts:
            continue
        v, f, e = map(np.array, zip(*pts))
        ax.errorbar(v, f, yerr=e, marker=marker, color=colour, linestyle="none", capsize=3, label=label,
                    markerfacecolor="none" if model == "langevin" else colour)
    slow = sorted((r["velocity"], r["friction"], r["sem"]) for r in rows
                  if r["model"] == "kramers" and r["velocity"] < 3.0)
    if len(slow) >= 3:
        v, f, e = map(np.array, zip(*slow))
        fc, b, vc = sang_fit(v, f, e)
        grid = np.geomspace(v.min(), min(vc, 10 * v.max()) * 0.999, 200)
        ax.plot(grid, fc - b * np.log(vc / grid) ** (2.0 / 3.0), color="tab:blue", linewidth=1,
                label=f"Sang et al.: $F_c$ = {fc:.3f} nN, $v_c$ = {vc:.3g} Å/s")
    ax.set_xscale("log")
    ax.set_xlabel("support velocity (Å/s)")
    top = ax.secondary_xaxis("top", functions=(lambda v: v * 1e-10, lambda v: v * 1e10))
    top.set_xlabel("support velocity (m/s)")
    ax.set_ylabel("mean friction (nN)")
    ax.set_title("NaF, 300 K: friction against velocity", fontsize="medium")
    ax.legend(fontsize="small")
    fig.tight_layout()
    return fig


def temperature_fit(rows: Sequence[Mapping[str, Any]], below: float = 300.0) -> tuple[float, float, float, float]:
    """The law of thermally activated slips at a fixed velocity, F = F_c -
    C T^(2/3) (Sang et al.'s F_c - [beta k_B T ln(v_c/v)]^(2/3) with the
    logarithm's slow change with T left out), fitted by weighted least
    squares through the points with 0 < T < below (K; above, jumps back
    set in); and the free exponent alpha of F_c - C T^alpha with its
    standard error (scipy's curve_fit, absolute sigma).  A point whose
    realizations all agree (standard error below 1e-9 nN: at low T the jumps scatter
    less than the sample spacing, so no sample tells them apart) gets the
    smallest standard error of the others.  Returns (F_c in nN, C in
    nN/K^(2/3), alpha, its standard error).

    Parameters
    ----------
    rows : sequence of dict
        Points with temperature (K), friction and sem (nN).
    below : float
        Only points with 0 < T < below (K) are fitted.

    Returns
    -------
    tuple of float
        (F_c in nN, C in nN/K^(2/3), the free exponent alpha, its standard error).
    """
    pts = [(r["temperature"], r["friction"], r["sem"]) for r in rows if 0.0 < r["temperature"] < below]
    t, f, e = (np.array(x, float) for x in zip(*pts))
    e = np.where(e > 1e-9, e, e[e > 1e-9].min())
    w = 1.0 / e ** 2

    from scipy.optimize import curve_fit

    def law(temperature, fc, c, alpha=2.0 / 3.0):
        return fc - c * temperature ** alpha

    (fc, c), _ = curve_fit(law, t, f, p0=(f.max(), 0.01), sigma=e, absolute_sigma=True)
    # The free exponent: its standard error from the covariance of the three (absolute sigma: the
    # points' own errors, as Delta chi^2 = 1 of the profile).
    (_, _, alpha), cov = curve_fit(law, t, f, p0=(fc, c, 2.0 / 3.0), sigma=e, absolute_sigma=True)
    return float(fc), float(c), float(alpha), float(math.sqrt(cov[2, 2]))


def friction_temperature(rows: Sequence[Mapping[str, Any]]) -> Figure:
    """The mean friction against the temperature with error bars (one
    standard error) and the law F_c - C T^(2/3) fitted below 300 K
    (temperature_fit).  rows: dicts with temperature (K), friction and sem
    (nN), as scripts/thermal_temperature.py gives.

    Parameters
    ----------
    rows : sequence of dict
        Points with temperature (K), friction and sem (nN).

    Returns
    -------
    Figure
        The figure (matplotlib, outside pyplot).
    """
    fig = _figure(figsize=(6.4, 4.4))
    ax = fig.add_subplot()
    pts = sorted((r["temperature"], r["friction"], r["sem"]) for r in rows)
    t, f, e = map(np.array, zip(*pts))
    ax.errorbar(t, f, yerr=e, marker="o", color="tab:blue", linestyle="none", capsize=3,
                label="reduced model (0 K: quasistatic tip)")
    fc, c, alpha, alpha_se = temperature_fit(rows)
    grid = np.linspace(0.0, t.max(), 300)
    law = fc - c * grid ** (2.0 / 3.0)
    # The 2/3 law is the model's form, not what the points say: drawn dashed, with the
    # free exponent and how many standard errors 2/3 lies from it.
    away = abs(2.0 / 3.0 - alpha) / alpha_se if alpha_se > 0 else float("inf")
    ax.plot(grid[law > 0], law[law > 0], "--", color="tab:orange", linewidth=1,
            label=f"$F_c - C\\,T^{{2/3}}$, exponent fixed, fitted below 300 K: $F_c$ = {fc:.3f} nN\n"
                  f"free exponent {alpha:.2f} ± {alpha_se:.2f}: 2/3 is {away:.1f} standard errors away")
    ax.axvspan(300.0, max(300.0, t.max()), color="0.93", zorder=0, label="not fitted (jumps back)")
    ax.axhline(0.0, color="grey", linewidth=0.5)
    ax.set_xlabel("temperature (K)")
    ax.set_ylabel("mean friction (nN)")
    ax.set_title("NaF, 0.1 Å/s: friction against temperature", fontsize="medium")
    ax.legend(fontsize="small")
    fig.tight_layout()
    return fig


# --------------------------------------------------------------------------
# fits of measured images (friction.fit)

def fit_maps(fit: ImageFit, channel: str | None = None) -> Figure:
    """A fit's measured, fitted and residual maps side by side (one channel of
    a friction.fit.ImageFit: the first, or `channel`), the residuals on their
    own colour scale.

    Parameters
    ----------
    fit : friction.fit.ImageFit
        A fit of friction.fit.image.
    channel : str, optional
        The channel drawn; default the first.

    Returns
    -------
    Figure
        The figure (matplotlib, outside pyplot).
    """
    channel = channel or sorted(fit.fitted)[0]
    if channel not in fit.fitted:
        raise ValueError(f"the fit has no channel {channel!r}: it has {sorted(fit.fitted)}")
    model, residual = fit.fitted[channel], fit.residuals[channel]
    measured = model + residual
    fig = _figure(figsize=(11.0, 3.6))
    axes = fig.subplots(1, 3)
    low, high = np.nanmin(measured), np.nanmax(measured)
    span = np.nanmax(np.abs(residual))
    for ax, values, title, kwargs in ((axes[0], measured, "measured", {"vmin": low, "vmax": high}),
                                      (axes[1], model, "fitted model", {"vmin": low, "vmax": high}),
                                      (axes[2], residual, f"residual (rms {fit.noise:.3g})",
                                       {"vmin": -span, "vmax": span, "cmap": "RdBu_r"})):
        image = ax.imshow(values, origin="lower", aspect="auto", interpolation="nearest", **kwargs)
        ax.set_title(f"{channel}: {title}", fontsize="medium")
        ax.set_xlabel("sample along the line")
        fig.colorbar(image, ax=ax, shrink=0.85)
    axes[0].set_ylabel("line")
    fig.tight_layout()
    return fig


def fit_corner(sample: np.ndarray, names: Sequence[str], truths: Sequence[float] | None = None) -> Figure:
    """The corner plot of an MCMC sample (ImageFit.sample(): rows of values in
    the order of `names`), with the truth marked when known (corner's
    corner.corner on a Figure of this module).

    Parameters
    ----------
    sample : numpy.ndarray
        Rows of values (ImageFit.sample()).
    names : sequence of str
        The parameters' names, in the columns' order.
    truths : sequence of float, optional
        The true values, marked.

    Returns
    -------
    Figure
        The figure (matplotlib, outside pyplot).

    Raises
    ------
    ImportError
        Without the corner package.
    """
    try:
        import corner
    except ImportError:
        raise ImportError("fit_corner needs the Python package corner (pip install corner)") from None
    sample = np.asarray(sample, float)
    size = 2.2 * sample.shape[1]
    fig = _figure(figsize=(size, size))
    corner.corner(sample, fig=fig, labels=list(names), truths=truths, show_titles=True, title_fmt=".4g",
                  quantiles=(0.16, 0.5, 0.84), title_kwargs={"fontsize": 8}, label_kwargs={"fontsize": 8})
    return fig


def friction_load(images: Sequence[MeasuredImage], labels: Sequence[str] | None = None) -> Figure:
    """Friction against load from measured images (friction.read_image): each
    image's mean (trace - retrace)/2 with the standard error of its lines'
    means, against its setpoint (metadata["setpoint"]), and the line fitted
    through them (numpy's polyfit).

    Parameters
    ----------
    images : sequence of MeasuredImage
        Measured images with metadata["setpoint"] (friction.read_image).
    labels : sequence of str, optional
        A label per image.

    Returns
    -------
    Figure
        The figure (matplotlib, outside pyplot).

    Raises
    ------
    ValueError
        An image without a setpoint.
    """
    points = []
    for image in images:
        if "setpoint" not in image.metadata:
            raise ValueError(f"{image.path}: no setpoint in the file's header: friction against load needs one")
        lines = image.line_friction()
        lines = lines[np.isfinite(lines)]
        points.append((image.metadata["setpoint"][0], float(np.mean(lines)),
                       float(np.std(lines, ddof=1) / math.sqrt(lines.size)), image.unit))
    points.sort()
    load_v, friction, sem, units = zip(*points)
    fig = _figure(figsize=(5.6, 4.0))
    ax = fig.add_subplot()
    ax.errorbar(load_v, friction, yerr=sem, marker="o", linestyle="none", capsize=3, color="tab:blue",
                label="mean of (trace - retrace)/2, one standard error of the lines")
    if len(points) >= 2:
        slope, intercept = np.polyfit(load_v, friction, 1)
        grid = np.linspace(min(load_v), max(load_v), 50)
        ax.plot(grid, slope * grid + intercept, color="tab:orange", linewidth=1,
                label=f"straight line: slope {slope:.4f} {units[0]}/V")
    ax.set_xlabel("setpoint (deflection, V): the load")
    ax.set_ylabel(f"friction ({units[0]})")
    ax.legend(fontsize="small")
    fig.tight_layout()
    return fig
