"""Jobs and computations: run(), Config, afm_line(), brake(), compute().

The library's job runs the program's whole computation (every group: &analysis,
&verify, &sweep) on this process and writes the program's HDF5 file; the
computations return numpy arrays without a file.
"""
from __future__ import annotations

import os
import re
import sys
import time
from collections import namedtuple
from pathlib import Path
from typing import Any, Callable, Mapping, Sequence, Union

import numpy as np

from . import _capi

__all__ = ["Config", "run", "afm_line", "brake", "compute", "Line"]

#: A file's name or path.
PathLike = Union[str, "os.PathLike[str]"]
#: What `progress` takes: True (a bar), False (nothing) or a callable (message, fraction).
Progress = Union[bool, Callable[[str, float], Any]]

Line = namedtuple("Line", "x fx fy")
Line.__doc__ = """One scan line.

Parameters
----------
x : numpy.ndarray
    Support positions along the scan (angstrom).
fx : numpy.ndarray
    Lateral force along the lattice's x axis there (nN).
fy : numpy.ndarray
    Lateral force along the lattice's y axis there (nN).
"""


class _TextProgress:
    """Progress as plain lines on a stream: at most one every `interval`
    seconds, the last one always; notes at once."""

    def __init__(self, label, stream=None, interval=2.0):
        self.label, self.stream, self.interval = label, stream or sys.stderr, interval
        self.last = -float("inf")

    def __call__(self, message, fraction):
        if fraction < 0:
            print(f"{self.label}: {message}", file=self.stream, flush=True)
            return
        now = time.monotonic()
        if now - self.last >= self.interval or fraction >= 1.0:
            self.last = now
            print(f"{self.label}: {message} ({100 * fraction:.0f} %)", file=self.stream, flush=True)

    def close(self):
        pass


class _TqdmProgress:
    """Progress as a tqdm bar in percent, the library's message beside it; notes above it."""

    def __init__(self, tqdm, label):
        self.tqdm = tqdm
        self.bar = tqdm(total=100, desc=label, unit="%", bar_format="{l_bar}{bar}| [{elapsed}<{remaining}{postfix}]")

    def __call__(self, message, fraction):
        if fraction < 0:
            self.tqdm.write(message)
            return
        self.bar.set_postfix_str(message, refresh=False)
        self.bar.update(round(100 * fraction, 2) - self.bar.n)

    def close(self):
        self.bar.close()


def _progress(progress, label):
    """The reporter for run()'s `progress`: None, a callable, or a bar (tqdm or text)."""
    if progress is None or progress is False:
        return None
    if callable(progress):
        return progress
    if progress is not True:
        raise TypeError(f"progress must be True, False or a callable (message, fraction), not {progress!r}")
    try:
        from tqdm.auto import tqdm
    except ImportError:
        return _TextProgress(label)
    return _TqdmProgress(tqdm, label)


def _job(start, progress, label):
    """start(report): a job or computation of the C API, which raises an
    exception of the report after it, and takes Ctrl-C (_capi._Stoppable);
    its value."""
    reporter = _progress(progress, label)
    try:
        return start(reporter)
    finally:
        if hasattr(reporter, "close"):
            reporter.close()


def _files(files):
    if isinstance(files, (str, os.PathLike)):
        return [Path(files)]
    return [Path(f) for f in files]


def run(files: PathLike | Sequence[PathLike], output: PathLike | None = None, force: bool = False,
        resume: bool = False, progress: Progress = True) -> Path:
    """Run a job as the program does, to its HDF5 file.

    Read the namelist files in order (a later file overrides earlier values
    variable by variable), compute the scene or sweep they describe on this
    process, write the HDF5 file (under a temporary name, renamed when
    complete).  Ctrl-C stops the job at its next scan line or sweep point and
    raises KeyboardInterrupt, its context a FrictionError with status 5: a
    sweep's file holds the points done, a map keeps the lines done beside the
    output; resume=True computes only the rest.

    MPI: in a process without MPI the job runs serially on this process,
    without starting MPI (the same file as `mpirun -n 1`); under
    `mpirun -n N python ...` with mpi4py initialising MPI first, the job is
    collective over every rank, as the program's.

    Parameters
    ----------
    files : str or os.PathLike or sequence of them
        A namelist file or a list of them.
    output : str or os.PathLike, optional
        The HDF5 file (default: the first file's name with .h5, in the
        current directory, as the program's).
    force : bool
        Overwrite an existing output.
    resume : bool
        A sweep or map reuses the checkpoints of an interrupted run.
    progress : bool or callable
        True: a tqdm bar where tqdm is installed, else a line on stderr every
        2 s; False: nothing; a callable: called with (message, fraction),
        fraction in [0, 1] for progress ("12 of 64 lines") and -1 for notes.

    Returns
    -------
    pathlib.Path
        The output file.

    Raises
    ------
    FrictionError
        Bad input (the program's message, with file and line), a failed
        integration or an unwritable file, or an existing output without force:
        nothing is written then.
    ValueError
        No file.
    KeyboardInterrupt
        Ctrl-C, after the job stopped.

    Examples
    --------
    >>> path = friction.run(friction.input_file("naf.nml"), "naf.h5", force=True)  # doctest: +SKIP
    """
    paths = _files(files)
    if not paths:
        raise ValueError("run() needs at least one namelist file")
    output = Path(output) if output is not None else Path.cwd() / (paths[0].stem + ".h5")
    _job(lambda report: _capi.run_job(paths, output, force=force, resume=resume, report=report),
         progress, output.name)
    return output


_LOGICAL = {".true.": True, ".false.": False, "t": True, "f": False, ".t.": True, ".f.": False}


def _parse_item(item, kind):
    item = item.strip()
    if kind == "text":
        if len(item) >= 2 and item[0] == item[-1] and item[0] in "'\"":
            return item[1:-1].replace(item[0] * 2, item[0])
        return item
    if kind == "logical":
        return _LOGICAL[item.lower()]
    if kind == "integer":
        return int(item)
    return float(item.lower().replace("d", "e"))


def _split_items(text):
    """Namelist value items, commas outside quotes, "n*value" repeats expanded."""
    items, current, quote = [], "", None
    for ch in text:
        if quote:
            current += ch
            if ch == quote:
                quote = None
        elif ch in "'\"":
            quote = ch
            current += ch
        elif ch == ",":
            items.append(current)
            current = ""
        else:
            current += ch
    items.append(current)
    expanded = []
    for item in (i.strip() for i in items):
        repeat = re.fullmatch(r"(\d+)\*(.*)", item)
        if repeat and not item.startswith(("'", '"')):
            expanded += [repeat.group(2)] * int(repeat.group(1))
        elif item:
            expanded.append(item)
    return expanded


class Config(_capi.Config):
    """A scene's configuration: its defaults, namelist files read over them
    and values set by name, checked by the program's own checks.

        cfg = friction.Config("afm", files=["inputs/naf.nml"], values={"scan.ny": 4})
        cfg.set("tip.kx", 5.0).set("surface.potential", "hopg")
        cfg["scan.nx"] = 64                  # the same as set()
        cfg["scan.nx"]                       # 64: the value as Python (value())
        cfg.get("scan.nx")                   # '64': namelist text
        line = cfg.afm_line(0)               # Line(x, fx, fy) of the map's line 0, trace
        maps = cfg.compute()                 # {"trace/fx": (ny, nx) array, ..., "support_x": ...}
        cfg.run("naf.h5", force=True)        # the job with every group, to a file

    Units are those of the namelist input.

    Parameters
    ----------
    scene : str
        "afm" (a friction-force map) or "brake" (the Girling brake).
    files : str or os.PathLike or sequence of them
        Namelist files read in order over the defaults.
    values : dict, optional
        {"group.variable": value} set after them.

    Raises
    ------
    FrictionError
        An unknown scene, a file or value the program refuses.
    """

    def __init__(self, scene: str = "afm", files: PathLike | Sequence[PathLike] = (),
                 values: Mapping[str, Any] | None = None) -> None:
        """Read the files over the scene's defaults, then set the values.
        """
        super().__init__(scene, files, values)

    def kinds(self) -> dict[str, tuple[str, int, str]]:
        """{name: (kind, elements, unit)} of every variable.

        Returns
        -------
        dict
            {name: (kind, elements, unit)}.
        """
        return {name: (kind, size, unit) for name, kind, size, unit in self.names()}

    def value(self, name: str) -> Any:
        """A variable's value as Python: float, int, bool, str, or a list of
        them for an array variable ("surface.sigma").

        Parameters
        ----------
        name : str
            "group.variable" or "group.variable(k)".

        Returns
        -------
        float or int or bool or str or list
            The value; one element for name(k).

        Raises
        ------
        FrictionError
            An unknown name.
        """
        base = re.sub(r"\(\d+\)$", "", name)
        kinds = self.kinds()
        if base not in kinds:
            self.get(name)   # the library's message for an unknown name
        kind, size, _ = kinds[base]
        items = [_parse_item(item, kind) for item in _split_items(self.get(name))]
        if size == 1 or base != name:
            return items[0] if items else None
        return items

    def unit(self, name: str) -> str:
        """The unit of "group.variable" ('N/m', 'angstrom', '' for none).

        Parameters
        ----------
        name : str
            "group.variable".

        Returns
        -------
        str
            The unit.

        Raises
        ------
        KeyError
            An unknown name.
        """
        return self.kinds()[re.sub(r"\(\d+\)$", "", name)][2]

    def __getitem__(self, name):
        return self.value(name)

    def __setitem__(self, name, value):
        self.set(name, value)

    def support_x(self) -> np.ndarray:
        """The support positions along a scan line (angstrom), as /afm/support_x.

        Returns
        -------
        numpy.ndarray
            scan.nx positions (angstrom).
        """
        nx, length = int(self.value("scan.nx")), float(self.value("scan.length"))
        return length * np.arange(nx, dtype=float) / float(nx - 1)

    def afm_line(self, line: int = 0, forward: bool = True, progress: Progress = False) -> Line:
        """Line `line` (0-based) of the map, trace (forward) or retrace: a Line
        (x, fx, fy), exactly the file's line of /afm/trace (/afm/retrace), with
        or without `progress`.  A callable `progress(message, fraction)` is
        called from inside a line that takes longer than 0.1 s, every 0.1 s
        ("started", fraction -1), and once when the line is done ("1 of 1
        lines", 1.0); an exception it raises inside the line stops the line
        there (within 1 ms for the Langevin tip and the reduced model) and is
        raised, its context a FrictionError with status 5. Ctrl-C stops a line
        the same way, with or without `progress`, and raises
        KeyboardInterrupt. Nothing is returned then, and the Config stays as
        it was, its kept surface too.

        Parameters
        ----------
        line : int
            The line, 0-based.
        forward : bool
            Trace (True) or retrace.
        progress : bool or callable
            False (the default), True (a tqdm bar or a line on stderr at the
            line's end) or a callable (message, fraction), also given the polls.

        Returns
        -------
        Line
            (x, fx, fy): angstrom, nN, nN.

        Raises
        ------
        FrictionError
            The library's refusal: the program's message (file, line, group, variable) and status.
        ValueError
            A line beyond C's int.
        KeyboardInterrupt
            Ctrl-C, after the line stopped.

        Examples
        --------
        >>> x, fx, fy = friction.Config("afm", files=["inputs/naf.nml"]).afm_line(0)  # doctest: +SKIP
        >>> line = cfg.afm_line(0, progress=lambda message, fraction: print(message))  # doctest: +SKIP
        """
        if callable(progress):
            fx, fy = _capi.Config.afm_line(self, line, forward, report=progress, polls=True)
        else:
            fx, fy = _job(lambda report: _capi.Config.afm_line(self, line, forward, report=report), progress,
                          f"line {line}")
        return Line(self.support_x(), fx, fy)

    def run(self, output: PathLike, force: bool = False, resume: bool = False, progress: Progress = True) -> Path:
        """The configuration's job (every group: &analysis, &verify, &sweep) to
        the HDF5 file `output`, whose `input` attribute is text(); arguments
        and MPI as friction.run().  Returns the output's Path.

        Parameters
        ----------
        output : str or os.PathLike
            The HDF5 file.
        force : bool
            Overwrite an existing output.
        resume : bool
            Reuse an interrupted run's checkpoints.
        progress : bool or callable
            As friction.run().

        Returns
        -------
        pathlib.Path
            The output file.

        Raises
        ------
        FrictionError
            The library's refusal: the program's message (file, line, group, variable) and status.
        KeyboardInterrupt
            Ctrl-C, after the job stopped.
        """
        output = Path(output)
        _job(lambda report: _capi.Config.run(self, output, force=force, resume=resume, report=report),
             progress, output.name)
        return output

    def compute(self, progress: Progress = False) -> dict[str, np.ndarray]:
        """The whole scene on this process, without a file: a dict of numpy
        arrays named as in the program's file (compute()).  progress: False
        (the default: a fit calls this often), True (a tqdm bar or a line on
        stderr every 2 s), or a callable (message, fraction), called after
        each scan line of a map ("12 of 48 lines") and 200 times along a
        brake trajectory.  Ctrl-C stops the computation at its next report
        and raises KeyboardInterrupt, its context a FrictionError with
        status 5; the Config stays as it was, ready for the next call.

        Parameters
        ----------
        progress : bool or callable
            False (the default), True, or a callable (message, fraction).

        Returns
        -------
        dict of str to numpy.ndarray
            The arrays.

        Raises
        ------
        FrictionError
            The library's refusal: the program's message (file, line, group, variable) and status.
        KeyboardInterrupt
            Ctrl-C, after the computation stopped.
        """
        return _job(lambda report: _capi.Config.compute(self, report=report), progress, self.scene)

    def __repr__(self):
        state = "closed" if not self._handle else f"{len(self.names())} variables"
        return f"<friction.Config {self.scene}: {state}>"


def compute(scene: str, files: PathLike | Sequence[PathLike] = (), values: Mapping[str, Any] | None = None,
            progress: Progress = False) -> dict[str, np.ndarray]:
    """The scene's computation on this process, without a file: a dict of
    numpy arrays named as in the program's file ("trace/fx" (ny, nx), ...,
    "support_x"; "t", "x", ..., "events/t").  &analysis, &verify and &sweep
    are for jobs (run()): a &sweep or &verify check = .true. is refused.
    progress and Ctrl-C as Config.compute().

    Parameters
    ----------
    scene : str
        "afm" or "brake".
    files : str or os.PathLike or sequence of them
        Namelist files, read in order.
    values : dict, optional
        {"group.variable": value} set after them.
    progress : bool or callable
        As Config.compute().

    Returns
    -------
    dict of str to numpy.ndarray
        The arrays.

    Raises
    ------
    FrictionError
        The library's refusal: the program's message (file, line, group, variable) and status.
    """
    with Config(scene, files, values) as cfg:
        return cfg.compute(progress)


def afm_line(files: PathLike | Sequence[PathLike] = (), values: Mapping[str, Any] | None = None, line: int = 0,
             forward: bool = True, progress: Progress = False) -> Line:
    """One line of a friction-force map: Line(x, fx, fy), numpy arrays.

        x, fx, fy = friction.afm_line("inputs/naf.nml", {"scan.nx": 64})

    Parameters
    ----------
    files : str or os.PathLike or sequence of them
        Namelist files, read in order.
    values : dict, optional
        {"group.variable": value} set after them.
    line : int
        The line, 0-based.
    forward : bool
        Trace (True) or retrace.
    progress : bool or callable
        As Config.afm_line(): a callable is also polled inside a long line,
        and an exception it raises there stops the line.

    Returns
    -------
    Line
        (x, fx, fy): angstrom, nN, nN.

    Raises
    ------
    FrictionError
        The library's refusal: the program's message (file, line, group, variable) and status.
    KeyboardInterrupt
        Ctrl-C, after the line stopped.
    """
    with Config("afm", files, values) as cfg:
        return cfg.afm_line(line, forward, progress)


def brake(files: PathLike | Sequence[PathLike] = (), values: Mapping[str, Any] | None = None,
          progress: Progress = False) -> dict[str, np.ndarray]:
    """A Girling brake run: a dict of numpy arrays, the trajectory "t", "x",
    "v", "y", "w", "stick" on the output grid and the events "events/t",
    "events/kind", "events/x", ... (as /brake of the program's file).

        run = friction.brake(values={"brake.t_end": 300.0})

    progress and Ctrl-C as Config.compute().

    Parameters
    ----------
    files : str or os.PathLike or sequence of them
        Namelist files, read in order.
    values : dict, optional
        {"group.variable": value} set after them.
    progress : bool or callable
        As Config.compute().

    Returns
    -------
    dict of str to numpy.ndarray
        The trajectory and events.

    Raises
    ------
    FrictionError
        The library's refusal: the program's message (file, line, group, variable) and status.
    """
    return compute("brake", files, values, progress)
