#!/usr/bin/env python3
"""The periodic orbits, Floquet multipliers and continuation of the brake with
a law of &law (&brake model = 'law'), through the program and its file,
against oracles that are not that model's output:

  coulomb-switched   &law coulomb (δ' = 0, μ and μs the switched model's) on
                     the paper's brake and brake_continuation.nml's slow belt:
                     the orbit, its multipliers and the branch followed in &law
                     mu against the switched model's own, followed in &brake mu
  stribeck-scipy     a Stribeck law with exact stick: the stick-to-slip section
                     map's Jacobian against central differences of the map
                     integrated here (SciPy's DOP853 through the stick/slip
                     switching, written out below), the fixed point and the
                     period against that map
  table-stribeck     &law table sampled from that Stribeck curve: the orbit
                     converges to the Stribeck law's as the rows densify,
                     within the interpolant's error (SciPy's PCHIP in ln v)
  arctan-scipy       the arctan law (no exact stick; the section is the exit
                     from the creep band): the same checks against SciPy's
                     Radau on Eq. 10 with the arctan force
  lugre-scipy        the LuGre law (a state: the bristles' deflection) on the
                     creep band's exit, coordinates (x, y, w, z/scale): the
                     section map's 4x4 Jacobian and multipliers against
                     central differences of the map integrated here (SciPy's
                     DOP853, events located), the orbit closing in SciPy's flow
  elastoplastic-scipy the same for the elasto-plastic law (LuGre's bristle
                     with an elastic range)
  lugre-continuation inputs/brake_lugre_orbit.nml's orbit followed in F_s:
                     the period doubling where the section map's real
                     multiplier passes -1, the orbit stable beyond it
  lugre-stiff        inputs/brake_lugre.nml's stiff bristles (σ0 = 1e5 N/m): Newton
                     stops unconverged, and SciPy's Radau map at its last
                     iterate gives the same residual and shows why: the map's
                     derivative doubles within 1e-6 m of that point
  refusals           what the orbit of this model does not do is refused with
                     file, line, group and variable, exit code 3, no file

    brake_law_orbit_oracles.py --binary build/friction --inputs inputs --workdir DIR CASE
"""
import sys
from pathlib import Path

import h5py
import numpy as np
from scipy.integrate import solve_ivp
from scipy.interpolate import PchipInterpolator

from machine_cases import run_program, check_refusals, case_main
from brake_law_oracles import brake_lugre

QUIET = {"analysis.spectrum": ".false.", "analysis.poincare": ".false.", "analysis.lyapunov": ".false.",
         "analysis.lyapunov_spectrum": ".false.", "analysis.rosenstein": ".false.", "analysis.orbit": ".true.",
         "analysis.continuation": "''"}
# brake.nml's mechanism (ξ, κ, g') and brake_continuation.nml's slow belt.
XI, KAPPA, G_PRIME, V_DR = 0.412, 1.5, 0.01778, -2.0e-4


def orbit_of(args, name, files, sets):
    with h5py.File(run_program(args, name, files, {**QUIET, **sets})) as f:
        g = f["brake/orbit"]
        orbit = {key: g[key][()] for key in g if isinstance(g[key], h5py.Dataset)}
        orbit.update({key: value.decode() if isinstance(value, bytes) else value for key, value in g.attrs.items()})
        if "branch" in g:
            orbit["branch"] = {key: g["branch"][key][()] for key in g["branch"]
                               if isinstance(g["branch"][key], h5py.Dataset)}
            orbit["bifurcations"] = {key: g["bifurcations"][key][()] for key in g["bifurcations"]}
    assert orbit["found"] == 1, orbit.get("reason")
    # h5py reads a Fortran (i, j) matrix as [j, i]: the Jacobian back to ∂P_i/∂s_j.
    orbit["section_jacobian"] = orbit["section_jacobian"].T
    orbit["multipliers"] = orbit["floquet_multipliers"][:, 0] + 1j * orbit["floquet_multipliers"][:, 1]
    return orbit


def coulomb_switched(args):
    # Coulomb's law with μ, μs and no viscous term is the switched model's kinetic law when δ' = 0, and its
    # static limit the same μs N': the same equations through another code path (law_model.f90's slip and
    # its stick-exit saltation, the law's static line on the section).  The law's slip Jacobian takes
    # ∂F/∂N' by a central difference where the switched model's is analytic: exact for an affine force up to
    # rounding, eps μN'/(1e-6 N') ~ 2e-10 relative in one entry of the variational equations; the bound
    # 1e-8 on the multipliers and the Jacobian is 50 times that.  The states and periods agree to the
    # integration's rounding (rk8pd at rtol 1e-10 on the same steps): 1e-12.
    # Two lines: from a stable orbit through a period doubling (μs = 0.59), and of unstable orbits (μs = 0.55).
    law = {"brake.model": "'law'", "law.model": "'coulomb'", "law.sigma2": 0.0}
    for mu, mu_s, end, points in ((0.57, 0.59, 0.45, 13), (0.45, 0.55, 0.35, 11)):
        sets = {"brake.delta_prime": 0.0, "brake.mu": mu, "brake.mu_s": mu_s, "analysis.continuation": "'mu'",
                "analysis.continuation_end": end, "analysis.continuation_points": points}
        own = orbit_of(args, f"switched_{mu}", ["brake.nml", "brake_continuation.nml"], sets)
        got = orbit_of(args, f"law_{mu}", ["brake.nml", "brake_continuation.nml"],
                       {**sets, **law, "law.mu": mu, "law.mu_s": mu_s})
        state = np.max(np.abs(got["point"] - own["point"]))
        period = abs(got["period"] - own["period"])
        multipliers = np.max(np.abs(got["multipliers"] - own["multipliers"]))
        jacobian = np.max(np.abs(got["section_jacobian"] - own["section_jacobian"]))
        print(f"coulomb-switched (mu {mu}, mu_s {mu_s}): period {own['period']:.10f} tau, multipliers "
              f"{np.round(own['multipliers'], 6)}; differences: state {state:.1e} m, period {period:.1e} tau, "
              f"multipliers {multipliers:.1e}, section Jacobian {jacobian:.1e}")
        assert got["section"] == own["section"] == "stick_to_slip"
        assert np.array_equal(got["events_per_period"], own["events_per_period"])
        assert state <= 1e-12 and period <= 1e-10, (state, period)
        assert multipliers <= 1e-8 and jacobian <= 1e-8 * np.max(np.abs(own["section_jacobian"])), \
            (multipliers, jacobian)
        a, b = own["branch"], got["branch"]
        assert np.array_equal(a["parameter"], b["parameter"]) and np.array_equal(a["found"], b["found"]), (a["found"], b["found"])
        assert a["found"].sum() >= 6, a["found"]
        found = a["found"] == 1
        branch_state = np.max(np.abs(a["point"][found] - b["point"][found]))
        branch_mu = np.max(np.abs((a["floquet_multipliers_real"] + 1j * a["floquet_multipliers_imag"])[found]
                                  - (b["floquet_multipliers_real"] + 1j * b["floquet_multipliers_imag"])[found]))
        print(f"  branch in mu to {end}: {int(found.sum())} of {found.size} points with an orbit; differences "
              f"state {branch_state:.1e} m, multipliers {branch_mu:.1e}; bifurcations "
              f"{list(own['bifurcations']['kind'])} at {np.round(own['bifurcations']['parameter'], 6)}")
        assert branch_state <= 1e-10 and branch_mu <= 1e-8, (branch_state, branch_mu)
        assert np.array_equal(own["bifurcations"]["kind"], got["bifurcations"]["kind"])
        assert np.allclose(own["bifurcations"]["parameter"], got["bifurcations"]["parameter"], rtol=0, atol=1e-8)


class SwitchedBrake:
    """Eq. 10 with exact stick and a set-valued law: in stick x' = v_dr and the
    crank moves on; a slip in direction s under slip_force(v_rel, s, N') ends
    where s v_rel falls through 0 (stick if |2x - y| is within the static
    limit slope N' + level, else a slip the other way); a stick ends where
    |2x - y| reaches the limit.  SciPy's DOP853 and its event location."""

    def __init__(self, slope, level, slip_force):
        self.slope, self.level, self.slip_force = slope, level, slip_force
        self.tol = dict(rtol=1e-12, atol=1e-15)

    def limit(self, y):
        return self.slope * ((1 - KAPPA) * y + G_PRIME) + self.level

    def slip_rhs(self, s):
        def rhs(t, z):
            x, v, y, w = z
            return [v, -(2 * x - y) - self.slip_force(v - V_DR, s, (1 - KAPPA) * y + G_PRIME), w,
                    (x - KAPPA * y) / XI]
        return rhs

    @staticmethod
    def stick_rhs(t, z):
        x, v, y, w = z
        return [V_DR, 0.0, w, (x - KAPPA * y) / XI]

    def section_map(self, sigma, point, t_max=400.0):
        """(y, w) on the limit σ to the next slip onset at the same limit; the image and the return time."""
        y, w = point
        z = np.array([(y + sigma * self.limit(y)) / 2, V_DR, y, w])
        t, s = 0.0, -sigma
        while t < t_max:
            # Slip: s v_rel grows from 0 (from second order when the slip force at 0 is the static limit):
            # a short step before the end is looked for.
            rhs = self.slip_rhs(s)
            start = solve_ivp(rhs, (t, t + 1e-4), z, method="DOP853", **self.tol)
            t, z = start.t[-1], start.y[:, -1]

            def end(t, z, s=s):
                return s * (z[1] - V_DR)
            end.terminal, end.direction = True, -1
            sol = solve_ivp(rhs, (t, t_max), z, method="DOP853", events=end, **self.tol)
            t, z = sol.t_events[0][0], sol.y_events[0][0].copy()
            if abs(2 * z[0] - z[2]) <= self.limit(z[2]):
                z[1] = V_DR

                def upper(t, z):
                    return 2 * z[0] - z[2] - self.limit(z[2])

                def lower(t, z):
                    return 2 * z[0] - z[2] + self.limit(z[2])
                upper.terminal, upper.direction = True, 1
                lower.terminal, lower.direction = True, -1
                sol = solve_ivp(self.stick_rhs, (t, t_max), z, method="DOP853", events=[upper, lower], **self.tol)
                which = 0 if sol.t_events[0].size else 1
                t, z = sol.t_events[which][0], sol.y_events[which][0].copy()
                exit_limit = 1.0 if which == 0 else -1.0
                if exit_limit == sigma:
                    return np.array([z[2], z[3]]), t
                s = -exit_limit
            else:
                s = -s
        raise RuntimeError("no return")


def central_differences(section_map, point, steps):
    """∂P/∂s by central differences with the given steps."""
    jac = np.zeros((len(point), len(point)))
    for j, h in enumerate(steps):
        d = np.zeros(len(point))
        d[j] = h
        jac[:, j] = (section_map(point + d)[0] - section_map(point - d)[0]) / (2 * h)
    return jac


def check_map(label, orbit, section_map, point, step, ratio, period_bound, point_bound, noise):
    """The program's fixed point, period and section Jacobian against the map integrated here: central
    differences with steps `step` and step/ratio, extrapolated (Richardson, the h² error removed)."""
    image, period = section_map(point)
    closure = np.max(np.abs(image - point))
    coarse = central_differences(section_map, point, step * np.ones(len(point)))
    fine = central_differences(section_map, point, step / ratio * np.ones(len(point)))
    # The spread of the two measures their truncation error: (1 - 1/ratio²) of the coarse one's.
    spread = np.max(np.abs(coarse - fine))
    extrapolated = fine + (fine - coarse) / (ratio ** 2 - 1)
    difference = np.max(np.abs(orbit["section_jacobian"] - extrapolated))
    size = np.max(np.abs(extrapolated))
    mu = np.sort_complex(np.linalg.eigvals(extrapolated))[::-1]
    print(f"{label}: period {orbit['period']:.10f} tau (SciPy's map {period:.10f}), |P(s) - s| by SciPy "
          f"{closure:.1e}; section Jacobian {difference:.1e} from SciPy's extrapolated differences (largest entry "
          f"{size:.3g}, the two steps' spread {spread:.1e}); multipliers {np.round(orbit['multipliers'], 7)}, "
          f"of the differences {np.round(mu, 7)}")
    assert closure <= point_bound, closure
    assert abs(period - orbit["period"]) <= period_bound, (period, orbit["period"])
    # What the extrapolation leaves is the h⁴ term, far below the spread, and the map's noise over the fine
    # step (`noise` of the entries, from the integration's tolerance).
    assert difference <= max(spread / ratio ** 2, noise * size), (difference, spread)
    return extrapolated


def stribeck_scipy(args):
    # The Stribeck law in the brake's units (units = 'nondimensional': forces in m, velocities in m/τ):
    # F_c = 0.0085, F_s = 0.0105 (about μ N' of the paper's brake), v_s = 2e-4 m/τ, δ = 2, σ2 = 0.
    fc, fs, vs = 0.0085, 0.0105, 2e-4
    sets = {"brake.model": "'law'", "law.model": "'stribeck'", "law.fc": fc, "law.fs": fs, "law.vs": vs,
            "law.exponent": 2.0, "law.sigma2": 0.0, "brake.event_tolerance": 1e-12,
            "integrator.rtol": 1e-12, "integrator.atol": 1e-15, "analysis.orbit_tolerance": 1e-11}
    orbit = orbit_of(args, "stribeck", ["brake.nml", "brake_continuation.nml"], sets)
    assert orbit["section"] == "stick_to_slip"
    sigma = float(orbit["static_limit"])
    brake = SwitchedBrake(0.0, fs, lambda v, s, n: s * (fc + (fs - fc) * np.exp(-(v / vs) ** 2)))
    point = orbit["point"][[2, 3]]
    # SciPy at rtol 1e-12: the map to ~1e-13 m; Newton stopped at 1e-11 m (the closure bound 1e-9 and the
    # period's 1e-8 τ leave room for the event times, located to 1e-12 τ, over a dozen events).  Differences
    # with steps of 1e-6 m and 2e-7 m, extrapolated: measured 8.7e-11 from the program's Jacobian (without
    # Richardson 1.1e-8, the h² error); the bound 1e-7 of the largest entry is a thousand times that.
    fine = check_map("stribeck-scipy", orbit, lambda p: brake.section_map(sigma, p), point, 1e-6, 5.0, 1e-8, 1e-9,
                     1e-7)
    # The orbit's multipliers: 1, the section map's two, 0 (the stick forgets the velocity).
    assert orbit["multipliers"][0] == 1 and orbit["multipliers"][3] == 0
    mu = np.linalg.eigvals(fine)
    assert np.max(np.abs(np.sort(np.abs(mu)) - np.sort(np.abs(orbit["multipliers"][1:3])))) <= 1e-5


def table_stribeck(args):
    # The table law's own code (a monotone cubic in ln v, its first row the static limit) against the
    # Stribeck law it samples, rows from 1e-7 m/τ (below, the table holds the first row's force where the
    # curve falls by (F_s - F_c)(v/v_s)² <= 2.5e-10 m) to 1 m/τ.  A force wrong by δF everywhere moves the
    # orbit by about δF (the brake's forces are lengths; measured: 5.7e-10 m at 40 rows a decade, where
    # the interpolant is 3.7e-8 m off at most): the state within the interpolant's largest error, and the
    # period converging faster than h² (PCHIP's h³; measured 3.0e-7 τ then 2.1e-8 τ).
    fc, fs, vs = 0.0085, 0.0105, 2e-4
    common = {"brake.model": "'law'", "brake.event_tolerance": 1e-12, "integrator.rtol": 1e-12,
              "integrator.atol": 1e-15, "analysis.orbit_tolerance": 1e-11}
    own = orbit_of(args, "stribeck", ["brake.nml", "brake_continuation.nml"],
                   {**common, "law.model": "'stribeck'", "law.fc": fc, "law.fs": fs, "law.vs": vs,
                    "law.exponent": 2.0, "law.sigma2": 0.0})
    periods = []
    for per_decade in (20, 40):
        v = np.logspace(-7, 0, 7 * per_decade + 1)
        force = fc + (fs - fc) * np.exp(-(v / vs) ** 2)
        table = Path(args.workdir) / f"stribeck_{per_decade}.txt"
        np.savetxt(table, np.column_stack([v, force]), fmt="%.17e", header="v (m per unit tau), F (m)")
        fine = np.logspace(-7, -1, 200001)
        error = np.max(np.abs(PchipInterpolator(np.log(v), force)(np.log(fine))
                              - (fc + (fs - fc) * np.exp(-(fine / vs) ** 2))))
        got = orbit_of(args, f"table_{per_decade}", ["brake.nml", "brake_continuation.nml"],
                       {**common, "law.model": "'table'", "law.table_file": f"'{table}'"})
        state = np.max(np.abs(got["point"] - own["point"]))
        periods.append(abs(got["period"] - own["period"]))
        multipliers = np.max(np.abs(got["multipliers"] - own["multipliers"]))
        print(f"table-stribeck ({per_decade} rows a decade): state {state:.1e} m, period {periods[-1]:.1e} tau, "
              f"multipliers {multipliers:.1e} from the Stribeck law's; the interpolant's largest error {error:.1e} m")
        assert state <= error, (state, error)
    assert periods[1] <= periods[0] / 4, periods


def arctan_map(mu, eps, delta, stick_velocity, sigma):
    """The creep band's exit v_rel = s v_s (s = -σ) crossed away from 0, Eq. 10 with the arctan law, SciPy's
    Radau with the exact Jacobian; coordinates (x, y, w)."""
    s = -sigma
    level = V_DR + s * stick_velocity

    def force(v, n):
        return mu * n * (2 / np.pi) * np.arctan(eps * v) / (1 + delta * abs(v))

    def rhs(t, z):
        x, v, y, w = z
        return [v, -(2 * x - y) - force(v - V_DR, (1 - KAPPA) * y + G_PRIME), w, (x - KAPPA * y) / XI]

    def jac(t, z):
        x, v, y, w = z
        u, n = v - V_DR, (1 - KAPPA) * y + G_PRIME
        d = 1 + delta * abs(u)
        dfdv = mu * n * (2 / np.pi) * (eps / (1 + (eps * u) ** 2) / d - np.arctan(eps * u) * delta * np.sign(u) / d ** 2)
        dfdn = force(u, 1.0)
        return [[0, 1, 0, 0], [-2, -dfdv, 1 - dfdn * (1 - KAPPA), 0], [0, 0, 0, 1], [1 / XI, 0, -KAPPA / XI, 0]]

    def crossing(t, z):
        return z[1] - level
    crossing.terminal, crossing.direction = True, s

    def section_map(point):
        x, y, w = point
        z = np.array([x, level, y, w])
        # Leave the start on the section before the crossing is looked for.
        start = solve_ivp(rhs, (0, 1e-3), z, method="Radau", jac=jac, rtol=1e-12, atol=1e-15)
        sol = solve_ivp(rhs, (start.t[-1], 400.0), start.y[:, -1], method="Radau", jac=jac, rtol=1e-12,
                        atol=1e-15, events=crossing)
        z = sol.y_events[0][0]
        return np.array([z[0], z[2], z[3]]), sol.t_events[0][0]
    return section_map


def arctan_scipy(args):
    # The paper's arctan law (μ = 0.59, ε' = 3.5121e7, δ' = 3.5121) on brake_continuation.nml's slow belt, with
    # a creep band of 1e-5 m/τ: the block creeps down to |v_rel| ~ 3e-6 m/τ, inside the band (the default
    # 1e-6 it never enters), and leaves it at the smooth flow's slip onset.
    mu, eps, delta, band = 0.59, 3.5121e7, 3.5121, 1e-5
    sets = {"brake.model": "'law'", "law.model": "'arctan'", "law.mu": mu, "law.epsilon": eps, "law.delta": delta,
            "brake.stick_velocity": band, "integrator.method": "'rk4imp'", "integrator.rtol": 1e-12,
            "integrator.atol": 1e-15, "brake.event_tolerance": 1e-12, "analysis.orbit_tolerance": 1e-10}
    orbit = orbit_of(args, "arctan", ["brake.nml", "brake_continuation.nml"], sets)
    assert orbit["section"] == "creep_band_exit"
    sigma = float(orbit["static_limit"])
    point = orbit["point"][[0, 2, 3]]
    # The program on rk4imp at rtol 1e-12 (rodas4, which 'auto' takes, steps through the creep by the state's
    # error alone and its uncontrolled tangent lags: at rtol 1e-11 its section Jacobian is 2e-5 off, at 1e-13
    # 7e-6; rk4imp at 1e-12 and rk8pd at 1e-13 agree to 1e-8, measured).  SciPy's Radau
    # at rtol 1e-12 on the stiff creep (dF/dv ~ 2e5 per τ): the map closes to 1e-13 m.  Differences with steps
    # 2e-7 m and 1e-7 m (the creep makes the map curve on the scale of 1e-5 m: their spread 3e-5),
    # extrapolated; the map's noise over 1e-7 m and the h⁴ term that remains: 2e-6 of the largest entry.
    fine = check_map("arctan-scipy", orbit, arctan_map(mu, eps, delta, band, sigma), point, 2e-7, 2.0, 1e-8, 1e-9,
                     2e-6)
    assert orbit["multipliers"][0] == 1
    mu_fd = np.linalg.eigvals(fine)
    assert np.max(np.abs(np.sort(np.abs(mu_fd)) - np.sort(np.abs(orbit["multipliers"][1:])))) <= 1e-5


def law_band_map(force, rate, scale, stick_velocity, sigma, t_max=100.0):
    """The creep band's exit v_rel = s v_s (s = -σ) crossed away from 0 of Eq. 10 with a law with states
    (force(u, z), rate(u, z), z in the law's units, the brake's units throughout), SciPy's DOP853 at rtol
    1e-12 (σ0 = 1000 is not stiff for an explicit stepper) with its located events; coordinates (x, y, w,
    z/scale) as the program's.  The laws' rates have a kink at v_rel = 0 (|v|, sgn v): located, and the
    integration started again there, so that no step straddles it (the map's differences would carry
    the stepper's first-order error there)."""
    s = -sigma
    level = V_DR + s * stick_velocity
    scale = np.asarray(scale, dtype=float)

    def rhs(t, q):
        x, v, y, w = q[:4]
        u, z = v - V_DR, q[4:] * scale
        return np.concatenate([[v, -(2 * x - y) - force(u, z), w, (x - KAPPA * y) / XI], rate(u, z) / scale])

    def crossing(t, q):
        return q[1] - level
    crossing.terminal, crossing.direction = True, s

    def kink(t, q):
        return q[1] - V_DR
    kink.terminal = True

    def section_map(point):
        q = np.concatenate([[point[0], level], point[1:]])
        # Leave the start on the section before the crossing is looked for.
        start = solve_ivp(rhs, (0, 1e-3), q, method="DOP853", rtol=1e-12, atol=1e-15)
        t, q = start.t[-1], start.y[:, -1]
        while t < t_max:
            sol = solve_ivp(rhs, (t, t_max), q, method="DOP853", rtol=1e-12, atol=1e-15, events=[crossing, kink])
            if sol.t_events[0].size:
                q = sol.y_events[0][0]
                return np.concatenate([[q[0]], q[2:]]), sol.t_events[0][0]
            # On from the kink's far side: a step past it (SciPy's located root may sit on either side).
            t, q = sol.t_events[1][0], sol.y_events[1][0]
            q = q + 1e-13 * np.asarray(rhs(t, q))
            t += 1e-13
        raise RuntimeError("no return")
    return section_map


# inputs/brake_lugre_orbit.nml's law in the brake's units: F_c 0.0095 m, F_s 0.0100 m, v_s 2e-3 m/τ, δ = 2,
# σ0 = 1000, σ1 = √σ0, σ2 = 0; a creep band of 1e-5 m/τ.
FC, FS, VS, SIGMA0, SIGMA1, BAND = 0.0095, 0.0100, 2e-3, 1000.0, np.sqrt(1000.0), 1e-5


def stribeck_g(u):
    return FC + (FS - FC) * np.exp(-(u / VS) ** 2)


def state_law_orbit(args, label, sets, force, rate):
    """The program's orbit on the creep band's exit (rk8pd at rtol 1e-13: its Jacobian's largest row moves by
    5e-4 from rtol 1e-12, measured) against the map integrated here.
    The laws' rates have a kink at v_rel = 0 (|v|, sgn v), which the orbit crosses in its stick: both maps
    locate it and start again there (stepped over, the program's section Jacobian was 1.7e-2 off at rtol
    1e-12, converging to first order in rtol only)."""
    sets = {"integrator.rtol": 1e-13, "integrator.atol": 1e-15, "brake.event_tolerance": 1e-12,
            "analysis.orbit_tolerance": 1e-10, "analysis.continuation": "''", **sets}
    orbit = orbit_of(args, label, ["brake_lugre_orbit.nml"], sets)
    assert orbit["section"] == "creep_band_exit"
    # Four coordinates (x, y, w, z/scale): the multipliers the trivial 1 and the map's four (LAPACK's dgeev).
    assert orbit["section_jacobian"].shape == (4, 4) and orbit["multipliers"].size == 5
    scale = orbit["law_state_scale"]
    sigma = float(orbit["static_limit"])
    point = np.concatenate([orbit["point"][[0, 2, 3]], orbit["law_states"] / scale])
    # SciPy's DOP853 at rtol 1e-12: the map closes to 1e-10 m (the orbit closes in SciPy's flow; measured
    # 5e-11 and 3e-12).  Differences with steps 1e-6 and 5e-7 (m, and units of the state's scale): smaller
    # steps meet the map's noise (1e-11 on z/scale over 1e-7: 1e-4 in the row of entries ~50); extrapolated,
    # what is left is within a quarter of the two steps' spread (measured 4.4e-4 and 7.8e-4 against
    # bounds 9e-4 and 1.0e-3, entries up to 59).
    fine = check_map(label, orbit, law_band_map(force, rate, scale, BAND, sigma), point, 1e-6, 2.0, 1e-8, 1e-9,
                     2e-6)
    assert orbit["multipliers"][0] == 1
    # The multipliers of the differences' map, paired by modulus: measured 1.9e-6 (LuGre) and 1.8e-5
    # (elasto-plastic, whose partials are the law's central differences); the differences' own Jacobian is
    # uncertain to ~1e-3 in entries ~50 (2e-5 relative), which moves its eigenvalues as much: 5e-5.
    mu_fd = np.linalg.eigvals(fine)
    assert np.max(np.abs(np.sort(np.abs(mu_fd)) - np.sort(np.abs(orbit["multipliers"][1:])))) <= 5e-5
    return orbit


def lugre_scipy(args):
    def rate(u, z):
        return u - SIGMA0 * np.abs(u) * z / stribeck_g(u)

    def force(u, z):
        return SIGMA0 * z[0] + SIGMA1 * rate(u, z)[0]
    orbit = state_law_orbit(args, "lugre-scipy", {}, force, rate)
    assert abs(orbit["law_state_scale"][0] - FS / SIGMA0) <= 1e-15 * FS / SIGMA0


def elastoplastic_scipy(args):
    # The elasto-plastic law on the same brake: LuGre's bristle elastic below z_ba = 5e-6 m (half of F_c/σ0).
    z_ba = 5e-6

    def share(u, z):
        if u == 0 or z == 0 or np.sign(u) != np.sign(z) or abs(z) <= z_ba:
            return 0.0
        z_ss = stribeck_g(u) / SIGMA0
        if abs(z) >= z_ss:
            return 1.0
        return 0.5 * np.sin(np.pi * (abs(z) - 0.5 * (z_ss + z_ba)) / (z_ss - z_ba)) + 0.5

    def rate(u, z):
        return np.array([u * (1 - share(u, z[0]) * SIGMA0 * abs(z[0]) / stribeck_g(u))])

    def force(u, z):
        return SIGMA0 * z[0] + SIGMA1 * rate(u, z)[0]
    state_law_orbit(args, "elastoplastic-scipy", {"law.model": "'elastoplastic'", "law.z_ba": z_ba}, force, rate)


def lugre_continuation(args):
    # inputs/brake_lugre_orbit.nml as it is: the orbit followed in F_s from 0.0100 to 0.0102.  The section
    # map's real multiplier rises through -1 (the unstable orbit of the input, -1.34, becomes stable): the
    # bifurcation found is a period doubling, between the two points where that multiplier (the real
    # negative one, looked for here in the written multipliers) is below and above -1, at the value where
    # the linear interpolation of |μ| - 1 of the largest multiplier is 0.
    with h5py.File(run_program(args, "lugre_continuation", ["brake_lugre_orbit.nml"], {})) as f:
        b, bif = f["brake/orbit/branch"], f["brake/orbit/bifurcations"]
        found, parameter = b["found"][()], b["parameter"][()]
        mu = b["floquet_multipliers_real"][()] + 1j * b["floquet_multipliers_imag"][()]
        kinds, at = bif["kind"][()], bif["parameter"][()]
    assert found.all(), found
    negative = np.array([min(m.real for m in row if abs(m.imag) == 0 and m.real < -0.5) for row in mu])
    k = np.where((negative[:-1] < -1) & (negative[1:] > -1))[0]
    print(f"lugre-continuation: F_s {np.round(parameter, 6)}; the real multiplier {np.round(negative, 4)}; "
          f"bifurcations {list(kinds)} at {np.round(at, 7)}")
    assert k.size == 1 and list(kinds) == [1], (k, kinds)
    assert parameter[k[0]] <= at[0] <= parameter[k[0] + 1], (at, parameter[k])
    # Beyond it the whole section map is inside the unit circle: the orbit is stable.
    assert np.all(np.abs(mu[k[0] + 1:, 1:]) < 1), mu


def stiff_band_map(sigma, stick_velocity, rtol=1e-12, t_max=100.0):
    """The creep band's exit of inputs/brake_lugre.nml (tests/brake_law_oracles.py's Eq. 10 with LuGre in SI,
    σ0 = 1e5 N/m) by SciPy's Radau with the exact Jacobian, coordinates (x, y, w, z/scale) as the
    program's: from the exit, a return counts once v_rel has come back to half the band (the program's
    rearming), the kink at v_rel = 0 located and the integration started again there."""
    field, jacobian, u = brake_lugre(1e5, np.sqrt(1e5), -0.002, 0.4)
    s, vdr = -sigma, u["vdr"]
    level, rearm = vdr + s * stick_velocity, vdr + s * stick_velocity / 2

    def crossing(t, q):
        return q[1] - level
    crossing.terminal, crossing.direction = True, s

    def back(t, q):
        return q[1] - rearm
    back.terminal, back.direction = True, -s

    def kink(t, q):
        return q[1] - vdr
    kink.terminal = True

    def run(t, q, event):
        while t < t_max:
            sol = solve_ivp(field, (t, t_max), q, method="Radau", jac=lambda _, y: jacobian(y), rtol=rtol,
                            atol=1e-15, events=[event, kink])
            assert sol.status == 1, sol.message
            if sol.t_events[0].size:
                return sol.t_events[0][0], sol.y_events[0][0]
            t, q = sol.t_events[1][0], sol.y_events[1][0]
            q = q + 1e-13 * field(t, q)
            t += 1e-13
        raise RuntimeError("no return")

    def section_map(point):
        t, q = run(0.0, np.array([point[0], level, point[1], point[2], point[3]]), back)
        t, q = run(t, q, crossing)
        return np.array([q[0], q[2], q[3], q[4]]), t
    return section_map


def lugre_stiff(args):
    # inputs/brake_lugre.nml with its orbit on (rodas4 at rtol 1e-9, as the input has it): Newton does not
    # converge from the attractor's slip onset.  Not the tangent's doing: the program's section Jacobian
    # there matches forward differences of its own map at h = 1e-10 to 1.3e-4 of each entry (rk8pd at rtol
    # 1e-12, measured; the differences at h = 1e-9 of Radau's map below and of the program's agree to 3e-6).
    # The map itself bends within the residual.
    with h5py.File(run_program(args, "lugre_stiff", ["brake_lugre.nml"], QUIET)) as f:
        g = f["brake/orbit"]
        found, residual = int(g.attrs["found"]), float(g.attrs["residual"])
        sigma = float(g.attrs["static_limit"])
        point = np.concatenate([g["point"][[0, 2, 3]], g["law_states"][()] / g["law_state_scale"][()]])
    assert found == 0, "the stiff bristles' orbit converged: update docs/chaos.md"
    section_map = stiff_band_map(sigma, 1e-6)
    image, period = section_map(point)
    # The same map through another stepper (Radau at rtol 1e-12 against rodas4 at 1e-9): the residual is the
    # flow's.  Where Newton ends depends on the last bits of its path: measured 2.7e-12 m apart at the end of
    # the path the program took in v, 1.5e-8 m (its residual 3.0e-4 m) at the end of the one it takes in
    # v_rel, and from 3e-12 to 1.5e-8 m at the iterates sampled on both paths (1 to 4, 8, 12, 16, 19:
    # rodas4's error at rtol 1e-9 through the bristles' stick).  1e-7 m is seven times the largest, 1/1600 of the smallest residual (1.6e-4 m).
    radau_residual = np.max(np.abs(image - point))
    print(f"lugre-stiff: program's residual {residual:.9e} m, Radau's map {radau_residual:.9e} m, return "
          f"{period:.6f} tau")
    assert abs(radau_residual - residual) <= 1e-7, (radau_residual, residual)
    # ∂x'/∂y of the flow's map by forward differences 1e-8 and 1e-6 m from the point: measured -81.9 and
    # -194.4.  A derivative that moves by more than half of itself over 1e-6 m, 1/160 of the residual,
    # leaves Newton's linear model no use at the residual's distance (the differences' own error, Radau's
    # 1e-12 over 1e-8, is 1e-4 of them).
    slopes = []
    for h in (1e-8, 1e-6):
        moved, _ = section_map(point + np.array([0.0, h, 0.0, 0.0]))
        slopes.append((moved[0] - image[0]) / h)
    print(f"lugre-stiff: dx'/dy by forward differences 1e-8 m: {slopes[0]:.4f}, 1e-6 m: {slopes[1]:.4f}")
    assert abs(slopes[1] - slopes[0]) > 0.5 * abs(slopes[0]), slopes
    assert 1e-6 < 1e-2 * residual


def refusals(args):
    cases = [  # (groups, line, names, why)
        ("&brake\n  model = 'law'\n/\n&law\n  model = 'coulomb'\n/\n&analysis\n  orbit = .true.\n"
         "  continuation = 'delta_prime'\n  continuation_end = 1.0\n/\n", 13, "&analysis: continuation",
         "not a variable"),
        ("&brake\n  model = 'law'\n  units = 'dimensional'\n/\n&law\n  model = 'coulomb'\n/\n&analysis\n"
         "  orbit = .true.\n  continuation = 'xi'\n  continuation_end = 0.5\n/\n", 14, "&analysis: continuation",
         "&brake_dimensional"),
        ("&brake\n  model = 'law'\n/\n&law\n  model = 'coulomb'\n  mu = 0.3\n  mu_s = 0.4\n/\n&analysis\n"
         "  orbit = .true.\n  continuation = 'mu'\n  continuation_end = 0.5\n/\n", 16,
         "&analysis: continuation_end", "mu_s"),
        # A law with states continues in its own parameters, up to where the law stops being one.
        ("&brake\n  model = 'law'\n/\n&law\n  model = 'elastoplastic'\n  fc = 0.0095\n  fs = 0.01\n"
         "  sigma0 = 1000.0\n  z_ba = 5e-6\n/\n&analysis\n  orbit = .true.\n  continuation = 'z_ba'\n"
         "  continuation_end = 2e-5\n/\n", 18, "&analysis: continuation_end", "z_ba"),
    ]
    check_refusals(args, cases, "refusals", scene="brake")


if __name__ == "__main__":
    sys.exit(case_main(__doc__, {"coulomb-switched": coulomb_switched, "stribeck-scipy": stribeck_scipy,
                                 "table-stribeck": table_stribeck, "arctan-scipy": arctan_scipy, "lugre-scipy": lugre_scipy,
                                 "elastoplastic-scipy": elastoplastic_scipy, "lugre-continuation": lugre_continuation,
                                 "lugre-stiff": lugre_stiff, "refusals": refusals}))
