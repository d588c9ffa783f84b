"""The response spectrum of a piecewise-linear ground acceleration, integrated exactly.

A linear oscillator of circular frequency ω = 2π/T and damping ratio ζ < 1,

    ü + 2ζω u̇ + ω² u = −a_g(t),    u(0) = u̇(0) = 0,

driven by accelerations a_g that are linear between the samples (the
first-order hold every solver of the toolkit uses), has inside each step
t_k + τ, 0 ≤ τ ≤ h, the closed-form response (Nigam & Jennings 1969)

    u(τ) = p0 + p1 τ + e^{−στ} (c1 cos ω_d τ + c2 sin ω_d τ),

σ = ζω, ω_d = ω √(1 − ζ²), with the particular part p1 = −s/ω²,
p0 = −a_k/ω² + 2ζ s/ω³ (s the step's slope of a_g) and c1, c2 from u, u̇ at
the start of the step. Its end values are the exact recurrence from step to
step. The total acceleration ü + a_g = −(2σ u̇ + ω² u) has the same form.

The maxima are **located on this solution**, not read at the samples (which
underestimates a short-period spectrum by several per cent: at T = 0.1 s and
h = 0.01 s, ω h = 0.63). A step can hold a larger value than its ends only
if the derivative f′ of the quantity f vanishes inside it; with B₁, B₂ bounds
of abs(f′), abs(f″) on the step (the exponential is at most 1), that needs

* (abs(f_k) + abs(f_{k+1}) + h B₁)/2 above the largest sampled value, and
* a sign change of f′ between the ends, or abs(f′_k) + abs(f′_{k+1}) ≤ h B₂.

Only such steps (a handful around each peak) are searched: f″ is
e^{−στ}(E cos ω_d τ + F sin ω_d τ), whose zeros are known in closed form;
between them f′ is monotone and its one zero, if any, is found by a
bracketed Newton iteration to round-off. Everything runs in one compiled
kernel (numba, cached on disk), periods in the outer loop.

The recurrence loses accuracy for very long periods, where p0 (of order
a_g/ω² and s/ω³) grows large against u: about 1e-13 relative at T = 5 s and
h = 0.01 s, still below 1e-10 at T = 50 s.

:func:`pseudo_spectra` gives the pseudo-spectral accelerations of many
motions of one step (a pool of simulated motions) in one compiled call per
batch, the same values bit for bit, without the total acceleration's peaks
and without the cache below.

A process computes a motion's peaks at a period once: they are kept by the
motion's content (its samples in m/s² and their step) and the damping, per
period, for :data:`CACHED_MOTIONS` motions (the least recently used dropped
first). The peaks at a period do not depend on the other periods of the
call, so the values are those of one call over all the periods, bit for bit.
"""

from __future__ import annotations

import hashlib
import math
import threading
from collections import OrderedDict
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import xarray as xr

from stochpound._jit import cached_njit
from stochpound.motions._arias import DEFAULT_G

if TYPE_CHECKING:  # the records package imports the analysis kernels, which import the model
    from stochpound.motions.records import Record

#: Default damping ratio of the spectrum.
DEFAULT_DAMPING = 0.05
_NEWTON_ITERATIONS = 60
#: Motions whose peaks a process keeps (module docstring).
CACHED_MOTIONS = 512
#: Motions of one compiled call of :func:`pseudo_spectra`.
POOL_BATCH = 16
_PEAKS: OrderedDict[tuple[bytes, float, float], dict[float, tuple[float, float]]] = OrderedDict()
_PEAKS_LOCK = threading.Lock()


def as_acceleration(
    acceleration: np.ndarray | Record | str | Path, dt: float | None, g: float = DEFAULT_G
) -> tuple[np.ndarray, float]:
    """Samples in m/s² and their step (s) of an array, a :class:`Record` or a bundled record name.

    Raises
    ------
    ValueError
        ``dt`` missing or not > 0 for an array, or given and different from a record's.
    """
    from stochpound.motions.records import Record, load_record

    if isinstance(acceleration, (str, Path)):
        acceleration = load_record(acceleration)
    if isinstance(acceleration, Record):
        if dt is not None and not math.isclose(float(dt), acceleration.dt, rel_tol=1e-9):
            raise ValueError(f"dt: the record {acceleration.name} has dt = {acceleration.dt:g} s, got {dt}")
        return acceleration.acceleration(g=g), acceleration.dt
    a = np.ascontiguousarray(acceleration, dtype=np.float64)
    if a.ndim != 1 or a.size < 2:
        raise ValueError(f"acceleration: must be a 1-D array of at least 2 samples, got shape {a.shape}")
    if dt is None or not (math.isfinite(dt) and dt > 0.0):
        raise ValueError(f"dt: must be > 0 s, got {dt!r}")
    return a, float(dt)


def check_periods(periods: np.ndarray | float, damping: float) -> tuple[np.ndarray, float]:
    """Periods as a 1-D float array and the damping ratio, validated.

    Raises
    ------
    ValueError
        A period not finite and > 0, or a damping ratio outside [0, 1).
    """
    values = np.atleast_1d(np.asarray(periods, dtype=np.float64))
    if values.ndim != 1 or values.size == 0 or not np.all(np.isfinite(values)) or np.any(values <= 0.0):
        raise ValueError(f"periods: must be finite and > 0 s, got {np.asarray(periods).tolist()}")
    zeta = float(damping)
    if not (0.0 <= zeta < 1.0):
        raise ValueError(f"damping: must be in [0, 1), got {damping!r}")
    return values, zeta


def response_spectrum(
    acceleration: np.ndarray | Record | str | Path,
    dt: float | None = None,
    periods: np.ndarray | float | None = None,
    damping: float = DEFAULT_DAMPING,
    *,
    g: float = DEFAULT_G,
) -> xr.Dataset:
    """Exact response spectrum of a piecewise-linear ground acceleration (module docstring).

    Parameters
    ----------
    acceleration : array_like, Record or str
        Samples in m/s² at ``dt`` from t = 0, linear between them; or a
        :class:`~stochpound.motions.records.Record` or a bundled record's name.
    dt : float, optional
        Step, s (required for an array).
    periods : array_like
        Oscillator periods, s (> 0).
    damping : float
        Damping ratio ζ in [0, 1).
    g : float
        m/s², to convert a record stored in g.

    Returns
    -------
    xarray.Dataset
        Over ``period`` (s): ``sd`` = max abs(u) (m), ``psv`` = ω·sd (m/s),
        ``psa`` = ω²·sd (m/s²) and ``sa`` = max abs(ü + a_g) (m/s²); attribute ``damping``.
    """
    a, step = as_acceleration(acceleration, dt, g)
    if periods is None:
        raise ValueError("periods: required (s)")
    values, zeta = check_periods(periods, damping)
    omega = 2.0 * np.pi / values
    sd, sa = _peaks(a, step, values, zeta)
    return xr.Dataset(
        {
            "sd": ("period", sd, {"units": "m", "long_name": "spectral displacement"}),
            "psv": ("period", omega * sd, {"units": "m/s", "long_name": "pseudo-spectral velocity"}),
            "psa": ("period", omega**2 * sd, {"units": "m/s2", "long_name": "pseudo-spectral acceleration"}),
            "sa": ("period", sa, {"units": "m/s2", "long_name": "spectral (total) acceleration"}),
        },
        coords={"period": ("period", values, {"units": "s"})},
        attrs={"damping": zeta},
    )


def pseudo_spectra(accelerations: np.ndarray, dt: float, periods: np.ndarray | float, damping: float = DEFAULT_DAMPING) -> np.ndarray:
    """Pseudo-spectral accelerations of many motions of one step: :func:`response_spectrum`'s ``psa``, bit for bit, at the cost of the
    displacement's peaks alone.

    Every motion's peaks come from one compiled call per batch of :data:`POOL_BATCH` motions, on numba's thread count
    (``NUMBA_NUM_THREADS``, as :func:`~stochpound.motions.site_motions`); a motion's values depend on its own samples alone,
    so not on the threads. No per-motion cache (the motions of a pool are met once).

    Parameters
    ----------
    accelerations : array_like, shape (n, n_time)
        Samples in m/s² at ``dt`` from t = 0, one motion a row, linear between them.
    dt : float
        Step, s.
    periods : array_like
        Oscillator periods, s (> 0).
    damping : float
        Damping ratio ζ in [0, 1).

    Returns
    -------
    numpy.ndarray, shape (n, len(periods))
        ω² max abs(u), m/s².
    """
    from stochpound.motions._site_model import on_motion_threads

    values, zeta = check_periods(periods, damping)
    a = np.ascontiguousarray(accelerations, dtype=np.float64)
    if a.ndim != 2 or a.shape[1] < 2:
        raise ValueError(f"accelerations: must be a 2-D array of motions of at least 2 samples, got shape {a.shape}")
    if not (math.isfinite(dt) and dt > 0.0):
        raise ValueError(f"dt: must be > 0 s, got {dt!r}")
    omega = 2.0 * np.pi / values
    sd = np.empty((a.shape[0], values.size))

    def batch(start: int) -> None:
        _pool_kernel(a[start : start + POOL_BATCH], float(dt), omega, zeta, sd[start : start + POOL_BATCH])

    on_motion_threads(batch, range(0, a.shape[0], POOL_BATCH))
    return omega**2 * sd


def _peaks(a: np.ndarray, step: float, periods: np.ndarray, zeta: float) -> tuple[np.ndarray, np.ndarray]:
    """max abs(u) (m) and max abs(ü + a_g) (m/s²) at ``periods`` (s), each computed once per process for a motion (module docstring)."""
    key = (hashlib.sha256(a.tobytes()).digest(), step, zeta)
    with _PEAKS_LOCK:
        known = _PEAKS.pop(key, {})
        _PEAKS[key] = known  # the most recently used last
        if len(_PEAKS) > CACHED_MOTIONS:
            _PEAKS.popitem(last=False)
        missing = np.array(sorted(set(periods.tolist()) - known.keys()))
    if missing.size:
        sd, sa = np.empty_like(missing), np.empty_like(missing)
        _spectrum_kernel(a, step, 2.0 * np.pi / missing, zeta, sd, sa)
        with _PEAKS_LOCK:
            known.update(zip(missing.tolist(), zip(sd.tolist(), sa.tolist())))
    peaks = np.array([known[period] for period in periods.tolist()]).reshape(-1, 2)
    return peaks[:, 0].copy(), peaks[:, 1].copy()


@cached_njit()
def _value(l0: float, l1: float, E: float, F: float, sigma: float, wd: float, tau: float) -> float:
    """f(τ) = l0 + l1 τ + e^{−στ}(E cos ω_d τ + F sin ω_d τ)."""
    return l0 + l1 * tau + math.exp(-sigma * tau) * (E * math.cos(wd * tau) + F * math.sin(wd * tau))


@cached_njit()
def _step_peak(l0: float, l1: float, E: float, F: float, sigma: float, wd: float, h: float) -> float:
    """Largest abs(f) at the zeros of f′ inside (0, h) (0 if there are none)."""
    E1, F1 = -sigma * E + wd * F, -sigma * F - wd * E  # f' = l1 + e(E1 cos + F1 sin)
    E2, F2 = -sigma * E1 + wd * F1, -sigma * F1 - wd * E1  # f'' = e(E2 cos + F2 sin)
    peak = 0.0
    # zeros of f'': ω_d τ = φ + π/2 + nπ with φ = atan2(F2, E2)
    first = 0.0
    if E2 != 0.0 or F2 != 0.0:
        theta = math.atan2(F2, E2) + 0.5 * math.pi
        theta = theta - math.pi * math.floor(theta / math.pi)
        first = theta / wd
    else:
        first = 2.0 * h
    left = 0.0
    d_left = l1 + E1
    next_zero = first
    while left < h:
        right = h if next_zero >= h else next_zero
        d_right = l1 + math.exp(-sigma * right) * (E1 * math.cos(wd * right) + F1 * math.sin(wd * right))
        if (d_left < 0.0 < d_right) or (d_right < 0.0 < d_left):
            lo, hi, d_lo = left, right, d_left
            tau = 0.5 * (lo + hi)
            for _ in range(_NEWTON_ITERATIONS):
                ex = math.exp(-sigma * tau)
                c, s = math.cos(wd * tau), math.sin(wd * tau)
                d1 = l1 + ex * (E1 * c + F1 * s)
                if d1 == 0.0:
                    break
                if (d1 < 0.0) == (d_lo < 0.0):
                    lo, d_lo = tau, d1
                else:
                    hi = tau
                d2 = ex * (E2 * c + F2 * s)
                candidate = tau - d1 / d2 if d2 != 0.0 else lo  # lo: not inside, so bisect
                if not (lo < candidate < hi):
                    candidate = 0.5 * (lo + hi)
                converged = abs(candidate - tau) <= 1e-15 * h or hi - lo <= 4e-16 * h
                tau = candidate
                if converged:
                    break
            value = abs(_value(l0, l1, E, F, sigma, wd, tau))
            if value > peak:
                peak = value
        left, d_left = right, d_right
        next_zero = next_zero + math.pi / wd
    return peak


@cached_njit()
def _needs_search(f0: float, f1: float, d0: float, d1: float, b2: float, h: float, peak: float) -> bool:
    """Whether a step with end values f0, f1, slopes d0, d1 and abs(f″) ≤ b2 can hold a value above ``peak``.

    At a zero τ* of f′, abs(f′) ≤ b2·abs(τ − τ*), so f(τ*) is within b2 τ*²/2 of
    f0 and within b2 (h − τ*)²/2 of f1: abs(f(τ*)) ≤ max(abs(f0), abs(f1)) + b2 h²/8.
    f′ can only vanish inside if it changes sign or abs(d0) + abs(d1) ≤ b2 h.
    """
    if max(abs(f0), abs(f1)) + 0.125 * b2 * h * h <= peak:
        return False
    return d0 * d1 <= 0.0 or abs(d0) + abs(d1) <= h * b2


@cached_njit()
def _spectrum_kernel(a, h, omega, zeta, sd_out, sa_out):  # pragma: no cover - compiled
    """max abs(u) and max abs(ü + a_g) for every ω (:func:`_period_peaks`, one period at a time)."""
    for j in range(omega.size):
        sd_out[j], sa_out[j] = _period_peaks(a, h, omega[j], zeta, True)


@cached_njit(nogil=True)
def _pool_kernel(accelerations, h, omega, zeta, sd_out):  # pragma: no cover - compiled
    """max abs(u) for every motion (rows of ``accelerations``) and every ω (:func:`_period_peaks` without the total acceleration)."""
    for m in range(accelerations.shape[0]):
        a = accelerations[m]
        for j in range(omega.size):
            sd_out[m, j] = _period_peaks(a, h, omega[j], zeta, False)[0]


@cached_njit(inline="always")  # into each kernel, where with_sa is a constant
def _period_peaks(a, h, w, zeta, with_sa):  # pragma: no cover - compiled
    """max abs(u) and (``with_sa``; else 0) max abs(ü + a_g) at circular frequency ``w`` (module docstring).

    One pass: a step is searched when :func:`_needs_search` says
    it can exceed the largest value so far (a lower bound of the final
    peak, so no step that could hold the peak is skipped). With r the
    amplitude √(c1² + c2²) of u's homogeneous part, abs(ü) ≤ ω² r; the total
    acceleration's homogeneous part is −(2σλ + ω²) times u's (λ = −σ + iω_d,
    the derivative's factor), of amplitude κ r with κ = abs(2σλ + ω²), and its
    second derivative is bounded by ω² κ r. The displacement's peak does not
    depend on ``with_sa``.
    """
    n = a.size
    root = math.sqrt(1.0 - zeta * zeta)
    w2 = w * w
    sigma, wd = zeta * w, w * root
    ex, cw, sw = math.exp(-sigma * h), math.cos(wd * h), math.sin(wd * h)
    kappa = math.hypot(w2 - 2.0 * sigma * sigma, 2.0 * sigma * wd)  # abs(2σλ + ω²)
    sd_peak, sa_peak = 0.0, 0.0
    u, v = 0.0, 0.0
    fa = 0.0
    for k in range(n - 1):
        slope = (a[k + 1] - a[k]) / h
        p1 = -slope / w2
        p0 = (-a[k] - 2.0 * sigma * p1) / w2
        c1 = u - p0
        c2 = (v - p1 + sigma * c1) / wd
        E1, F1 = -sigma * c1 + wd * c2, -sigma * c2 - wd * c1
        u_next = p0 + p1 * h + ex * (c1 * cw + c2 * sw)
        v_next = p1 + ex * (E1 * cw + F1 * sw)
        sd_peak = max(sd_peak, abs(u_next))
        r = math.sqrt(c1 * c1 + c2 * c2)
        # u: f = u, f' = u̇, abs(f'') = abs(ü) <= ω² r (ü has no particular part)
        if _needs_search(u, u_next, v, v_next, w2 * r, h, sd_peak):
            sd_peak = max(sd_peak, _step_peak(p0, p1, c1, c2, sigma, wd, h))
        if with_sa:
            fa_next = -(2.0 * sigma * v_next + w2 * u_next)
            sa_peak = max(sa_peak, abs(fa_next))
            # total acceleration: f = −(2σ u̇ + ω² u) = a_k + s τ + e(Ea cos + Fa sin)
            ra = kappa * r
            if max(abs(fa), abs(fa_next)) + 0.125 * w2 * ra * h * h > sa_peak:
                Ea, Fa = -(2.0 * sigma * E1 + w2 * c1), -(2.0 * sigma * F1 + w2 * c2)
                Ea1, Fa1 = -sigma * Ea + wd * Fa, -sigma * Fa - wd * Ea
                d0 = slope + Ea1
                d1 = slope + ex * (Ea1 * cw + Fa1 * sw)
                if _needs_search(fa, fa_next, d0, d1, w2 * ra, h, sa_peak):
                    sa_peak = max(sa_peak, _step_peak(a[k], slope, Ea, Fa, sigma, wd, h))
            fa = fa_next
        u, v = u_next, v_next
    return sd_peak, sa_peak
