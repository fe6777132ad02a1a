"""What the spectrum tests of the brake with a law (brake_law_oracles.py) and of
the machine (machine_chaos.py) share: the exact finite-time exponents of a
linear flow, Φ(t) = e^{Jt}, renormalised as the program renormalises.

    from tangent_oracles import finite_time_spectrum, finite_time_benettin, generic_frame
"""
import numpy as np


def finite_time_spectrum(step, frame, intervals):
    """Σ ln |R_ii| of Q R = step Q over `intervals` QR steps from `frame`, largest first."""
    logs = np.zeros(frame.shape[1])
    for _ in range(intervals):
        q, r = np.linalg.qr(step @ frame)
        frame, logs = q * np.sign(np.diag(r)), logs + np.log(np.abs(np.diag(r)))
    return np.sort(logs)[::-1]


def finite_time_benettin(step, direction, intervals):
    """Σ ln |δ_k+1|/|δ_k| with δ renormalised to unit length every interval."""
    delta, total = direction / np.linalg.norm(direction), 0.0
    for _ in range(intervals):
        delta = step @ delta
        total += np.log(np.linalg.norm(delta))
        delta /= np.linalg.norm(delta)
    return total


def generic_frame(n):
    """The tangent vectors' starting frame, the QR of I + the n x n Hilbert matrix (documented in
    analysis/lyapunov_spectrum.f90), with R's diagonal positive."""
    q, r = np.linalg.qr(np.eye(n) + 1.0 / (np.add.outer(np.arange(n), np.arange(n)) + 1.0))
    return q * np.sign(np.diag(r))
