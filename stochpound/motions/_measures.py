"""Intensity measures of a ground motion, exact for accelerations linear between samples.

With a_g linear in every step (a_k + s τ, 0 ≤ τ ≤ h), from rest:

* ground velocity v_g is quadratic and displacement d_g cubic in every step,
  v_g(τ) = v_k + a_k τ + s τ²/2, d_g(τ) = d_k + v_k τ + a_k τ²/2 + s τ³/6; PGV
  and PGD are their largest absolute values, located at the zeros of a_g
  and of v_g inside the steps (no baseline correction: the PGD of an
  unprocessed record includes its drift);
* Arias intensity I_a = π/(2g) ∫ a_g² dt = π/(2g) Σ h (a_k² + a_k a_{k+1} + a_{k+1}²)/3
  (the trapezoid rule on a_g² differs by about 1 % on a 0.01 s record);
* significant duration D5–95: the time between the instants the cumulative
  integral ∫ a_g² reaches 5 % and 95 % of its total; the integral is cubic
  in every step, a_k² τ + a_k s τ² + s² τ³/3, and is inverted to round-off;
* PSA at given periods (:func:`~stochpound.motions.response_spectrum`)
  and Sa_avg, the geometric mean of PSA over a set of periods.

A motion scaled by λ has every measure scaled by abs(λ), I_a by λ², D5–95 unchanged.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import xarray as xr

from stochpound.motions._arias import DEFAULT_G, arias_intensity, squared_integrals
from stochpound.motions._spectrum import DEFAULT_DAMPING, as_acceleration, response_spectrum

if TYPE_CHECKING:
    from stochpound.motions.records import Record

#: Fractions of the Arias intensity that bound the significant duration.
SIGNIFICANT_FRACTIONS = (0.05, 0.95)


def peak_ground_motion(acceleration: np.ndarray, dt: float) -> tuple[float, float, float]:
    """PGA (m/s²), PGV (m/s) and PGD (m) of a piecewise-linear acceleration from rest (module docstring)."""
    a = np.asarray(acceleration, dtype=np.float64)
    h = float(dt)
    left, right = a[:-1], a[1:]
    slope = (right - left) / h
    v = np.concatenate(([0.0], np.cumsum(h * (left + right) / 2.0)))
    d = np.concatenate(([0.0], np.cumsum(h * v[:-1] + h * h * (2.0 * left + right) / 6.0)))
    pgv = _interior_peak(v, [v[:-1], left, slope / 2.0], h)
    pgd = _interior_peak(d, [d[:-1], v[:-1], left / 2.0, slope / 6.0], h)
    return float(np.max(np.abs(a))), pgv, pgd


def _interior_peak(values: np.ndarray, coefficients: list[np.ndarray], h: float) -> float:
    """Largest abs of the step polynomials Σ c_i τ^i (samples ``values``), at the samples and at interior stationary points."""
    peak = float(np.max(np.abs(values)))
    derivative = [i * c for i, c in enumerate(coefficients)][1:]  # c1 + 2 c2 τ (+ 3 c3 τ²)
    for tau in _roots_inside(derivative, h):
        step = np.flatnonzero(np.isfinite(tau))
        t = tau[step]
        value = sum(c[step] * t**i for i, c in enumerate(coefficients))
        if value.size:
            peak = max(peak, float(np.max(np.abs(value))))
    return peak


def _roots_inside(coefficients: list[np.ndarray], h: float) -> list[np.ndarray]:
    """Roots in (0, h) of c0 + c1 τ (+ c2 τ²) per step, NaN where none (one array per root)."""
    c0, c1 = coefficients[0], coefficients[1]
    with np.errstate(divide="ignore", invalid="ignore"):
        if len(coefficients) == 2:
            roots = [-c0 / c1]
        else:
            c2 = coefficients[2]
            disc = c1 * c1 - 4.0 * c2 * c0
            sq = np.sqrt(np.where(disc >= 0.0, disc, np.nan))
            q = -0.5 * (c1 + np.copysign(sq, c1))  # the stable pair q/c2, c0/q
            linear = c2 == 0.0
            roots = [np.where(linear, -c0 / c1, q / c2), np.where(linear, np.nan, c0 / q)]
    return [np.where((r > 0.0) & (r < h), r, np.nan) for r in roots]


def significant_duration(acceleration: np.ndarray, dt: float, fractions: tuple[float, float] = SIGNIFICANT_FRACTIONS) -> float:
    """Time (s) between the instants ∫ a_g² dt reaches ``fractions`` of its total (D5–95 by default; 0 for a null motion)."""
    from scipy.optimize import brentq

    a = np.asarray(acceleration, dtype=np.float64)
    h = float(dt)
    left, right = a[:-1], a[1:]
    slope = (right - left) / h
    cumulative = np.concatenate(([0.0], np.cumsum(squared_integrals(a, h))))
    total = cumulative[-1]
    if not total > 0.0:
        return 0.0
    times = []
    for fraction in fractions:
        target = fraction * total
        k = int(np.clip(np.searchsorted(cumulative, target, side="left") - 1, 0, left.size - 1))
        a0, s = left[k], slope[k]
        residual = target - cumulative[k]

        def partial(tau: float, a0: float = a0, s: float = s, residual: float = residual) -> float:
            return a0 * a0 * tau + a0 * s * tau * tau + s * s * tau**3 / 3.0 - residual

        tau = h if partial(h) <= 0.0 else brentq(partial, 0.0, h, xtol=1e-15 * h, rtol=4 * np.finfo(float).eps)
        times.append(k * h + tau)
    return float(times[1] - times[0])


def sa_avg(
    acceleration: np.ndarray | Record | str,
    dt: float | None,
    periods: np.ndarray,
    damping: float = DEFAULT_DAMPING,
    *,
    g: float = DEFAULT_G,
) -> float:
    """Sa_avg: the geometric mean of PSA (m/s²) over ``periods`` (s), e.g. log-spaced over 0.2–3 T1."""
    psa = response_spectrum(acceleration, dt, periods, damping, g=g)["psa"].values
    return float(np.exp(np.mean(np.log(psa))))


def intensity_measures(
    acceleration: np.ndarray | Record | str | Path,
    dt: float | None = None,
    periods: np.ndarray | None = None,
    damping: float = DEFAULT_DAMPING,
    *,
    g: float = DEFAULT_G,
) -> xr.Dataset:
    """Intensity measures of a ground motion (module docstring).

    ``acceleration``, ``dt`` and ``damping`` are as in
    :func:`~stochpound.motions.response_spectrum`; ``periods`` (s,
    optional) adds ``psa``, ``sd`` and ``sa`` over ``period``; ``g`` (m/s²) is
    that of the Arias intensity and of a record stored in g.

    Returns
    -------
    xarray.Dataset
        ``pga`` (m/s²), ``pgv`` (m/s), ``pgd`` (m), ``arias_intensity`` (m/s),
        ``significant_duration`` (s, D5–95); with ``periods``, also ``psa``,
        ``sd`` and ``sa`` over ``period``.
    """
    a, step = as_acceleration(acceleration, dt, g)
    pga, pgv, pgd = peak_ground_motion(a, step)
    dataset = xr.Dataset(
        {
            "pga": ((), pga, {"units": "m/s2", "long_name": "peak ground acceleration"}),
            "pgv": ((), pgv, {"units": "m/s", "long_name": "peak ground velocity"}),
            "pgd": ((), pgd, {"units": "m", "long_name": "peak ground displacement"}),
            "arias_intensity": ((), arias_intensity(a, step, g), {"units": "m/s", "long_name": "Arias intensity"}),
            "significant_duration": ((), significant_duration(a, step), {"units": "s", "long_name": "D5-95"}),
        },
        attrs={"g": float(g)},
    )
    if periods is not None:
        spectrum = response_spectrum(a, step, periods, damping)
        dataset = dataset.assign(spectrum[["psa", "sd", "sa"]])
        dataset.attrs["damping"] = spectrum.attrs["damping"]
    return dataset
