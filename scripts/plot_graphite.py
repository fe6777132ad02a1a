#!/usr/bin/env python3
"""Plot a lattice-sum friction map written by `friction` (e.g. inputs/graphite.nml).

Reads one output file of an AFM scene with a crystal net (group /surface,
potential 'lj') and writes two PNGs into the output directory (default: the
current directory, like `friction` itself):

  <stem>_net.png    the crystal net as in the paper's Fig. 9a: atoms as dots
                    coloured by species, bonds (pairs closer than 1.2 x the
                    nearest-neighbour distance) as thin lines, the scan region
                    (the parallelogram the support covers) and the path of the
                    tip on one trace line (line 0 by default); zoomed to the
                    scan region plus --margin angstrom, or --whole for the net
  <stem>_lines.png  the scan lines stacked as in Fig. 9b: one force component
                    (Fx by default) of the trace trip (--trip retrace for the
                    other one) against the support position along the scan,
                    line j shifted up by j x the offset, labelled with its
                    offset across the scan

Positions are in angstrom in the lattice frame, forces in nN.  Lines are
counted from 0, as in /afm/support_y.  Files of the other AFM scenes (NaF,
HOPG: no /surface/atoms) are refused; plot those with plot_afm.py.

Examples:
  plot_graphite.py graphite.h5
  plot_graphite.py graphite.h5 --component f_along --trip retrace -o plots
  plot_graphite.py graphite.h5 --whole --no-tip --dpi 200

Exit codes: 0 done, 1 a PNG could not be written, 2 bad command line or
bad input file (missing, not a friction map, no crystal net, no such trip).
"""

import argparse
import sys
import warnings
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # headless: no display needed

from friction_output import InputError, open_output, text  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402
from matplotlib.patches import Polygon  # noqa: E402

PROG = "plot_graphite.py"
COMPONENTS = {
    "fx": ("$F_x$", "force along the lattice x axis"),
    "fy": ("$F_y$", "force along the lattice y axis"),
    "fz": ("$F_z$", "vertical force"),
    "f_along": ("$F_\\parallel$", "force along the scan"),
    "f_across": ("$F_\\perp$", "force across the scan"),
}
POTENTIAL_LABELS = {"lj": "Lennard-Jones lattice sum"}
BOND_FACTOR = 1.2  # bonds: pairs closer than this x the nearest-neighbour distance
NN_SAMPLE = 400  # atoms whose nearest neighbour sets the nearest-neighbour distance


# --------------------------------------------------------------------------
# Reading
# --------------------------------------------------------------------------


def read_file(path):
    """Read the scan, the tip path and the net into a dict; InputError if unfit."""
    with open_output(path, "afm", "force-map") as f:
        if "surface" not in f or "atoms" not in f["surface"]:
            raise InputError("not a lattice-sum scene: no /surface/atoms "
                             "(for NaF/HOPG maps use plot_afm.py)")
        afm, surf = f["afm"], f["surface"]
        data = {
            "potential": text(afm.attrs.get("potential", b"?")),
            "angle": float(afm.attrs["angle"]),
            "origin": np.array([float(afm.attrs["origin_x"]),
                                float(afm.attrs["origin_y"])]),
            "x": np.asarray(afm["support_x"][()], dtype=float),
            "y": np.asarray(afm["support_y"][()], dtype=float),
            "atoms": np.asarray(surf["atoms"][()], dtype=float),
            "species": (np.asarray(surf["species"][()], dtype=int)
                        if "species" in surf else None),
            "species_names": [s.strip() for s in
                              text(surf.attrs.get("species_names", b"")).split(",")],
            "cutoff": (float(surf.attrs["cutoff"]) if "cutoff" in surf.attrs else None),
            "trips": {},
        }
        for trip in ("trace", "retrace"):
            if trip in afm:
                data["trips"][trip] = {q: np.asarray(afm[trip][q][()], dtype=float)
                                       for q in (*COMPONENTS, "tip_x", "tip_y")
                                       if q in afm[trip]}

    atoms = data["atoms"]
    if atoms.ndim != 2 or atoms.shape[1] not in (2, 3) or atoms.shape[0] < 1:
        raise InputError(f"/surface/atoms has shape {atoms.shape}, expected (natoms, 3)")
    if not np.all(np.isfinite(atoms)):
        raise InputError("/surface/atoms holds non-finite positions")
    names = [n for n in data["species_names"] if n] or ["atom"]
    data["species_names"] = names
    species = data["species"]
    if species is None:
        data["species"] = np.ones(atoms.shape[0], dtype=int)
    elif species.shape != (atoms.shape[0],):
        raise InputError(f"/surface/species has shape {species.shape}, "
                         f"expected (natoms,) = ({atoms.shape[0]},)")
    elif species.size and (species.min() < 1 or species.max() > len(names)):
        raise InputError(f"/surface/species holds indices {species.min()} .. {species.max()}, "
                         f"but species_names lists {len(names)}")
    if data["x"].ndim != 1 or data["y"].ndim != 1 or data["x"].size < 1 or data["y"].size < 1:
        raise InputError("/afm/support_x and /afm/support_y must be nonempty 1-D arrays")
    if "trace" not in data["trips"]:
        raise InputError("no /afm/trace group")
    shape = (data["y"].size, data["x"].size)
    for trip, values in data["trips"].items():
        for name, array in values.items():
            if array.shape != shape:
                raise InputError(f"/afm/{trip}/{name} has shape {array.shape}, "
                                 f"expected (ny, nx) = {shape}")
    return data


# --------------------------------------------------------------------------
# Geometry
# --------------------------------------------------------------------------


def scan_axes(angle_deg):
    """Unit vectors along (u) and across (n) the scan in the lattice frame."""
    t = np.radians(angle_deg)
    return np.array([np.cos(t), np.sin(t)]), np.array([-np.sin(t), np.cos(t)])


def scan_region(data):
    """Corners of the area covered by the support: origin, +L u, +L u + W n, +W n."""
    u, n = scan_axes(data["angle"])
    x0, x1 = data["x"].min(), data["x"].max()
    y0, y1 = data["y"].min(), data["y"].max()
    o = data["origin"]
    return np.array([o + x0 * u + y0 * n, o + x1 * u + y0 * n,
                     o + x1 * u + y1 * n, o + x0 * u + y1 * n])


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
    """Index pairs (i, j), i < j, of atoms closer than cutoff: a cell list in x, y."""
    count = xyz.shape[0]
    if count < 2 or not cutoff or cutoff <= 0:
        return np.empty((0, 2), dtype=int)
    cell = np.floor((xyz[:, :2] - xyz[:, :2].min(axis=0)) / cutoff).astype(np.int64)
    stride = int(cell[:, 1].max()) + 3
    key = (cell[:, 0] + 1) * stride + (cell[:, 1] + 1)
    order = np.argsort(key, kind="stable")
    sorted_key = key[order]
    pairs = []
    # Half the 3 x 3 neighbourhood (plus the cell itself): each pair once.
    for dx, dy in ((0, 0), (1, -1), (1, 0), (1, 1), (0, 1)):
        target = key + dx * stride + dy
        lo = np.searchsorted(sorted_key, target, side="left")
        hi = np.searchsorted(sorted_key, target, side="right")
        counts = hi - lo
        total = int(counts.sum())
        if total == 0:
            continue
        i = np.repeat(np.arange(count), counts)
        start = np.repeat(lo - np.concatenate(([0], np.cumsum(counts)[:-1])), counts)
        j = order[start + np.arange(total)]
        keep = np.sum((xyz[i] - xyz[j]) ** 2, axis=1) < cutoff ** 2
        if (dx, dy) == (0, 0):
            keep &= i < j
        pairs.append(np.column_stack((i[keep], j[keep])))
    return np.concatenate(pairs) if pairs else np.empty((0, 2), dtype=int)


# --------------------------------------------------------------------------
# Plots
# --------------------------------------------------------------------------


def _describe(data):
    name = POTENTIAL_LABELS.get(data["potential"], data["potential"])
    return f"{name}, scan angle {data['angle']:g}°"


def plot_net(data, out, dpi, margin, whole, tip_line):
    """The net with bonds, the scan region and the tip path of one trace line."""
    xyz = data["atoms"]
    species = data["species"]
    names = data["species_names"]
    region = scan_region(data)
    tip = None
    if tip_line is not None:
        trace = data["trips"]["trace"]
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
    fig, ax = plt.subplots(figsize=(7.0, 6.2 * aspect + 1.4), layout="constrained")
    pairs = bonds(pts, bond_cut)
    if pairs.size:
        segments = np.stack((pts[pairs[:, 0], :2], pts[pairs[:, 1], :2]), axis=1)
        ax.add_collection(LineCollection(segments, colors="0.55", linewidths=0.6, zorder=1))
    marker = float(np.clip(3000.0 / max(pts.shape[0], 1), 1.0, 30.0))
    colours = plt.get_cmap("tab10")
    for k, name in enumerate(names, start=1):
        mine = spc == k
        count = int(np.sum(species == k))
        if count == 0:
            continue
        ax.scatter(pts[mine, 0], pts[mine, 1], s=marker, color=colours((k - 1) % 10),
                   edgecolors="none", zorder=2, label=f"{name} ({count} atoms)")

    ax.add_patch(Polygon(region, closed=True, fill=False, edgecolor="tab:red",
                         linewidth=1.6, zorder=3, label="scan region (support)"))
    u, _ = scan_axes(data["angle"])
    arrow = 0.25 * (data["x"].max() - data["x"].min()) or 1.0
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
    if data["cutoff"]:
        note += f", cutoff {data['cutoff']:.3g} Å"
    ax.set_title(f"Crystal net and scan region: {_describe(data)}\n{note}", fontsize="medium")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.08), ncols=3, fontsize="small",
              markerscale=max(1.0, 4.0 / np.sqrt(marker)), frameon=False)
    fig.savefig(out, dpi=dpi)
    plt.close(fig)


def plot_lines(data, trip, component, offset, out, dpi):
    """Stacked lines: component against support position, line j shifted by j x offset."""
    x, y = data["x"], data["y"]
    values = data["trips"][trip][component]
    ny = y.size
    if offset is None:
        with warnings.catch_warnings():  # all-NaN lines: no peak-to-peak, no warning
            warnings.simplefilter("ignore", RuntimeWarning)
            ptp = np.nanmax(values, axis=1) - np.nanmin(values, axis=1)
        ptp = ptp[np.isfinite(ptp)]
        offset = 1.2 * float(ptp.max()) if ptp.size and ptp.max() > 0 else 1.0
    symbol, meaning = COMPONENTS[component]

    fig, ax = plt.subplots(figsize=(8, min(4.0 + 0.35 * ny, 12.0)), layout="constrained")
    cmap = plt.get_cmap("viridis")
    span = (y.max() - y.min()) or 1.0
    norm = plt.Normalize(y.min(), y.min() + span)
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
    ax.set_xlim(x.min(), x.max()) if x.size > 1 else None
    direction = "→" if trip == "trace" else "←"
    ax.set_xlabel(f"support position along the scan (Å), {trip} {direction}")
    ax.set_ylabel(f"{symbol} (nN), line j shifted up by j × {offset:.3g} nN")
    ax.set_ylim(-offset, (ny - 1) * offset + offset)
    sm = plt.cm.ScalarMappable(norm=norm, cmap=cmap)
    bar_ax = fig.colorbar(sm, ax=ax, shrink=0.5, aspect=15, pad=0.09)
    bar_ax.set_label("line offset across the scan (Å)", fontsize="small")
    ax.set_title(f"{symbol}, {meaning}, {ny} scan lines, {trip}: {_describe(data)}",
                 fontsize="medium")
    fig.savefig(out, dpi=dpi)
    plt.close(fig)
    return offset


# --------------------------------------------------------------------------
# Command line
# --------------------------------------------------------------------------


def parse_args(argv):
    parser = argparse.ArgumentParser(
        prog=PROG,
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("file", type=Path,
                        help="friction output file (HDF5, scene 'afm' with /surface)")
    parser.add_argument("--trip", choices=("trace", "retrace"), default="trace",
                        help="trip of the stacked lines (default: %(default)s)")
    parser.add_argument("--component", choices=tuple(COMPONENTS), default="fx",
                        help="force component of the stacked lines (default: %(default)s)")
    parser.add_argument("--offset", type=float, default=None, metavar="NN",
                        help="vertical shift between stacked lines, nN "
                             "(default: 1.2 x the largest peak-to-peak of the lines)")
    parser.add_argument("--margin", type=float, default=5.0, metavar="A",
                        help="net view: margin around the scan region, angstrom "
                             "(default: %(default)s)")
    parser.add_argument("--whole", action="store_true",
                        help="net view: show the whole net instead of the scan region")
    parser.add_argument("--tip-line", type=int, default=0, metavar="N",
                        help="net view: the trace line whose tip path is drawn, "
                             "0 .. ny-1 (default: %(default)s)")
    parser.add_argument("--no-tip", action="store_true",
                        help="net view: do not draw the tip path")
    parser.add_argument("-o", "--output-dir", type=Path, default=Path("."), metavar="DIR",
                        help="directory for the PNGs, created if missing (default: .)")
    parser.add_argument("--dpi", type=int, default=150, help="resolution (default: %(default)s)")
    args = parser.parse_args(argv)
    if args.dpi <= 0:
        parser.error("--dpi must be positive")
    if args.margin < 0 or not np.isfinite(args.margin):
        parser.error("--margin must be zero or positive")
    if args.offset is not None and not (args.offset > 0 and np.isfinite(args.offset)):
        parser.error("--offset must be positive")
    return args


def main(argv=None):
    args = parse_args(argv)
    try:
        data = read_file(args.file)
        ny = data["y"].size
        if args.trip not in data["trips"]:
            raise InputError(f"no /afm/{args.trip}: the run had retrace off")
        if args.component not in data["trips"][args.trip]:
            raise InputError(f"no /afm/{args.trip}/{args.component} in the file")
        tip_line = None if args.no_tip else args.tip_line
        if tip_line is not None and not 0 <= tip_line < ny:
            raise InputError(f"--tip-line {tip_line} out of range: "
                             f"the file has lines 0 .. {ny - 1}")
    except InputError as err:
        print(f"{PROG}: {args.file}: {err}", file=sys.stderr)
        return 2

    stem = args.file.stem
    net = args.output_dir / f"{stem}_net.png"
    lines = args.output_dir / f"{stem}_lines.png"
    try:
        args.output_dir.mkdir(parents=True, exist_ok=True)
        plot_net(data, net, args.dpi, args.margin, args.whole, tip_line)
        print(f"wrote {net}")
        plot_lines(data, args.trip, args.component, args.offset, lines, args.dpi)
        print(f"wrote {lines}")
    except OSError as err:
        print(f"{PROG}: cannot write into {args.output_dir}: {err}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
