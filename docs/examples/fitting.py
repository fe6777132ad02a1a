# %% [markdown]
# # From a friction image to the microscope's parameters
#
# A notebook in the percent format, run whole by the tests (CTest `example.fitting`). It needs
# the `friction` package, the library, scipy and (for section 4) emcee and corner. Pictures go
# to `FRICTION_EXAMPLE_OUTPUT` (default `fitting-output/`).
#
# 1. a synthetic "measured" NaF image: known parameters, 2 % noise, an offset and a drift;
# 2. its fit: estimates, standard errors, correlations, the maps;
# 3. before the experiment: which scan would determine V0 and k;
# 4. a degenerate pair seen whole: an MCMC sample and its corner plot.
#
# The fits here run on this process (`workers=1`): a pool of processes imports the main
# module again, so a script that asks for one keeps its work under
# `if __name__ == "__main__":`.

# %%
import os
from pathlib import Path

import numpy as np

import friction
import friction.fit
import friction.plot

inputs = Path(os.environ.get("FRICTION_INPUTS", "inputs"))
out = Path(os.environ.get("FRICTION_EXAMPLE_OUTPUT", "fitting-output"))
out.mkdir(parents=True, exist_ok=True)

# %% [markdown]
# ## 1. A "measured" image
#
# NaF(001) with V0 = 0.8 eV and k = kx = ky = 6 N/m, 12 lines of 32 samples over the paper's
# 20 × 20 Å scan, trace and retrace. The microscope adds an offset of 0.05 nN, its support
# drifts 0.02 Å per line along x and −0.01 Å along y, and the force carries Gaussian noise of
# 2 % of the image's spread. Each line is computed with its origin moved, as the drift moves it.

# %%
TRUE = {"surface.v0": 0.8, "tip.kx": 6.0, "tip.ky": 6.0}
scan = {"scan.nx": 32, "scan.ny": 12, "integrator.rtol": 1e-6, "integrator.atol": 1e-7}
drift = (0.02, -0.01)
with friction.Config("afm", files=[inputs / "naf.nml"], values={**scan, **TRUE}) as cfg:
    clean = {"trace/fx": [], "retrace/fx": []}
    for j in range(scan["scan.ny"]):
        cfg.set("scan.origin_x", drift[0] * j).set("scan.origin_y", drift[1] * j)
        clean["trace/fx"].append(cfg.afm_line(j, True).fx)
        clean["retrace/fx"].append(cfg.afm_line(j, False).fx)
clean = {k: np.array(v) for k, v in clean.items()}
sigma = 0.02 * np.std(np.concatenate([v.ravel() for v in clean.values()]))
rng = np.random.default_rng(1)
measured = {k: v + 0.05 + sigma * rng.standard_normal(v.shape) for k, v in clean.items()}
print(f"noise {sigma:.4f} nN")

# %% [markdown]
# ## 2. The fit
#
# V0 and the tied spring constants free, started 25 % and 33 % off; the offset and both drifts
# fitted alongside. `summary()` gives each estimate with its standard error, the noise level
# from the residuals and the degenerate pairs.

# %%
with friction.Config("afm", files=[inputs / "naf.nml"], values=scan) as cfg:
    fit = friction.fit.image(measured, cfg, {"surface.v0": 0.6, "tip.kx=tip.ky": 8.0},
                             nuisances=("offset", "drift_x", "drift_y"), workers=1)
print(fit.summary())
truth = {"surface.v0": 0.8, "tip.kx=tip.ky": 6.0, "offset": 0.05, "drift_x": drift[0], "drift_y": drift[1]}
for name in fit.names:
    print(f"{name:>15}: {(fit.values[name] - truth[name]) / fit.errors[name]:+.2f} standard errors from the truth")
friction.plot.fit_maps(fit, "trace/fx").savefig(out / "fit_maps.png", dpi=110)

# %% [markdown]
# ## 3. Before the experiment
#
# The Fisher information of a planned scan gives the standard errors a fit would have and the
# correlations between parameters, from the model alone. One line at 400 Å/s leaves V0 and k
# nearly degenerate (a deeper corrugation and a stiffer spring give nearly the same line); a
# second line a thousand times faster, where the tip's mass and damping count, separates them.

# %%
line = {"scan.nx": 64, "scan.ny": 1, "scan.retrace": False, "scan.origin_y": 1.0,
        "integrator.rtol": 1e-6, "integrator.atol": 1e-7, **TRUE}
plans = {}
for label, extra in {"400 Å/s": {}, "45°": {"scan.angle": 45.0}, "4e5 Å/s": {"scan.velocity": 4.0e5}}.items():
    with friction.Config("afm", files=[inputs / "naf.nml"], values={**line, **extra}) as cfg:
        plans[label] = friction.fit.identifiability(cfg, ["surface.v0", "tip.kx=tip.ky"], 0.02, workers=1)
for label, plan in plans.items():
    print(f"{label:>8}: SE(V0) {plan.errors['surface.v0']:.2e} eV, SE(k) {plan.errors['tip.kx=tip.ky']:.2e} N/m, "
          f"corr {plan.correlation[0, 1]:+.3f}")


def joint(*labels):
    jac = np.vstack([plans[label].jacobian for label in labels])
    cov = 0.02 ** 2 * np.linalg.inv(jac.T @ jac)
    return cov[0, 1] / np.sqrt(cov[0, 0] * cov[1, 1])


print(f"400 Å/s with 45°: corr {joint('400 Å/s', '45°'):+.3f}; "
      f"with 4e5 Å/s: corr {joint('400 Å/s', '4e5 Å/s'):+.3f}")

# %% [markdown]
# ## 4. The degenerate pair seen whole
#
# One noisy line, V0 and k free with an offset: the standard errors describe an ellipse, and an
# MCMC sample (emcee) shows the posterior whole, drawn as a corner plot.

# %%
try:
    import corner  # noqa: F401
    import emcee  # noqa: F401
    have_sampler = True
except ImportError:
    have_sampler = False
    print("emcee or corner missing: no sample")
if have_sampler:
    with friction.Config("afm", files=[inputs / "naf.nml"], values=line) as cfg:
        truth_line = cfg.afm_line(0).fx
    noisy = truth_line + 0.05 + 0.05 * np.random.default_rng(7).standard_normal(truth_line.size)
    with friction.Config("afm", files=[inputs / "naf.nml"], values=line) as cfg:
        one = friction.fit.image({"trace/fx": noisy}, cfg, {"surface.v0": 0.7, "tip.kx=tip.ky": 7.0},
                                 nuisances=("offset",), workers=1)
    print(one.summary())
    sample = one.sample(steps=300, walkers=10, seed=3)
    print("sample's standard deviations:", dict(zip(one.names, np.round(np.std(sample, axis=0), 5))),
          "standard errors:", {n: round(one.errors[n], 5) for n in one.names})
    friction.plot.fit_corner(sample, one.names, truths=[0.8, 6.0, 0.05]).savefig(out / "fit_corner.png", dpi=90)
