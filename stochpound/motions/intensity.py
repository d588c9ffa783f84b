"""Setting the white-noise level S0 from a target RMS or a target PGA.

* ``rms``: the stationary standard deviation σ = sqrt(∫ S dω), so
  S0 = σ² / ∫ abs(H)² dω (the integral is exact, from the Lyapunov equation).
* ``pga``: PGA = p · σ with a peak factor p = E[max_k abs(a_k)] / σ, the
  expected largest sample of the (modulated) motion in units of σ. Two
  estimates of p are offered:

  ``"poisson"`` (default) — level crossings as a Poisson process (Rice;
  Davenport 1964), with the envelope e(t) (peak 1) making the level relative
  to the local standard deviation σ e(t)::

      P(max abs(a) ≤ b σ) = exp(−ν ∫ exp(−b² / (2 e(t)²)) dt),
      ν = arccos(ρ1) / (π dt),   ρ1 = R(dt) / R(0),

  where ν is the exact mean rate of sign changes of the *sampled* sequence
  (for a stationary process this is Davenport's peak factor with the rate of
  the sampled process; a Kanai–Tajimi process has no finite continuous-time
  zero-crossing rate). It overestimates the realised peaks slightly: by
  1–4 % for firm and medium soil over 20–30 s, by up to about 13 % for soft
  soil and short (10 s) enveloped motions, where crossings cluster.

  ``"simulated"`` — the mean of max abs(a)/σ over a pilot ensemble of
  :data:`PILOT_REALIZATIONS` realizations drawn from a fixed pilot seed (not
  the user's), by the same method and envelope: accurate to about 1 %.

  Either way the *expected* peak is matched; each realization's own PGA
  scatters around it (typically ±10 %).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.linalg import expm

from stochpound.motions.psd import FilteredWhiteNoise

#: Realizations of the pilot ensemble of the "simulated" peak factor.
PILOT_REALIZATIONS = 256
#: Fixed seed of the pilot ensemble, so that the simulated peak factor is deterministic.
PILOT_SEED = 20_240_601
PEAK_FACTORS = ("poisson", "simulated")


def s0_from_rms(model: FilteredWhiteNoise, rms: float, omega_max: float | None = None) -> float:
    """S0 (m²/s³) that gives the stationary process the standard deviation ``rms`` (m/s²).

    ``omega_max`` (rad/s): for a process band-limited to abs(ω) ≤ omega_max.
    """
    if not (math.isfinite(rms) and rms > 0.0):
        raise ValueError(f"rms: must be > 0 m/s², got {rms!r}")
    return rms**2 / model.with_S0(1.0).variance(omega_max)


def s0_from_pga(model: FilteredWhiteNoise, pga: float, peak_factor: float, omega_max: float | None = None) -> float:
    """S0 (m²/s³) such that ``peak_factor`` × σ equals ``pga`` (m/s²) (``omega_max`` as in :func:`s0_from_rms`)."""
    if not (math.isfinite(pga) and pga > 0.0):
        raise ValueError(f"pga: must be > 0 m/s², got {pga!r}")
    if not (math.isfinite(peak_factor) and peak_factor > 0.0):
        raise ValueError(f"peak_factor: must be > 0, got {peak_factor!r}")
    return s0_from_rms(model, pga / peak_factor, omega_max)


def sampled_crossing_rate(model: FilteredWhiteNoise, dt: float) -> float:
    """Mean rate of sign changes of the sampled sequence, arccos(ρ1)/(π dt), 1/s."""
    A, _, C = model.state_space()
    P = model.state_covariance()
    r0 = float((C @ P @ C.T)[0, 0])
    r1 = float((C @ expm(A * dt) @ P @ C.T)[0, 0])
    return math.acos(max(-1.0, min(1.0, r1 / r0))) / (math.pi * dt)


def poisson_peak_factor(model: FilteredWhiteNoise, dt: float, envelope: np.ndarray) -> float:
    """Expected peak factor under Poisson level crossings (module docstring).

    Parameters
    ----------
    model : FilteredWhiteNoise
        The stationary process (its S0 does not matter).
    dt : float
        Step, s.
    envelope : np.ndarray
        e(t_k) at the sample times (ones for a stationary motion), peak ≈ 1.
    """
    e = np.maximum(np.asarray(envelope, dtype=float), 1e-12)
    rate = sampled_crossing_rate(model.with_S0(1.0), dt)
    levels = np.linspace(0.0, 10.0, 1001)  # b in units of σ; P(max > 10σ) is negligible
    inverse_e2 = 0.5 / e**2
    weights = np.full(e.size, dt)
    weights[0] = weights[-1] = 0.5 * dt  # trapezoid in t
    exposure = np.array([np.sum(weights * np.exp(-(b * b) * inverse_e2)) for b in levels])
    below = np.exp(-rate * exposure)
    return float(np.trapezoid(1.0 - below, levels))


def simulated_peak_factor(
    model: FilteredWhiteNoise, dt: float, envelope: np.ndarray, method: str, band_limit: bool = False
) -> float:
    """Mean of max abs(a)/σ over a pilot ensemble (module docstring)."""
    from stochpound.motions.generators import stationary_samples
    from stochpound.motions._seeding import realization_rngs

    unit = model.with_S0(1.0)
    e = np.asarray(envelope, dtype=float)
    rngs = realization_rngs(PILOT_SEED, 0, PILOT_REALIZATIONS)
    samples = stationary_samples(unit, e.size, dt, rngs, method, band_limit)
    peaks = np.max(np.abs(samples * e), axis=1)
    return float(np.mean(peaks)) / math.sqrt(unit.variance(math.pi / dt if band_limit else None))
