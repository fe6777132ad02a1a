"""The project's input files (inputs/*.nml: the paper's cases) wherever the
package is: its own copy in an installed wheel, the installation's
share/friction/inputs beside a `cmake --install` copy, or the repository's
inputs/ beside python/friction."""
from pathlib import Path

_PACKAGE_DIR = Path(__file__).resolve().parent

# In the order looked in: the wheel's copy (setup.py), PREFIX/share/friction/inputs
# (package at PREFIX/share/friction/python/friction) and the clone's inputs/
# (package at python/friction): both ../../inputs from the package.
_FOLDERS = (_PACKAGE_DIR / "inputs", _PACKAGE_DIR.parent.parent / "inputs")


def input_file(name: str) -> Path:
    """The path of the project's input file `name` ("hopg.nml"), for
    friction.run or Config(files=...) from any folder.

    Raises FileNotFoundError naming the folders looked in.

    Parameters
    ----------
    name : str
        The file's name ("hopg.nml").

    Returns
    -------
    pathlib.Path
        Its path.

    Raises
    ------
    FileNotFoundError
        No such input file; the message names the folders looked in.
    """
    for folder in _FOLDERS:
        if (folder / name).is_file():
            return folder / name
    raise FileNotFoundError(f"no input file {name!r} in " + ", ".join(str(f) for f in _FOLDERS))
