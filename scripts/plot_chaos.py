#!/usr/bin/env python3
"""Plot the chaos diagnostics of a Girling brake run (`friction` with an
&analysis group; docs/physics.md, Chaos diagnostics).

Reads one output file and writes into the output directory (default: the
current directory, like `friction` itself) the PNGs of what the file holds:

  <stem>_spectrum.png  the amplitude spectrum of the analysed variable over
                       its window, as the paper's Fig. 13, with the peak
                       frequency and the bin width (the resolution)
  <stem>_poincare.png  the stroboscopic map (x, x') at the strobe period, as
                       the paper's Fig. 14, beside the true section (x, y)
  <stem>_lyapunov.png  the running Benettin estimate (from the equations)
                       and the Rosenstein divergence curve with its fit range
                       and slope (from the series)

Frequencies in cycles per unit tau, exponents in 1/tau (natural log).

Examples:
  plot_chaos.py brake.h5
  plot_chaos.py brake.h5 -o plots --dpi 200

Exit codes: 0 done, 1 a PNG could not be written, 2 bad command line or
bad input file (missing, not a brake run, no diagnostics in it).
"""

import argparse
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # headless: no display needed

from friction_output import InputError, open_output, text  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def read_diagnostics(path):
    """The /brake/spectrum, /brake/poincare and /brake/lyapunov groups present."""
    d = {}
    with open_output(path, "brake", "brake") as f:
        brake = f["brake"]
        d["model"] = text(brake.attrs["model"])
        d["v_dr"] = float(brake.attrs["v_dr_prime"])
        if "spectrum" in brake:
            s = brake["spectrum"]
            d["spectrum"] = {"frequency": s["frequency"][()], "amplitude": s["amplitude"][()],
                             "series": text(s.attrs["series"]), "window": text(s.attrs["window"]),
                             **{k: float(s.attrs[k]) for k in ("peak_frequency", "resolution",
                                                              "window_start", "window_end")}}
        if "poincare" in brake:
            p = brake["poincare"]
            d["poincare"] = {k: p[k][()] for k in p}
            d["poincare"]["period"] = float(p.attrs["strobe_period"])
            d["poincare"]["section"] = text(p.attrs["section"])
        if "lyapunov" in brake:
            g = brake["lyapunov"]
            d["lyapunov"] = {k: g[k][()] for k in g}
            d["lyapunov"]["attrs"] = dict(g.attrs)
    if not any(k in d for k in ("spectrum", "poincare", "lyapunov")):
        raise InputError("no chaos diagnostics in the file (run friction with an &analysis group)")
    return d


def plot_spectrum(d, out, dpi):
    s = d["spectrum"]
    fig, ax = plt.subplots(figsize=(8, 5), layout="constrained")
    ax.semilogy(s["frequency"], np.maximum(s["amplitude"], 1e-300), "-", linewidth=0.8)
    ax.axvline(s["peak_frequency"], color="tab:red", linestyle="--", linewidth=0.8,
               label=f"peak {s['peak_frequency']:.6f} ± {s['resolution'] / 2:.6f} (bin {s['resolution']:.6f})")
    ax.axvline(0.143433, color="0.5", linestyle=":", linewidth=0.8, label="paper: 0.143433")
    ax.set_xlim(0, min(1.0, s["frequency"][-1]))
    ax.set_xlabel("frequency (cycles per unit τ)")
    ax.set_ylabel(f"amplitude of {s['series']}")
    ax.set_title(f"Spectrum of {s['series']}, τ ∈ [{s['window_start']:g}, {s['window_end']:g}], "
                 f"{s['window']} window (paper Fig. 13)\n{d['model']} model")
    ax.legend(fontsize="small")
    fig.savefig(out, dpi=dpi)
    plt.close(fig)


def plot_poincare(d, out, dpi):
    p = d["poincare"]
    fig, (strobe, section) = plt.subplots(1, 2, figsize=(12, 5), layout="constrained")
    strobe.plot(p["strobe_x"], p["strobe_v"], ".", markersize=3)
    strobe.set_title(f"Stroboscopic map, period {p['period']:.6g} τ (paper Fig. 14)\n"
                     f"{p['strobe_t'].size} points")
    # On the stick-to-slip section x' = v'_dr: (x, y) shows what changes.
    section.plot(p["section_x"], p["section_y"], ".", markersize=3, color="tab:green")
    section.set_title(f"Section: {p['section']} (x, y)\n{p['section_t'].size} points")
    section.set_ylabel("y, crank arm tip displacement (m)")
    strobe.set_ylabel("x', block velocity (m per unit τ)")
    for ax in (strobe, section):
        ax.set_xlabel("x, block displacement (m)")
    fig.savefig(out, dpi=dpi)
    plt.close(fig)


def plot_lyapunov(d, out, dpi):
    g = d["lyapunov"]
    a = g["attrs"]
    fig, (flow, series) = plt.subplots(1, 2, figsize=(12, 5), layout="constrained")
    if "benettin_estimate" in g:
        flow.plot(g["benettin_time"], g["benettin_estimate"], "-", linewidth=0.8)
        flow.axhline(0, color="0.5", linewidth=0.6)
        flow.set_title(f"Benettin running estimate: {float(a['benettin_exponent']):.3g} per τ\n"
                       f"renormalised every {float(a['benettin_renormalise']):g} τ, "
                       f"d0 = {float(a['benettin_d0']):g}, transient {float(a['benettin_transient']):g} τ")
        flow.set_xlabel("measuring time (τ)")
        flow.set_ylabel("λ estimate (1/τ)")
    else:
        flow.set_axis_off()
    if "rosenstein_divergence" in g:
        t, curve = g["rosenstein_time"], g["rosenstein_divergence"]
        k0, k1 = int(a["rosenstein_fit_start"]), int(a["rosenstein_fit_end"])
        lam = float(a["rosenstein_exponent"])
        series.plot(t, curve, "-", linewidth=0.8, label="mean ln divergence")
        series.plot(t[k0:k1 + 1], curve[k0] + lam * (t[k0:k1 + 1] - t[k0]), "--", color="tab:red",
                    label=f"fit: λ = {lam:.3g} per τ ({float(a['rosenstein_log2_per_sample']):.3g} log2/sample)")
        series.set_title(f"Rosenstein: m = {int(a['rosenstein_dimension'])}, delay {int(a['rosenstein_delay'])}, "
                         f"Theiler {int(a['rosenstein_theiler'])} samples of "
                         f"{float(a['rosenstein_sample_spacing']):g} τ")
        series.set_xlabel("time after the pairing (τ)")
        series.set_ylabel("⟨ln distance⟩")
        series.legend(fontsize="small")
    else:
        series.set_axis_off()
    fig.savefig(out, dpi=dpi)
    plt.close(fig)


def parse_args(argv):
    parser = argparse.ArgumentParser(
        prog="plot_chaos.py",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("file", type=Path, help="friction output file (HDF5, scene 'brake', &analysis on)")
    parser.add_argument("-o", "--output-dir", type=Path, default=Path("."), metavar="DIR",
                        help="directory for the PNGs, created if missing (default: .)")
    parser.add_argument("--dpi", type=int, default=150, help="resolution (default: %(default)s)")
    args = parser.parse_args(argv)
    if args.dpi <= 0:
        parser.error("--dpi must be positive")
    return args


def main(argv=None):
    args = parse_args(argv)
    prog = "plot_chaos.py"
    try:
        d = read_diagnostics(args.file)
    except InputError as err:
        print(f"{prog}: {args.file}: {err}", file=sys.stderr)
        return 2
    stem = args.file.stem
    plots = [("spectrum", plot_spectrum), ("poincare", plot_poincare), ("lyapunov", plot_lyapunov)]
    try:
        args.output_dir.mkdir(parents=True, exist_ok=True)
        for name, draw in plots:
            if name in d:
                out = args.output_dir / f"{stem}_{name}.png"
                draw(d, out, args.dpi)
                print(f"wrote {out}")
    except OSError as err:
        print(f"{prog}: cannot write into {args.output_dir}: {err}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
