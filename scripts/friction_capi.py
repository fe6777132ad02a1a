"""The friction package's C API layer under its old name (python/friction/_capi.py).

Kept for the programs that import friction_capi from scripts/; new code
imports the package: `import friction` (friction.Config, friction.run, ...)
or `from friction import _capi`.  Unlike the package, which loads the
library on first use, this module loads it on import, as it always did
(module attribute `library`).
"""
import sys
from pathlib import Path

if __name__ == "__main__":   # a module to import, not a command: say what it is
    print(__doc__)
    sys.exit(0)

# The package beside the scripts: python/ in the repository, share/friction/python when installed.
_PACKAGE = Path(__file__).resolve().parent.parent / "python"
if _PACKAGE.is_dir():
    sys.path.insert(0, str(_PACKAGE))

from friction._capi import *  # noqa: E402,F401,F403
from friction._capi import __all__ as _names  # noqa: E402
from friction import _capi as _module  # noqa: E402

__all__ = [name for name in _names if name != "library"] + ["library"]
library = _module.library()
