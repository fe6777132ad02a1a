#!/usr/bin/env python3
"""Karnopp's law on the Girling brake (&brake model = 'law', &law model =
'karnopp'): the periodic orbit on the section where a hold at the band's edge
ends, and the Lyapunov spectrum through the band's switches, against the
band's flow written here (SciPy's DOP853, with located events at the band's
edges |v_rel| = Δv and where the pull A = -(2x - y) reaches ±F_s):

  orbit-scipy   the section map's Jacobian against central differences of the
                map integrated here (extrapolated), the program's orbit closing
                in that map, its period and multipliers
  spectrum      the finite-time exponents over a window against those of the
                flow map's Jacobian from central differences of SciPy's flow:
                the QR of Φ G from the same frame G the program starts from
  spectrum-slide  the same with σ2 = 0.1, whose holds at the edge end in the
                sliding mode (the force just outside above F_s), in a window
                with two of them
  stick-limit   the orbit followed in dv towards 0 against the Stribeck law's
                through exact stick (another code path, itself checked against
                SciPy in brake_law_orbit_oracles.py): the band's hold at F_s is
                exact stick at the static limit F_s as Δv -> 0; the branch's
                last three points extrapolated to Δv = 0
  refusals      msadams on the band is refused for the run, with file, line,
                group and variable, exit code 3

    brake_karnopp_oracles.py --binary build/friction --inputs inputs --workdir DIR CASE
"""

import h5py
import numpy as np
from scipy.integrate import solve_ivp

from machine_cases import run_program, check_refusals, case_main
from brake_law_orbit_oracles import QUIET, XI, KAPPA, V_DR, orbit_of, check_map

# The law in the brake's units (units = 'nondimensional': forces over k1 in m, velocities in m per unit τ):
# inputs/brake_karnopp.nml's, on the slow belt of brake_continuation.nml.
FC, FS, VS, DELTA, SIGMA2, DV = 0.0095, 0.0105, 2e-3, 2.0, 0.0, 1e-4
TIGHT = {"brake.event_tolerance": 1e-12, "integrator.rtol": 1e-12, "integrator.atol": 1e-15}


class KarnoppBrake:
    """Eq. 10 with Karnopp's force, its band taken exactly: outside, F = s g(|w|)
    + σ2 w (w = v - v_dr, s its sign); a block that reaches an edge e with
    -F_s <= eA <= F_h holds there (v' = 0, v the edge's); a hold ends where eA
    reaches F_h, out through that edge, or -F_s, when the block drifts into
    the band under v' = A ∓ F_s, which ends at an edge (held there if eA <
    F_h, else out) or where |A| falls back to F_s (a hold inside).  F_h =
    max(F_s, g(Δv) + σ2 Δv): a pull between F_s and the force just outside
    keeps the block on the edge (Filippov's sliding mode).  Modes: ('out',
    s), ('hold', e) with e the edge's sign (0 inside), ('drift', σ)."""

    def __init__(self, sigma2=SIGMA2, dv=DV):
        self.tol = dict(rtol=1e-12, atol=1e-15)
        self.sigma2, self.dv = sigma2, dv
        self.hold_limit = max(FS, FC + (FS - FC) * np.exp(-abs(dv / VS) ** DELTA) + sigma2 * dv)

    @staticmethod
    def pull(z):
        return -(2 * z[0] - z[2])

    def rhs(self, mode):
        kind, s = mode

        def f(t, z):
            x, v, y, w = z
            if kind == "out":
                u = v - V_DR
                force = s * (FC + (FS - FC) * np.exp(-abs(u / VS) ** DELTA)) + self.sigma2 * u
                dv = self.pull(z) - force
            elif kind == "hold":
                dv = 0.0
            else:
                dv = self.pull(z) - s * FS
            return [v, dv, w, (x - KAPPA * y) / XI]
        return f

    def events(self, mode):
        kind, s = mode
        if kind == "out":
            def enter(t, z):
                return s * (z[1] - V_DR) - self.dv
            enter.terminal, enter.direction = True, -1
            return [enter]
        if kind == "hold":
            up = self.hold_limit if s > 0 else FS
            down = self.hold_limit if s < 0 else FS

            def upper(t, z):
                return self.pull(z) - up
            def lower(t, z):
                return self.pull(z) + down
            upper.terminal, upper.direction = True, 1
            lower.terminal, lower.direction = True, -1
            return [upper, lower]

        def top(t, z):
            return z[1] - V_DR - self.dv
        def bottom(t, z):
            return z[1] - V_DR + self.dv
        def back(t, z):
            return s * self.pull(z) - FS
        top.terminal, top.direction = True, 1
        bottom.terminal, bottom.direction = True, -1
        back.terminal, back.direction = True, -1
        return [top, bottom, back]

    def switch(self, mode, which, z):
        """The mode after event `which` of `mode` at z (z's velocity set on the edge);
        and whether that was the end of a hold at an edge (the section)."""
        kind, s = mode
        a = self.pull(z)
        if kind == "out":
            z[1] = V_DR + s * self.dv
            if -FS <= s * a <= self.hold_limit:
                return ("hold", s), False
            assert np.sign(a) == -s, "the edge attracts from both sides"
            return ("drift", np.sign(a)), False
        if kind == "hold":
            sigma = 1.0 if which == 0 else -1.0
            if s == sigma:
                return ("out", sigma), True
            return ("drift", sigma), False
        if which == 2:
            return ("hold", 0.0), False
        edge = 1.0 if which == 0 else -1.0
        z[1] = V_DR + edge * self.dv
        if edge * a < self.hold_limit:
            return ("hold", edge), False
        return ("out", edge), False

    def run(self, t, z, mode, t_end, stop_at_section=False):
        """From (t, z) in `mode` to t_end, or to the first end of a hold at an edge."""
        z = np.array(z, dtype=float)
        while t < t_end:
            sol = solve_ivp(self.rhs(mode), (t, t_end), z, method="DOP853", events=self.events(mode), **self.tol)
            hits = [k for k, e in enumerate(sol.t_events) if e.size]
            if not hits:
                return sol.t[-1], sol.y[:, -1], mode
            which = min(hits, key=lambda k: sol.t_events[k][0])
            t, z = sol.t_events[which][0], sol.y_events[which][0].copy()
            mode, section = self.switch(mode, which, z)
            if section and stop_at_section:
                return t, z, mode
        return t, z, mode

    def section_map(self, sigma, point, t_max=400.0):
        """(y, w) where the hold at the edge -σ ends with 2x - y = σ F_s, to the next such end."""
        y, w = point
        z = np.array([(y + sigma * self.hold_limit) / 2, V_DR - sigma * self.dv, y, w])
        t, z, mode = self.run(0.0, z, ("out", -sigma), t_max, stop_at_section=True)
        assert t < t_max and np.sign(2 * z[0] - z[2]) == sigma, "no return to the section"
        return np.array([z[2], z[3]]), t


def karnopp_sets():
    return {"brake.model": "'law'", "law.model": "'karnopp'", "law.fc": FC, "law.fs": FS, "law.vs": VS,
            "law.exponent": DELTA, "law.sigma2": SIGMA2, "law.dv": DV, **TIGHT}


def orbit_scipy(args):
    orbit = orbit_of(args, "karnopp", ["brake_karnopp.nml"], {**karnopp_sets(), "analysis.orbit_tolerance": 1e-11})
    assert orbit["section"] == "band_hold_end", orbit["section"]
    sigma = float(orbit["static_limit"])
    point = orbit["point"][[2, 3]]
    # The section point: 2x - y = σ F_s, the block at the edge -σ of the band.
    assert abs(2 * orbit["point"][0] - orbit["point"][2] - sigma * FS) <= 1e-15
    assert abs(orbit["point"][1] - (V_DR - sigma * DV)) <= 1e-18
    brake = KarnoppBrake()
    # SciPy at rtol 1e-12: the map to ~1e-13 m; Newton stopped at 1e-11 m.  The closure bound 1e-9 m and the
    # period's 1e-8 τ leave room for the event times (located to 1e-12 τ by both) over the period's events.
    # Differences with steps 1e-6 m and 2e-7 m, extrapolated (Richardson); what remains is the h⁴ term and
    # the map's noise over the fine step, rtol |z| / h = 1e-12 * 0.02 / 2e-7 ~ 1e-7 of the entries: the
    # bound is 1e-6 of the largest entry.
    fine = check_map("orbit-scipy", orbit, lambda p: brake.section_map(sigma, p), point, 1e-6, 5.0, 1e-8, 1e-9,
                     1e-6)
    # The multipliers: 1 along the flow, the section map's two, 0 (the hold forgets the block's velocity).
    assert orbit["multipliers"][0] == 1 and orbit["multipliers"][3] == 0, orbit["multipliers"]
    mu = np.sort_complex(np.linalg.eigvals(fine))[::-1]
    got = orbit["multipliers"][1:3]
    difference = np.max(np.abs(np.sort(np.abs(mu)) - np.sort(np.abs(got))))
    print(f"orbit-scipy: multipliers {np.round(got, 8)} against {np.round(mu, 8)} (|μ| {difference:.1e} apart)")
    assert difference <= 1e-5, difference


def flow_jacobian(brake, t0, z0, mode, t1, frame, step):
    """Φ(t1, t0) G by central differences along the columns of G (the mode at t0 a slip: smooth there)."""
    columns = []
    for j in range(frame.shape[1]):
        plus = brake.run(t0, z0 + step * frame[:, j], mode, t1)[1]
        minus = brake.run(t0, z0 - step * frame[:, j], mode, t1)[1]
        columns.append((plus - minus) / (2 * step))
    return np.column_stack(columns)


def generic_frame(n):
    """The program's starting frame (analysis/lyapunov_spectrum.f90): Hilbert's matrix plus I, orthonormalised."""
    q = np.array([[1.0 / (i + j + 1) for j in range(n)] for i in range(n)]) + np.eye(n)
    return np.linalg.qr(q)[0]


def spectrum(args, sigma2=SIGMA2, start=60.0, name="spectrum", steps=(2e-7, 4e-8), noise=2e-8):
    brake = KarnoppBrake(sigma2=sigma2)
    # SciPy's trajectory from the input's start (x = y = 0, the block at the belt's velocity: inside the band)
    # to a window that starts in a slip, where the flow map is smooth in every direction (in a hold at an
    # edge a change of v would leave the band or not), half a τ on at most from `start`.
    t0, z0, mode0 = brake.run(0.0, np.array([0.0, V_DR, 0.0, 0.0]), ("hold", 0.0), start)
    while mode0[0] != "out":
        t0, z0, mode0 = brake.run(t0, z0, mode0, t0 + 0.125)
    assert t0 <= start + 0.5, t0
    duration = 20.0
    out = run_program(args, f"karnopp_{name}", ["brake_karnopp.nml"],
                      {**karnopp_sets(), **{k: v for k, v in QUIET.items() if k != "analysis.orbit"},
                       "law.sigma2": sigma2,
                       "analysis.orbit": ".false.", "analysis.lyapunov_spectrum": ".true.",
                       "analysis.lyapunov_spectrum_transient": t0, "analysis.lyapunov_spectrum_duration": duration,
                       "analysis.lyapunov_spectrum_renormalise": 1.0, "brake.t_end": t0 + duration + 1.0})
    with h5py.File(out) as f:
        exponents = f["brake/lyapunov/exponents"][()]
        lost = int(f["brake/lyapunov"].attrs["spectrum_lost_directions"])
    frame = generic_frame(4)
    estimates = []
    for step in steps:
        phi = flow_jacobian(brake, t0, z0, mode0, t0 + duration, frame, step)
        r = np.linalg.qr(phi[:, :3])[1]
        # Largest first, as the program reports them.
        estimates.append(np.sort(np.log(np.abs(np.diag(r))) / duration)[::-1])
    coarse, fine = estimates
    extrapolated = fine + (fine - coarse) / ((steps[0] / steps[1]) ** 2 - 1)
    spread = np.max(np.abs(coarse - fine))
    difference = np.max(np.abs(exponents[:3] - extrapolated))
    print(f"{name}: window [{t0}, {t0 + duration}] tau; the program's exponents {exponents} (lost {lost}); "
          f"SciPy's flow map, QR of its differences: {extrapolated} ({difference:.1e} apart, the two steps' "
          f"spread {spread:.1e})")
    # The window holds holds: δv is forgotten at each, one direction lost, reported as -inf.
    assert lost == 1 and exponents[3] == -np.inf, (lost, exponents)
    # The differences' error: the h⁴ term that Richardson leaves, below the h² spread over 25 (the map
    # curves strongly: the hold's length depends on where the slip entered it), and the map's noise,
    # rtol |z| / h = 1e-12 * 0.01 / 4e-8 ~ 2.5e-7 of an entry of Φ, 1.3e-8 per τ in a log over 20 τ; the
    # two start states agree to the integrations' 1e-11 m.  Measured: 1.0e-9 per τ.
    assert difference <= max(noise, spread / 25), (difference, spread)


def spectrum_slide(args):
    # σ2 = 0.1 (m per m/τ): the force just outside the band 7.5e-6 above F_s, so the holds at the edge in
    # the window [95, 115] τ (two) end in the sliding mode, where the pull reaches that force and the
    # force is continuous (the saltation the identity); the same check as `spectrum`'s.  The flow map is
    # smooth over a smaller neighbourhood here (at steps of 2e-7 m the differences' second and third
    # exponents are still 0.01 and 0.04 off those at 4e-8 and 1e-8 m, which agree to 6e-7): steps 4e-8
    # and 1e-8 m, and the map's noise rtol |z| / h = 1e-12 * 0.01 / 1e-8 = 1e-6 of an entry of Φ, 5e-8
    # per τ in a log over 20 τ: 1e-7 per τ.
    spectrum(args, sigma2=0.1, start=95.0, name="spectrum-slide", steps=(4e-8, 1e-8), noise=1e-7)


def stick_limit(args):
    # Newton does not find the orbit from the attractor at small Δv (the hold's end is then a near-grazing
    # exit, x'' = A - g(Δv) rising from F_s - g(Δv) ~ (F_s - F_c)(Δv/v_s)²): the branch from the input's
    # Δv = 1e-4 down to 1e-6 in steps of 3e-6, each point from the previous orbit.
    sets = {**karnopp_sets(), "analysis.orbit_tolerance": 1e-11, "analysis.continuation": "'dv'",
            "analysis.continuation_end": 1e-6, "analysis.continuation_points": 34}
    with h5py.File(run_program(args, "karnopp_dv", ["brake_karnopp.nml"], {**QUIET, **sets})) as f:
        b = f["brake/orbit/branch"]
        branch = {key: b[key][()] for key in ("parameter", "found", "period", "point", "floquet_multipliers_real",
                                               "floquet_multipliers_imag")}
    stick = orbit_of(args, "stribeck", ["brake_karnopp.nml"], {**karnopp_sets(), "law.model": "'stribeck'",
                                                                 "analysis.orbit_tolerance": 1e-11,
                                                                 "analysis.orbit_transient": 200.0,
                                                                 "brake.t_end": 1200.0})
    assert stick["section"] == "stick_to_slip"
    last = slice(-3, None)
    assert branch["found"][last].all() and np.allclose(branch["parameter"][last], [7e-6, 4e-6, 1e-6], atol=1e-12)
    dv = branch["parameter"][last]
    assert np.all(branch["floquet_multipliers_imag"][last] == 0)
    quantities = {"period (tau)": (branch["period"][last], stick["period"], 1e-9),
                  "y (m)": (branch["point"][last, 2], stick["point"][2], 1e-10),
                  "w (m/tau)": (branch["point"][last, 3], stick["point"][3], 1e-10),
                  "mu_1": (branch["floquet_multipliers_real"][last, 1], stick["multipliers"][1].real, 1e-8),
                  "mu_2": (branch["floquet_multipliers_real"][last, 2], stick["multipliers"][2].real, 1e-8)}
    for name, (values, exact, noise) in quantities.items():
        # Linear in Δv to leading order (the hold's velocity, the edge's crossing): the quadratic through the
        # three points at Δv = 0, its distance from the linear one through the last two the size of the term
        # it removes (what remains, the cubic, is smaller); `noise` the orbits' own precision (Newton at
        # 1e-11 m, events at 1e-12 τ; the multipliers' 1e-8 the section Jacobian's, orbit-scipy).
        quadratic = np.polyval(np.polyfit(dv, values, 2), 0.0)
        linear = np.polyval(np.polyfit(dv[1:], values[1:], 1), 0.0)
        difference = abs(quadratic - exact)
        print(f"stick-limit: {name}: Karnopp at dv = 1e-6 {values[-1]:.10g}, extrapolated to 0 {quadratic:.10g}, "
              f"the Stribeck law through exact stick {exact:.10g} ({difference:.1e} apart; the quadratic term "
              f"{abs(quadratic - linear):.1e})")
        assert difference <= abs(quadratic - linear) + noise, (name, difference)


def refusals(args):
    # A multistep stepper on the band: with the edges located, msadams on inputs/brake_karnopp.nml at rtol 1e-6
    # takes 58 times rk8pd's steps and misses the events by 6e-2 tau (docs/speed.md).
    held = "&law\n  model = 'karnopp'\n  fc = 0.0095\n  fs = 0.0105\n  vs = 2e-3\n  dv = 1e-4\n/\n"
    cases = [(f"&brake\n  model = 'law'\n/\n{held}&integrator\n  method = 'msadams'\n/\n", 16,
              "&integrator: method", "a multistep stepper on &law model = 'karnopp'")]
    check_refusals(args, cases, "refusals", scene="brake")


if __name__ == "__main__":
    raise SystemExit(case_main(__doc__, {"orbit-scipy": orbit_scipy, "spectrum": spectrum,
                                          "spectrum-slide": spectrum_slide,
                                          "stick-limit": stick_limit, "refusals": refusals}))
