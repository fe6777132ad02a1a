"""ctypes binding of the friction C API (include/friction.h, API version 2).

The low layer of the package: the library's functions with their C
signatures, the error handle, configurations and results as Python objects.
`friction.Config` and `friction.run` build on it; import it directly only
for what they leave out.

    from friction import _capi

    with _capi.Config("afm", files=["inputs/naf.nml"]) as cfg:
        cfg.set("tip.kx", 5.0)                  # numbers, True/False, text, lists
        cfg.set("scan.nx", 64)
        cfg.set("surface.potential", "hopg")    # text is quoted for you; set_text takes namelist text
        fx, fy = cfg.afm_line(0)                # line 0 of the map, trace (forward=False: retrace)
        maps = cfg.compute()                    # dict of numpy arrays: maps["trace/fx"] is (ny, nx)

    run = _capi.Config("brake", values={"brake.t_end": 100.0}).compute()   # run["t"], run["x"], ...
    _capi.run_job(["inputs/naf.nml"], "naf.h5", force=True,
                  report=lambda message, fraction: print(message))  # the program's job, no MPI launcher

A configuration has its scene's defaults and the variables of the namelist
input, by "group.variable" ("tip.kx", "surface.sigma(2)"), in its units
(README: Input reference).  Every value is checked by the scene's own checks,
as the program checks its input; a call the library refuses raises
FrictionError with the library's status and message.  A Config is freed with
close(), at the end of a `with` block, or when it is collected.  ctypes
releases the GIL during each call, so different Config objects compute at
once in different threads; one Config must not be used by two threads at
once.

The library is loaded on first use (importing the package needs no library),
from the first of (find_library):
  1. the file named by the environment variable FRICTION_LIBRARY (and only it);
  2. the library of the installation the package was installed into by
     `cmake --install` (PREFIX/share/friction/python/friction ->
     PREFIX/lib/libfriction.so.0, recorded in friction/_installed.py);
  3. the library of the build the package was installed from with pip
     (the clone's build/libfriction.so.0, recorded in friction/_built.py);
  4. build/libfriction.so.0 of a build tree: the package's folder and each
     folder above it are searched for build/ (python/friction in the
     repository -> the repository's build/);
  5. the system's loader (LD_LIBRARY_PATH, ldconfig's cache): libfriction.so.0.
A library of another C API version is refused.
"""
from __future__ import annotations

import ctypes
import ctypes.util
import numbers
import operator
import os
import signal
import threading
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["FrictionError", "LibraryNotFoundError", "Config", "library", "library_path", "find_library",
           "library_candidates", "version", "api_version", "run_job", "API_VERSION", "SONAME"]

API_VERSION = 2   # the C API this module is written for (FRICTION_API_VERSION)
SONAME = "libfriction.so.0"

# void report(const char *message, double fraction, void *user)
_REPORT = ctypes.CFUNCTYPE(None, ctypes.c_char_p, ctypes.c_double, ctypes.c_void_p)
# int progress(const char *message, double fraction, void *user): nonzero stops
_PROGRESS = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_char_p, ctypes.c_double, ctypes.c_void_p)
FORCE, RESUME, INIT_MPI = 1, 2, 4
# Statuses (friction.h)
OK, ERROR_INPUT, ERROR_NUMERICAL, ERROR_IO, ERROR_INTERNAL, INTERRUPTED = 0, 1, 2, 3, 4, 5


class FrictionError(RuntimeError):
    """A call the library refused or could not finish.

    Parameters
    ----------
    status : int
        Its code: 1 input, 2 numerical, 3 I/O, 4 internal, 5 stopped on request.
    message : str
        The library's message.
    """

    def __init__(self, status: int, message: str) -> None:
        """The status and the message, as the library gave them.
        """
        super().__init__(f"{message} (status {status})")
        self.status = status
        self.message = message


class LibraryNotFoundError(OSError):
    """No libfriction could be loaded; the message lists where the package looked."""


_PACKAGE_DIR = Path(__file__).resolve().parent


def _installed_candidates(package_dir):
    """The library of the installation `cmake --install` put the package in, if it did."""
    record = package_dir / "_installed.py"
    if not record.is_file():
        return []
    namespace = {}
    exec(compile(record.read_text(), str(record), "exec"), namespace)  # our own generated file
    found = []
    if namespace.get("LIBRARY_RELATIVE"):
        found.append(("the installation beside the package", str((package_dir / namespace["LIBRARY_RELATIVE"]))))
    if namespace.get("LIBRARY_ABSOLUTE"):
        found.append(("the installation the package was installed from", namespace["LIBRARY_ABSOLUTE"]))
    return found


def _built_candidates(package_dir):
    """The library of the build the package was installed from by pip (setup.py's record)."""
    record = package_dir / "_built.py"
    if not record.is_file():
        return []
    namespace = {}
    exec(compile(record.read_text(), str(record), "exec"), namespace)  # our own generated file
    return [("the build the package was installed from", namespace["LIBRARY"])] if namespace.get("LIBRARY") else []


def library_candidates(environ=None, package_dir=None):
    """Where the library is looked for, in order: a list of (what, path).

    The last entry, ("the system's loader", SONAME), has no folder: the
    dynamic loader's own search."""
    environ = os.environ if environ is None else environ
    package_dir = Path(package_dir or _PACKAGE_DIR).resolve()
    if environ.get("FRICTION_LIBRARY"):
        return [("FRICTION_LIBRARY", environ["FRICTION_LIBRARY"])]
    found = _installed_candidates(package_dir) + _built_candidates(package_dir)
    for folder in (package_dir, *package_dir.parents):
        found.append(("a build tree", str(folder / "build" / SONAME)))
    found.append(("the system's loader", SONAME))
    return found


def find_library(environ=None, package_dir=None):
    """The path (or, for the system's loader, the name) of the library to load;
    LibraryNotFoundError with every place tried."""
    tried = []
    for what, path in library_candidates(environ, package_dir):
        if what == "the system's loader":
            try:
                ctypes.CDLL(path)
                return path
            except OSError:
                pass
            located = ctypes.util.find_library("friction")
            if located:
                return located
            tried.append(f"{what}: {path} (LD_LIBRARY_PATH, ldconfig)")
        elif os.path.isfile(path):
            return path
        else:
            tried.append(f"{what}: {path}")
    raise LibraryNotFoundError(
        "libfriction not found; set FRICTION_LIBRARY to the library (for example build/libfriction.so.0 "
        "after scripts/build) or install friction with `cmake --install`. Looked in:\n  " + "\n  ".join(tried))


def _signatures(lib):
    c_int, c_size_t, c_char_p, c_void_p, c_double = (ctypes.c_int, ctypes.c_size_t, ctypes.c_char_p,
                                                     ctypes.c_void_p, ctypes.c_double)
    size_p = ctypes.POINTER(c_size_t)
    signatures = {
        "friction_version": (c_int, [c_char_p, c_size_t]),
        "friction_api_version": (c_int, []),
        "friction_error_new": (c_void_p, []),
        "friction_error_free": (None, [c_void_p]),
        "friction_error_status": (c_int, [c_void_p]),
        "friction_error_message": (c_int, [c_void_p, c_char_p, c_size_t]),
        "friction_config_new": (c_void_p, [c_char_p, c_void_p]),
        "friction_config_free": (None, [c_void_p]),
        "friction_config_read": (c_int, [c_void_p, c_char_p, c_void_p]),
        "friction_config_set": (c_int, [c_void_p, c_char_p, c_char_p, c_void_p]),
        "friction_config_set_real": (c_int, [c_void_p, c_char_p, c_double, c_void_p]),
        "friction_config_get": (c_int, [c_void_p, c_char_p, c_char_p, c_size_t, c_void_p]),
        "friction_config_text": (c_int, [c_void_p, c_char_p, c_size_t, size_p]),
        "friction_config_names": (c_int, [c_void_p, c_char_p, c_size_t, size_p]),
        "friction_config_check": (c_int, [c_void_p, c_void_p]),
        "friction_config_warnings": (c_int, [c_void_p, c_char_p, c_size_t, size_p]),
        "friction_afm_line": (c_int, [c_void_p, c_int, c_int, c_void_p, c_void_p, c_size_t, c_void_p]),
        "friction_afm_line_progress": (c_int, [c_void_p, c_int, c_int, c_void_p, c_void_p, c_size_t, _PROGRESS,
                                               c_void_p, c_void_p]),
        "friction_compute": (c_void_p, [c_void_p, c_void_p]),
        "friction_compute_progress": (c_void_p, [c_void_p, _PROGRESS, c_void_p, c_void_p]),
        "friction_result_get": (c_int, [c_void_p, c_char_p, c_void_p, c_size_t, size_p, c_void_p]),
        "friction_result_shape": (c_int, [c_void_p, c_char_p, ctypes.POINTER(c_size_t * 2), c_void_p]),
        "friction_result_names": (c_int, [c_void_p, c_char_p, c_size_t]),
        "friction_result_free": (None, [c_void_p]),
        "friction_run_job": (c_int, [ctypes.POINTER(c_char_p), c_int, c_char_p, c_int, _REPORT, c_void_p,
                                     c_void_p]),
        "friction_run_config": (c_int, [c_void_p, c_char_p, c_int, _REPORT, c_void_p, c_void_p]),
        "friction_job_stop": (None, []),
        "friction_law_new": (c_void_p, [c_char_p, c_void_p]),
        "friction_law_free": (None, [c_void_p]),
        "friction_law_set": (c_int, [c_void_p, c_char_p, c_char_p, c_void_p]),
        "friction_law_set_real": (c_int, [c_void_p, c_char_p, c_double, c_void_p]),
        "friction_law_get": (c_int, [c_void_p, c_char_p, c_char_p, c_size_t, c_void_p]),
        "friction_law_check": (c_int, [c_void_p, c_void_p]),
        "friction_law_state_count": (c_int, [c_void_p, c_void_p]),
        "friction_law_history": (c_int, [c_void_p, c_double, c_void_p, c_void_p, c_size_t, c_int, c_void_p,
                                         c_void_p, c_size_t, c_void_p]),
    }
    for name, (restype, argtypes) in signatures.items():
        function = getattr(lib, name, None)
        if function is None:   # a library of API version 2 built before the function came
            raise LibraryNotFoundError(f"{lib._name}: libfriction without {name}, older than this package; "
                                       "build the library of this package's version (scripts/build)")
        function.restype = restype
        function.argtypes = argtypes


def _open(path):
    lib = ctypes.CDLL(path)
    if not hasattr(lib, "friction_api_version"):
        raise LibraryNotFoundError(f"{path}: a libfriction of API version 1; this package needs API version "
                                   f"{API_VERSION}")
    lib.friction_api_version.restype = ctypes.c_int
    if lib.friction_api_version() != API_VERSION:
        raise LibraryNotFoundError(f"{path}: libfriction of API version {lib.friction_api_version()}; this "
                                   f"package needs {API_VERSION}")
    _signatures(lib)
    return lib


_loaded = None
_loaded_path = None
_lock = threading.Lock()


def library():
    """The loaded library (ctypes.CDLL), loaded on the first call (find_library)."""
    global _loaded, _loaded_path
    if _loaded is None:
        with _lock:
            if _loaded is None:
                path = find_library()
                _loaded = _open(path)
                _loaded_path = path
    return _loaded


def library_path() -> str:
    """The file the library was loaded from (loading it if need be).

    Returns
    -------
    str
        Its real path.

    Raises
    ------
    LibraryNotFoundError
        No library could be loaded.
    """
    library()
    if os.path.sep in _loaded_path:
        return os.path.realpath(_loaded_path)

    # Loaded by name through the system's loader: ask the loader for the file.
    class DlInfo(ctypes.Structure):
        _fields_ = [("dli_fname", ctypes.c_char_p), ("dli_fbase", ctypes.c_void_p),
                    ("dli_sname", ctypes.c_char_p), ("dli_saddr", ctypes.c_void_p)]

    dladdr = ctypes.CDLL(None).dladdr
    dladdr.argtypes = [ctypes.c_void_p, ctypes.POINTER(DlInfo)]
    record = DlInfo()
    if dladdr(ctypes.cast(library().friction_version, ctypes.c_void_p), ctypes.byref(record)) and record.dli_fname:
        return os.path.realpath(record.dli_fname.decode())
    return _loaded_path


def version():
    """The library's version string ("major.minor.patch")."""
    buf = ctypes.create_string_buffer(64)
    library().friction_version(buf, len(buf))
    return buf.value.decode()


def api_version() -> int:
    """The library's C API version (FRICTION_API_VERSION).

    Returns
    -------
    int
        The version.

    Raises
    ------
    LibraryNotFoundError
        No library could be loaded.
    """
    return library().friction_api_version()


class _ErrorHandle:
    """A friction_error for one call; check() turns a failure into FrictionError."""

    def __enter__(self):
        self.lib = library()
        self.handle = self.lib.friction_error_new()
        if not self.handle:
            raise MemoryError("friction_error_new")
        return self

    def __exit__(self, *exc):
        self.lib.friction_error_free(self.handle)

    def check(self, status):
        if status != 0:
            buf = ctypes.create_string_buffer(4096)
            self.lib.friction_error_message(self.handle, buf, len(buf))
            raise FrictionError(status, buf.value.decode(errors="replace"))

    def status(self):
        return self.lib.friction_error_status(self.handle)


def _call(function, *args):
    """Call with a fresh error handle as the last argument; raise FrictionError on failure."""
    with _ErrorHandle() as err:
        err.check(function(*args, err.handle))


def _quote(text):
    return "'" + str(text).replace("'", "''") + "'"


def _item(value):
    if isinstance(value, (bool, np.bool_)):
        return ".true." if value else ".false."
    if isinstance(value, numbers.Integral):
        return str(int(value))
    if isinstance(value, numbers.Real):
        return repr(float(value))
    if isinstance(value, (list, tuple, np.ndarray)):
        # A whole array (&law element_stiffness): its items, comma-separated.
        return ", ".join(_item(item) for item in value)
    return _quote(value)


def _c_text(text, what):
    """Text for a char * argument: a NUL inside would end it there, silently."""
    data = text if isinstance(text, bytes) else str(text).encode()
    if b"\0" in data:
        raise ValueError(f"{what} {text!r} contains a NUL character")
    return data


def _c_path(path, what="path"):
    return _c_text(os.fsencode(os.fspath(path)), what)


def _c_int(value, what):
    """An integer for an int argument: ctypes would wrap one beyond C's int
    silently (line 2**40 became line 0)."""
    value = operator.index(value)
    if not -2**31 <= value < 2**31:
        raise ValueError(f"{what} = {value} is beyond a C int")
    return value


class _Stoppable:
    """Progress for the user's `report(message, fraction)`, and Ctrl-C, around
    one call that reports (a job, or a computation with progress).

    An exception the report raises (ctypes would print and drop it) is
    raised again when the call has returned.  On the main thread SIGINT is
    the call's for its duration: Ctrl-C asks it to stop at its next report
    (Python runs the handler when the call reports, so the callback is
    installed even without `report`), and once it has returned, the handler
    that was there before runs (KeyboardInterrupt).  Subclasses say how a
    stop is asked for, and which exceptions of the report ask for one."""

    def __init__(self, lib, report):
        self.lib, self.report = lib, report
        self.raised = None
        self.signalled = None

    def _ask_stop(self):
        raise NotImplementedError

    def _stops_on(self, error):
        return not isinstance(error, Exception)

    def _deliver(self, message, fraction):
        if self.report is None or self.raised is not None:
            return
        try:
            self.report(message.decode(errors="replace"), fraction)
        except BaseException as error:  # noqa: B902 - raised again after the call
            self.raised = error
            if self._stops_on(error):
                self._ask_stop()

    def _on_signal(self, signum, frame):
        self.signalled = (signum, frame)
        self._ask_stop()

    def _guarded(self, call):
        """call(): the library's call, raising FrictionError on failure; its
        value.  Raises after it what the report or Ctrl-C raised."""
        previous = None
        if threading.current_thread() is threading.main_thread():
            current = signal.getsignal(signal.SIGINT)
            if current is not None and current != signal.SIG_IGN:
                try:
                    previous = signal.signal(signal.SIGINT, self._on_signal)
                except ValueError:   # not the main interpreter
                    previous = None
        try:
            try:
                value = call()
            finally:
                if previous is not None:
                    signal.signal(signal.SIGINT, previous)
        except FrictionError:
            self._raise_pending(previous)
            raise
        self._raise_pending(previous)
        return value

    def _raise_pending(self, previous):
        if self.raised is not None:
            raise self.raised
        if self.signalled is not None:
            if callable(previous):
                previous(*self.signalled)
            elif previous == signal.SIG_DFL:
                signal.raise_signal(signal.SIGINT)


class _JobReport(_Stoppable):
    """A job's report callback: progress (fraction in [0, 1]) and notes
    (fraction -1).  The job runs on after an Exception of the report; a
    KeyboardInterrupt or SystemExit raised in it, or Ctrl-C, asks the job to
    stop (friction_job_stop) at its next scan line or sweep point."""

    def __init__(self, lib, report):
        super().__init__(lib, report)
        self.function = _REPORT(self._called)

    def _called(self, message, fraction, user):
        self._deliver(message, fraction)

    def _ask_stop(self):
        self.lib.friction_job_stop()

    def run(self, function, *args):
        """function(*args, report, user, err): the job.  Raises the job's
        FrictionError, and after it what the report or Ctrl-C raised."""
        self._guarded(lambda: _call(function, *args, self.function, None))


class _ComputeProgress(_Stoppable):
    """A computation's progress callback (friction_compute_progress): it
    returns 1, stopping the computation at its next report, once Ctrl-C came
    or the report raised anything.  A call with fraction -1 is a poll from
    inside a scan line at a temperature (every 0.1 s), not progress: it is
    not delivered, and so Ctrl-C stops such a line within it."""

    def __init__(self, lib, report, polls=False):
        super().__init__(lib, report)
        self.stop = False
        self.polls = polls   # deliver the polls too (a single line's callback: its only chance to stop it)
        self.function = _PROGRESS(self._called)

    def _called(self, message, fraction, user):
        if fraction >= 0.0 or self.polls:
            self._deliver(message, fraction)
        return int(self.stop)

    def _ask_stop(self):
        self.stop = True

    def _stops_on(self, error):
        return True


class Config:
    """A configuration of scene "afm" or "brake" (friction.h: friction_config).

    files: namelist files read in order over the defaults (read());
    values: {"group.variable": value} set after them (set())."""

    def __init__(self, scene="afm", files=(), values=None):
        self._lib = library()
        self._handle = None
        with _ErrorHandle() as err:
            handle = self._lib.friction_config_new(_c_text(scene, "scene"), err.handle)
            if not handle:
                err.check(err.status())
        self._handle = handle
        self.scene = scene
        if isinstance(files, (str, os.PathLike)):
            files = [files]
        for path in files:
            self.read(path)
        for name, value in (values or {}).items():
            self.set(name, value)

    # ---- lifetime ----
    def close(self) -> None:
        """Free the configuration (also at the end of a `with` block, or when collected).

        Closing twice is harmless.
        """
        if self._handle:
            self._lib.friction_config_free(self._handle)
            self._handle = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        if getattr(self, "_handle", None):
            self.close()

    @property
    def handle(self) -> int:
        """The C API's handle of the configuration.

        Returns
        -------
        int
            The handle.

        Raises
        ------
        ValueError
            A closed configuration.
        """
        if not self._handle:
            raise ValueError("the configuration is closed")
        return self._handle

    # ---- values ----
    def read(self, path: str | os.PathLike[str]) -> Config:
        """Apply a namelist file over the current values (all or nothing).

        Parameters
        ----------
        path : str or os.PathLike
            A namelist file.

        Returns
        -------
        Config
            This configuration, for chaining.

        Raises
        ------
        FrictionError
            The library's refusal: the program's message (file, line, group, variable) and status.
        """
        _call(self._lib.friction_config_read, self.handle, _c_path(path))
        return self

    def set(self, name: str, value: Any) -> Config:
        """Set "group.variable" (or "group.variable(k)"): a number, True/False, a
        text (quoted for you), or a list of them.

        Parameters
        ----------
        name : str
            "group.variable", or "group.variable(k)" from element k on.
        value : float or int or bool or str or sequence
            The value; a list sets elements one after another.

        Returns
        -------
        Config
            This configuration, for chaining.

        Raises
        ------
        FrictionError
            The library's refusal: the program's message (file, line, group, variable) and status.
        ValueError
            A name or value with a NUL character.
        """
        if isinstance(value, numbers.Real) and not isinstance(value, (bool, np.bool_)):
            _call(self._lib.friction_config_set_real, self.handle, _c_text(name, "name"), float(value))
        elif isinstance(value, (list, tuple, np.ndarray)):
            self.set_text(name, ", ".join(_item(v) for v in value))
        else:
            self.set_text(name, _item(value))
        return self

    def set_text(self, name: str, text: str) -> Config:
        """Set a variable from namelist value text ("5.0", "'hopg'", ".true.", "3*0.0").

        Parameters
        ----------
        name : str
            "group.variable", or "group.variable(k)" from element k on.
        text : str
            Namelist value text.

        Returns
        -------
        Config
            This configuration, for chaining.

        Raises
        ------
        FrictionError
            The library's refusal: the program's message (file, line, group, variable) and status.
        ValueError
            A NUL character.
        """
        _call(self._lib.friction_config_set, self.handle, _c_text(name, "name"), _c_text(text, "value"))
        return self

    def get(self, name: str) -> str:
        """A variable's value as namelist text ("10.0", "'naf'", ".true.", "2*0.0").

        Parameters
        ----------
        name : str
            "group.variable", or "group.variable(k)" from element k on.

        Returns
        -------
        str
            The value as namelist text.

        Raises
        ------
        FrictionError
            The library's refusal: the program's message (file, line, group, variable) and status.
        """
        buf = ctypes.create_string_buffer(1 << 16)
        _call(self._lib.friction_config_get, self.handle, _c_text(name, "name"), buf, len(buf))
        return buf.value.decode()

    def _text(self, function):
        needed = ctypes.c_size_t(0)
        if function(self.handle, None, 0, ctypes.byref(needed)) != 0:
            raise FrictionError(ERROR_INPUT, f"{function.__name__}: the size query failed")
        buf = ctypes.create_string_buffer(needed.value)
        if function(self.handle, buf, len(buf), None) != 0:
            raise FrictionError(ERROR_INPUT, f"{function.__name__}: the text did not fit")
        return buf.value.decode()

    def text(self) -> str:
        """The whole configuration as namelist text (read() reads it back).

        Returns
        -------
        str
            Namelist groups, every variable of the scene.
        """
        return self._text(self._lib.friction_config_text)

    def warnings(self) -> list[str]:
        """The warnings the program's input would give for these values
        (friction.h: friction_config_warnings): a value that looks like a
        number in another unit than its variable's, the scene's own, and a
        sweep's values that do; none when the checks refuse the
        configuration (check() says why).

        Returns
        -------
        list of str
            One per warning, in the program's words ("&scan: angle = 0.122:
            ... it looks like radians, and the unit is degrees (...)").

        Examples
        --------
        >>> friction.Config("afm", values={"scan.angle": 0.122}).warnings()  # doctest: +SKIP
        """
        return self._text(self._lib.friction_config_warnings).splitlines()

    def names(self) -> list[tuple[str, str, int, str]]:
        """Every variable: a list of (name, kind, elements, unit), kind "real",
        "integer", "logical" or "text".

        Returns
        -------
        list of tuple
            (name, kind, elements, unit) per variable.
        """
        rows = []
        for line in self._text(self._lib.friction_config_names).splitlines():
            name, kind, size, unit = line.split("\t")
            rows.append((name, kind, int(size), unit))
        return rows

    def check(self) -> Config:
        """The scene's checks; FrictionError with the first value refused.

        Returns
        -------
        Config
            This configuration, for chaining.

        Raises
        ------
        FrictionError
            The library's refusal: the program's message (file, line, group, variable) and status.
        """
        _call(self._lib.friction_config_check, self.handle)
        return self

    # ---- computations on this process ----
    def afm_line(self, line=0, forward=True, report=None, polls=False):
        """Line `line` (0-based) of the map, trace or retrace: fx, fy (nN) at scan.nx points
        (friction.h: friction_afm_line_progress).  `report(message, fraction)`
        if given receives the line's end ("1 of 1 lines", 1.0) and, with
        `polls`, the library's polls from inside a long line ("started", -1.0)
        every 0.1 s.  Ctrl-C (on the main thread), or anything the report
        raises at a poll, stops the line within the trip's next look and
        raises KeyboardInterrupt (the report's exception), its context a
        FrictionError with status 5; an exception at the end is raised after
        the line.  Nothing is returned then; the Config stays as it was."""
        nx = int(self.get("scan.nx")) if self.scene == "afm" else 1
        fx, fy = np.zeros(nx), np.zeros(nx)
        progress = _ComputeProgress(self._lib, report, polls)
        line, forward = _c_int(line, "line"), int(bool(forward))
        progress._guarded(lambda: _call(self._lib.friction_afm_line_progress, self.handle, line, forward,
                                        fx.ctypes.data_as(ctypes.c_void_p), fy.ctypes.data_as(ctypes.c_void_p),
                                        nx, progress.function, None))
        return fx, fy

    def compute(self, report=None):
        """The whole scene on this process: a dict of numpy arrays, maps (ny, nx),
        series 1-D (friction.h: friction_compute_progress).  `report(message,
        fraction)` if given receives progress ("12 of 48 lines", fraction in
        [0, 1]) after each scan line of a map and 200 times along a brake
        trajectory.  Ctrl-C (on the main thread) stops the computation at its
        next report and raises KeyboardInterrupt, its context a FrictionError
        with status 5; so does anything the report raises (raised itself).
        The Config stays as it was."""
        progress = _ComputeProgress(self._lib, report)

        def call():
            with _ErrorHandle() as err:
                result = self._lib.friction_compute_progress(self.handle, progress.function, None, err.handle)
                if not result:
                    err.check(err.status())
                try:
                    return _result_arrays(self._lib, result, err)
                finally:
                    self._lib.friction_result_free(result)

        return progress._guarded(call)

    def run(self, output, force=False, resume=False, report=None, init_mpi=False):
        """The configuration's job to the HDF5 file `output` (friction.h: friction_run_config);
        `report(message, fraction)` as for run_job."""
        flags = (FORCE if force else 0) | (RESUME if resume else 0) | (INIT_MPI if init_mpi else 0)
        _JobReport(self._lib, report).run(self._lib.friction_run_config, self.handle, _c_path(output, "output"),
                                          flags)


def _result_arrays(lib, result, err):
    buf = ctypes.create_string_buffer(1 << 16)
    if lib.friction_result_names(result, buf, len(buf)) != 0:
        raise FrictionError(ERROR_INPUT, "friction_result_names: the names did not fit")
    arrays = {}
    for name in buf.value.decode().split("\n"):
        shape = (ctypes.c_size_t * 2)()
        err.check(lib.friction_result_shape(result, name.encode(), ctypes.byref(shape), err.handle))
        rows, columns = shape[0], shape[1]
        values = np.zeros(rows * columns)
        err.check(lib.friction_result_get(result, name.encode(), values.ctypes.data_as(ctypes.c_void_p),
                                          values.size, None, err.handle))
        arrays[name] = values.reshape(rows, columns) if columns > 1 else values
    return arrays


def run_job(files, output, force=False, resume=False, report=None, init_mpi=False):
    """Run a namelist job as the program does (friction.h: friction_run_job): read
    `files` in order, compute, write `output`.  `report(message, fraction)` if
    given receives progress (fraction in [0, 1]) and notes (fraction -1).
    init_mpi: in a process that has not initialised MPI the job runs serially on
    this process without MPI; True has the library initialise MPI first
    (MPI_THREAD_FUNNELED, for the rest of the process) and run it there.
    Ctrl-C (on the main thread) stops the job at its next scan line or sweep
    point and then raises KeyboardInterrupt, its context the job's
    FrictionError with status 5: a sweep's file holds the points done, a
    map's lines done are kept beside the output, and resume=True computes
    the rest."""
    paths = [_c_path(path, "file") for path in files]
    array = (ctypes.c_char_p * max(1, len(paths)))(*paths)
    flags = (FORCE if force else 0) | (RESUME if resume else 0) | (INIT_MPI if init_mpi else 0)
    lib = library()
    _JobReport(lib, report).run(lib.friction_run_job, array, len(paths), _c_path(output, "output"), flags)
