"""Measured friction images: the lateral-force channels of a microscope's
file, trace and retrace, and the friction loop's reduction.

    img = friction.read_image("scan.spm", channel="Friction")   # Bruker Nanoscope
    img.trace, img.retrace          # (ny, nx) arrays in img.unit ("V")
    img.friction()                  # (trace - retrace) / 2 per pixel
    img.offset()                    # (trace + retrace) / 2 per pixel
    img.line_friction()             # the mean of each line (ny,)
    img.mean_friction()             # the image's mean
    nn = img.calibrated(12.5)       # V -> nN with 12.5 nN/V

Formats: Bruker Nanoscope (.spm, .000, .001, ...) and Nanonis (.sxm)
through pySPM, Gwyddion (.gwy) through gwyfile, numpy (.npy, .npz) and
plain text (.txt, .csv, .dat) always.  The readers of the three
instrument formats are optional dependencies, imported on first use.
Lengths are given in angstrom (the model's unit), angles in degrees.
"""
from __future__ import annotations

import math
import os
import re
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, Mapping

import numpy as np

if TYPE_CHECKING:
    import os

    from numpy.typing import ArrayLike

__all__ = ["MeasuredImage", "ImageError", "read_image", "image_from_arrays"]

_BRUKER_SUFFIX = re.compile(r"^\.(spm|\d{3})$", re.IGNORECASE)
_TEXT_SUFFIXES = (".txt", ".csv", ".dat", ".asc")
_LENGTH_TO_ANGSTROM = {"m": 1e10, "mm": 1e7, "um": 1e4, "~m": 1e4, "µm": 1e4, "nm": 10.0, "pm": 0.01,
                       "angstrom": 1.0, "a": 1.0, "å": 1.0}
# A channel title that names the backward (retrace) pass, as Gwyddion's importers write it.
_BACKWARD = re.compile(r"retrace|backward|\bbwd\b|\bback\b|reverse", re.IGNORECASE)


class ImageError(ValueError):
    """A measured image that cannot be read or used; the message names the file."""


@dataclass
class MeasuredImage:
    """A lateral-force image: trace (and retrace) of one channel.

    Parameters
    ----------
    trace : numpy.ndarray
        (ny, nx): row j the j-th line in the order the file stores it,
        column i the i-th sample along the line.
    retrace : numpy.ndarray, optional
        (ny, nx), stored by position like trace (None if absent).
    unit : str
        Of the values ("V" raw, "nN" once calibrated).
    size : tuple of float
        (along the lines, across them), angstrom.
    direction : str
        The frame's direction ("down", "up" or "").
    angle : float
        The scan angle, degrees (0 when the file has none).
    channel : str
        The channel's name.
    path : str
        The file it came from.
    format : str
        The format read.
    metadata : dict
        What else the reader found (a Bruker setpoint, ...).

    Raises
    ------
    ImageError
        Arrays that are not 2-D or differ in shape.
    """

    trace: np.ndarray
    retrace: np.ndarray = None
    unit: str = ""
    size: tuple = (float("nan"), float("nan"))
    direction: str = ""
    angle: float = 0.0
    channel: str = ""
    path: str = ""
    format: str = "arrays"
    metadata: dict = field(default_factory=dict)

    def __post_init__(self):
        self.trace = np.asarray(self.trace, dtype=float)
        if self.trace.ndim != 2:
            raise ImageError(f"{self._where()}: the trace has {self.trace.ndim} dimensions, not 2")
        if self.retrace is not None:
            self.retrace = np.asarray(self.retrace, dtype=float)
            if self.retrace.shape != self.trace.shape:
                raise ImageError(f"{self._where()}: trace {self.trace.shape} and retrace {self.retrace.shape} "
                                 "differ in shape")

    def _where(self):
        return self.path or "the image"

    @property
    def pixels(self) -> tuple[int, int]:
        """The image's size in pixels, (nx, ny).

        Returns
        -------
        tuple of int
            (nx, ny).
        """
        return (self.trace.shape[1], self.trace.shape[0])

    @property
    def mask(self) -> np.ndarray:
        """Where the pixels are valid (finite in trace and retrace).

        Returns
        -------
        numpy.ndarray
            (ny, nx) bool.
        """
        valid = np.isfinite(self.trace)
        if self.retrace is not None:
            valid &= np.isfinite(self.retrace)
        return valid

    @property
    def masked(self) -> int:
        """The number of invalid pixels.

        Returns
        -------
        int
            The count.
        """
        return int(self.mask.size - np.count_nonzero(self.mask))

    def _needs_retrace(self, what):
        if self.retrace is None:
            raise ImageError(f"{self._where()}: channel {self.channel!r} has no retrace: {what} needs both passes")

    def friction(self) -> np.ndarray:
        """(trace - retrace) / 2 per pixel: half the friction loop's width, NaN where masked.

        Returns
        -------
        numpy.ndarray
            (ny, nx).

        Raises
        ------
        ImageError
            An image without retrace.
        """
        self._needs_retrace("the friction")
        return np.where(self.mask, (self.trace - self.retrace) / 2.0, np.nan)

    def offset(self) -> np.ndarray:
        """(trace + retrace) / 2 per pixel: the loop's centre (the signal's offset, topography's cross-talk).

        Returns
        -------
        numpy.ndarray
            (ny, nx).

        Raises
        ------
        ImageError
            An image without retrace.
        """
        self._needs_retrace("the offset")
        return np.where(self.mask, (self.trace + self.retrace) / 2.0, np.nan)

    def line_friction(self) -> np.ndarray:
        """The friction of each line: the mean of (trace - retrace)/2 over its valid pixels, (ny,).

        Returns
        -------
        numpy.ndarray
            (ny,).

        Raises
        ------
        ImageError
            An image without retrace.
        """
        return _row_means(self.friction())

    def line_offset(self) -> np.ndarray:
        """The offset of each line: the mean of (trace + retrace)/2 over its valid pixels.

        Returns
        -------
        numpy.ndarray
            (ny,).

        Raises
        ------
        ImageError
            An image without retrace.
        """
        return _row_means(self.offset())

    def mean_friction(self) -> float:
        """The image's friction: the mean of (trace - retrace)/2 over its valid pixels.

        Returns
        -------
        float
            In the image's unit.

        Raises
        ------
        ImageError
            An image without retrace.
        """
        return float(np.nanmean(self.friction()))

    def mean_offset(self) -> float:
        """The image's offset: the mean of (trace + retrace)/2 over its valid pixels.

        Returns
        -------
        float
            In the image's unit.

        Raises
        ------
        ImageError
            An image without retrace.
        """
        return float(np.nanmean(self.offset()))

    def calibrated(self, factor: float, unit: str = "nN") -> MeasuredImage:
        """The image in force units: every value times `factor` (nN per V, the
        lateral sensitivity the user calibrated).

        Parameters
        ----------
        factor : float
            Units of the result per unit of the image (nN per V).
        unit : str
            The result's unit.

        Returns
        -------
        MeasuredImage
            A new image; this one is unchanged.

        Raises
        ------
        ImageError
            A factor that is 0 or not finite.
        """
        factor = float(factor)
        if not math.isfinite(factor) or factor == 0.0:
            raise ImageError(f"{self._where()}: the calibration factor must be finite and nonzero, not {factor}")
        return replace(self, trace=self.trace * factor,
                       retrace=None if self.retrace is None else self.retrace * factor, unit=unit,
                       metadata={**self.metadata, "calibration": (factor, f"{unit}/{self.unit or '1'}")})

    def __repr__(self):
        nx, ny = self.pixels
        passes = "trace and retrace" if self.retrace is not None else "trace"
        return (f"<MeasuredImage {self.channel!r} {passes}, {nx} x {ny} px, {self.size[0]:g} x {self.size[1]:g} "
                f"angstrom, {self.unit or 'no unit'}, {self.masked} masked, from {self.path or 'arrays'}>")


def _row_means(values):
    counts = np.count_nonzero(np.isfinite(values), axis=1)
    sums = np.nansum(values, axis=1)
    return np.where(counts > 0, sums / np.maximum(counts, 1), np.nan)


def image_from_arrays(trace: ArrayLike, retrace: ArrayLike | None = None, size: tuple[float, float] | None = None,
                      unit: str = "", angle: float = 0.0, direction: str = "", channel: str = "", path: str = "",
                      format: str = "arrays", metadata: Mapping[str, Any] | None = None) -> MeasuredImage:
    """A MeasuredImage from numpy arrays (size in angstrom along and across the lines).

    Parameters
    ----------
    trace : array_like
        (ny, nx).
    retrace : array_like, optional
        (ny, nx), stored by position.
    size : tuple of float, optional
        (along, across) in angstrom.
    unit : str
        Of the values.
    angle : float
        The scan angle, degrees.
    direction : str
        "down", "up" or "".
    channel : str
        The channel's name.
    path : str
        Where it came from.
    format : str
        The format read.
    metadata : dict, optional
        What else is known.

    Returns
    -------
    MeasuredImage
        The image.

    Raises
    ------
    ImageError
        Arrays not 2-D or of different shapes.
    """
    trace = np.asarray(trace, dtype=float)
    if size is None:
        size = (float("nan"), float("nan"))
    return MeasuredImage(trace, retrace, unit, tuple(float(s) for s in size), direction, float(angle), channel,
                         str(path), format, dict(metadata or {}))


def _optional(module, what, path):
    import importlib
    try:
        return importlib.import_module(module)
    except ImportError as error:
        raise ImageError(f"{path}: reading {what} files needs the Python package {module} "
                         f"(pip install {module}; or pip install 'friction[readers]'): {error}") from None


def _length(value, unit, path):
    key = unit.strip().lower()
    if key not in _LENGTH_TO_ANGSTROM:
        raise ImageError(f"{path}: the scan size's unit {unit!r} is not a length this reader knows")
    return float(value) * _LENGTH_TO_ANGSTROM[key]


def _pick(names, channel, path, kinds="channels"):
    """The name in `names` that `channel` names (exactly, else case-insensitively); None: a lateral one."""
    if channel is None:
        lateral = [n for n in names if re.search(r"friction|lateral|latdefl|lfm", n, re.IGNORECASE)]
        if not lateral:
            raise ImageError(f"{path}: no lateral-force channel among the {kinds} {names}; name one with channel=")
        return lateral[0]
    if channel in names:
        return channel
    folded = [n for n in names if n.lower() == channel.lower()]
    if folded:
        return folded[0]
    raise ImageError(f"{path}: no channel {channel!r}; the file's {kinds} are {names}")


def _signature(path, expected, what):
    """Refuse a file whose first bytes are not its format's (a reader could loop on one)."""
    with open(path, "rb") as file:
        start = file.read(64)
    if not any(start.startswith(magic) for magic in expected):
        raise ImageError(f"{path}: not a {what} file (it does not start with {expected[0].decode()!r})")


def _read_bruker(path, channel):
    _signature(path, (b"\\*File list", b"\\*EC File list", b"\\*Force file list"), "Bruker Nanoscope")
    pySPM = _optional("pySPM", "Bruker Nanoscope", path)
    try:
        scan = pySPM.Bruker(str(path))
    except Exception as error:  # pySPM raises bare Exception and struct errors on foreign files
        raise ImageError(f"{path}: not a Bruker Nanoscope file ({type(error).__name__}: {error})") from None
    layers = []
    for layer in scan.layers:
        title = layer.get(b"@2:Image Data", [b""])[0].decode("latin-1")
        quoted = re.search(r'"([^"]*)"', title)
        layers.append((quoted.group(1) if quoted else title,
                       layer.get(b"Line Direction", [b""])[0].decode("latin-1").strip().lower(), layer))
    if not layers:
        raise ImageError(f"{path}: not a Bruker Nanoscope file (no image layers)")
    names = list(dict.fromkeys(name for name, _, _ in layers))
    name = _pick(names, channel, path)
    directions = {direction for n, direction, _ in layers if n == name}
    try:
        trace = np.asarray(scan.get_channel(name, backward=False).pixels, dtype=float) \
            if "trace" in directions else None
        retrace = np.asarray(scan.get_channel(name, backward=True).pixels, dtype=float) \
            if "retrace" in directions else None
    except Exception as error:
        raise ImageError(f"{path}: channel {name!r} could not be read ({error})") from None
    if trace is None:   # a channel recorded on the retrace alone: its one pass, named as such
        trace, retrace = retrace, None
    image = scan.get_channel(name, backward=trace is None)
    real = image.size["real"]
    size = (_length(real["x"], real["unit"], path), _length(real["y"], real["unit"], path))
    layer = next(lay for n, _, lay in layers if n == name)
    direction = layer.get(b"Frame direction", [b""])[0].decode("latin-1").strip().lower()
    scanner = scan.scanners[0] if getattr(scan, "scanners", None) else {}
    # Nanoscope's "Rotate Ang." is in radians (1.5708 for a 90 degree scan).
    angle = math.degrees(float(scanner.get(b"Rotate Ang.", [b"0"])[0])) if scanner else 0.0
    metadata = {}
    header = Path(path).read_bytes()[:200000].decode("latin-1")
    setpoint = re.search(r"@2:AFMSetDeflection: V \[[^]]*\] \([^)]*\) ([-+\d.eE]+) (\w+)", header)
    if setpoint:
        metadata["setpoint"] = (float(setpoint.group(1)), setpoint.group(2))
    velocity = scanner.get(b"Tip Velocity") if scanner else None
    if velocity:
        metadata["velocity"] = (float(velocity[0]) * 1e4, "angstrom/s")   # the header's um/s
    return image_from_arrays(trace, retrace, size, str(image.zscale or ""), angle, direction, name, str(path),
                             "bruker", metadata)


def _read_sxm(path, channel):
    _signature(path, (b":NANONIS_VERSION:",), "Nanonis .sxm")
    pySPM = _optional("pySPM", "Nanonis", path)
    try:
        scan = pySPM.SXM(str(path))
        table = scan.header["DATA_INFO"]
        column = table[0].index("Name")
        names = [row[column] for row in table[1:]]
    except Exception as error:
        raise ImageError(f"{path}: not a Nanonis .sxm file ({type(error).__name__}: {error})") from None
    name = _pick(names, channel, path)
    row = table[1 + names.index(name)]
    both = row[table[0].index("Direction")] == "both"
    trace = np.asarray(scan.get_channel(name, direction="forward").pixels, dtype=float)
    # Nanonis stores the backward pass in the order it was scanned: reversed along the line.
    retrace = np.asarray(scan.get_channel(name, direction="backward").pixels, dtype=float)[:, ::-1] \
        if both else None
    direction = (scan.header.get("SCAN_DIR", [[""]])[0] or [""])[0].lower()
    if direction == "up":   # rows from the bottom: the first line scanned is the last row stored
        trace = trace[::-1]
        retrace = None if retrace is None else retrace[::-1]
    angle = float(scan.header.get("SCAN_ANGLE", [["0"]])[0][0])
    real = scan.size["real"]
    unit = row[table[0].index("Unit")] if "Unit" in table[0] else ""
    return image_from_arrays(trace, retrace, (real["x"] * 1e10, real["y"] * 1e10), unit, angle, direction, name,
                             str(path), "nanonis")


def _read_gwy(path, channel):
    _signature(path, (b"GWYP",), "Gwyddion .gwy")
    gwyfile = _optional("gwyfile", "Gwyddion", path)
    try:
        container = gwyfile.load(str(path))
        fields = {}
        for key in container.keys():
            match = re.fullmatch(r"/(\d+)/data", key)
            if match:
                title = container.get(f"/{match.group(1)}/data/title", f"channel {match.group(1)}")
                fields[str(title)] = container[key]
    except Exception as error:
        raise ImageError(f"{path}: not a Gwyddion .gwy file ({type(error).__name__}: {error})") from None
    if not fields:
        raise ImageError(f"{path}: the Gwyddion file holds no data field")
    forward = [t for t in fields if not _BACKWARD.search(t)]
    base = _pick(forward or list(fields), channel, path)
    stem = _BACKWARD.sub("", base).strip(" ()-_[]")
    backward = [t for t in fields if _BACKWARD.search(t) and _BACKWARD.sub("", t).strip(" ()-_[]") == stem]
    trace_field = fields[base]
    trace = np.asarray(trace_field.data, dtype=float)
    retrace = np.asarray(fields[backward[0]].data, dtype=float) if backward else None
    unit = ""
    if getattr(trace_field, "si_unit_z", None) is not None:
        unit = trace_field.si_unit_z.get("unitstr", "") or ""
    size = (float(trace_field.xreal) * 1e10, float(trace_field.yreal) * 1e10)   # Gwyddion keeps metres
    return image_from_arrays(trace, retrace, size, unit, 0.0, "", base, str(path), "gwyddion")


def _read_numpy(path, channel):
    try:
        if path.suffix.lower() == ".npy":
            data = np.load(path, allow_pickle=False)
            arrays = {"trace": data[0], "retrace": data[1]} if data.ndim == 3 and data.shape[0] == 2 else \
                {"trace": data}
            meta = {}
        else:
            with np.load(path, allow_pickle=False) as archive:
                arrays = {k: archive[k] for k in archive.files}
            meta = {}
    except Exception as error:
        raise ImageError(f"{path}: not a numpy file ({type(error).__name__}: {error})") from None
    prefix = "" if channel is None else channel.rstrip("/") + "/"
    trace_key, retrace_key = prefix + "trace", prefix + "retrace"
    if trace_key not in arrays:
        raise ImageError(f"{path}: no array {trace_key!r}; the file holds {sorted(arrays)}")
    size = tuple(float(v) for v in arrays["size"]) if "size" in arrays else None
    angle = float(arrays["angle"]) if "angle" in arrays else 0.0
    unit = str(arrays["unit"]) if "unit" in arrays else ""
    return image_from_arrays(arrays[trace_key], arrays.get(retrace_key), size, unit, angle, "",
                             channel or "", str(path), "numpy", meta)


def _read_text(path, channel, retrace):
    def table(file):
        delimiter = "," if file.suffix.lower() == ".csv" else None
        try:
            return np.loadtxt(file, delimiter=delimiter, comments="#", ndmin=2)
        except (ValueError, OSError) as error:
            raise ImageError(f"{file}: not a plain-text table of numbers ({error})") from None
    trace = table(path)
    back = table(Path(retrace)) if retrace is not None else None
    return image_from_arrays(trace, back, None, "", 0.0, "", channel or "", str(path), "text")


def read_image(path: str | os.PathLike[str], channel: str | None = None,
               retrace: str | os.PathLike[str] | None = None, calibration: float | None = None,
               size: tuple[float, float] | None = None) -> MeasuredImage:
    """A lateral-force image from a microscope's file.

    Parameters
    ----------
    path : str or os.PathLike
        .spm or .000-.999 (Bruker Nanoscope, pySPM), .sxm (Nanonis, pySPM),
        .gwy (Gwyddion, gwyfile), .npy ((ny, nx) or (2, ny, nx): trace and
        retrace), .npz (arrays "trace", "retrace", optional "size", "angle",
        "unit"; with channel "fy": "fy/trace", "fy/retrace"), or text (.txt,
        .dat, .asc whitespace, .csv commas: one (ny, nx) table, the trace).
    channel : str, optional
        The channel's name ("Friction"); None: the first lateral one (a name
        with friction, lateral, LFM).
    retrace : str or os.PathLike, optional
        For a text file, the file of the retrace.
    calibration : float, optional
        nN per unit of the file's values (V): the image returned in nN
        (MeasuredImage.calibrated).
    size : tuple of float, optional
        (along, across) in angstrom, for files that carry none.

    Returns
    -------
    MeasuredImage
        Trace and retrace of the channel.

    Raises
    ------
    ImageError
        Naming the file: a missing file or channel, a format not among these,
        a file whose content is not its format's, a reader package that is
        not installed.
    """
    path = Path(os.fspath(path))
    if not path.is_file():
        raise ImageError(f"{path}: no such file")
    suffix = path.suffix.lower()
    if _BRUKER_SUFFIX.match(suffix):
        image = _read_bruker(path, channel)
    elif suffix == ".sxm":
        image = _read_sxm(path, channel)
    elif suffix == ".gwy":
        image = _read_gwy(path, channel)
    elif suffix in (".npy", ".npz"):
        image = _read_numpy(path, channel)
    elif suffix in _TEXT_SUFFIXES:
        image = _read_text(path, channel, retrace)
    else:
        raise ImageError(f"{path}: {suffix or 'no extension'} is not a format read_image knows (Bruker .spm or "
                         ".000-.999, Nanonis .sxm, Gwyddion .gwy, numpy .npy/.npz, text .txt/.dat/.asc/.csv)")
    if size is not None:
        image.size = tuple(float(s) for s in size)
    if calibration is not None:
        image = image.calibrated(calibration)
    return image
