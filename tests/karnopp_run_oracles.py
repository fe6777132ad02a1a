#!/usr/bin/env python3
"""Karnopp's law in the plain run (the trajectory and its events, not the
orbit's map): the program's run through the band's located edges and holds
against the band's flow written here in its limit of no depth (SciPy's DOP853
at rtol 1e-12, terminal events at the edges |w| = dv and where the applied
force reaches +-F_s):

  machine       the belt oscillator of inputs/machine_karnopp.nml (30 s): every
                event (into a hold, the end of a hold) in kind and time, the
                trajectory on the output grid, and a hold sits exactly at the
                edge's velocity (v' = 0 there, not a creep)
  machine-slide bands whose force just outside exceeds F_s (the sliding mode:
                the holds end where the pull reaches that force), a wide and
                a narrow one: the events, the pull at the holds' ends, x, v
  brake         inputs/brake_karnopp.nml's brake (60 tau): the same for the
                brake's run, /brake/events, the trajectory and stick_time
  brake-slide   the brake with sigma2 = 0.1 (the sliding mode): the same
  brake-benettin  Benettin's two runs on the brake against the same two runs
                of the oracle's flow
  stick-limit   the belt oscillator as dv -> 0 against the Stribeck law through
                exact stick (another code path: machine/run.f90's switching):
                the slip onsets converge to exact stick's, in proportion to dv,
                without a viscous term and with one (the sliding mode's bands)
  machine-chaos the Poincare section of slip onsets of the belt oscillator (the
                holds' ends the oracle finds), Benettin's exponent against
                the same two-run procedure on the oracle's flow, and the
                Lyapunov spectrum's first exponent against its exact value
                along the cycle (the other lost in the holds)

    karnopp_run_oracles.py --binary build/friction --inputs inputs --workdir DIR CASE
"""
import h5py
import numpy as np
from scipy.integrate import solve_ivp

from machine_cases import run_program, case_main
from brake_karnopp_oracles import KarnoppBrake, FS, DV
from brake_law_orbit_oracles import V_DR

# /machine/events and /brake/events kinds.
STICK_TO_SLIP, SLIP_TO_STICK, REVERSAL = 1, 2, 3
TOL = dict(rtol=1e-12, atol=1e-14)


def terminal(f, direction):
    f.terminal, f.direction = True, direction
    return f


def machine_oracle(p, grid, x0, v0):
    """The belt oscillator (m x'' = A - F, A = -k x - c v) with Karnopp's band in its limit of no
    depth: modes 'out' (the Stribeck curve), 'hold' at an edge (v' = 0) and 'in' (v' = (A - clip(A,
    +-F_s))/m, a hold inside where |A| <= F_s).  Returns x and v on `grid` and the events (t, kind), kinds as
    the program records them: into a hold slip_to_stick, into the band without one reversal, out of a
    hold (at once through its edge, or drifting out after one) stick_to_slip."""
    belt, dv, fs, m, k, c = p["belt"], p["dv"], p["fs"], p["m"], p["k"], p["c"]

    def applied(x, v):
        return -k * x - c * v

    def outside(w):
        return np.sign(w) * (p["fc"] + (fs - p["fc"]) * np.exp(-np.abs(w / p["vs"]) ** p["exponent"])) \
            + p["sigma2"] * w

    # The largest pull a hold at an edge keeps: F_s, or the force just outside when larger (Filippov's
    # sliding mode: the pull between the two drives the block out, the slip force back, so it stays on the
    # edge with v' = 0, entered from outside or driven onto the edge from inside).
    hold_limit = max(fs, outside(dv))
    xs, vs, events = np.full(len(grid), np.nan), np.full(len(grid), np.nan), []
    t, x, v = grid[0], x0, v0
    xs[0], vs[0] = x, v
    mode, edge = ("out" if abs(v - belt) >= dv else "in"), 0.0
    held = mode == "in"   # as the program: leaving the band after starting in it is a slip onset
    end = grid[-1]

    def fill(r, t_from, t_to):
        inside = (grid > t_from) & (grid <= t_to)
        if inside.any():
            values = r.sol(grid[inside])
            xs[inside], vs[inside] = values[0], values[1]

    while t < end:
        if mode == "out":
            evs = (terminal(lambda tt, y: y[1] - belt - dv, -1), terminal(lambda tt, y: y[1] - belt + dv, 1))
            r = solve_ivp(lambda tt, y: [y[1], (applied(y[0], y[1]) - outside(y[1] - belt)) / m], (t, end),
                          [x, v], method="DOP853", events=evs, dense_output=True, **TOL)
        elif mode == "hold":
            vh = v
            up, down = (hold_limit, fs) if edge > 0 else (fs, hold_limit)
            evs = (terminal(lambda tt, y: up - applied(y[0], vh), -1),
                   terminal(lambda tt, y: down + applied(y[0], vh), -1))
            r = solve_ivp(lambda tt, y: [vh, 0.0], (t, end), [x, vh], method="DOP853", events=evs,
                          dense_output=True, **TOL)
        else:
            def inside(tt, y):
                a = applied(y[0], y[1])
                return [y[1], (a - np.clip(a, -fs, fs)) / m]
            evs = (terminal(lambda tt, y: y[1] - belt - dv, 1), terminal(lambda tt, y: y[1] - belt + dv, -1),
                   terminal(lambda tt, y: fs - abs(applied(y[0], y[1])), 1))
            r = solve_ivp(inside, (t, end), [x, v], method="DOP853", events=evs, dense_output=True, **TOL)
        t_new = r.t[-1]
        fill(r, t, t_new)
        t, x, v = t_new, r.y[0, -1], r.y[1, -1]
        if r.status != 1:
            break
        which = next(i for i, e in enumerate(r.t_events) if e.size)
        if mode == "out":
            edge = dv if which == 0 else -dv
            v = belt + edge
            if -fs <= np.sign(edge) * applied(x, v) <= hold_limit:
                mode, held = "hold", True
                events.append((t, SLIP_TO_STICK))
            else:
                mode, held = "in", False
                events.append((t, REVERSAL))
        elif mode == "hold":
            sigma = 1.0 if which == 0 else -1.0
            if sigma * edge > 0:
                v = belt + edge
                mode, held = "out", False
                events.append((t, STICK_TO_SLIP))
            else:
                mode = "in"   # a kink: the block drifts into the band, still counted as held
        else:
            if which == 2:
                held = True   # |A| back within F_s inside: a hold where it is (v' = 0 in this mode)
                continue
            edge = dv if which == 0 else -dv
            v = belt + edge
            if np.sign(edge) * applied(x, v) < hold_limit:
                # Onto the edge from inside, held there by the slip force outside: a hold (on, if held).
                mode = "hold"
                if not held:
                    events.append((t, SLIP_TO_STICK))
                held = True
                continue
            mode = "out"
            if held:
                events.append((t, STICK_TO_SLIP))
            held = False
    return xs, vs, events


def read_machine(path):
    with h5py.File(path) as f:
        g = f["machine"]
        got = {key: g[key][()] for key in ("t", "x", "v", "stick")}
        got["events"] = list(zip(g["events/t"][()], g["events/kind"][()]))
        got["event_v"] = g["events/v"][()]
        got["stick_time"] = g.attrs["stick_time"]
    return got


def compare_events(label, got, expected):
    """The largest time difference of events paired in order, after checking their kinds agree."""
    kinds_got = [k for _, k in got]
    kinds_expected = [k for _, k in expected]
    print(f"{label}: {len(got)} events, the oracle's {len(expected)}")
    assert kinds_got == kinds_expected, (kinds_got[:20], kinds_expected[:20])
    return max(abs(a - b) for (a, _), (b, _) in zip(got, expected))


TIGHT_BRAKE = {"brake.event_tolerance": 1e-12, "integrator.rtol": 1e-12, "integrator.atol": 1e-15}
BELT = dict(m=1.0, k=2.0, c=0.0, belt=0.1, fc=1.0, fs=1.5, vs=1e-3, exponent=2.0, sigma2=0.4, dv=1e-4)


def machine(args):
    got = read_machine(run_program(args, "machine_karnopp", ["machine_karnopp.nml"], {}))
    xs, vs, expected = machine_oracle(BELT, got["t"], 0.0, 0.0)
    worst_t = compare_events("machine", got["events"], expected)
    dx = np.max(np.abs(got["x"] - xs))
    dv = np.max(np.abs(got["v"] - vs))
    print(f"machine: events within {worst_t:.2e} s of the oracle's; trajectory within |dx| {dx:.2e} m, "
          f"|dv| {dv:.2e} m/s over {got['t'][-1]:g} s")
    # Each event is located to event_tolerance 1e-10 s; between them the program's stepper at its rtol
    # 1e-9 (atol 1e-12) carries some 1e-9 of the 0.3 m cycle per cycle, and an error dx in a hold's start
    # moves its end (|A| = F_s at the spring's rate k v_edge = 0.2 N/s) by k dx / 0.2 = 10 dx: 1e-7 s
    # and 1e-7 m bound a few cycles' accumulation with a factor of 10 to spare.
    assert worst_t < 1e-7, worst_t
    assert dx < 1e-7 and dv < 1e-7, (dx, dv)
    # A hold is at an edge's velocity exactly: the events into a hold are at belt +- dv to the last bits,
    # inside the band, and the output's stick points sit there (v' = 0, not a creep).
    into = np.array([k for _, k in got["events"]]) == SLIP_TO_STICK
    edge = np.abs(got["event_v"][into] - 0.1)
    assert np.all(np.abs(edge - 1e-4) < 1e-15) and np.all(edge < 1e-4), edge
    held = got["stick"] == 1
    assert held.any() and np.all(np.abs(np.abs(got["v"][held] - 0.1) - 1e-4) < 1e-15), got["v"][held]
    # stick_time: the time in the band, the oracle's holds.
    hold_time = sum(b[0] - a[0] for a, b in zip(expected, expected[1:]) if a[1] == SLIP_TO_STICK)
    if expected[-1][1] == SLIP_TO_STICK:
        hold_time += got["t"][-1] - expected[-1][0]
    print(f"machine: stick_time {got['stick_time']:.9f} s, the oracle's holds {hold_time:.9f} s")
    assert abs(got["stick_time"] - hold_time) < 1e-6, (got["stick_time"], hold_time)


def machine_slide(args):
    # Bands whose force just outside, g(dv) + sigma2 dv, exceeds F_s: an edge attracts from both sides and
    # the block slides along it (Filippov's sliding mode), held there until the pull reaches that force.
    # Wide: vs = 0.05 m/s, dv = 1e-3 m/s (the force outside 1.5002 N, 2e-4 N above F_s: each hold's end
    # 1e-3 s later at the spring's rate k v_edge = 0.2 N/s); narrow: the input's curve with dv = 1e-7 m/s,
    # below the 8e-7 m/s where sigma2 = 0.4 N s/m makes every band slide (3.5e-8 N above F_s, 1.75e-7 s).
    tight = {"integrator.rtol": 1e-12, "integrator.atol": 1e-15, "machine.event_tolerance": 1e-12}
    for name, law in (("wide", {"law.vs": 0.05, "law.dv": 1e-3}), ("narrow", {"law.dv": 1e-7})):
        p = dict(BELT, vs=law.get("law.vs", BELT["vs"]), dv=law["law.dv"])
        path = run_program(args, f"machine_slide_{name}", ["machine_karnopp.nml"], dict(tight, **law))
        got = read_machine(path)
        xs, vs, expected = machine_oracle(p, got["t"], 0.0, 0.0)
        outside = p["fc"] + (p["fs"] - p["fc"]) * np.exp(-(p["dv"] / p["vs"]) ** 2) + p["sigma2"] * p["dv"]
        shift = (outside - p["fs"]) / (p["k"] * p["belt"])
        worst_t = compare_events(f"machine-slide ({name})", got["events"], expected)
        dx = np.max(np.abs(got["x"] - xs))
        dvel = np.max(np.abs(got["v"] - vs))
        # Each hold ends where the pull reaches the force just outside (the spring's A = -k x at the edge).
        ends = [i for i, (_, k) in enumerate(got["events"]) if k == STICK_TO_SLIP]
        with h5py.File(path) as f:
            x_end = f["machine/events/x"][()][ends]
        pull_gap = np.max(np.abs(np.abs(p["k"] * x_end) - outside))
        print(f"machine-slide ({name}): the force outside {outside:.10f} N, F_s {p['fs']} N: each hold "
              f"{shift:.2e} s longer than at F_s; events within {worst_t:.2e} s of the oracle's, |A| at the "
              f"{len(ends)} ends of holds within {pull_gap:.1e} N of it; trajectory within |dx| {dx:.2e} m, "
              f"|dv| {dvel:.2e} m/s")
        assert len(ends) >= 3 and got["events"][0][1] == SLIP_TO_STICK, got["events"][:4]
        # The program at rtol 1e-12 and events to 1e-12 s against the oracle's DOP853 at rtol 1e-12: a hold's
        # start off by dx moves its end by k dx / 0.2 N/s = 10 dx, so 1e-9 s and 1e-9 m bound a few
        # cycles' accumulation of ~1e-12 of the 0.3 m cycle, and stay below the sliding mode's own shift
        # (1.75e-7 s at its narrowest): ending the holds at F_s instead fails this.
        assert worst_t < 1e-9 < shift, (worst_t, shift)
        assert dx < 1e-9 and dvel < 1e-9, (dx, dvel)
        # The event's state is the located time's: k |dx| = 2 (1e-12 s of v_edge) and the stepper's 1e-12.
        assert pull_gap < 1e-10, pull_gap
        # A hold in the sliding mode is exactly at the edge's velocity (v' = 0, no creep).
        held = got["stick"] == 1
        assert held.any() and np.all(np.abs(np.abs(got["v"][held] - 0.1) - p["dv"]) < 1e-15), got["v"][held]


def brake_oracle(t_grid, z0, band=None):
    """KarnoppBrake's flow (brake_karnopp_oracles.py; `band`, else the input's) from z0 on the grid, with its
    events recorded as the program records them (the machine's kinds), and the time it spends in the band."""
    band = band or KarnoppBrake()
    n = len(t_grid)
    out = np.full((4, n), np.nan)
    out[:, 0] = z0
    events = []
    z = np.array(z0, dtype=float)
    u = z[1] - V_DR
    # Inside the band with |A| <= F_s the block holds where it is (at rest on the belt to start), and
    # leaving the band after that is a slip onset, as after any hold.
    if abs(u) >= band.dv:
        mode, held = ("out", np.sign(u)), False
    elif abs(band.pull(z)) <= FS:
        mode, held = ("hold", 0.0), True
    else:
        mode, held = ("drift", np.sign(band.pull(z))), False
    t, end = t_grid[0], t_grid[-1]
    band_time = 0.0
    while t < end:
        sol = solve_ivp(band.rhs(mode), (t, end), z, method="DOP853", events=band.events(mode), dense_output=True,
                        **band.tol)
        hits = [k for k, e in enumerate(sol.t_events) if e.size]
        t_to = min(sol.t_events[k][0] for k in hits) if hits else sol.t[-1]
        if mode[0] != "out":
            band_time += t_to - t
        inside = (t_grid > t) & (t_grid <= t_to)
        if inside.any():
            out[:, inside] = sol.sol(t_grid[inside])
        if not hits:
            break
        which = min(hits, key=lambda k: sol.t_events[k][0])
        t, z = sol.t_events[which][0], sol.y_events[which][0].copy()
        kind = mode[0]
        new, section = band.switch(mode, which, z)
        if kind == "out":
            if new[0] == "hold":
                held = True
                events.append((t, SLIP_TO_STICK))
            else:
                held = False
                events.append((t, REVERSAL))
        elif kind == "hold":
            if section:
                held = False
                events.append((t, STICK_TO_SLIP))
        elif new[0] == "out":
            if held:
                events.append((t, STICK_TO_SLIP))
            held = False
        elif new[1] != 0.0 and not held:
            # Driven across the band onto an edge that holds it (the sliding mode): into a hold.
            held = True
            events.append((t, SLIP_TO_STICK))
        else:
            held = True
        mode = new
    return out, events, band_time


def brake(args):
    sets = {"brake.t_end": 60.0, "analysis.orbit": ".false.", "analysis.continuation": "''"}
    with h5py.File(run_program(args, "brake_karnopp", ["brake_karnopp.nml"], sets)) as f:
        tr = f["brake"]
        t = tr["t"][()]
        got = np.array([tr[k][()] for k in ("x", "v", "y", "w")])
        stick = tr["stick"][()]
        ev = f["brake/events"]
        events = list(zip(ev["t"][()], ev["kind"][()]))
        event_v = ev["v"][()]
        stick_time = f["brake"].attrs["stick_time"]
        x0, v0, y0, w0 = got[:, 0]
    expected_traj, expected, band_time = brake_oracle(t, [x0, v0, y0, w0])
    worst_t = compare_events("brake", events, expected)
    diff = np.max(np.abs(got - expected_traj), axis=1)
    print(f"brake: events within {worst_t:.2e} tau of the oracle's; trajectory within |dx| {diff[0]:.2e}, "
          f"|dv| {diff[1]:.2e}, |dy| {diff[2]:.2e}, |dw| {diff[3]:.2e} over {t[-1]:g} tau")
    # The input's rk8pd at rtol 1e-10 and event_tolerance 1e-10 tau; the pull's rate at a hold's end, |2x' -
    # y'| ~ 1e-3 m/tau, turns a position error dx into a time 2 dx / 1e-3: 1e-7 tau and 1e-9 m (the
    # positions are ~1e-2 m, rtol 1e-10 of them accumulated over some 20 cycles) leave a factor of ~10.
    assert worst_t < 1e-6, worst_t
    assert np.all(diff < 1e-8), diff
    into = np.array([k for _, k in events]) == SLIP_TO_STICK
    holds = event_v[into]
    # The belt moves at v_dr = -2e-4: a hold sits at v_dr + dv or v_dr - dv, inside the band to the last bit.
    assert np.all(np.min(np.abs(holds[:, None] - (V_DR + np.array([DV, -DV]))[None, :]), axis=1) < 1e-17), holds
    assert np.any(stick == 1)
    # stick_time: the time in the band, between the located edges (event_tolerance 1e-10 tau each).
    print(f"brake: stick_time {stick_time:.9f} tau, the oracle's time in the band {band_time:.9f} tau")
    assert abs(stick_time - band_time) < 1e-8, (stick_time, band_time)


def brake_slide(args):
    # inputs/brake_karnopp.nml with sigma2 = 0.1 (m per m/tau): the force just outside the band, g(dv) +
    # sigma2 dv = F_s + 7.5e-6, exceeds F_s = 0.0105, so a hold at an edge goes on as the block slides along
    # it until the pull reaches that force (each hold's end 7.5e-6 / |2x' - y'| ~ 1e-2 tau later than at F_s);
    # 120 tau for three such ends.
    band = KarnoppBrake(sigma2=0.1)
    sets = dict(TIGHT_BRAKE, **{"brake.t_end": 120.0, "analysis.orbit": ".false.", "analysis.continuation": "''",
                                "law.sigma2": 0.1})
    with h5py.File(run_program(args, "brake_slide", ["brake_karnopp.nml"], sets)) as f:
        tr = f["brake"]
        t = tr["t"][()]
        got = np.array([tr[k][()] for k in ("x", "v", "y", "w")])
        ev = f["brake/events"]
        events = list(zip(ev["t"][()], ev["kind"][()]))
        states = np.array([ev[k][()] for k in ("x", "y")])
        stick_time = f["brake"].attrs["stick_time"]
    expected_traj, expected, band_time = brake_oracle(t, got[:, 0], band)
    worst_t = compare_events("brake-slide", events, expected)
    diff = np.max(np.abs(got - expected_traj), axis=1)
    kinds = np.array([k for _, k in events])
    # The ends of holds at an edge (after an entry into one; the first leaves the start's hold inside the
    # band, the pull already past the limit when the block has drifted across to the edge).
    ends = (kinds == STICK_TO_SLIP) & (np.roll(kinds, 1) == SLIP_TO_STICK)
    ends[0] = False
    pull_gap = np.max(np.abs(np.abs(2 * states[0, ends] - states[1, ends]) - band.hold_limit))
    print(f"brake-slide: the hold's limit {band.hold_limit:.10f} against F_s {FS}; events within {worst_t:.2e} "
          f"tau of the oracle's, |A| at the {ends.sum()} ends of holds within {pull_gap:.1e} of the limit; "
          f"trajectory within {diff}; stick_time {stick_time:.9f} tau against {band_time:.9f}")
    assert ends.sum() >= 3
    # Both at rtol 1e-12 with events to 1e-12 tau: the pull's rate at a hold's end, ~1e-3 m/tau, turns a
    # position error of ~1e-14 m into 1e-11 tau; the entries into a hold, where v reaches the edge at a small
    # slope, are the least sharp (4.0e-10 tau measured).  1e-9 tau and 1e-11 m stay far below the sliding
    # mode's own ~1e-2 tau.
    assert worst_t < 1e-9, worst_t
    assert np.all(diff < 1e-11), diff
    # The located ends: 1e-12 tau at the pull's rate, and the positions' rounding.
    assert pull_gap < 1e-13, pull_gap
    assert abs(stick_time - band_time) < 1e-9, (stick_time, band_time)


def brake_benettin(args):
    # Benettin's two runs on the brake through the band's switches, against the same procedure on the
    # oracle's flow (brake_benettin of brake/diagnostics.f90: the perturbation (1, 1, 1, 1)/2, on the
    # positions alone, (1, 0, 1, 0)/sqrt 2, when the reference is in the band), from 60 tau over 40 tau.
    sets = dict(TIGHT_BRAKE, **{"brake.t_end": 100.0, "analysis.orbit": ".false.", "analysis.continuation": "''",
                                "analysis.lyapunov": ".true.", "analysis.lyapunov_transient": 60.0})
    with h5py.File(run_program(args, "brake_benettin", ["brake_karnopp.nml"], sets)) as f:
        got = f["brake/lyapunov"].attrs["benettin_exponent"]
        z0 = np.array([f["brake"][k][0] for k in ("x", "v", "y", "w")])

    def flow(t, z, span):
        out, _, _ = brake_oracle(np.array([t, t + span]), z)
        return out[:, -1]

    reference = flow(0.0, z0, 60.0)
    t = 60.0
    direction = np.ones(4)
    if abs(reference[1] - V_DR) < DV:
        direction[1::2] = 0.0
    perturbed = reference + 1e-8 * direction / np.linalg.norm(direction)
    logs = 0.0
    for _ in range(40):
        reference, perturbed = flow(t, reference, 1.0), flow(t, perturbed, 1.0)
        t += 1.0
        d = np.linalg.norm(perturbed - reference)
        logs += np.log(d / 1e-8)
        perturbed = reference + (perturbed - reference) * 1e-8 / d
    oracle = logs / 40.0
    print(f"brake-benettin: the exponent {got:.7f} 1/tau, the oracle's two runs {oracle:.7f} 1/tau")
    # Both flows at rtol 1e-12 on states of ~1e-2 leave ~1e-14 in the separations of d0 = 1e-8, 1e-6 of
    # each interval's log, and the events located to 1e-12 tau at |A'| ~ 1e-3 another ~1e-7: 1e-5 1/tau
    # over the 40 intervals is a factor of 10 above their sum.  (As one ODE: -0.0249509, 3.6e-5 off.)
    assert abs(got - oracle) < 1e-5, (got, oracle)


def stick_limit(args):
    # Karnopp's slip onsets as dv falls, against Stribeck's through exact stick (the same curve, the
    # static limit F_s): the hold's edge sits dv off the belt, which shifts the phase by O(dv).
    # sigma2 = 0, and the input's 0.4 N s/m with bands below 8e-7 m/s, where the force just outside,
    # g(dv) + sigma2 dv, exceeds F_s and the holds end in the sliding mode, at that force: F_s + O(dv) too.
    for sigma2, widths in ((0.0, [1e-5, 1e-6, 1e-7]), (0.4, [4e-7, 4e-8, 4e-9])):
        base = {"machine.t_end": 20.0, "integrator.rtol": 1e-11, "integrator.atol": 1e-14, "law.sigma2": sigma2}
        stribeck = run_program(args, f"stribeck_{sigma2:g}", ["machine_karnopp.nml"],
                               dict(base, **{"law.model": "'stribeck'"}))
        with h5py.File(stribeck) as f:
            kinds = f["machine/events/kind"][()]
            onsets = f["machine/events/t"][()][kinds == STICK_TO_SLIP]
        errors = []
        for dv in widths:
            got = read_machine(run_program(args, f"karnopp_{sigma2:g}_{dv:g}", ["machine_karnopp.nml"],
                                           dict(base, **{"law.dv": dv})))
            mine = np.array([t for t, k in got["events"] if k == STICK_TO_SLIP])
            assert len(mine) == len(onsets), (len(mine), len(onsets))
            errors.append(np.max(np.abs(mine - onsets)))
            print(f"stick-limit: sigma2 = {sigma2:g} N s/m, dv = {dv:g} m/s: slip onsets within {errors[-1]:.3e} s "
                  f"of exact stick's ({len(onsets)} onsets in {base['machine.t_end']:g} s)")
        # First order in dv: each factor of 10 in dv takes a factor of about 10 off (8 to 12 allowed: the
        # curve's own change over the band, (dv/vs)^2 = 1e-4 of it at the widest, and the run's error, ~1e-9
        # s at rtol 1e-11, are far below the differences).
        for a, b in zip(errors, errors[1:]):
            assert 8 < a / b < 12, errors
        assert errors[-1] < 1e-4, errors


def oracle_benettin(p, t0, state, transient, duration, interval, d0):
    """Benettin's exponent of the oracle's flow, as the program computes it: the reference run to the end
    of the transient, then a perturbed run from reference + d0 (1, 1)/sqrt 2 ((1, 0) inside the band,
    both runs in the same hold), both advanced an interval, the separation's log summed and scaled back
    to d0."""
    def flow(t, y, span):
        xs, vs, _ = machine_oracle(p, np.array([t, t + span]), y[0], y[1])
        return np.array([xs[-1], vs[-1]])

    reference = flow(t0, np.array(state, dtype=float), transient)
    t = t0 + transient
    direction = np.array([1.0, 0.0]) if abs(reference[1] - p["belt"]) < p["dv"] else np.array([1.0, 1.0])
    perturbed = reference + d0 * direction / np.linalg.norm(direction)
    logs = 0.0
    for _ in range(int(duration / interval + 1e-9)):
        reference, perturbed = flow(t, reference, interval), flow(t, perturbed, interval)
        t += interval
        d = np.linalg.norm(perturbed - reference)
        logs += np.log(d / d0)
        perturbed = reference + (perturbed - reference) * d0 / d
    return logs / duration


def machine_chaos(args):
    # At tight tolerances, so that the program's separations (d0 = 1e-8 m) carry errors of ~1e-12
    # relative to the 0.3 m cycle, some 1e-4 of d0, like the oracle's at rtol 1e-12; rk8pd, whose tangent
    # is of the orbit's order (rodas4's, stepped by the orbit's error alone, is 2.4e-4 off in |Φ| after
    # a hold's end, where the slip's Stribeck slope makes δv grow at ~100/s from a standing start).
    sets = {"integrator.method": "'rk8pd'", "analysis.poincare": ".true.", "analysis.section": "'stick_to_slip'", "analysis.strobe_period": 1.0,
            "analysis.lyapunov": ".true.", "analysis.lyapunov_transient": 10.0, "analysis.lyapunov_spectrum": ".true.",
            "analysis.lyapunov_spectrum_transient": 10.0, "integrator.rtol": 1e-12,
            "integrator.atol": 1e-15, "machine.event_tolerance": 1e-13}
    path = run_program(args, "karnopp_chaos", ["machine_karnopp.nml"], sets)
    with h5py.File(path) as f:
        section_t = f["machine/poincare/section_t"][()]
        exponent = f["machine/lyapunov"].attrs["exponent"]
        spectrum = f["machine/lyapunov/exponents"][()]
        lost = f["machine/lyapunov"].attrs["spectrum_lost_directions"]
        t = f["machine/t"][()]
    _, _, expected = machine_oracle(BELT, t, 0.0, 0.0)
    ends = np.array([e for e, k in expected if k == STICK_TO_SLIP])
    gap = np.max(np.abs(section_t - ends)) if len(section_t) == len(ends) else np.inf
    print(f"machine-chaos: {len(section_t)} section points, the oracle's {len(ends)} ends of holds, within "
          f"{gap:.2e} s")
    # The section is the located ends of holds: event_tolerance 1e-13 s and rtol 1e-12 here.
    assert gap < 1e-9, (section_t, ends)
    oracle = oracle_benettin(BELT, 0.0, [0.0, 0.0], 10.0, 20.0, 1.0, 1e-8)
    print(f"machine-chaos: Benettin's exponent {exponent:.6f} 1/s, the oracle's {oracle:.6f} 1/s")
    # Each interval's log of the separation's growth carries the runs' errors relative to d0 = 1e-8 m:
    # ~1e-12 m of state (both sides) and the holds' ends located to 1e-13 s at |v'| ~ 1 m/s^2, so some
    # 1e-4 per interval, 2e-3 over the 20 intervals of 1 s, a sum divided by 20 s: 1e-3 1/s leaves room.
    # (The run as one ODE gave +0.657 1/s here, the step control's noise in the band's depth.)
    assert abs(exponent - oracle) < 1e-3, (exponent, oracle)
    # The spectrum from 10 s to 30 s.  A hold forgets δv (its exponent -inf), and from the first hold in
    # the window on what is left of Φ's first column is a multiple c of the flow's field f, which the
    # tangent flow carries along the orbit (through every saltation S f⁻ = f⁺): the first exponent is
    # ln(|c| |f(y(30))|)/20 exactly, c from central differences of the oracle's flow map from 10 s into
    # the hold that begins at 10.378 s (at 12 s: δx = c v_edge, δv = 0), along the spectrum's first
    # starting direction, generic_frame(2)'s first column (2, 1/2)/|.|.
    def state(t1, y0, t0=0.0):
        xs, vs, _ = machine_oracle(BELT, np.array([t0, t1]), y0[0], y0[1])
        return np.array([xs[-1], vs[-1]])

    y10 = state(10.0, [0.0, 0.0])
    q1 = np.array([2.0, 0.5]) / np.hypot(2.0, 0.5)
    h = 1e-6
    delta = (state(12.0, y10 + h * q1, 10.0) - state(12.0, y10 - h * q1, 10.0)) / (2 * h)
    y12, y30 = state(12.0, y10, 10.0), state(30.0, [0.0, 0.0])
    assert abs(abs(y12[1] - 0.1) - 1e-4) < 1e-15 and abs(delta[1]) < 1e-6, (y12, delta)
    w = y30[1] - 0.1
    force = np.sign(w) * (1.0 + 0.5 * np.exp(-(w / 1e-3) ** 2)) + 0.4 * w
    held = [k for e, k in expected if e < 30.0][-1] == SLIP_TO_STICK
    field = np.array([y30[1], 0.0]) if held else np.array([y30[1], -2.0 * y30[0] - force])
    first = np.log(abs(delta[0] / y12[1]) * np.linalg.norm(field)) / 20.0
    print(f"machine-chaos: spectrum {spectrum} 1/s ({lost} direction lost), the first against the "
          f"oracle's {first:.9f} 1/s")
    # The differences' error, h^2 times the map's curvature and the oracle's rtol 1e-12 over h, is ~1e-6
    # of δx, 5e-8 1/s over 20 s; the program's tangent at rtol 1e-12 is closer.  (The run as one ODE gave
    # 0.675 and 0.036 1/s: two positive exponents for a stable cycle.)
    assert lost == 1 and spectrum[1] == -np.inf, (spectrum, lost)
    assert abs(spectrum[0] - first) < 1e-6, (spectrum, first)


def main():
    return case_main(__doc__, {"machine": machine, "machine-slide": machine_slide, "brake": brake,
                               "brake-slide": brake_slide,
                               "brake-benettin": brake_benettin,
                               "stick-limit": stick_limit,
                               "machine-chaos": machine_chaos})


if __name__ == "__main__":
    raise SystemExit(main())
