"""Stationary Gaussian sample sequences of a :class:`FilteredWhiteNoise` process.

Both methods produce samples a_k = a(k·dt) whose second-order statistics are
those of the continuous process at the sample times: variance σ² = ∫ S dω and
autocovariance R(k·dt). Their PSD as a sequence is therefore the *aliased*
PSD S_d(ω) = Σ_m S(ω + 2πm/dt) on abs(ω) ≤ π/dt (see
:meth:`FilteredWhiteNoise.sampled_psd`), not S truncated at the Nyquist
frequency, which would lose the variance above π/dt.

``"spectral"`` — spectral representation (Shinozuka & Deodatis 1991), by FFT::

    a_k = Σ_{j=0}^{M/2} A_j cos(ω_j t_k + φ_j),   ω_j = j Δω,  Δω = 2π/(M dt),
    A_j² / 2 = w_j S_d(ω_j) Δω,  w_j = 2 (w_0 = w_{M/2} = 1),

with independent phases φ_j ~ U(0, 2π). The sequence has period M·dt; M is
chosen so that the record plus a margin of 20 / (slowest decay rate of the
filter) fits in one period, which makes the wrap-around correlation below
e^{−20}. Each realization has (asymptotically) Gaussian values and, over a
full period, exactly the target mean square.

With ``band_limit=True`` the spectral method uses S itself on abs(ω) ≤ π/dt
instead: no aliasing (a Clough–Penzien sequence keeps S(0) = 0, which the
aliased high-frequency tail of the Kanai–Tajimi factor otherwise fills with a
small white floor), at the cost of the variance above π/dt.

``"filter"`` — time-domain filtering with the exact discretisation of the
filter (x_{k+1} = Φ x_k + η_k, η_k ~ N(0, P − Φ P Φᵀ), x_0 ~ N(0, P)); exactly
Gaussian and stationary from t = 0.

Each realization draws only from its own generator (:mod:`.seeding`).
"""

from __future__ import annotations

import numpy as np
from scipy.fft import irfft, next_fast_len

from stochpound.motions.psd import FilteredWhiteNoise

#: Decay (in e-folds of the slowest filter pole) left between the record's end and its periodic copy.
WRAP_MARGIN_EFOLDS = 20.0
#: Realizations generated per block (bounds memory; results do not depend on it).
BLOCK = 512

#: ``method`` of the stationary samples and of the synthetic generators that draw them: spectral synthesis, or the exact recursive filter.
METHODS = ("spectral", "filter")


def spectral_length(model: FilteredWhiteNoise, n_time: int, dt: float) -> int:
    """FFT length M (even) used by the spectral method for ``n_time`` samples."""
    margin = int(np.ceil(WRAP_MARGIN_EFOLDS / (model.decay_rate() * dt)))
    return 2 * next_fast_len((n_time + margin + 1) // 2 + 1)


def spectral_amplitudes(model: FilteredWhiteNoise, n_fft: int, dt: float, band_limit: bool = False) -> np.ndarray:
    """Cosine amplitudes A_j, j = 0..M/2, of the spectral representation, m/s².

    From the sampled (aliased) PSD S_d, or from S itself if ``band_limit``.
    """
    d_omega = 2.0 * np.pi / (n_fft * dt)
    omega = d_omega * np.arange(n_fft // 2 + 1)
    weights = np.full(omega.size, 2.0)
    weights[0] = weights[-1] = 1.0
    density = model.psd(omega) if band_limit else model.sampled_psd(omega, dt)
    return np.sqrt(2.0 * weights * np.clip(density, 0.0, None) * d_omega)


def spectral_samples(
    model: FilteredWhiteNoise, n_time: int, dt: float, rngs: list[np.random.Generator], band_limit: bool = False
) -> np.ndarray:
    """Stationary samples (len(rngs), n_time) by the spectral representation.

    ``band_limit=True`` uses S(ω) on abs(ω) ≤ π/dt instead of the aliased S_d:
    the spectral shape below the Nyquist frequency is exact (e.g. a
    Clough–Penzien process keeps S(0) = 0) but the variance above π/dt is lost.
    Each realization draws its phases φ_j ~ U(0, 2π) from its own generator.
    """
    n_phases = spectral_length(model, n_time, dt) // 2 + 1
    phases = np.array([rng.uniform(0.0, 2.0 * np.pi, n_phases) for rng in rngs]).reshape(len(rngs), n_phases)
    return spectral_from_phases(model, n_time, dt, phases, band_limit)


def spectral_from_phases(model: FilteredWhiteNoise, n_time: int, dt: float, phases: np.ndarray, band_limit: bool = False) -> np.ndarray:
    """Stationary samples (rows of ``phases``, n_time) by the spectral representation, given the phases.

    Parameters
    ----------
    model : FilteredWhiteNoise
        The process (its S0 included).
    n_time : int
        Samples per realization.
    dt : float
        Step, s.
    phases : np.ndarray
        (realizations, M/2 + 1) phases φ_j, rad, M = ``spectral_length(model, n_time, dt)``.
    band_limit : bool
        As in :func:`spectral_samples`.

    Returns
    -------
    np.ndarray
        (realizations, n_time) accelerations, m/s². Each realization is
        synthesised on its own (one inverse FFT per row), so its numbers cannot
        depend on how many others are generated with it.
    """
    n_fft = spectral_length(model, n_time, dt)
    amplitudes = spectral_amplitudes(model, n_fft, dt, band_limit)
    scaled = (0.5 * n_fft) * amplitudes
    out = np.empty((len(phases), n_time))
    for row, phase in enumerate(phases):
        coefficients = scaled * np.exp(1j * phase)
        # irfft reads only the real part of the first and last coefficients and
        # counts them once: the A_0 and A_{M/2} cosines need twice that.
        coefficients[0] = 2.0 * scaled[0] * np.cos(phase[0])
        coefficients[-1] = 2.0 * scaled[-1] * np.cos(phase[-1])
        out[row] = irfft(coefficients, n=n_fft)[:n_time]
    return out


def filter_samples(model: FilteredWhiteNoise, n_time: int, dt: float, rngs: list[np.random.Generator]) -> np.ndarray:
    """Stationary samples (len(rngs), n_time) by exact discrete-time filtering of white noise.

    Each realization draws its (n_time + 1) × order standard normals from its
    own generator (:func:`filter_from_normals` maps them to the samples).
    """
    order = model.discretize(dt)[0].shape[0]
    out = np.empty((len(rngs), n_time))
    for first in range(0, len(rngs), BLOCK):
        block = rngs[first : first + BLOCK]
        z = np.stack([rng.standard_normal((n_time + 1) * order) for rng in block])
        out[first : first + len(block)] = filter_from_normals(model, n_time, dt, z)
    return out


def filter_from_normals(model: FilteredWhiteNoise, n_time: int, dt: float, normals: np.ndarray) -> np.ndarray:
    """Stationary samples by exact discrete-time filtering, given the standard normals that drive it.

    Parameters
    ----------
    model, n_time, dt
        The process (its S0 included), the samples per realization and the
        step (s), as in :func:`spectral_from_phases`.
    normals : np.ndarray
        (realizations, (n_time + 1) · order) independent standard normals,
        order the filter's: per realization the first ``order`` start the
        state in its stationary distribution, the next ``order`` per step
        drive it.

    Returns
    -------
    np.ndarray
        (realizations, n_time) accelerations, m/s². The recursion runs over a
        block of realizations at once with element-wise operations only (no
        BLAS), so each row's numbers do not depend on the batch.
    """
    Phi, noise_factor, C, start_factor = model.discretize(dt)
    order = Phi.shape[0]
    normals = np.asarray(normals, dtype=float)
    out = np.empty((len(normals), n_time))
    for first in range(0, len(normals), BLOCK):
        block = normals[first : first + BLOCK]
        z = np.ascontiguousarray(block.reshape(len(block), n_time + 1, order).transpose(2, 1, 0))  # (order, n_time + 1, block)
        state = _apply(start_factor, list(z[:, 0, :]))
        eta = np.stack(_apply(noise_factor, list(z[:, 1:, :])))  # (order, n_time, block)
        y = np.empty((n_time, len(block)))
        for k in range(n_time):
            y[k] = _apply(C, state)[0]
            state = [new + noise[k] for new, noise in zip(_apply(Phi, state), eta)]
        out[first : first + len(block)] = y.T
    return out


def _apply(matrix: np.ndarray, components: list[np.ndarray]) -> list[np.ndarray]:
    """Components of matrix @ v, with v given by its components, by element-wise products in a fixed order."""
    result = []
    for row in matrix:
        total = row[0] * components[0]
        for coefficient, component in zip(row[1:], components[1:]):
            total = total + coefficient * component
        result.append(total)
    return result


def stationary_samples(
    model: FilteredWhiteNoise,
    n_time: int,
    dt: float,
    rngs: list[np.random.Generator],
    method: str = "spectral",
    band_limit: bool = False,
) -> np.ndarray:
    """Stationary samples by ``method`` (``"spectral"`` or ``"filter"``; ``band_limit``: spectral only)."""
    if method == "spectral":
        return spectral_samples(model, n_time, dt, rngs, band_limit)
    if band_limit:
        raise ValueError("band_limit: only available with method='spectral' (the filter method is exact, hence aliased)")
    if method == "filter":
        return filter_samples(model, n_time, dt, rngs)
    raise ValueError(f"method: must be one of {', '.join(METHODS)}; got {method!r}")
