#!/usr/bin/env python3
"""Plot a Girling brake run written by `friction` (scene 'brake').

The command line of friction.commands.plot_brake (python/friction/commands/plot_brake.py),
which the installed package also offers as the command friction-plot-brake; --help says the rest.
"""

import sys
from pathlib import Path

# The package beside the scripts: python/ in the repository, share/friction/python when installed.
_PACKAGE = Path(__file__).resolve().parent.parent / "python"
if _PACKAGE.is_dir():
    sys.path.insert(0, str(_PACKAGE))

from friction.commands.plot_brake import main  # noqa: E402

if __name__ == "__main__":
    sys.exit(main())
