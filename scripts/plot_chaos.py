#!/usr/bin/env python3
"""Plot the chaos diagnostics of a Girling brake run (`friction` with an

The command line of friction.commands.plot_chaos (python/friction/commands/plot_chaos.py),
which the installed package also offers as the command friction-plot-chaos; --help says the rest.
"""

import sys
from pathlib import Path

# The package beside the scripts: python/ in the repository, share/friction/python when installed.
_PACKAGE = Path(__file__).resolve().parent.parent / "python"
if _PACKAGE.is_dir():
    sys.path.insert(0, str(_PACKAGE))

from friction.commands.plot_chaos import main  # noqa: E402

if __name__ == "__main__":
    sys.exit(main())
