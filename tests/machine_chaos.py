#!/usr/bin/env python3
"""The machine scene's Poincaré maps and Lyapunov spectrum, through the
program and its file, against oracles computed here:

  linear        no friction (normal = 0): a damped linear oscillator on a
                harmonically moving support.  The strobe at the support's
                period against the closed-form steady state; both exponents
                against -c/(2m) (the eigenvalues' real part), their sum against
                the trace -c/m exactly, Benettin's exponent against the same
  sum-rule      the LuGre paper's stick-slip: the sum of the exponents against
                the time average of the trace of the Jacobian (the flow's
                divergence) along the written trajectory, the law's formulas
                written out below; the largest exponent against Benettin's
  stiff-lugre   the LuGre paper's Table I law (sigma0 = 1e5 N/m, the bristles
                relaxing at 1e4 1/s in slip): at rest on the belt, a stable
                equilibrium, the exponents against the real parts of the
                Jacobian's eigenvalues there; in stick-slip, their sum against
                the time average of tr J along the written trajectory and
                against the file's spectrum_divergence
  coulomb-cycle Coulomb friction with exact stick on the belt: the located
                slip onsets at x = mu_s N/k and v = belt velocity (the closed-form
                cycle), the spectrum through the switching (saltation) with
                its largest exponent 0 (the cycle's phase) and the velocity's
                direction lost in stick (-inf)
  rosenstein    Rosenstein's exponent of the Coulomb cycle's x against the same
                algorithm written here on the written trajectory (numpy,
                brute-force neighbours), and against 0, the largest exponent
                of a limit cycle
  gms-steady    the Generalized Maxwell-Slip law (two elements) in steady
                sliding, a stable equilibrium: the four exponents against
                the exact finite-time values of e^{J t} (the same QR steps)
                and the real parts of J's eigenvalues, J written below from
                the law's equations with the element's smoothed switch; the
                sum against tr J; Benettin's exponent likewise
  gms-onset     inputs/machine_gms.nml (four elements at Table I's stiffness)
                over 1 s to 7.75 s, across the first slip onset: the sum of
                the exponents against the time average of tr J along the
                flow integrated here (SciPy's LSODA at rtol 1e-12, tr J
                written from the law's smoothed switch), Liouville
  refusals      a section the law has no events for: exit code 3 naming
                the file, line, group and variable, nothing written

    machine_chaos.py --binary build/friction --inputs inputs --workdir DIR CASE
"""
import sys

import h5py
import numpy as np
from scipy.integrate import solve_ivp
from scipy.linalg import expm

from machine_cases import run_program, check_refusals, case_main
from tangent_oracles import finite_time_benettin, finite_time_spectrum, generic_frame


def run(args, name, files, sets):
    return h5py.File(run_program(args, name, files, sets))


def linear(args):
    m, k, c, amplitude, frequency = 1.0, 2.0, 2.0, 0.01, 0.5
    sets = {"law.model": "'arctan'", "machine.normal": 0.0, "machine.damping": c, "machine.belt_velocity": 0.1,
            "machine.support_amplitude": amplitude, "machine.support_frequency": frequency, "machine.v0": 0.0,
            "machine.t_end": 60.0, "machine.dt_out": 0.01, "analysis.poincare": ".true.",
            "analysis.section": "'none'", "analysis.strobe_start": 30.0, "analysis.lyapunov": ".true.",
            "analysis.lyapunov_transient": 10.0, "analysis.lyapunov_spectrum": ".true.",
            "analysis.lyapunov_spectrum_transient": 10.0, "analysis.lyapunov_spectrum_renormalise": 0.5}
    with run(args, "linear", ["machine_arctan.nml"], sets) as f:
        p = f["machine/poincare"]
        period = p.attrs["strobe_period"]
        source = p.attrs["strobe_period_from"].decode()
        t, x, v = p["strobe_t"][:], p["strobe_x"][:], p["strobe_v"][:]
        exponents = f["machine/lyapunov/exponents"][:]
        benettin = f["machine/lyapunov"].attrs["exponent"]
        duration = f["machine/lyapunov"].attrs["spectrum_duration"]
    # m x'' + c x' + k x = k u + c u', u = A sin(ωt): the steady state is Im(H A e^{iωt}).
    omega = 2 * np.pi * frequency
    h = (k + 1j * c * omega) / (k - m * omega**2 + 1j * c * omega)
    x_exact = np.imag(h * amplitude * np.exp(1j * omega * t))
    v_exact = np.imag(1j * omega * h * amplitude * np.exp(1j * omega * t))
    error = max(np.max(np.abs(x - x_exact)), np.max(np.abs(v - v_exact)) / omega)
    print(f"linear: strobe period {period} s from {source}, {t.size} points; max error {error:.2e} m "
          f"(amplitude {abs(h) * amplitude:.3e} m)")
    assert source == "support" and period == 1.0 / frequency and t.size == 16
    # The strobe times fall on output points (2 s is 200 of 0.01 s), so only the integration's error is
    # left: rtol 1e-9 of an amplitude of 1e-2 m is 1e-11 m a step; the transient from the start is
    # e^{-c t/2m} = e^{-30} = 1e-13 of it at t = 30 s.  1e-9 m is 100 times the error that leaves and
    # 1e-7 of the amplitude; a wrong phase or gain (u' left out of the damper) is 1e-3 m off.
    assert error < 1e-9, error
    # The exponents: the eigenvalues -c/2m ± i sqrt(k/m - (c/2m)²) have equal real parts.  Over T, the QR
    # estimate of each is off by at most ln(cond(V))/T, V the eigenvectors (the tangent vectors' angle to
    # them at the start and at the end); the sum is the trace exactly, to the integrator's rounding.
    jacobian = np.array([[0.0, 1.0], [-k / m, -c / m]])
    vectors = np.linalg.eig(jacobian)[1]
    bound = np.log(np.linalg.cond(vectors)) / duration
    expected = -c / (2 * m)
    print(f"linear: exponents {exponents}, sum {exponents.sum():.12f} (trace {-c / m}); Benettin {benettin:.6f}; "
          f"expected {expected} within {bound:.2e}")
    assert np.all(np.abs(exponents - expected) <= bound), (exponents, bound)
    # The sum telescopes: sum ln R_ii = ln det Φ = ∫ tr J = -c T/m, exact but for the tangent's integration
    # error (rtol 1e-9 a step, over 100 intervals): 1e-8 of c/m.
    assert abs(exponents.sum() + c / m) < 1e-8 * c / m, exponents.sum()
    # Benettin over 50 s of a 1e-8 separation: the same bound on its log growth.
    assert abs(benettin - expected) <= bound and abs(benettin - exponents[0]) <= 2 * bound, benettin


def lugre_trace(x, v, z, m, k, c, vb, fc, fs, vs, s0, s1, s2):
    """tr J = ∂v'/∂v + ∂z'/∂z for the LuGre belt oscillator (the paper's equations)."""
    w = v - vb
    g = fc + (fs - fc) * np.exp(-(w / vs) ** 2)
    dg = (fs - fc) * np.exp(-(w / vs) ** 2) * (-2 * w / vs**2)
    # z' = w - σ0 |w| z / g(w)
    dzdot_dw = 1 - s0 * z * (np.sign(w) / g - np.abs(w) * dg / g**2)
    dzdot_dz = -s0 * np.abs(w) / g
    # F = σ0 z + σ1 z' + σ2 w; v' = (-k x - c v - F)/m
    dvdot_dv = -(c + s1 * dzdot_dw + s2) / m
    return dvdot_dv + dzdot_dz


def lugre_jacobian_at_rest(m, k, c, vb, fc, fs, vs, s0, s1, s2):
    """J at steady sliding with the block at rest (w = -vb, z = g(w) sgn(w)/σ0, k x = -F)."""
    w = -vb
    g = fc + (fs - fc) * np.exp(-(w / vs) ** 2)
    dg = (fs - fc) * np.exp(-(w / vs) ** 2) * (-2 * w / vs**2)
    z = np.sign(w) * g / s0
    dzdot_dw = 1 - s0 * z * (np.sign(w) / g - abs(w) * dg / g**2)
    dzdot_dz = -s0 * abs(w) / g
    return np.array([[0.0, 1.0, 0.0],
                     [-k / m, -(c + s1 * dzdot_dw + s2) / m, -(s0 + s1 * dzdot_dz) / m],
                     [0.0, dzdot_dw, dzdot_dz]])


def lugre_sum_rule(args, name, sets, transient, duration, parameters):
    """A LuGre run of machine_lugre.nml with `sets`: its exponents and spectrum_divergence, and the time
    average of tr J after the transient along the written trajectory by the trapezoid, with the
    quadrature's own error from every second sample (trapezoid: 4 times the error of every sample)."""
    with run(args, name, ["machine_lugre.nml"], sets) as f:
        t, x, v, z = (f["machine"][key][:] for key in ("t", "x", "v", "z"))
        exponents = f["machine/lyapunov/exponents"][:]
        divergence = f["machine/lyapunov"].attrs["spectrum_divergence"]
    keep = t >= transient - 1e-12
    trace = lugre_trace(x[keep], v[keep], z[keep], *parameters)
    average = np.trapezoid(trace, t[keep]) / duration
    quadrature = abs(np.trapezoid(trace[::2], t[keep][::2]) / duration - average) / 3
    return exponents, divergence, average, quadrature


def sum_rule(args):
    # LuGre with a soft bristle (σ0 = 100 N/m, σ1 = 10 N s/m): its relaxation σ0|w|/g, 10 1/s here, is
    # resolved by the orbit's own steps (the paper's σ0 = 1e5 N/m is stiff-lugre's).
    m, k, c, vb, fc, fs, vs, s0, s1, s2 = 1.0, 2.0, 0.0, 0.1, 1.0, 1.5, 1e-3, 100.0, 10.0, 0.4
    transient, duration = 5.0, 20.0
    law = {"law.sigma0": s0, "law.sigma1": s1}
    sets = dict(law, **{"machine.t_end": transient + duration, "machine.dt_out": 2e-4,
                        "analysis.lyapunov_spectrum": ".true.", "analysis.lyapunov_spectrum_transient": transient,
                        "analysis.lyapunov_spectrum_renormalise": 0.1})
    exponents, divergence, average, quadrature = lugre_sum_rule(args, "lugre", sets, transient, duration,
                                                                (m, k, c, vb, fc, fs, vs, s0, s1, s2))
    print(f"sum-rule: exponents {exponents}, sum {exponents.sum():.9f} 1/s; time average of tr J "
          f"{average:.9f} 1/s (quadrature error ~{quadrature:.1e})")
    # Σλ T = ln det Φ(T) = ∫ tr J dt exactly (Liouville), whatever the motion.  What differs: the tangent's
    # quadrature of tr J on the orbit's steps (the exponentials' Gauss points: measured 2e-12 of the sum; it
    # was 5e-7 with the stepper carrying the tangent) and the trapezoid on the written samples (4e-11).
    # 1e-9 of the sum is 500 times the first; leaving σ1's part out of ∂F/∂v, or the states' scale out of
    # the Jacobian, moves the sum by more than 10 %.
    assert abs(exponents.sum() - average) <= 1e-9 * abs(average) + 3 * quadrature, (exponents.sum(), average)
    # The file's own sum-rule check, ∫ tr J integrated by the stepper beside the orbit: measured 6e-13 of
    # it (1.3e-5 without D's row in the stepper's Jacobian); 1e-8 leaves room for the kinks of |w| in tr J.
    print(f"sum-rule: the file's spectrum_divergence {divergence:.9f} 1/s")
    assert abs(divergence - average) <= 1e-8 * abs(average), (divergence, average)

    # Started near steady sliding and measured after it has settled (e^(-0.2 * 60) = 6e-6 of the
    # disturbance is left), the exponents are the real parts of J's eigenvalues there, and Benettin's
    # estimate is the largest of them.
    transient, duration = 60.0, 40.0
    sets = dict(law, **{"machine.t_end": transient + duration, "analysis.lyapunov": ".true.",
                        "analysis.lyapunov_transient": transient, "analysis.lyapunov_renormalise": 0.5,
                        "analysis.lyapunov_spectrum": ".true.", "analysis.lyapunov_spectrum_transient": transient,
                        "analysis.lyapunov_spectrum_renormalise": 0.05})
    with run(args, "lugre_rest", ["machine_lugre.nml"], sets) as f:
        exponents = f["machine/lyapunov/exponents"][:]
        benettin = f["machine/lyapunov"].attrs["exponent"]
    jacobian = lugre_jacobian_at_rest(m, k, c, vb, fc, fs, vs, s0, s1, s2)
    values, vectors = np.linalg.eig(jacobian)
    expected = np.sort(values.real)[::-1]
    # Over T the QR and Benettin estimates are off by at most ln(cond V)/T (V: J's eigenvectors; the
    # tangent vectors' angles to them at the start and the end) plus what is left of the transient's
    # approach, 6e-6 of the disturbance: ln(1 + 6e-6)/T, negligible.
    bound = np.log(np.linalg.cond(vectors)) / duration
    print(f"sum-rule: at rest: exponents {exponents}, Benettin {benettin:.6f}; J's eigenvalues' real parts "
          f"{expected} (bound {bound:.2e}); sum {exponents.sum():.9f}, trace {np.trace(jacobian):.9f}")
    assert np.all(np.abs(exponents - expected) <= bound), (exponents, expected, bound)
    assert abs(benettin - expected[0]) <= bound and abs(benettin - exponents[0]) <= 2 * bound, benettin
    # At rest the trace is constant: the sum is it, but for what is left of the transient, whose velocity
    # moves the average of σ0|w|/g by σ0 Δx / (g T) (measured 1.5e-7 of the sum; 5e-5 when the stepper
    # carried the tangent, whose damping of the fast direction on steps of 0.05 s is not e^(-10 h)).
    # 2e-6 of the trace is 13 times that.
    assert abs(exponents.sum() - np.trace(jacobian)) <= 2e-6 * abs(np.trace(jacobian)), exponents.sum()


def stiff_lugre(args):
    # The paper's Table I: the bristles relax at σ0|w|/g = 1e4 1/s in slip, while the orbit's steps
    # follow the motion's time scales, up to 1e4 times longer.  The tangent is carried over each step by
    # exponentials (docs/chaos.md), which damp that direction at its own rate; a stiff stepper's
    # stability function does not (the program's exponents before: 0.022, -12.9, -48, summing to -61
    # against a divergence of -9652 1/s).
    m, k, c, vb, fc, fs, vs, s0, s1, s2 = 1.0, 2.0, 0.0, 0.1, 1.0, 1.5, 1e-3, 1e5, np.sqrt(1e5), 0.4
    # At rest on the belt (w = -vb), the spring balancing the steady friction g(w) + σ2 |w|: an equilibrium
    # whose Jacobian has eigenvalues -0.2 ± 1.4i and -1e4, stable (from x0 = 0 the block falls into stick-slip
    # instead: the equilibrium has a basin of its own).  Started δ = 1e-3 m off it and measured after 60 s:
    # e^-12 δ = 6e-9 m is left, and the velocity's part of tr J (σ0 |w| / g) moves the average over T by
    # σ0 Δx / (g T), 1.5e-5 1/s (after 20 s it was 0.04 1/s).
    g = fc + (fs - fc) * np.exp(-(vb / vs) ** 2)
    x_rest = (g + s2 * vb) / k
    transient, duration = 60.0, 40.0
    sets = {"machine.x0": x_rest + 1e-3, "machine.t_end": transient + duration, "machine.dt_out": 0.1,
            "analysis.lyapunov_spectrum": ".true.", "analysis.lyapunov_spectrum_transient": transient,
            "analysis.lyapunov_spectrum_renormalise": 0.5}
    with run(args, "stiff_rest", ["machine_lugre.nml"], sets) as f:
        exponents = f["machine/lyapunov/exponents"][:]
        divergence = f["machine/lyapunov"].attrs["spectrum_divergence"]
        x_end, v_end = f["machine/x"][-1], f["machine/v"][-1]
    jacobian = lugre_jacobian_at_rest(m, k, c, vb, fc, fs, vs, s0, s1, s2)
    values = np.linalg.eigvals(jacobian)
    expected = np.sort(values.real)[::-1]
    # The bound ln(cond V)/T of the QR estimate over T (V: J's eigenvectors) in the program's coordinates,
    # z over its scale F_s/σ0 (docs/laws.md); the transient's 1.5e-5 1/s adds nothing visible.
    scaled = np.diag([1.0, 1.0, s0 / fs])
    vectors = np.linalg.eig(scaled @ jacobian @ np.linalg.inv(scaled))[1]
    bound = np.log(np.linalg.cond(vectors)) / duration
    print(f"stiff-lugre: at rest (x = {x_end:.9f} m against {x_rest:.9f}, v = {v_end:.1e} m/s): exponents {exponents}; "
          f"J's eigenvalues' real parts {expected} (bound {bound:.2e} 1/s); sum {exponents.sum():.6f}, "
          f"trace {np.trace(jacobian):.6f}, spectrum_divergence {divergence:.6f}")
    assert abs(x_end - x_rest) < 1e-4 and abs(v_end) < 1e-4, (x_end, v_end)
    assert np.all(np.abs(exponents - expected) <= bound), (exponents, expected, bound)

    # Stick-slip from rest at x = 0.  Σλ T = ln det Φ(T) = ∫ tr J dt (Liouville).  The oracle: the time
    # average of tr J along the written trajectory, the law's formulas written out here, by the trapezoid on
    # a 5e-5 s grid (the bristles' transients at the switches last 1e-4 s), with its error estimated from
    # every second sample.
    transient, duration = 10.0, 10.0
    sets = {"machine.t_end": transient + duration, "machine.dt_out": 5e-5, "analysis.lyapunov_spectrum": ".true.",
            "analysis.lyapunov_spectrum_transient": transient}
    exponents, divergence, average, quadrature = lugre_sum_rule(args, "stiff_stick_slip", sets, transient,
                                                                duration, (m, k, c, vb, fc, fs, vs, s0, s1, s2))
    print(f"stiff-lugre: stick-slip: exponents {exponents}, sum "
          f"{exponents.sum():.6f} 1/s; time average of tr J {average:.6f} (quadrature error ~{quadrature:.1e}); "
          f"spectrum_divergence {divergence:.6f}")
    # What separates the sum from the trapezoid's average: the trapezoid's own error (measured 4.2e-4 1/s
    # apart, its estimate 7.4e-4: 3 times the estimate) and the tangent's quadrature of tr J on the orbit's
    # steps (Gauss: the sum moves by 5e-6 1/s from rtol 1e-9 to 1e-13); 1e-7 of the sum for the rest.
    assert abs(exponents.sum() - average) <= 3 * quadrature + 1e-7 * abs(average), (exponents.sum(), average)
    # The file's own check: spectrum_divergence is the stepper's quadrature of tr J beside the orbit,
    # independent of the tangent; at rtol 1e-9 it is 7e-8 of itself from its value at rtol 1e-13 (docs/chaos.md),
    # and the sum 6.9e-8 from it here.  1e-6 of it is 14 times that, and 1e6 times closer than the sum came
    # when the stepper carried the tangent.
    assert abs(exponents.sum() - divergence) <= 1e-6 * abs(divergence), (exponents.sum(), divergence)


def first_frame_column():
    """|Q[0, 0]| of the tangent vectors' starting frame, the QR of I + the 2 x 2 Hilbert matrix
    (documented in analysis/lyapunov_spectrum.f90): in stick only δx survives of the first vector."""
    return abs(np.linalg.qr(np.eye(2) + 1.0 / (np.add.outer(np.arange(2), np.arange(2)) + 1.0))[0][0, 0])


def coulomb_cycle(args):
    mu, mu_s, n, k, m, vb = 0.5, 1.0, 1.0, 2.0, 1.0, 0.1
    base = {"law.model": "'coulomb'", "law.mu": mu, "law.mu_s": mu_s}
    sets = dict(base, **{"machine.t_end": 100.0, "analysis.poincare": ".true.", "analysis.section": "'stick_to_slip'",
                         "analysis.strobe_period": 1.0})
    with run(args, "coulomb", ["machine_coulomb.nml"], sets) as f:
        p = f["machine/poincare"]
        sx, sv = p["section_x"][:], p["section_v"][:]
        ev, kind = f["machine/events/t"][:], f["machine/events/kind"][:]
    print(f"coulomb-cycle: {sx.size} slip onsets at x in [{sx.min():.12f}, {sx.max():.12f}] m (mu_s N/k = {mu_s * n / k})")
    # Stick ends where the spring's pull k x reaches mu_s N: the event is located to event_tolerance
    # 1e-10 s, in which x moves by belt 1e-10 = 1e-11 m; 1e-9 m leaves the stepper's rounding room.
    assert sx.size >= 5 and np.all(np.abs(sx - mu_s * n / k) < 1e-9) and np.all(sv == vb), (sx, sv)
    # The spectrum through the switches.  The system is autonomous, so the flow carries its own field:
    # Φ(t, s) f(y(s)) = f(y(t)) in slip, the saltation matrix maps f⁻ to f⁺ at a switch, and stick keeps
    # f = (belt, 0).  Started in stick, the first tangent vector keeps only its δx = Q[0, 0] there, along f;
    # from then on it is f(y(t)) Q[0, 0] / belt, and the QR steps' logs telescope: λ1 T = ln Q[0, 0] +
    # ln(|f(y(t0 + T))| / belt), f = (v, a) with a = (-k x - F)/m from the written end of the run.
    stick_start = ev[kind == 2]
    t0 = round(float(stick_start[stick_start > 20.0][0]) + 0.5, 2)   # 0.5 s into a stick phase, on the grid
    for duration in (40.0, 55.3, 71.1):
        sets = dict(base, **{"machine.t_end": t0 + duration, "analysis.lyapunov_spectrum": ".true.",
                             "analysis.lyapunov_spectrum_transient": t0,
                             "analysis.lyapunov_spectrum_renormalise": duration / 40})
        with run(args, "coulomb_spectrum", ["machine_coulomb.nml"], sets) as f:
            exponents = f["machine/lyapunov/exponents"][:]
            lost = f["machine/lyapunov"].attrs["spectrum_lost_directions"]
            x, v, force, stick = (f["machine"][key][-1] for key in ("x", "v", "force", "stick"))
            end = f["machine/t"][-1]
        speed = vb if stick else np.hypot(v, (-k * x - force) / m)
        expected = (np.log(first_frame_column()) + np.log(speed / vb)) / duration
        print(f"coulomb-cycle: T = {duration} s (end at {end} s, {'stick' if stick else 'slip'}): exponents {exponents}, "
              f"lost {lost}; expected λ1 = {expected:.12f}")
        # The identity is exact; what is left is the integration's error (rtol 1e-9) in the end state and
        # in Φ, and the events' times (1e-10 s): measured 7e-12 1/s, 1e-9 1/s is 100 times that.  Without
        # the saltation matrices λ1 comes out -0.12 1/s.
        assert abs(end - (t0 + duration)) < 1e-9
        assert abs(exponents[0] - expected) < 1e-9, (exponents, expected)
        assert lost == 1 and np.isneginf(exponents[1]), exponents


def coulomb_forced(args):
    # A support moving harmonically drives the Coulomb oscillator onto a period-1 orbit whose strobe point
    # sticks.  The strobe map in stick is one-dimensional (δv is 0 there): its slope μ from finite
    # differences of two runs started at the strobe point ± δ is the orbit's one nonzero multiplier, and
    # over N periods from the strobe point λ1 N T = ln Q[0, 0] + N ln |μ| (the logs telescope as in
    # coulomb-cycle; here the switches' ∂h/∂t term, the support's motion, is in the saltation too).
    amplitude, frequency = 0.2, 0.15
    period = 1.0 / frequency
    base = {"law.model": "'coulomb'", "law.mu": 0.5, "law.mu_s": 1.0, "machine.support_amplitude": amplitude,
            "machine.support_frequency": frequency, "analysis.poincare": ".true.", "analysis.section": "'none'"}
    periods = 10
    sets = dict(base, **{"machine.t_end": 300.0 + periods * period, "analysis.strobe_start": 300.0})
    with run(args, "forced", ["machine_coulomb.nml"], sets) as f:
        p = f["machine/poincare"]
        assert p.attrs["strobe_period_from"].decode() == "support"
        ts, xs, vs = p["strobe_t"][0], p["strobe_x"][0], p["strobe_v"][0]
        spread = np.ptp(p["strobe_x"][:])
    # 300 s at λ1 = -0.07 1/s: the orbit is reached to e^-21 = 1e-9 of the motion's size.
    assert vs == 0.1 and spread < 1e-8, (vs, spread)
    delta = 1e-5
    ends = []
    for sign in (1.0, -1.0):
        sets = dict(base, **{"machine.t_start": ts, "machine.t_end": ts + 1.5 * period, "machine.x0": xs + sign * delta,
                             "machine.v0": 0.1, "analysis.strobe_start": ts})
        with run(args, "forced_fd", ["machine_coulomb.nml"], sets) as f:
            ends.append(f["machine/poincare/strobe_x"][1])
    slope = (ends[0] - ends[1]) / (2 * delta)
    sets = dict(base, **{"machine.t_end": ts + periods * period, "analysis.poincare": ".false.",
                         "analysis.lyapunov_spectrum": ".true.", "analysis.lyapunov_spectrum_transient": ts,
                         "analysis.lyapunov_spectrum_renormalise": period, "analysis.lyapunov": ".true.",
                         "analysis.lyapunov_transient": ts, "analysis.lyapunov_renormalise": period})
    with run(args, "forced_spectrum", ["machine_coulomb.nml"], sets) as f:
        exponents = f["machine/lyapunov/exponents"][:]
        benettin = f["machine/lyapunov"].attrs["exponent"]
    expected = (np.log(first_frame_column()) + periods * np.log(abs(slope))) / (periods * period)
    print(f"coulomb-forced: strobe point ({xs:.9f} m, {vs} m/s) at {ts:.6f} s; multiplier from finite differences "
          f"{slope:.9f}; λ1 = {exponents[0]:.9f} 1/s against {expected:.9f}")
    # The central difference's error: the map's curvature times δ² (stick ends move smoothly with x), and
    # each run's end to ~1e-11 m over 2δ = 2e-5 m, 1e-6 of μ; N ln|μ| then carries N 1e-6 / N T = 1.5e-7 1/s.
    # 1e-6 1/s is 7 times that; leaving out the switches' ∂h/∂t (the support's motion) gives -0.272 1/s.
    assert abs(exponents[0] - expected) < 1e-6, (exponents, expected)
    assert np.isneginf(exponents[1]), exponents
    # Benettin's two runs through the same switching, the separation (δx, 0) in stick at the strobe
    # point and renormalised every period: each period multiplies it by μ, so λ = ln|μ|/T with no
    # starting term.  Its separation d0 = 1e-8 m adds the map's curvature times d0 (measured: 1.5e-7
    # 1/s off); 1e-6 1/s as above.
    print(f"coulomb-forced: Benettin {benettin:.9f} 1/s against ln|μ|/T = {np.log(abs(slope)) / period:.9f}")
    assert abs(benettin - np.log(abs(slope)) / period) < 1e-6, benettin


def rosenstein_here(series, dt, dimension, delay, theiler, horizon, fit_start, fit_end):
    """Rosenstein et al.'s estimate: delay embedding, each point's nearest neighbour outside the
    Theiler window, the mean log distance of the pairs k samples later, its least-squares slope."""
    m = series.size - (dimension - 1) * delay
    embedded = np.stack([series[k * delay:k * delay + m] for k in range(dimension)], axis=1)
    last = m - horizon
    points = embedded[:last]
    distance = ((points[:, None, :] - points[None, :, :]) ** 2).sum(axis=2)
    index = np.arange(last)
    distance[np.abs(index[:, None] - index[None, :]) <= theiler] = np.inf
    distance[distance == 0.0] = np.inf
    neighbour = distance.argmin(axis=1)
    divergence = np.array([np.mean(np.log(np.linalg.norm(embedded[index + k] - embedded[neighbour + k], axis=1)))
                           for k in range(horizon + 1)])
    time = dt * np.arange(horizon + 1)
    return np.polyfit(time[fit_start:fit_end + 1], divergence[fit_start:fit_end + 1], 1)[0], divergence


def rosenstein(args):
    window_start, window_end = 20.0, 200.0
    sets = {"machine.t_end": window_end, "analysis.rosenstein": ".true.", "analysis.lyapunov": ".true.",
            "analysis.window_start": window_start, "analysis.window_end": window_end}
    with run(args, "rosenstein", ["machine_coulomb.nml"], sets) as f:
        t, x = f["machine/t"][:], f["machine/x"][:]
        g = f["machine/lyapunov"]
        a = {key: g.attrs[key] for key in g.attrs if key.startswith("rosenstein_")}
        exponent, divergence = a["rosenstein_exponent"], g["rosenstein_divergence"][:]
        benettin = g.attrs["exponent"]
        units = (g.attrs["rosenstein_exponent_units"], g["rosenstein_time"].attrs["units"])
    stride = int(a["rosenstein_stride"])
    window = x[(t >= window_start) & (t <= window_end)][::stride]
    dt = float(t[1] - t[0]) * stride
    here, here_divergence = rosenstein_here(window, dt, *(int(a["rosenstein_" + key]) for key in
                                            ("dimension", "delay", "theiler", "horizon", "fit_start", "fit_end")))
    print(f"rosenstein: {exponent:.15f} 1/s against {here:.15f} written here; Benettin {benettin:.6f} 1/s; "
          f"units {units}")
    # The same sums in another order: the divergence's means agree to rounding (1e-15 of ln d ~ 8);
    # 1e-11 leaves room for summation order over 700 pairs.
    assert abs(a["rosenstein_sample_spacing"] - dt) < 1e-15 and units == (b"1/s", b"s"), (a, units)
    assert np.max(np.abs(divergence - here_divergence)) < 1e-11, np.max(np.abs(divergence - here_divergence))
    assert abs(exponent - here) < 1e-10, (exponent, here)
    # A limit cycle's neighbours keep their distance: the slope over the fit (50 samples, 2 s) is 0 up to
    # the neighbours' phase drift; measured -0.0035 1/s, a change of 0.007 in ln d over the fit.  0.05 1/s
    # (0.1 in ln d) still tells it from a chaotic orbit's positive exponent or a decay.
    assert abs(exponent) < 0.05 and abs(benettin) < 0.05, (exponent, benettin)


# Two GMS elements sharing a Stribeck curve (Table I's F_c, F_s, v_s) on the belt; soft elements (k_i of
# 1e-2 N/m), so that an element's relaxation at its limit, |w| k_i/(ε w_i g), ε = 1e-5 the smoothing of
# its switch (law/gms.f90), is 15 and 7.5 1/s at w = 3e-3 m/s: resolved by the orbit's steps.
GMS = dict(fc=1.0, fs=1.5, vs=1e-3, s2=0.4, k=np.array([0.03, 0.01]), weight=np.array([0.6, 0.4]), attraction=20.0,
           entry=1e-5)
GMS_SETS = {"law.model": "'gms'", "law.fc": GMS["fc"], "law.fs": GMS["fs"], "law.vs": GMS["vs"],
            "law.sigma2": GMS["s2"], "law.elements": 2, "law.element_stiffness": "0.03, 0.01",
            "law.element_weight": "0.6, 0.4", "law.attraction": GMS["attraction"]}


def gms_machine(m, k, c, belt):
    """The belt oscillator with the GMS law in the program's variables (x, v, z_i over w_i F_s/k_i): the
    field (the law's smoothed rate: a sticking element's rate falls from w to 0 over the last ε of its
    way to the limit, and beyond it the rate pulls back as a(u) blends from |w|/ε to C/k_i over
    [1, 1 + ε]) and its Jacobian at steady sliding, every element at its limit (u_i = 1)."""
    ki, wi, eps = GMS["k"], GMS["weight"], GMS["entry"]
    scale = wi * GMS["fs"] / ki

    def g(w):
        e = np.exp(-(w / GMS["vs"]) ** 2)
        return GMS["fc"] + (GMS["fs"] - GMS["fc"]) * e, (GMS["fs"] - GMS["fc"]) * e * (-2 * w / GMS["vs"] ** 2)

    def field(_, state):
        x, v, zh = state[0], state[1], state[2:]
        z, w = zh * scale, v - belt
        gw, _ = g(w)
        s = np.sign(w)
        u = ki * z * s / (wi * gw)
        blend = np.clip((1 + eps - u) / eps, 0.0, 1.0)
        pull = GMS["attraction"] / ki + (abs(w) / eps - GMS["attraction"] / ki) * blend
        rate = np.where((w == 0) | (u < 1 - eps), w, s * (1 - u) * pull)
        force = np.sum(ki * z) + GMS["s2"] * w
        return np.concatenate([[v, (-k * x - c * v - force) / m], rate / scale])

    def jacobian_steady(w):
        # At u_i = 1: ż_i = s (1 - u_i) |w|/ε near it, so ∂ż_i/∂z_i = -(|w|/ε) k_i/(w_i g) and, through
        # u_i's g(w), ∂ż_i/∂w = s (|w|/ε) g'(w)/g.
        gw, dg = g(w)
        a = abs(w) / eps
        j = np.zeros((4, 4))
        j[0, 1] = 1.0
        j[1, 0], j[1, 1] = -k / m, -(c + GMS["s2"]) / m
        j[1, 2:] = -ki * scale / m
        j[2:, 1] = np.sign(w) * a * dg / gw / scale
        j[2:, 2:] = np.diag(-a * ki / (wi * gw))
        return j

    def ratio(state):
        """u_i, each element's force in the direction of motion over its limit."""
        w = state[1] - belt
        return ki * state[2:] * scale * np.sign(w) / (wi * g(w)[0])

    return field, jacobian_steady, scale, ratio


def inner_differences(field, ratio, state):
    """∂f/∂y by one-sided second-order differences on the side where every element stays within its
    limit (u_i <= 1): there the smoothed rate is linear in u, whereas across u = 1 its slope turns over
    the width ε, which a central difference of any useful step would feel."""
    columns = []
    for i in range(state.size):
        h = 1e-7 * max(abs(state[i]), 1.0)
        e = np.eye(state.size)[i]
        if np.any(ratio(state + 2 * h * e) > 1.0):
            h = -h
        columns.append((-3 * field(0, state) + 4 * field(0, state + h * e) - field(0, state + 2 * h * e)) / (2 * h))
    return np.column_stack(columns)


def gms_steady(args):
    # At 3 v_s the Stribeck curve's slope (0.37 N s/m) is below σ2 + c: steady sliding with the block at
    # rest (x = (g + σ2 belt)/k, the elements at their limits, which the program's steady start sets) is
    # a stable equilibrium, and the run stays on it.
    m, k, c, belt = 1.0, 2.0, 1.0, 3e-3
    field, jacobian_steady, scale, ratio = gms_machine(m, k, c, belt)
    gw = GMS["fc"] + (GMS["fs"] - GMS["fc"]) * np.exp(-(belt / GMS["vs"]) ** 2)
    x0 = (gw + GMS["s2"] * belt) / k
    state = np.concatenate([[x0, 0.0], -GMS["weight"] * gw / GMS["k"] / scale])
    j = jacobian_steady(-belt)
    fd = inner_differences(field, ratio, state)
    residual = np.max(np.abs(field(0, state)))
    # The Jacobian written above against central differences of the field written above (its algebra).
    assert np.allclose(fd, j, rtol=1e-5, atol=1e-6), (fd, j)
    transient, duration, every, interval = 5.0, 60.0, 0.02, 0.5
    sets = dict(GMS_SETS, **{"machine.belt_velocity": belt, "machine.damping": c, "machine.x0": x0,
                             "machine.v0": 0.0, "machine.t_end": transient + duration, "machine.dt_out": 0.05,
                             "analysis.lyapunov": ".true.", "analysis.lyapunov_transient": transient,
                             "analysis.lyapunov_renormalise": interval, "analysis.lyapunov_spectrum": ".true.",
                             "analysis.lyapunov_spectrum_transient": transient,
                             "analysis.lyapunov_spectrum_renormalise": every})
    with run(args, "gms_steady", ["machine_gms.nml"], sets) as f:
        exponents = f["machine/lyapunov/exponents"][:]
        benettin = f["machine/lyapunov"].attrs["exponent"]
        divergence = f["machine/lyapunov"].attrs["spectrum_divergence"]
        drift = float(np.ptp(f["machine/x"][:]))
    values, vectors = np.linalg.eig(j)
    expected = np.sort(values.real)[::-1]
    bound = np.log(np.linalg.cond(vectors)) / duration
    qr_exact = finite_time_spectrum(expm(j * every), generic_frame(4), int(round(duration / every))) / duration
    benettin_exact = finite_time_benettin(expm(j * interval), np.ones(4), int(round(duration / interval))) / duration
    print(f"gms-steady: residual of the start {residual:.1e}, drift {drift:.1e} m; exponents {exponents}; J's "
          f"eigenvalues' real parts {expected} (bound {bound:.2e}); exact finite-time {qr_exact}; sum "
          f"{exponents.sum():.9f}, trace {np.trace(j):.9f}, the file's divergence {divergence:.9f}; Benettin "
          f"{benettin:.9f}, exact finite-time {benettin_exact:.9f}")
    assert exponents.size == 4, exponents
    # On the equilibrium the perturbations' flow is e^{J t} exactly: the same QR steps from the same frame
    # give the finite-time exponents themselves.  The program carries the tangent over the orbit's steps
    # by exponentials of J at the steps' Gauss points (fourth order; J is constant here, so only the
    # exponentials' Padé error and rounding are left): measured 1.6e-9 1/s at most.  1e-7 1/s is 60 times
    # that; a wrong partial of the smoothed switch moves these by O(1) (the elements' rates are its |w|/ε).
    assert np.all(np.abs(exponents - qr_exact) <= 1e-7), exponents - qr_exact
    # The largest two (the block's motion) against the real parts of J's eigenvalues: over T the QR
    # estimates are off by at most ln(cond V)/T (the tangent vectors' angles to the eigenvectors at the
    # start and the end).  (The elements' two tend to theirs more slowly: the exact finite-time values
    # above are 0.04 1/s from them at 60 s.)
    assert np.all(np.abs(exponents[:2] - expected[:2]) <= bound), (exponents, expected, bound)
    # Benettin's separation 1e-8 against atol 1e-12: at most 1e-4 of ln growth a renormalisation (0.5 s),
    # 2e-4 1/s if every error had one sign; measured 5.8e-6.  1e-4 1/s.
    assert abs(benettin - benettin_exact) <= 1e-4, (benettin, benettin_exact)
    # The sum: ln det Φ = ∫ tr J dt, the trace here (det exp(X) = exp(tr X)): measured 6.7e-11 of it;
    # 1e-8 of it.  The file's divergence integrates tr J itself, constant on the equilibrium: the trace
    # to rounding.
    assert abs(exponents.sum() - np.trace(j)) <= 1e-8 * abs(np.trace(j)), (exponents.sum(), np.trace(j))
    assert abs(divergence - np.trace(j)) <= 1e-9 * abs(np.trace(j)), (divergence, np.trace(j))


def gms_onset(args):
    # Across a slip onset every element crosses its switch band (3.7e-11 m wide, tr J down to -1e9 1/s in it),
    # which the spectrum's steps now end at. The oracle: ∫ tr J dt along the flow from the run's start, the
    # integral a component of the ODE solved here (LSODA, rtol 1e-12: 1e-12 and 1e-13 agree to 3e-8).
    m, k, vb = 1.0, 2.0, 0.1
    fc, fs, vs, s2, attraction, eps = 1.0, 1.5, 1e-3, 0.4, 20.0, 1e-5
    ks, ws = (4e4, 3e4, 2e4, 1e4), (0.1, 0.2, 0.3, 0.4)

    def extended(_, y):
        w = y[1] - vb
        s = 1.0 if w >= 0 else -1.0
        g = fc + (fs - fc) * np.exp(-(w / vs) ** 2)
        out = [y[1], 0.0, 0.0, 0.0, 0.0, 0.0, -s2 / m]
        force = s2 * w
        for i, (ki, wi) in enumerate(zip(ks, ws)):
            force += ki * y[2 + i]
            u = ki * y[2 + i] * s / (wi * g)
            if w == 0 or u < 1 - eps:
                out[2 + i] = w   # sticks: ∂ż/∂z = 0
                continue
            blend = min(1.0, max(0.0, (1 + eps - u) / eps))
            pull = attraction / ki + (abs(w) / eps - attraction / ki) * blend
            slope = -(abs(w) / eps - attraction / ki) / eps if 1 < u < 1 + eps else 0.0   # ∂pull/∂u
            out[2 + i] = s * (1 - u) * pull
            out[6] += (-pull + (1 - u) * slope) * ki / (wi * g)   # ∂ż_i/∂z_i (s² = 1)
        out[1] = (-k * y[0] - force) / m
        return out

    rtol = 1e-12
    atol = [1e-3 * rtol] * 2 + [1e-6 * rtol] * 4 + [1e9 * rtol]
    # The run's start: at rest (v0 = 0, x0 = 0) on the belt, the elements in steady sliding at w = -vb.
    g0 = fc + (fs - fc) * np.exp(-(vb / vs) ** 2)
    start = [0.0, 0.0] + [-wi * g0 / ki for ki, wi in zip(ks, ws)] + [0.0]
    first = solve_ivp(extended, (0.0, 1.0), start, method="LSODA", rtol=rtol, atol=atol)
    rest = solve_ivp(extended, (1.0, 7.75), first.y[:, -1], method="LSODA", rtol=rtol, atol=atol)
    trace = (rest.y[6, -1] - first.y[6, -1]) / 6.75
    with run(args, "gms_onset", ["machine_gms.nml"], {
            "machine.t_end": 9.0, "analysis.lyapunov_spectrum": ".true.", "analysis.lyapunov_spectrum_transient": 1.0,
            "analysis.lyapunov_spectrum_duration": 6.75, "analysis.lyapunov_spectrum_renormalise": 0.25}) as f:
        exponents = f["machine/lyapunov/exponents"][()]
        divergence = f["machine/lyapunov"].attrs["spectrum_divergence"]
    print(f"gms-onset: exponents {exponents}, sum {exponents.sum()!r}, mean tr J here {trace!r} "
          f"({abs(exponents.sum() / trace - 1):.2e} of it); the stepper's spectrum_divergence {divergence!r}")
    assert np.all(np.isfinite(exponents)), exponents
    # Measured 6.0e-6 at the default rtol 1e-9 (1.1e-7 at 1e-10), the oracle's own 3e-8: 5e-5 is the
    # integration's error with room. With the steps across the bands' edges the fastest exponent alone was
    # -2.3e8, the sum five times this; the stepper's own quadrature, spectrum_divergence, is 1.1e-2 off.
    assert abs(exponents.sum() / trace - 1) < 5e-5, (exponents.sum(), trace)


def refusals(args):
    cases = [  # (the groups' lines, the line named, what the message names, why)
        # (A window within the 100 s run: the default, 100 to 1000 s, is refused first for the strobe's spectrum.)
        ("&law\n  model = 'lugre'\n/\n&analysis\n  poincare = .true.\n  section = 'stick_to_slip'\n  window_start = 10.0\n/\n",
         10,
         "&analysis: section = ", "has none: use section = 'w_zero_up'"),
    ]
    check_refusals(args, cases, "refusals")


def main():
    return case_main(__doc__, {"linear": linear, "sum-rule": sum_rule, "stiff-lugre": stiff_lugre,
                               "coulomb-cycle": coulomb_cycle,
                               "coulomb-forced": coulomb_forced, "rosenstein": rosenstein,
                               "gms-steady": gms_steady, "gms-onset": gms_onset, "refusals": refusals})


if __name__ == "__main__":
    sys.exit(main())
