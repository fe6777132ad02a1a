"""friction: dry friction from the atomic scale (AFM friction maps over NaF,
HOPG, graphite) to the machine scale (the Girling brake), in Python.

    import friction

    path = friction.run(friction.input_file("naf.nml"), output="naf.h5", force=True)   # the job, with progress
    data = friction.load(path)                      # an xarray.DataTree: coordinates, units
    fig = friction.plot.afm_maps(data)              # the maps as a matplotlib Figure

    cfg = friction.Config("afm", files=["inputs/naf.nml"], values={"scan.nx": 64})
    x, fx, fy = cfg.afm_line(0)                     # one line, numpy arrays, no file
    maps = cfg.compute()                            # the whole map: {"trace/fx": (ny, nx), ...}
    run = friction.brake(values={"brake.t_end": 300.0})   # {"t": ..., "x": ..., "events/t": ...}
    img = friction.read_image("scan.spm")           # a microscope's friction channels, trace and retrace
    fit = friction.fit.image(img, cfg, free={"surface.v0": 0.5, "tip.kx=tip.ky": 8.0})   # with errors

The computations go through the C API of the shared library libfriction
(found as friction._capi.find_library says: FRICTION_LIBRARY, the
installation, the clone it was installed from, a build tree, the system's
loader), loaded on first use:
importing the package, load() and the plots need no library.
Reference: docs/python.md.
"""
from . import _capi
from ._capi import FrictionError, LibraryNotFoundError, api_version, library_path
from ._data import FileError, groups, load, paths
from ._image import ImageError, MeasuredImage, read_image
from ._inputs import input_file
from ._run import Config, Line, afm_line, brake, compute, run
from ._version import __version__

__all__ = ["__version__", "library_version", "api_version", "library_path", "FrictionError",
           "LibraryNotFoundError", "FileError", "read_image", "MeasuredImage", "ImageError", "input_file", "Config",
           "Line", "run", "compute", "afm_line", "brake", "load", "paths", "groups",
           "plot", "fit", "law", "thermal"]


def library_version() -> str:
    """The version of the loaded library (friction_version() of the C API);
    __version__ is the package's, and the two agree for a matched install.

    Returns
    -------
    str
        The library's version ("0.1.0").
    """
    return _capi.version()


def __getattr__(name):
    # friction.plot, fit, law and thermal on first use: matplotlib only when plotting.
    if name in ("plot", "fit", "law", "thermal"):
        import importlib
        module = importlib.import_module(f".{name}", __name__)
        globals()[name] = module
        return module
    raise AttributeError(f"module 'friction' has no attribute {name!r}")
