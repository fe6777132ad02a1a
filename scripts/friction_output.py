"""Reading friction's HDF5 output in the plotting scripts.

The checks every script makes before it draws anything live here: the file
exists, is HDF5, was written by friction for the expected scene, and has the
datasets asked for.  Anything amiss becomes an InputError, which the scripts
turn into a message naming the file and exit code 2.
"""
import contextlib

import h5py
import numpy as np


class InputError(Exception):
    """A problem with the input file or the request; exit code 2."""


def text(value):
    """HDF5 string attributes come back as (arrays of) bytes; give str."""
    if isinstance(value, np.ndarray) and value.shape == ():
        value = value[()]
    return value.decode() if isinstance(value, bytes) else str(value)


@contextlib.contextmanager
def open_output(path, scene, what):
    """Open a friction output file of the given scene for reading.

    path: a pathlib.Path; scene: 'afm' or 'brake', also the group that must
    exist; what: how to call the file in messages ('force-map', 'brake').
    Missing datasets (KeyError), unreadable files (OSError) and unexpected
    data (TypeError, ValueError) inside the block become InputError.
    """
    if not path.exists():
        raise InputError("no such file")
    if not path.is_file():
        raise InputError("not a regular file")
    try:
        with h5py.File(path, "r") as f:
            if (text(f.attrs.get("program", b"")) != "friction"
                    or text(f.attrs.get("scene", b"")) != scene or scene not in f):
                raise InputError(f"not a friction {what} file "
                                 f"(needs program = 'friction', scene = '{scene}', group /{scene})")
            yield f
    except KeyError as err:
        raise InputError(f"incomplete friction {what} file ({err})") from None
    except OSError as err:
        raise InputError(f"cannot read as HDF5 ({err})") from None
    except (TypeError, ValueError) as err:
        raise InputError(f"unexpected data in the file ({err})") from None
