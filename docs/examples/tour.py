# %% [markdown]
# # A tour of friction from Python
#
# A notebook in the percent format (`# %%` cells): open it in Jupyter with jupytext, in VS Code
# or Spyder as cells, or run it whole with `python3 docs/examples/tour.py`. The tests run it
# (CTest `example.tour`), so it stays in step with the package.
#
# It needs the `friction` package (`pip install ./python`, or `PYTHONPATH=python`) and the
# library (`FRICTION_LIBRARY=build/libfriction.so.0`, or an installation). Run it from the
# repository's root, or set `FRICTION_INPUTS` to the `inputs/` folder; the files and pictures
# go to `FRICTION_EXAMPLE_OUTPUT` (default `tour-output/`).
#
# 1. one scan line of NaF, in memory;
# 2. a NaF map as the program writes it, its maps and its friction loop;
# 3. the paper's Girling brake with its spectrum;
# 4. a small sweep of the corrugation V0 at two support velocities.

# %%
import os
from pathlib import Path

import numpy as np

import friction
import friction.plot

inputs = Path(os.environ.get("FRICTION_INPUTS", "inputs"))
out = Path(os.environ.get("FRICTION_EXAMPLE_OUTPUT", "tour-output"))
out.mkdir(parents=True, exist_ok=True)
print(f"friction package {friction.__version__}, library {friction.library_version()} "
      f"({friction.library_path()})")

# %% [markdown]
# ## 1. One scan line, in memory
#
# A `Config` holds a scene's values: the defaults, then namelist files, then values set by
# name ("group.variable", in the input's units). `afm_line` computes one line of the map on
# this process through the C API: the support positions and the lateral force there.

# %%
naf = friction.Config("afm", files=[inputs / "naf.nml"], values={"scan.nx": 200})
print("tip.kx =", naf["tip.kx"], naf.unit("tip.kx"), "| surface.v0 =", naf["surface.v0"], naf.unit("surface.v0"))
x, fx, fy = naf.afm_line(0)
slips = np.flatnonzero(np.diff(fx) < -0.5)      # stick-slip: the force drops at each slip
print(f"{x.size} samples over {x[-1]:g} Å, Fx from {fx.min():.3f} to {fx.max():.3f} nN, "
      f"{slips.size} slips, {np.diff(x[slips]).mean() if slips.size > 1 else float('nan'):.2f} Å apart "
      f"(lattice period {naf['surface.ax']:g} Å)")

# %% [markdown]
# ## 2. A NaF map, as the program writes it
#
# `Config.run` (or `friction.run(files, output=...)`) runs the program's job on this process
# and writes its HDF5 file, with a progress bar (tqdm) or lines on stderr. `friction.load`
# reads the file back as an `xarray.DataTree`: a node per group, arrays with their coordinates
# and units.

# %%
naf.set("scan.nx", 64).set("scan.ny", 16)
path = naf.run(out / "naf.h5", force=True)
data = friction.load(path)
fx_map = data["afm/trace/fx"]
print(fx_map)
print("mean friction over the lines:", data["afm/friction"].values.mean().round(4), data["afm/friction"].attrs["units"])

# %%
maps = friction.plot.afm_maps(data)
maps.savefig(out / "naf_maps.png", dpi=100)
maps

# %% [markdown]
# The friction loop of the middle line: trace and retrace against the support position; the
# enclosed area is the energy the tip dissipates.

# %%
loop = friction.plot.friction_loop(data)
loop.savefig(out / "naf_loop.png", dpi=100)
middle = data["afm/trace/f_along"].sel(support_y=data["afm/support_y"].values[8], method="nearest")
print(f"line at {data['afm/support_y'].values[8]:.3g} Å: mean F along the trace {middle.values.mean():.4f} {middle.attrs['units']}")
loop

# %% [markdown]
# ## 3. The Girling brake and its spectrum
#
# The paper's brake (inputs/brake.nml: the switched stick/slip model over τ ∈ [0, 3200], with
# its chaos diagnostics). The spectrum of x over τ ∈ [100, 1000] has one sharp line at 0.1476
# cycles per τ, where the paper reports a band at 0.1434 (README: "The paper's claims, tested").

# %%
brake_path = friction.run(inputs / "brake.nml", output=out / "brake.h5", force=True)
brake = friction.load(brake_path, scene="brake")
spectrum = brake["brake/spectrum"].attrs
assert abs(spectrum["peak_frequency"] - 0.14762) < 0.0006    # the README's value, within half a bin
print(f"peak {spectrum['peak_frequency']:.5f} {spectrum['peak_frequency_units']} "
      f"(bin {spectrum['resolution']:.5f}); {brake['brake/events/t'].size} stick/slip events; "
      f"stuck {brake['brake/stick'].values.mean():.1%} of the time")
phase = friction.plot.brake_phase(brake)
phase.savefig(out / "brake_phase.png", dpi=100)
figure = friction.plot.brake_spectrum(brake)
figure.savefig(out / "brake_spectrum.png", dpi=100)
figure

# %% [markdown]
# A run without a file: `friction.brake` returns the trajectory and the events as numpy arrays.

# %%
run = friction.brake(values={"brake.t_end": 200.0, "brake.dt_out": 0.1, "analysis.spectrum": False,
                             "analysis.poincare": False, "analysis.lyapunov": False,
                             "analysis.rosenstein": False})
print({name: values.shape for name, values in run.items() if not name.startswith("events/")})

# %% [markdown]
# ## 4. A small sweep
#
# inputs/afm_sweep.nml sweeps V0 (log-spaced) at several support velocities; here 6 values of
# V0 at two velocities on small maps. The file's per-point results come back as a grid over
# both swept variables.

# %%
small = out / "afm_sweep_small.nml"
small.write_text("&scan nx = 32, ny = 2 /\n&sweep sweep_count = 6, sweep_values2 = 100.0, 10000.0 /\n")
sweep_path = friction.run([inputs / "afm_sweep.nml", small], output=out / "afm_sweep.h5", force=True, progress=False)
sweep = friction.load(sweep_path)
mean = sweep["sweep/mean_friction"]
print(mean.dims, mean.shape, mean.attrs["units"])
slow = mean.sel({"scan.velocity": 100.0})
for v0, f in zip(slow["surface.v0"].values, slow.values):
    print(f"V0 = {v0:.3f} eV: mean friction {f:.4f} nN")
figure = friction.plot.sweep(sweep)["friction"]
figure.savefig(out / "afm_sweep.png", dpi=100)
figure

# %% [markdown]
# The file is an xarray tree, so the ecosystem's tools apply as they are: the /sweep node as
# an `xarray.Dataset`, here its largest force at the faster velocity over V0.

# %%
ds = sweep["sweep"].to_dataset()
print(ds["max_force"].sel({"scan.velocity": 10000.0}).values)
