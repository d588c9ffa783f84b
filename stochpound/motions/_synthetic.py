"""Ensembles of synthetic ground accelerations: :func:`white_noise`, :func:`kanai_tajimi`, :func:`clough_penzien`,
and :func:`~stochpound.motions.scenario_motions` (the site model's, ``stochpound.motions._scenario_motions``).

Each is a :class:`~stochpound.motions.NormalMotion` (the motion as a function
of standard normals, :func:`normal_motion`) applied to every realization's own
random stream.
"""

from __future__ import annotations

import inspect
import math
from typing import Any, Mapping

import numpy as np
import xarray as xr

from stochpound.motions.envelopes import make_envelope
from stochpound.motions.generators import METHODS
from stochpound.motions.intensity import PEAK_FACTORS, poisson_peak_factor, s0_from_pga, s0_from_rms, simulated_peak_factor
from stochpound.motions.psd import FilteredWhiteNoise, clough_penzien_model, kanai_tajimi_model
from stochpound.motions._normals import NormalMotion
from stochpound.motions._scenario_motions import SCENARIO_TYPE, ScenarioNormalMotion, scenario_motions, scenario_normal_motion
from stochpound.motions._seeding import check_seed, realization_rngs

PSD_CONVENTION = "two-sided in omega (rad/s) on (-inf, inf); variance = integral of S domega"
#: The synthetic kinds: a scene's ``[motion] type`` and an experiment's ``[synthetic.<name>] type``.
SYNTHETIC_TYPES = ("kanai_tajimi", "clough_penzien", "white_noise", SCENARIO_TYPE)
#: Fields of a synthetic table that :func:`normal_motion` accepts and does not use (they name seeded realizations).
_NOT_USED = ("seed", "count", "start", "realization", "interpolation")


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
    motion = _filtered_motion(
        model, duration, dt, S0=S0, pga=pga, rms=rms, peak_factor=peak_factor, envelope=envelope, method=method,
        baseline=baseline, band_limit=band_limit,
    )
    return _ensemble(motion, count, first, seed)


def white_noise(
    n_realizations: int,
    duration: float,
    dt: float,
    S0: float | None = None,
    envelope: Any = None,
    seed: int = 0,
    *,
    start: int = 0,
    rms: float | None = None,
    baseline: bool = False,
) -> xr.DataArray:
    """Realizations of sampled Gaussian white noise of two-sided PSD S0.

    a_k = √(2π S0 / dt) u_k with independent standard normals u_k: the sampled
    process's PSD is S0 on abs(ω) ≤ π/dt, its variance σ² = 2π S0 / dt. The
    solvers take it linear between the samples, as every motion. This is the
    excitation of Au & Beck's (2001) linear oscillator (model §13).

    Parameters
    ----------
    n_realizations : int
        Number of realizations (>= 0).
    duration : float
        Length, s; samples at t = 0, dt, ..., round(duration/dt)·dt.
    dt : float
        Step, s.
    S0 : float, optional
        Two-sided PSD, m²/s³. Exactly one of ``S0`` and ``rms`` must be given.
    envelope : None, str, mapping, Envelope or callable
        Intensity envelope (see :mod:`stochpound.motions.envelopes`); None = stationary.
    seed : int
        Seed (>= 0). Realization i is determined by (seed, i) alone.
    start : int
        Index of the first realization (as in :func:`kanai_tajimi`).
    rms : float, optional
        Target standard deviation σ of the samples, m/s² (S0 = σ² dt / 2π).
    baseline : bool
        Correct each realization to end with zero velocity and displacement.

    Returns
    -------
    xarray.DataArray
        Ground acceleration, m/s², dims ``(realization, time)``; the
        parameters (S0, σ, envelope, seed, ...) in ``attrs``.
    """
    count = _index(n_realizations, "n_realizations")
    first = _index(start, "start")
    seed = check_seed(seed)
    return _ensemble(_white_motion(duration, dt, S0=S0, envelope=envelope, rms=rms, baseline=baseline), count, first, seed)


def normal_motion(motion: Mapping[str, Any]) -> NormalMotion | ScenarioNormalMotion:
    """A synthetic ensemble's motion as a function of standard normals (model §13).

    Parameters
    ----------
    motion : mapping
        The ensemble's fields, as an experiment's ``[synthetic.<name>]`` table
        writes them: ``type`` (one of :data:`SYNTHETIC_TYPES`, default
        ``"kanai_tajimi"``) and the generator's parameters (``duration`` and
        ``dt`` in s, ``S0`` m²/s³ or ``pga`` / ``rms`` m/s², ``envelope``, ...).
        ``seed``, ``count``, ``start``, ``realization`` and ``interpolation``
        are accepted and not used: the normals replace the seeded streams.

    Returns
    -------
    NormalMotion or ScenarioNormalMotion
        a = f(u), u ∈ Rⁿ independent standard normals (a
        :class:`~stochpound.motions.ScenarioNormalMotion` for ``type = "scenario_motions"``,
        the site model's map of K + n_time normals, K its model's).

    Raises
    ------
    ValueError
        Naming the field (``motion.<field>: ...``) that is unknown, missing or
        out of range.
    """
    if not isinstance(motion, Mapping):
        raise ValueError(f"motion: must be a table (type and the generator's parameters), got {type(motion).__name__}")
    kind = motion.get("type", "kanai_tajimi")
    if kind not in SYNTHETIC_TYPES:
        raise ValueError(f"motion.type: must be one of {', '.join(SYNTHETIC_TYPES)}, got {kind!r}")
    signature = inspect.signature(_GENERATORS[kind]).parameters
    own = [name for name in signature if name not in ("n_realizations", "start", "seed")]
    given = {key: value for key, value in motion.items() if key not in ("type", *_NOT_USED)}
    unknown = sorted(set(given) - set(own))
    if unknown:
        raise ValueError(f"motion.{unknown[0]}: unknown field for type = {kind!r} (allowed: {', '.join(sorted(own))})")
    missing = [name for name in own if signature[name].default is inspect.Parameter.empty and name not in given]
    if missing:
        raise ValueError(f"motion.{missing[0]}: required for type = {kind!r}")
    if kind == "white_noise":
        return _white_motion(**given)
    if kind == SCENARIO_TYPE:
        try:
            return scenario_normal_motion(**given)
        except ValueError as error:
            raise ValueError(f"motion.{error}") from None
    factory, names = _MODELS[kind]
    model = factory(*(given.pop(name) for name in names))
    return _filtered_motion(model, **given)


def _filtered_motion(
    model: FilteredWhiteNoise,
    duration: float,
    dt: float,
    *,
    S0: float | None = None,
    pga: float | None = None,
    rms: float | None = None,
    peak_factor: float | str | None = None,
    envelope: Any = None,
    method: str = "spectral",
    baseline: bool = False,
    band_limit: bool = False,
) -> NormalMotion:
    """The motion of a filtered white noise, its intensity resolved (S0 from ``pga`` or ``rms``)."""
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
    attrs: dict[str, float | str] = {}
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
        "method": method,
        "baseline_corrected": int(bool(baseline)),
        "dt": dt,
        "duration": float(time[-1]),
    }
    return NormalMotion(process, float(level), n_time, dt, method, bool(band_limit), shape, bool(baseline), attrs)


def _white_motion(
    duration: float, dt: float, S0: float | None = None, envelope: Any = None, *, rms: float | None = None, baseline: bool = False
) -> NormalMotion:
    """The motion of sampled white noise of two-sided PSD S0 (or of standard deviation ``rms``)."""
    duration, dt = _positive(duration, "duration"), _positive(dt, "dt")
    if dt > duration:
        raise ValueError(f"dt: must be <= duration ({duration:g} s), got {dt:g}")
    if (S0 is None) == (rms is None):
        raise ValueError(f"give exactly one of S0, rms (got {'both' if S0 is not None else 'none'})")
    n_time = int(round(duration / dt)) + 1
    shape = make_envelope(envelope, duration)
    level = _positive(S0, "S0") if S0 is not None else _positive(rms, "rms") ** 2 * dt / (2.0 * math.pi)
    attrs = {
        "long_name": "ground acceleration",
        "units": "m/s2",
        "model": "white_noise",
        "S0": float(level),
        "S0_units": "m2/s3 (two-sided PSD of the white noise)",
        "sigma": math.sqrt(2.0 * math.pi * level / dt),
        "band_limited": 0,
        "psd_convention": PSD_CONVENTION,
        **({"rms_target": float(rms)} if rms is not None else {}),
        "envelope": "null" if shape is None else shape.describe(),
        "method": "white",
        "baseline_corrected": int(bool(baseline)),
        "dt": dt,
        "duration": float((n_time - 1) * dt),
    }
    return NormalMotion(None, float(level), n_time, dt, "white", False, shape, bool(baseline), attrs)


def _ensemble(motion: NormalMotion, count: int, first: int, seed: int) -> xr.DataArray:
    """Realizations ``first`` .. ``first + count − 1`` of ``motion``, each from its own generator."""
    rngs = realization_rngs(seed, first, count)
    values = motion.sample(rngs) if count else np.empty((0, motion.n_time))
    attrs = {**motion.attrs, "seed": seed, "realization_streams": "numpy PCG64(SeedSequence(seed, spawn_key=(realization,)))"}
    return xr.DataArray(
        values,
        dims=("realization", "time"),
        coords={"realization": np.arange(first, first + count), "time": motion.time},
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


_MODELS = {"kanai_tajimi": (kanai_tajimi_model, ("omega_g", "zeta_g")), "clough_penzien": (clough_penzien_model, ("omega_g", "zeta_g", "omega_f", "zeta_f"))}
_GENERATORS = {"kanai_tajimi": kanai_tajimi, "clough_penzien": clough_penzien, "white_noise": white_noise, SCENARIO_TYPE: scenario_motions}
