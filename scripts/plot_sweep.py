#!/usr/bin/env python3
"""Plot a parameter sweep (`friction` with a &sweep group; docs/sweeps.md).

The command line of friction.commands.plot_sweep (python/friction/commands/plot_sweep.py),
which the installed package also offers as the command friction-plot-sweep; --help says the rest.
"""

import sys
from pathlib import Path

# The package beside the scripts: python/ in the repository, share/friction/python when installed.
_PACKAGE = Path(__file__).resolve().parent.parent / "python"
if _PACKAGE.is_dir():
    sys.path.insert(0, str(_PACKAGE))

from friction.commands.plot_sweep import main  # noqa: E402

if __name__ == "__main__":
    sys.exit(main())
