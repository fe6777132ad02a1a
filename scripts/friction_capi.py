"""Python access to the friction C API (include/friction.h) through ctypes.

    import friction_capi as fc
    fx, fy = fc.afm_line(potential="naf", v0=1.0, kx=10.0, ky=10.0, nx=128)
    run = fc.brake(t_end=100.0, dt_out=0.1)      # dict of numpy arrays t, x, v, y, w
    fc.run_job(["inputs/naf.nml"], "naf.h5", force=True,
               report=lambda message, fraction: print(message))   # the CLI's job, no MPI launcher

Units are those of the namelist input (docs/input.md).  A failed
call raises FrictionError with the library's status and message.

The library is found, in order: the path in the environment variable
FRICTION_LIBRARY; build/libfriction.so next to this script's repository;
lib/libfriction.so of an installation this script was installed into
(share/friction/scripts); the system's search path (ctypes.util).
"""
import ctypes
import ctypes.util
import os

import numpy as np

__all__ = ["FrictionError", "library", "version", "afm_line", "brake", "run_job"]

_double_array = np.ctypeslib.ndpointer(dtype=np.float64, flags="C_CONTIGUOUS")


# void report(const char *message, double fraction, void *user)
_REPORT = ctypes.CFUNCTYPE(None, ctypes.c_char_p, ctypes.c_double, ctypes.c_void_p)
FORCE, RESUME = 1, 2


class FrictionError(RuntimeError):
    """A call the library refused or could not finish; .status is its code."""

    def __init__(self, status, message):
        super().__init__(f"{message} (status {status})")
        self.status = status


def _candidates():
    here = os.path.dirname(os.path.abspath(__file__))
    if os.environ.get("FRICTION_LIBRARY"):
        yield os.environ["FRICTION_LIBRARY"]
        return
    yield os.path.join(here, "..", "build", "libfriction.so")
    for libdir in ("lib", "lib64"):
        yield os.path.join(here, "..", "..", "..", libdir, "libfriction.so")
    found = ctypes.util.find_library("friction")
    if found:
        yield found


def _load():
    tried = []
    for path in _candidates():
        if os.path.sep in path and not os.path.exists(path):
            tried.append(path)
            continue
        lib = ctypes.CDLL(path)
        break
    else:
        raise OSError("libfriction not found (set FRICTION_LIBRARY); tried: " + ", ".join(tried))
    c_double, c_int, c_size_t, c_char_p, c_void_p = (ctypes.c_double, ctypes.c_int, ctypes.c_size_t,
                                                     ctypes.c_char_p, ctypes.c_void_p)
    lib.friction_version.argtypes = [ctypes.c_char_p, c_size_t]
    lib.friction_version.restype = c_int
    lib.friction_error_new.argtypes = []
    lib.friction_error_new.restype = c_void_p
    lib.friction_error_free.argtypes = [c_void_p]
    lib.friction_error_free.restype = None
    lib.friction_error_status.argtypes = [c_void_p]
    lib.friction_error_status.restype = c_int
    lib.friction_error_message.argtypes = [c_void_p, ctypes.c_char_p, c_size_t]
    lib.friction_error_message.restype = c_int
    lib.friction_afm_line.argtypes = ([c_char_p] + [c_double] * 14 + [c_int, c_int, c_char_p, c_double,
                                                                         c_double, _double_array, _double_array,
                                                                         c_void_p])
    lib.friction_afm_line.restype = c_int
    lib.friction_brake.argtypes = ([c_char_p] + [c_double] * 10 + [c_char_p, c_double, c_double]
                                   + [c_void_p] * 5 + [c_size_t, ctypes.POINTER(c_size_t), c_void_p])
    lib.friction_brake.restype = c_int
    lib.friction_run_job.argtypes = [ctypes.POINTER(c_char_p), c_int, c_char_p, c_int, _REPORT, c_void_p,
                                     c_void_p]
    lib.friction_run_job.restype = c_int
    return lib


library = _load()


def version():
    """The library's version string."""
    buf = ctypes.create_string_buffer(64)
    library.friction_version(buf, len(buf))
    return buf.value.decode()


def _call(function, *args):
    """Call with a fresh error handle; raise FrictionError on failure."""
    handle = library.friction_error_new()
    if not handle:
        raise MemoryError("friction_error_new")
    try:
        status = function(*args, handle)
        if status != 0:
            buf = ctypes.create_string_buffer(1024)
            library.friction_error_message(handle, buf, len(buf))
            raise FrictionError(status, buf.value.decode(errors="replace"))
    finally:
        library.friction_error_free(handle)


def afm_line(potential="naf", v0=1.0, ax=4.62, ay=4.62, a=2.46, mass=1.0e-8, kx=10.0, ky=10.0,
             cx=1.0e-3, cy=1.0e-3, velocity=400.0, x0=0.0, y0=0.0, angle=0.0, length=20.0, nx=128,
             forward=True, stepper="rkf45", rtol=1.0e-3, atol=1.0e-4):
    """One scan line: fx, fy (nN) at nx support positions from (x0, y0) Å
    along `angle` degrees over `length` Å (see friction.h)."""
    nx = int(nx)
    fx = np.zeros(max(nx, 0))
    fy = np.zeros(max(nx, 0))
    _call(library.friction_afm_line, potential.encode(), v0, ax, ay, a, mass, kx, ky, cx, cy, velocity,
          x0, y0, angle, length, nx, int(bool(forward)), stepper.encode(), rtol, atol, fx, fy)
    return fx, fy


def brake(model="switched", xi=0.412, kappa=1.5, g_prime=0.01778, mu=0.59, mu_s=0.59,
          epsilon_prime=3.5121e7, delta_prime=3.5121, v_dr=-0.002788, t_end=100.0, dt_out=0.1,
          stepper="rk8pd", rtol=1.0e-10, atol=1.0e-12):
    """The brake of Eq. 10 from the state of §4.1: dict of t, x, v, y, w."""
    args = (model.encode(), xi, kappa, g_prime, mu, mu_s, epsilon_prime, delta_prime, v_dr, t_end, dt_out,
            stepper.encode(), rtol, atol)
    needed = ctypes.c_size_t(0)
    try:
        _call(library.friction_brake, *args, None, None, None, None, None, 0, ctypes.byref(needed))
    except FrictionError:
        if needed.value == 0:
            raise
    out = {key: np.zeros(needed.value) for key in ("t", "x", "v", "y", "w")}
    pointers = [out[key].ctypes.data_as(ctypes.c_void_p) for key in ("t", "x", "v", "y", "w")]
    _call(library.friction_brake, *args, *pointers, needed.value, None)
    return out


def run_job(files, output, force=False, resume=False, report=None):
    """Run a namelist job as the CLI does (friction.h: friction_run_job): read
    `files` in order, compute, write `output`.  `report(message, fraction)` if
    given receives progress (fraction in [0, 1]) and notes (fraction -1).  In
    a process that has not initialised MPI the job runs on this process alone.
    An interrupted sweep raises FrictionError with status 5."""
    paths = [os.fsencode(os.fspath(path)) for path in files]
    array = (ctypes.c_char_p * max(1, len(paths)))(*paths)
    callback = _REPORT(lambda message, fraction, user: report(message.decode(errors="replace"), fraction)) \
        if report is not None else _REPORT()
    flags = (FORCE if force else 0) | (RESUME if resume else 0)
    _call(library.friction_run_job, array, len(paths), os.fsencode(os.fspath(output)), flags, callback, None)
