"""The package's command lines: one module per plotting command, each with
main(argv=None) -> exit code.  Installed with the package as console
commands (friction-plot-afm, friction-plot-brake, friction-plot-chaos,
friction-plot-graphite, friction-plot-sweep); scripts/plot_*.py in the
repository run the same main()."""
