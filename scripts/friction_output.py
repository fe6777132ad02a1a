"""Reading friction's HDF5 output: the package's checks under their old name.

Kept for programs that import friction_output from scripts/; the plotting
scripts and new code use the package: friction.load(path, scene=...) and
friction.FileError (python/friction/_data.py).  InputError is FileError.
"""
import sys
from pathlib import Path

if __name__ == "__main__":   # a module to import, not a command: say what it is
    print(__doc__)
    sys.exit(0)

_PACKAGE = Path(__file__).resolve().parent.parent / "python"
if _PACKAGE.is_dir():
    sys.path.insert(0, str(_PACKAGE))

from friction._data import FileError as InputError, open_output, text  # noqa: E402,F401

__all__ = ["InputError", "open_output", "text"]
