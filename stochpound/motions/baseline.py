"""Baseline correction of accelerograms: zero final velocity and displacement.

The accelerogram is taken as piecewise linear between samples (the solvers'
first-order hold), so velocity and displacement follow exactly:

    v_{k+1} = v_k + dt (a_k + a_{k+1}) / 2
    d_{k+1} = d_k + dt v_k + dt² (2 a_k + a_{k+1}) / 6      (v_0 = d_0 = 0).

The correction subtracts c(t) = α φ1(t) + β φ2(t) with φ1 = s(1 − s),
φ2 = s(1 − s)(2s − 1), s = t/T, chosen so that v(T) = d(T) = 0. Both φ vanish
at t = 0 and t = T, so the first and last samples are unchanged (an
enveloped motion still starts and ends at rest).
"""

from __future__ import annotations

import numpy as np


def final_velocity_displacement(acceleration: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """v(T) and d(T) of piecewise-linear accelerations along the last axis (m/s, m)."""
    a = np.asarray(acceleration, dtype=float)
    w_v, w_d = _weights(a.shape[-1], dt)
    return np.sum(a * w_v, axis=-1), np.sum(a * w_d, axis=-1)


def _weights(n: int, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Sample weights of v(T) = ∫ a dt and d(T) = ∫ (T − t) a dt for a piecewise-linear a.

    With a = Σ a_k h_k(t) (hat functions), the weights are the integrals of h_k
    and of (T − t) h_k: dt and (T − t_k) dt inside; at the ends dt/2, and
    T dt/2 − dt²/6 (first) and dt²/6 (last).
    """
    if n < 2:
        return np.zeros(n), np.zeros(n)
    T = (n - 1) * dt
    w_v = np.full(n, dt)
    w_v[0] = w_v[-1] = 0.5 * dt
    w_d = (T - np.arange(n) * dt) * dt
    w_d[0] = T * dt / 2.0 - dt**2 / 6.0
    w_d[-1] = dt**2 / 6.0
    return w_v, w_d


def baseline_correct(acceleration: np.ndarray, dt: float) -> np.ndarray:
    """Accelerations (along the last axis) corrected to end with zero velocity and displacement.

    Parameters
    ----------
    acceleration : np.ndarray
        Samples, m/s², time along the last axis (any leading shape).
    dt : float
        Step, s.

    Returns
    -------
    np.ndarray
        Corrected copy; see the module docstring for the correction.
    """
    a = np.asarray(acceleration, dtype=float)
    n = a.shape[-1]
    if n < 3:
        return a.copy()
    s = np.linspace(0.0, 1.0, n)
    phi1, phi2 = s * (1.0 - s), s * (1.0 - s) * (2.0 * s - 1.0)
    w_v, w_d = _weights(n, dt)
    system = np.array([[np.sum(phi1 * w_v), np.sum(phi2 * w_v)], [np.sum(phi1 * w_d), np.sum(phi2 * w_d)]])
    inverse = np.linalg.inv(system)
    # element-wise sums (not BLAS) so that each row's result does not depend on the batch
    v_end = np.sum(a * w_v, axis=-1)[..., None]
    d_end = np.sum(a * w_d, axis=-1)[..., None]
    alpha = inverse[0, 0] * v_end + inverse[0, 1] * d_end
    beta = inverse[1, 0] * v_end + inverse[1, 1] * d_end
    return a - alpha * phi1 - beta * phi2
