"""Ensembles of synthetic ground accelerations: :func:`kanai_tajimi`, :func:`clough_penzien`."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import xarray as xr

from stochpound.motions.baseline import baseline_correct
from stochpound.motions.envelopes import make_envelope
from stochpound.motions.generators import METHODS, stationary_samples
from stochpound.motions.intensity import PEAK_FACTORS, poisson_peak_factor, s0_from_pga, s0_from_rms, simulated_peak_factor
from stochpound.motions.psd import FilteredWhiteNoise, clough_penzien_model, kanai_tajimi_model
from stochpound.motions._seeding import check_seed, realization_rngs

PSD_CONVENTION = "two-sided in omega (rad/s) on (-inf, inf); variance = integral of S domega"


def kanai_tajimi(
    n_realizations: int,
    duration: float,
    dt: float,
    omega_g: float,
    zeta_g: float,
    S0: float | None = None,
    pga: float | None = None,
    envelope: Any = None,
    seed: int = 0,
    method: str = "spectral",
    *,
    start: int = 0,
    rms: float | None = None,
    peak_factor: float | str | None = None,
    baseline: bool = False,
    band_limit: bool = False,
) -> xr.DataArray:
    """Realizations of Kanai–Tajimi ground acceleration.

    Parameters
    ----------
    n_realizations : int
        Number of realizations (>= 0).
    duration : float
        Length, s; samples at t = 0, dt, ..., round(duration/dt)·dt.
    dt : float
        Step, s.
    omega_g : float
        Ground frequency ω_g, rad/s (> 0).
    zeta_g : float
        Ground damping ratio ζ_g (> 0).
    S0 : float, optional
        Two-sided PSD of the bedrock white noise, m²/s³. Exactly one of
        ``S0``, ``pga`` and ``rms`` must be given.
    pga : float, optional
        Target expected peak ground acceleration, m/s²: S0 is set so that
        ``peak_factor`` × σ = pga (see :mod:`stochpound.motions.intensity`).
    envelope : None, str, mapping, Envelope or callable
        Intensity envelope (see :mod:`stochpound.motions.envelopes`); None = stationary.
    seed : int
        Seed (>= 0). Realization i is determined by (seed, i) alone.
    method : {"spectral", "filter"}
        Spectral representation (FFT) or exact time-domain filtering of white noise.
    start : int
        Index of the first realization: the result holds realizations
        start .. start + n_realizations − 1, identical to the same indices of
        any other call with the same seed.
    rms : float, optional
        Target stationary standard deviation σ, m/s².
    peak_factor : float or {"poisson", "simulated"}, optional
        Peak factor p = E[max abs(a)]/σ used with ``pga``: a number, or how to
        estimate it: ``"poisson"`` (default; level crossings of the sampled,
        enveloped process) or ``"simulated"`` (pilot ensemble); see
        :mod:`stochpound.motions.intensity`.
    baseline : bool
        Correct each realization to end with zero velocity and displacement
        (:mod:`stochpound.motions.baseline`).
    band_limit : bool
        Spectral method only: synthesise from S on abs(ω) ≤ π/dt instead of the
        aliased PSD of the sampled process (see :mod:`stochpound.motions.generators`).
        The variance is then ∫_{abs(ω)<π/dt} S dω, not ∫ S dω.

    Returns
    -------
    xarray.DataArray
        Ground acceleration, m/s², dims ``(realization, time)``; the
        parameters (ω_g, ζ_g, S0, σ, envelope, seed, method, ...) in ``attrs``
        (``envelope`` as JSON text: ``{"type": name, ...}``, or ``null`` if stationary).
    """
    model = kanai_tajimi_model(omega_g, zeta_g)
    return synthetic_ground_motion(
        model, n_realizations, duration, dt, S0=S0, pga=pga, rms=rms, peak_factor=peak_factor,
        envelope=envelope, seed=seed, method=method, start=start, baseline=baseline, band_limit=band_limit,
    )


def clough_penzien(
    n_realizations: int,
    duration: float,
    dt: float,
    omega_g: float,
    zeta_g: float,
    omega_f: float,
    zeta_f: float,
    S0: float | None = None,
    pga: float | None = None,
    envelope: Any = None,
    seed: int = 0,
    method: str = "spectral",
    *,
    start: int = 0,
    rms: float | None = None,
    peak_factor: float | str | None = None,
    baseline: bool = False,
    band_limit: bool = False,
) -> xr.DataArray:
    """Realizations of Clough–Penzien ground acceleration.

    As :func:`kanai_tajimi`, with the high-pass filter's frequency
    ``omega_f`` (rad/s, > 0) and damping ratio ``zeta_f`` (> 0).
    """
    model = clough_penzien_model(omega_g, zeta_g, omega_f, zeta_f)
    return synthetic_ground_motion(
        model, n_realizations, duration, dt, S0=S0, pga=pga, rms=rms, peak_factor=peak_factor,
        envelope=envelope, seed=seed, method=method, start=start, baseline=baseline, band_limit=band_limit,
    )


def synthetic_ground_motion(
    model: FilteredWhiteNoise,
    n_realizations: int,
    duration: float,
    dt: float,
    *,
    S0: float | None = None,
    pga: float | None = None,
    rms: float | None = None,
    peak_factor: float | str | None = None,
    envelope: Any = None,
    seed: int = 0,
    method: str = "spectral",
    start: int = 0,
    baseline: bool = False,
    band_limit: bool = False,
) -> xr.DataArray:
    """Realizations of any :class:`FilteredWhiteNoise` model (the engine behind the named models).

    Parameters are those of :func:`kanai_tajimi`; ``model``'s own S0 is
    replaced by the one given or derived from ``pga`` / ``rms``.
    """
    count = _index(n_realizations, "n_realizations")
    first = _index(start, "start")
    seed = check_seed(seed)
    duration, dt = _positive(duration, "duration"), _positive(dt, "dt")
    if dt > duration:
        raise ValueError(f"dt: must be <= duration ({duration:g} s), got {dt:g}")
    if method not in METHODS:
        raise ValueError(f"method: must be one of {', '.join(METHODS)}; got {method!r}")
    if band_limit and method != "spectral":
        raise ValueError("band_limit: only available with method='spectral' (the filter method is exact, hence aliased)")
    n_time = int(round(duration / dt)) + 1
    time = np.arange(n_time) * dt
    shape = make_envelope(envelope, duration)
    given = {key: value for key, value in (("S0", S0), ("pga", pga), ("rms", rms)) if value is not None}
    if len(given) != 1:
        raise ValueError(f"give exactly one of S0, pga, rms (got {', '.join(given) or 'none'})")
    if peak_factor is not None and pga is None:
        raise ValueError("peak_factor: only used with pga")
    attrs: dict[str, Any] = {}
    omega_max = math.pi / dt if band_limit else None
    if S0 is not None:
        level = _positive(S0, "S0")
    elif rms is not None:
        level = s0_from_rms(model, _positive(rms, "rms"), omega_max)
        attrs["rms_target"] = float(rms)
    else:
        envelope_values = shape(time) if shape is not None else np.ones(n_time)
        factor = _peak_factor(model, peak_factor, dt, envelope_values, method, band_limit)
        level = s0_from_pga(model, _positive(pga, "pga"), factor, omega_max)
        how = peak_factor if isinstance(peak_factor, str) else ("poisson" if peak_factor is None else "given")
        attrs.update(pga_target=float(pga), peak_factor=float(factor), peak_factor_method=how)
    process = model.with_S0(level)
    rngs = realization_rngs(seed, first, count)
    values = stationary_samples(process, n_time, dt, rngs, method, band_limit) if count else np.empty((0, n_time))
    if shape is not None:
        values *= shape(time)
    if baseline:
        values = baseline_correct(values, dt)
    attrs = {
        "long_name": "ground acceleration",
        "units": "m/s2",
        "model": model.name,
        **model.parameters,
        "S0": float(level),
        "S0_units": "m2/s3 (two-sided PSD of the bedrock white noise)",
        "sigma": math.sqrt(process.variance(omega_max)),
        "band_limited": int(bool(band_limit)),
        "psd_convention": PSD_CONVENTION,
        **attrs,
        "envelope": "null" if shape is None else shape.describe(),  # JSON text either way: null is the stationary specification
        "seed": seed,
        "method": method,
        "baseline_corrected": int(bool(baseline)),
        "realization_streams": "numpy PCG64(SeedSequence(seed, spawn_key=(realization,)))",
        "dt": dt,
        "duration": float(time[-1]),
    }
    return xr.DataArray(
        values,
        dims=("realization", "time"),
        coords={"realization": np.arange(first, first + count), "time": time},
        name="ground_acceleration",
        attrs=attrs,
    )




def _peak_factor(model: FilteredWhiteNoise, spec: Any, dt: float, envelope: np.ndarray, method: str, band_limit: bool) -> float:
    if spec is None or spec == "poisson":
        return poisson_peak_factor(model, dt, envelope)
    if spec == "simulated":
        return simulated_peak_factor(model, dt, envelope, method, band_limit)
    if isinstance(spec, str):
        raise ValueError(f"peak_factor: must be a number > 0 or one of {', '.join(PEAK_FACTORS)}; got {spec!r}")
    return _positive(spec, "peak_factor")


def _index(value: Any, name: str) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 0:
        raise ValueError(f"{name}: must be an integer >= 0, got {value!r}")
    return int(value)


def _positive(value: Any, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ValueError(f"{name}: must be a number > 0, got {value!r}")
    if not (math.isfinite(value) and value > 0.0):
        raise ValueError(f"{name}: must be > 0, got {value!r}")
    return float(value)
