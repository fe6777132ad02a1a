#!/usr/bin/env python3
"""The periodic orbit of a piecewise-linear stick-slip brake against its
closed-form solution (CTest: orbit-piecewise-linear).

With kappa = 1 the normal force N' = (1 - kappa) y + g' = g' is constant, and
with delta' = 0 the kinetic friction is Coulomb's, -mu g' s in slip direction
s.  Every phase of the switched model is then a linear ODE with constant
coefficients, solved here exactly, independently of the program's stepper,
event locator, tangent equations and saltation matrices:

  slip:  z = (x, x', y, y'),  z' = A z + b,  A = [[0, 1, 0, 0], [-2, 0, 1, 0],
         [0, 0, 0, 1], [1/xi, 0, -1/xi, 0]],  b = (0, -mu g' s, 0, 0).
         A is invertible (det = 1/xi), its equilibrium z_p = -A^-1 b is
         x = y = -mu g' s, and z(t) = z_p + exp(A t) (z0 - z_p), exp(A t)
         from A's eigenvectors (two undamped modes, eigenvalues +-i w1,2).
         The slip ends at the first root of s (x' - v_dr) (falling).
  stick: x' = v_dr, so x = x0 + v_dr u, and xi y'' + y = x has the exact
         solution y = x + A cos(w u) + B sin(w u), w = 1/sqrt(xi),
         A = y0 - x0, B = (y0' - v_dr)/w (x is its own particular solution
         because x'' = 0).  The stick ends at the first root of
         mu_s g' -+ (2x - y) (Eq. 5), and the slip starts in the direction
         s = -sign(2x - y).
  end of a slip: stick if |2x - y| <= mu_s g', else a slip reversal.

Roots: a scan in steps of 1e-3 tau for the first sign change, then
bisection down to adjacent floating-point times.  The section map P(y, y') (slip onset to the next slip onset at
the same static limit, x = (y + sigma mu_s g')/2 on it) is thereby exact to
rounding (about 1e-15 m).  The checks on the program's /brake/orbit:

  - its point is a fixed point of the exact map: |P(s) - s| < 1e-10 m (the
    program's Newton tolerance 1e-12 plus its integration at rtol 1e-12 over
    one period);
  - its period is the exact return time within 1e-10 tau (events to 1e-12);
  - its two multipliers are the eigenvalues of the exact map's Jacobian from
    central differences with eps = 1e-7 (truncation eps^2 P''' ~ 1e-10, the
    map's rounding 1e-15/eps = 1e-8): within 1e-6;
  - the stick's multiplier is exactly 0 and the trivial one exactly 1.

    orbit_piecewise_linear.py --binary FRICTION --inputs DIR --workdir DIR
"""

import argparse
import os
import subprocess
import sys

import h5py
import numpy as np

XI, G, MU, MU_S, V_DR = 0.412, 0.01778, 0.5, 0.59, -0.002788

OVERRIDE = (f"&brake kappa = 1.0, delta_prime = 0.0, mu = {MU}, mu_s = {MU_S}, t_end = 1500.0,"
            " event_tolerance = 1.0e-12 /\n"
            "&integrator rtol = 1.0e-12, atol = 1.0e-14 /\n"
            "&analysis spectrum = .false., poincare = .false., lyapunov = .false., rosenstein = .false.,"
            " lyapunov_spectrum = .false., orbit_tolerance = 1.0e-12 /\n")

A = np.array([[0.0, 1.0, 0.0, 0.0], [-2.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0], [1 / XI, 0.0, -1 / XI, 0.0]])
EIGENVALUES, VECTORS = np.linalg.eig(A)
INVERSE = np.linalg.inv(VECTORS)
OMEGA = 1 / np.sqrt(XI)


def slip_state(z0, s, t):
    equilibrium = np.array([-MU * G * s, 0.0, -MU * G * s, 0.0])
    return equilibrium + (VECTORS @ (np.exp(EIGENVALUES * t) * (INVERSE @ (z0 - equilibrium)))).real


def stick_state(z0, u):
    a, b = z0[2] - z0[0], (z0[3] - V_DR) / OMEGA
    x = z0[0] + V_DR * u
    return np.array([x, V_DR, x + a * np.cos(OMEGA * u) + b * np.sin(OMEGA * u),
                     V_DR + OMEGA * (b * np.cos(OMEGA * u) - a * np.sin(OMEGA * u))])


def first_root(g, start=1e-9, step=1e-3, limit=1000.0):
    """The first t > start where g changes sign from its value just after start."""
    t0, g0 = start, g(start)
    while t0 < limit:
        t1 = t0 + step
        g1 = g(t1)
        if np.sign(g1) != np.sign(g0) and g1 != 0:
            while True:
                middle = (t0 + t1) / 2
                if middle in (t0, t1):
                    return t1
                if np.sign(g(middle)) == np.sign(g0):
                    t0 = middle
                else:
                    t1 = middle
        t0, g0 = t1, g1
    raise RuntimeError("no root within the limit")


def return_map(section, sigma):
    """From the slip onset (y, y') at the limit sigma to the next slip onset: its (y, y'), the time, sigma."""
    y, w = section
    z = np.array([(y + sigma * MU_S * G) / 2, V_DR, y, w])
    s, t = -sigma, 0.0
    while True:
        # Slip in direction s until s (x' - v_dr) falls through 0.
        tau = first_root(lambda u: s * (slip_state(z, s, u)[1] - V_DR))
        z, t = slip_state(z, s, tau), t + tau
        z[1] = V_DR
        if abs(2 * z[0] - z[2]) > MU_S * G:
            s = -s      # slip reversal
            continue
        # Stick until |2x - y| reaches mu_s g'.
        limit = lambda u: MU_S * G - abs(2 * stick_state(z, u)[0] - stick_state(z, u)[2])
        tau = first_root(limit)
        z, t = stick_state(z, tau), t + tau
        return z[2:4], t, np.sign(2 * z[0] - z[2])


def fail(message):
    print(f"FAILED: {message}")
    sys.exit(1)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--binary", required=True)
    parser.add_argument("--inputs", required=True)
    parser.add_argument("--workdir", required=True)
    args = parser.parse_args()
    os.makedirs(args.workdir, exist_ok=True)
    override = os.path.join(args.workdir, "piecewise_linear.nml")
    with open(override, "w") as handle:
        handle.write(OVERRIDE)
    out = os.path.join(args.workdir, "piecewise_linear.h5")
    subprocess.run([args.binary, "--quiet", "--force", "-o", out, os.path.join(args.inputs, "brake.nml"), override],
                   check=True)
    with h5py.File(out, "r") as f:
        o = f["brake/orbit"]
        if o.attrs["found"] != 1:
            fail(f"no orbit: {o.attrs.get('reason')}")
        point, period = o["point"][()], float(o.attrs["period"])
        mu = o["floquet_multipliers"][()]
        sigma = float(o.attrs["static_limit"])
    section = point[2:4]
    image, t, back = return_map(section, sigma)
    print(f"program: period {period:.12f}, point {section}, multipliers {mu[1:3].tolist()}")
    print(f"exact:   return time {t:.12f}, |P(s) - s| = {np.max(np.abs(image - section)):.2e}, limit {back:+.0f}")
    if back != sigma:
        fail("the exact map returns at the other static limit")
    if np.max(np.abs(image - section)) > 1e-10:
        fail(f"not a fixed point of the exact map: {image} vs {section}")
    if abs(t - period) > 1e-10:
        fail(f"period {period} vs the exact return time {t}")
    eps = 1e-7
    jac = np.empty((2, 2))
    for j in range(2):
        step = np.zeros(2)
        step[j] = eps
        jac[:, j] = (return_map(section + step, sigma)[0] - return_map(section - step, sigma)[0]) / (2 * eps)
    exact = np.linalg.eigvals(jac)
    exact = exact[np.argsort(-np.abs(exact))]
    program = mu[1:3, 0] + 1j * mu[1:3, 1]
    print(f"exact multipliers {exact}; differences: multipliers {np.max(np.abs(exact - program)):.1e},"
          f" period {abs(t - period):.1e}")
    if np.max(np.abs(exact - program)) > 1e-6:
        fail(f"multipliers {program} vs exact {exact}")
    if tuple(mu[0]) != (1.0, 0.0) or tuple(mu[3]) != (0.0, 0.0):
        fail(f"trivial and stick multipliers {mu[0]}, {mu[3]}")
    print("1 passed, 0 failed")


if __name__ == "__main__":
    main()
