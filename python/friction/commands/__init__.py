"""The package's command lines: one module per plotting command, each with
main(argv=None) -> exit code.  Installed with the package as console
commands (friction-plot-afm, friction-plot-brake, friction-plot-chaos,
friction-plot-graphite, friction-plot-sweep); scripts/plot_*.py in the
repository run the same main()."""

import sys as _sys


def save_figures(prog, figures, output_dir, stem, dpi):
    """Write each figure of {name: figure} as OUTPUT_DIR/STEM_NAME.png, saying
    so; 0, or 1 with a message naming the folder when it cannot be written."""
    try:
        output_dir.mkdir(parents=True, exist_ok=True)
        for name, figure in figures.items():
            out = output_dir / f"{stem}_{name}.png"
            figure.savefig(out, dpi=dpi)
            print(f"wrote {out}")
    except OSError as err:
        print(f"{prog}: cannot write into {output_dir}: {err}", file=_sys.stderr)
        return 1
    return 0
