#!/usr/bin/env python3
"""Run a notebook-style example (docs/examples/NAME.py) whole, and check its pictures.

    run_example.py EXAMPLE.py --inputs DIR --workdir DIR

The example runs as a script in a fresh WORKDIR with FRICTION_INPUTS=DIR and
FRICTION_EXAMPLE_OUTPUT=WORKDIR/output, the repository's package first on
PYTHONPATH; it must exit 0 and leave at least one PNG there, each a complete
image of more than 100 x 100 px (check_png.py).
"""
import argparse
import os
import shutil
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import helpers  # noqa: E402
from check_png import png_problem  # noqa: E402
from helpers import fail  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("example", type=Path)
    parser.add_argument("--inputs", type=Path, required=True)
    parser.add_argument("--workdir", type=Path, required=True)
    args = parser.parse_args()
    shutil.rmtree(args.workdir, ignore_errors=True)
    args.workdir.mkdir(parents=True)
    output = args.workdir / "output"
    path = os.pathsep.join([str(helpers.PACKAGE)] + [p for p in [os.environ.get("PYTHONPATH")] if p])
    result = helpers.run([sys.executable, args.example], cwd=args.workdir, echo=True,
                         extra_env={"FRICTION_INPUTS": str(args.inputs.resolve()),
                                    "FRICTION_EXAMPLE_OUTPUT": str(output), "PYTHONPATH": path,
                                    "MPLBACKEND": "Agg"})
    pictures = sorted(output.glob("*.png"))
    if not pictures:
        fail(f"{args.example.name} wrote no PNG into {output}")
    for picture in pictures:
        problem = png_problem(picture, 100, None)
        if problem:
            fail(f"{picture}: {problem}")
    print(f"PASS: {args.example.name} ran ({len(result.stdout.splitlines())} lines of output), "
          f"{len(pictures)} pictures: {', '.join(p.name for p in pictures)}")


if __name__ == "__main__":
    main()
