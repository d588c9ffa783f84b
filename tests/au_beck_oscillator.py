"""Au & Beck's (2001) linear oscillator under white noise, written independently of the package (shared by the rare-event tests).

The oscillator's displacement at the samples is a linear map X = A u of the
white noise's standard normals (the exact discretisation of
ẍ + 2ζωẋ + ω²x = −a_g for an acceleration linear between the samples, by one
matrix exponential); P(max_k |X_k| > b) is estimated by importance sampling
with elementary events (ISEE), unbiased at any level.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.linalg import expm
from scipy.signal import fftconvolve
from scipy.special import ndtr, ndtri

OMEGA, ZETA, S, DT, DURATION = 7.85, 0.02, 1.0, 0.02, 30.0  # Au & Beck (2001): rad/s, 1, m²/s³, s, s
N_TIME = int(round(DURATION / DT)) + 1


def impulse_responses() -> tuple[np.ndarray, np.ndarray]:
    """Displacement at sample m after a unit normal at sample j >= 1 (h[m − j]) and at sample 0 (first[m]), m."""
    F = np.array([[0.0, 1.0], [-OMEGA**2, -2.0 * ZETA * OMEGA]])
    M = np.zeros((4, 4))
    M[:2, :2], M[:2, 2], M[2, 3] = F, (0.0, -1.0), 1.0  # ẋ = F x − a_g e2, a_g = a_k + s·t on the interval, ṡ = 0
    E = expm(M * DT)
    phi, ramp = E[:2, :2], E[:2, 3] / DT
    hold = E[:2, 2] - ramp  # x_{k+1} = Φ x_k + hold a_k + ramp a_{k+1}
    scale = math.sqrt(2.0 * math.pi * S / DT)  # a_k = √(2π S / dt) u_k
    h, first, power = np.empty(N_TIME), np.zeros(N_TIME), np.eye(2)
    h[0] = ramp[0]
    for m in range(1, N_TIME):
        previous, power = power, phi @ power
        h[m] = (power @ ramp + previous @ hold)[0]
        first[m] = (previous @ hold)[0]
    return scale * h, scale * first


H, FIRST = impulse_responses()


def displacements(u: np.ndarray) -> np.ndarray:
    """X = A u for rows of u, m."""
    x = fftconvolve(u, H[None, :], axes=1)[:, :N_TIME]
    return x + (FIRST - H)[None, :] * u[:, :1]


def peak(u: np.ndarray) -> np.ndarray:
    return np.abs(displacements(np.atleast_2d(u))).max(axis=1)


def isee(b: float, samples: int, seed: int) -> tuple[float, float]:
    """P(max |X_k| > b) and its coefficient of variation by ISEE: sample one elementary event {|X_k| > b} by its probability, then u in it."""
    rows = displacements(np.eye(N_TIME)).T[1:]  # A's rows a_k (X_0 = 0 is never exceeded)
    norms = np.linalg.norm(rows, axis=1)
    elementary = 2.0 * ndtr(-b / norms)
    total = elementary.sum()
    rng = np.random.default_rng(seed)
    k = rng.choice(len(rows), samples, p=elementary / total)
    e = rows[k] / norms[k, None]
    tail = -ndtri(ndtr(-b / norms[k]) * rng.random(samples))  # |e·u| beyond b / |a_k|
    side = np.where(rng.random(samples) < 0.5, -1.0, 1.0)
    z = rng.standard_normal((samples, N_TIME))
    u = z - np.sum(e * z, axis=1)[:, None] * e + (side * tail)[:, None] * e
    estimates = total / np.count_nonzero(np.abs(displacements(u)[:, 1:]) > b, axis=1)
    return float(estimates.mean()), float(estimates.std() / math.sqrt(samples) / estimates.mean())
