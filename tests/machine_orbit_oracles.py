#!/usr/bin/env python3
"""The machine's periodic orbits, Floquet multipliers and continuation, through
the program and its file, against oracles computed here:

  forced-linear     the support-driven oscillator with the arctan law in its
                    viscous limit: the orbit and the multipliers in closed form
  forced-lugre      a driven LuGre oscillator (stroboscopic section, three
                    coordinates): the section map's Jacobian against central
                    differences of the map integrated here (SciPy's Radau), and
                    the product of the multipliers against exp(∮ div f dt)
  arctan-belt       the self-excited belt oscillator with a velocity-weakening
                    arctan law (the section v = 0 upwards): the same two checks
  hopf-belt         the LuGre paper's belt oscillator continued in belt_velocity:
                    the Hopf bifurcation of steady sliding where c + dF/dv = 0
  refusals          what the orbit cannot do is refused with file, line, group
                    and variable, exit code 3, no file written

    machine_orbit_oracles.py --binary build/friction --inputs inputs --workdir DIR CASE
"""
import sys

import h5py
import numpy as np
from scipy.integrate import solve_ivp, trapezoid
from scipy.optimize import brentq

from machine_cases import run_program, check_refusals, case_main


def run(args, name, files, sets):
    with h5py.File(run_program(args, name, files, sets)) as f:
        g = f["machine/orbit"]
        orbit = {key: g[key][()] for key in g if isinstance(g[key], h5py.Dataset)}
        orbit.update({key: value for key, value in g.attrs.items()})
        if "branch" in g:
            orbit["branch"] = {key: g["branch"][key][()] for key in g["branch"]}
            orbit["bifurcations"] = {key: g["bifurcations"][key][()] for key in ("kind", "parameter")}
    assert orbit["found"] == 1, orbit.get("reason")
    # h5py reads a Fortran (i, j) matrix as [j, i]: the Jacobian back to ∂P_i/∂s_j.
    if "section_jacobian" in orbit:
        orbit["section_jacobian"] = orbit["section_jacobian"].T
    orbit["multipliers"] = orbit["floquet_multipliers"][:, 0] + 1j * orbit["floquet_multipliers"][:, 1]
    return orbit


def jacobian_of(field, y, steps):
    """∂f/∂y by central differences (the divergence's oracle: no analytic partial of the program)."""
    n = len(y)
    jac = np.zeros((n, n))
    for j in range(n):
        d = np.zeros(n)
        d[j] = steps[j]
        jac[:, j] = (np.asarray(field(0.0, y + d)) - np.asarray(field(0.0, y - d))) / (2 * steps[j])
    return jac


def forced_linear(args):
    # m x'' = -k (x - u) - F(x'), u = A sin ωt, F = (2/π) μ N arctan(ε x')/(1 + δ|x'|) with δ = 0 and
    # ε |x'| <= 3e-4: F = c x' (1 + O((ε x')²)), c = 2 μ N ε/π, a relative error of 3e-8 in F, whose share of
    # the forces on the block is 5 %: the orbit agrees with the linear one to ~1e-9 relative.
    m, k, mu, normal, eps, amp, freq = 1.0, 2.0, 1.0, 10.0, 0.01, 0.01, 0.3
    got = run(args, "linear", ["machine_arctan.nml"], {
        "machine.belt_velocity": 0.0, "machine.v0": 0.0, "machine.normal": normal, "machine.support_amplitude": amp,
        "machine.support_frequency": freq, "machine.t_end": 40.0, "law.mu": mu, "law.epsilon": eps,
        "law.delta": 0.0, "analysis.orbit": ".true.", "analysis.orbit_transient": 20.0,
        "analysis.orbit_tolerance": 1e-12})
    c = 2 * mu * normal * eps / np.pi
    omega = 2 * np.pi * freq
    t0 = got["guess_time"]
    h = k * amp / (k - m * omega**2 + 1j * c * omega)   # x = Im(h e^{iωt})
    x = np.imag(h * np.exp(1j * omega * t0))
    v = np.imag(1j * omega * h * np.exp(1j * omega * t0))
    lam = -c / (2 * m) + 1j * np.sqrt(k / m - (c / (2 * m)) ** 2)
    expected = np.array([np.exp(lam / freq), np.exp(np.conj(lam) / freq)])
    orbit_error = max(abs(got["point"][0] - x) / abs(h), abs(got["point"][1] - v) / (omega * abs(h)))
    mult_error = np.max(np.abs(np.sort_complex(got["multipliers"]) - np.sort_complex(expected)))
    print(f"forced-linear: t0 = {t0} s, |point - closed form|/amplitude = {orbit_error:.2e}, "
          f"max |mu - exp(lambda T)| = {mult_error:.2e}, period {got['period']} s")
    # The program's integration (rtol 1e-9) and Newton (1e-12) bound the orbit at ~1e-8 of its amplitude; the
    # multipliers come from the variational equations at the same rtol (|mu| = 0.90, 1e-7 is 100 rtol).
    assert orbit_error < 1e-7, orbit_error
    assert mult_error < 1e-7, mult_error
    assert abs(got["period"] - 1 / freq) < 1e-12


def lugre_field(m, k, c, vb, fc, fs, vs, s0, s1, s2, amp=0.0, freq=0.0):
    def g(w):
        return fc + (fs - fc) * np.exp(-(w / vs) ** 2)

    def field(t, y):
        x, v, z = y
        om = 2 * np.pi * freq
        u, du = amp * np.sin(om * t), amp * om * np.cos(om * t)
        w = v - vb
        zdot = w - s0 * abs(w) * z / g(w)
        return [v, (-k * (x - u) - c * (v - du) - (s0 * z + s1 * zdot + s2 * w)) / m, zdot]
    return field


def check_fd_liouville(name, got, section_map, field, states_of, period, steps, tol_fd, tol_liouville):
    """DP against central differences of the map; ∏μ against exp(∮ div f dt) along the orbit."""
    s = got["section"]
    dp = got["section_jacobian"]
    fd = np.zeros_like(dp)
    for j in range(len(s)):
        d = np.zeros(len(s))
        d[j] = steps[j]
        fd[:, j] = (section_map(s + d) - section_map(s - d)) / (2 * steps[j])
    scale = np.max(np.abs(fd))
    fd_error = np.max(np.abs(dp - fd)) / scale
    # The multipliers: the program's closed forms against NumPy's eigenvalues of the differences' DP
    # (autonomous: the trivial 1 comes first and is not the section map's).
    section_mu = got["multipliers"][1:] if got.get("autonomous") else got["multipliers"]
    expected = np.linalg.eigvals(fd)
    mu_error = max(np.min(np.abs(expected - mu)) for mu in section_mu) / np.max(np.abs(expected))
    print(f"{name}: multipliers {np.round(section_mu, 9)}, differences' eigenvalues {np.round(expected, 9)}, "
          f"max difference {mu_error:.2e} of the largest")
    assert mu_error < tol_fd, (section_mu, expected)
    # ∮ div f dt along the orbit (Radau's dense output, the trace by differences of the field here).
    t0 = got["t0"]
    orbit = solve_ivp(field, (t0, t0 + period), states_of(s), method="Radau", rtol=1e-12, atol=1e-15,
                      dense_output=True)
    ts = np.linspace(t0, t0 + period, 4001)
    ys = orbit.sol(ts)
    div = np.array([np.trace(jacobian_of(lambda _, y: field(t, y), ys[:, i], 1e-7 * np.maximum(np.abs(ys[:, i]), 1e-6)))
                    for i, t in enumerate(ts)])
    integral = trapezoid(div, ts)   # 4000 intervals of a smooth integrand: error ~1e-7 relative
    log_product = np.sum(np.log(np.abs(got["multipliers"])))
    print(f"{name}: max |DP - DP_fd| / max|DP_fd| = {fd_error:.2e}; ln prod|mu| = {log_product:.9f}, "
          f"∮ div f dt = {integral:.9f}, difference {abs(log_product - integral):.2e}")
    assert fd_error < tol_fd, (dp, fd)
    assert abs(log_product - integral) < tol_liouville * max(1.0, abs(integral))


def forced_lugre(args):
    p = dict(m=1.0, k=2.0, c=0.0, vb=0.1, fc=1.0, fs=1.5, vs=1e-3, s0=20.0, s1=1.0, s2=0.4, amp=0.01, freq=0.25)
    got = run(args, "forced_lugre", ["machine_lugre.nml"], {
        "law.sigma0": p["s0"], "law.sigma1": p["s1"], "machine.support_amplitude": p["amp"],
        "machine.support_frequency": p["freq"], "machine.x0": 0.5, "machine.t_end": 60.0,
        "analysis.orbit": ".true.", "analysis.orbit_transient": 40.0})
    field = lugre_field(**p)
    t0 = got["guess_time"]
    period = 1 / p["freq"]

    def strobe(s):
        r = solve_ivp(field, (t0, t0 + period), s, method="Radau", rtol=1e-12, atol=1e-15)
        return r.y[:, -1]

    got["section"] = got["point"]
    got["t0"] = t0
    assert np.max(np.abs(strobe(got["point"]) - got["point"])) < 1e-8   # the orbit closes under SciPy too
    # Steps 1e-5 of x, v and z's sizes: truncation ~1e-10, Radau's noise 1e-15/1e-5 ~1e-10 (the map is
    # linear to that here); the program's DP from the variational equations at rtol 1e-9: 1e-6 is 1000 rtol.
    check_fd_liouville("forced-lugre", got, strobe, field, lambda s: s, period, [1e-5, 1e-5, 1e-7], 1e-6, 1e-6)


def arctan_belt(args):
    m, k, vb, mu, normal, eps, delta = 1.0, 2.0, 0.1, 1.0, 1.0, 20.0, 10.0
    got = run(args, "arctan_belt", ["machine_arctan.nml"], {
        "law.epsilon": eps, "law.delta": delta, "machine.t_end": 100.0, "analysis.orbit": ".true.",
        "analysis.orbit_transient": 50.0})

    def field(_, y):
        x, v = y
        w = v - vb
        return [v, (-k * x - mu * normal * (2 / np.pi) * np.arctan(eps * w) / (1 + delta * abs(w))) / m]

    def crossing(t, y):
        return y[1]
    crossing.direction = 1
    crossing.terminal = True

    def section_map(s):
        # Leave the section first (v = 0 there), then stop at the next upward crossing.
        start = solve_ivp(field, (0.0, 0.5), [s[0], 0.0], method="Radau", rtol=1e-12, atol=1e-15)
        r = solve_ivp(field, (0.5, 100.0), start.y[:, -1], method="Radau", rtol=1e-12, atol=1e-15,
                      events=crossing)
        return np.array([r.y_events[0][0][0]])

    got["section"] = np.array([got["point"][0]])
    got["t0"] = 0.0
    got["autonomous"] = True
    assert abs(section_map(got["section"])[0] - got["point"][0]) < 1e-8
    # Liouville over the period with the trivial multiplier 1 included (ln 1 = 0).
    check_fd_liouville("arctan-belt", got, section_map, field, lambda s: [s[0], 0.0], got["period"], [1e-5],
                       1e-6, 1e-6)


def hopf_belt(args):
    got = run(args, "hopf", ["machine_orbit.nml"], {})
    fc, fs, vs, s0, s1, s2, m, k, c = 1.0, 1.5, 1e-3, 1e5, np.sqrt(1e5), 0.4, 1.0, 2.0, 0.0

    def g(w):
        return fc + (fs - fc) * np.exp(-(w / vs) ** 2)

    def dg(w):
        return -(fs - fc) * 2 * w / vs**2 * np.exp(-(w / vs) ** 2)

    def growth(vb):
        # Steady sliding at w = -vb linearized by hand: ż = w - σ0 |w| z/g(w) gives ∂ż/∂v = w g'/g, ∂ż/∂z = σ0 w/g.
        w = -vb
        a, b = w * dg(w) / g(w), s0 * w / g(w)
        jac = np.array([[0, 1, 0], [-k / m, -(c + s1 * a + s2) / m, -(s0 + s1 * b) / m], [0, a, b]])
        return np.max(np.linalg.eigvals(jac).real)

    # c + dF/dv = 0 with F = g(v) + σ2 v the steady force at the belt velocity (the quasi-static prediction).
    linear = brentq(lambda v: c + s2 + dg(v), 2e-3, 4e-3, xtol=1e-16, rtol=1e-15)
    exact = brentq(growth, 2.5e-3, 3.5e-3, xtol=1e-16, rtol=1e-15)
    kinds, where = got["bifurcations"]["kind"], got["bifurcations"]["parameter"]
    assert list(kinds) == [5], kinds   # one Hopf, no multiplier through the unit circle (the orbit is superstable)
    found = where[0]
    print(f"hopf-belt: Hopf at belt_velocity = {found:.12e} m/s; c + dF/dv = 0 at {linear:.12e} m/s "
          f"(relative difference {abs(found - linear) / linear:.2e}); the bristles' 3x3 linearization at "
          f"{exact:.12e} m/s ({abs(found - exact) / exact:.2e}); orbits found at "
          f"{int(np.sum(got['branch']['found']))} of {len(got['branch']['found'])} points")
    # c + dF/dv = 0 is the limit of fast bristles: their lag g/(σ0 |v|) = 5e-3 s against the period
    # 2π/√(k/m) = 4.4 s moves the Hopf by 7.4e-8 relative (the 3x3 linearization above); 1e-6 bounds it.
    assert abs(found - linear) / linear < 1e-6
    # The program bisects the largest real part of its equilibrium's eigenvalues (the cubic's roots, ~1e-13)
    # to 1e-12 of the step: 1e-9 relative is far outside both.
    assert abs(found - exact) / exact < 1e-9
    assert np.all(got["branch"]["found"] == 1)


def refusals(args):
    cases = [  # (the groups, the line named, what the message names, why)
        ("&law\n  model = 'coulomb'\n/\n&analysis\n  orbit = .true.\n/\n", 9, "&analysis: orbit = ",
         "switches between stick and slip"),
        ("&law\n  model = 'lugre'\n/\n&analysis\n  orbit = .true.\n  continuation = 'gravity'\n/\n", 10,
         "&analysis: continuation = ", "not a variable of &machine the orbit can follow"),
        ("&law\n  model = 'lugre'\n/\n&analysis\n  orbit = .true.\n  continuation = 'stiffness'\n"
         "  continuation_end = -1.0\n/\n", 11, "&analysis: continuation_end = ", "not a valid machine"),
        ("&machine\n  support_amplitude = 0.01\n  support_frequency = 0.2\n/\n&law\n  model = 'lugre'\n/\n"
         "&analysis\n  orbit = .true.\n  continuation = 'support_amplitude'\n  continuation_end = 0.0\n/\n", 15,
         "&analysis: continuation_end = ", "keep the support moving"),
    ]
    check_refusals(args, cases, "refusals")


def main():
    return case_main(__doc__, {"forced-linear": forced_linear, "forced-lugre": forced_lugre,
                               "arctan-belt": arctan_belt, "hopf-belt": hopf_belt, "refusals": refusals})


if __name__ == "__main__":
    sys.exit(main())
