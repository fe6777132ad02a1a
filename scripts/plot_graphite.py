#!/usr/bin/env python3
"""Plot a lattice-sum friction map written by `friction` (e.g. inputs/graphite.nml).

The command line of friction.commands.plot_graphite (python/friction/commands/plot_graphite.py),
which the installed package also offers as the command friction-plot-graphite; --help says the rest.
"""

import sys
from pathlib import Path

# The package beside the scripts: python/ in the repository, share/friction/python when installed.
_PACKAGE = Path(__file__).resolve().parent.parent / "python"
if _PACKAGE.is_dir():
    sys.path.insert(0, str(_PACKAGE))

from friction.commands.plot_graphite import main  # noqa: E402

if __name__ == "__main__":
    sys.exit(main())
