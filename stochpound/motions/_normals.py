"""A synthetic ground motion as a function of independent standard normals: :class:`NormalMotion`.

Everything random in a synthetic motion is a vector u of n independent
standard normals; the motion is a deterministic function a = f(u), the
envelope and the baseline correction applied after the stationary samples.
A sampler that moves in the space of u (subset simulation, model §13) calls
the motion with its own u; the seeded generators draw u for realization i
from that realization's own generator. The three kinds of u:

``white`` (``white_noise``)
    n = n_time: a_k = √(2π S0 / dt) u_k, the sampled white noise of two-sided
    PSD S0 (the solvers take it linear between the samples).
``filter``
    n = (n_time + 1) × the filter's order: the normals that start the filter's
    state and drive its exact discretisation
    (:func:`~stochpound.motions.filter_from_normals`).
``spectral``
    n = M/2 + 1: one normal per frequency of the spectral representation,
    whose phase is φ_j = 2π Φ(u_j) (Φ the standard normal distribution
    function), uniform on (0, 2π). The seeded generator draws the phases
    themselves, so its realization i is f(Φ⁻¹(φ/2π)) to round-off, not bit
    for bit. A random-phase sum with fixed amplitudes is bounded
    (abs(a_k) ≤ Σ A_j): it is only approximately Gaussian, and its far tail is
    lighter than a Gaussian process's. Rare-event estimates (model §13) of a
    Gaussian ground motion therefore want ``filter``, which is exactly
    Gaussian.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from stochpound.motions.baseline import baseline_correct
from stochpound.motions.generators import filter_from_normals, filter_samples, spectral_from_phases, spectral_length, spectral_samples
from stochpound.motions.psd import FilteredWhiteNoise


@dataclass(frozen=True)
class NormalMotion:
    """A synthetic ground motion a = f(u) of n independent standard normals u.

    Build one with :func:`~stochpound.motions.normal_motion` (from a synthetic
    ensemble's fields); the generators (:func:`~stochpound.motions.kanai_tajimi`,
    :func:`~stochpound.motions.clough_penzien`,
    :func:`~stochpound.motions.white_noise`) are this map applied to each
    realization's own numbers.

    Parameters
    ----------
    process : FilteredWhiteNoise or None
        The filtered process (its S0 the motion's), or None for white noise.
    level : float
        Two-sided PSD S0 of the (bedrock) white noise, m²/s³.
    n_time : int
        Samples, at t = 0, dt, ..., (n_time − 1)·dt.
    dt : float
        Step, s.
    method : {"white", "filter", "spectral"}
        What the normals are (module docstring).
    band_limit : bool
        Spectral method: synthesise from S on abs(ω) ≤ π/dt.
    envelope : callable or None
        e(t) multiplying the stationary samples; None = stationary.
    baseline : bool
        Correct each motion to end with zero velocity and displacement.
    attrs : dict[str, float | str]
        The motion's parameters, as the generators' results carry them.
    """

    process: FilteredWhiteNoise | None
    level: float
    n_time: int
    dt: float
    method: str
    band_limit: bool = False
    envelope: Callable[[np.ndarray], np.ndarray] | None = None
    baseline: bool = False
    attrs: dict[str, float | str] = field(default_factory=dict, compare=False)

    @property
    def time(self) -> np.ndarray:
        """Sample times, s."""
        return np.arange(self.n_time) * self.dt

    @property
    def dimension(self) -> int:
        """n, the number of standard normals a motion takes."""
        if self.method == "white":
            return self.n_time
        if self.method == "filter":
            return (self.n_time + 1) * self.process.discretize(self.dt)[0].shape[0]
        return spectral_length(self.process, self.n_time, self.dt) // 2 + 1

    def __call__(self, u: np.ndarray) -> np.ndarray:
        """The ground acceleration of the normals ``u``.

        Parameters
        ----------
        u : array_like
            (n,) or (m, n) independent standard normals, n = :attr:`dimension`.

        Returns
        -------
        np.ndarray
            (n_time,) or (m, n_time) accelerations, m/s².
        """
        from scipy.special import ndtr

        u = np.asarray(u, dtype=float)
        if u.ndim not in (1, 2) or u.shape[-1] != self.dimension:
            raise ValueError(f"u: must have shape (n,) or (m, n) with n = {self.dimension}, got {u.shape}")
        rows = u.reshape(-1, u.shape[-1])
        if self.method == "spectral":
            values = spectral_from_phases(self.process, self.n_time, self.dt, 2.0 * np.pi * ndtr(rows), self.band_limit)
        else:
            values = self._stationary(rows)
        values = self._modulated(values)
        return values[0] if u.ndim == 1 else values

    def sample(self, rngs: list[np.random.Generator]) -> np.ndarray:
        """One motion per generator, each from its own generator's numbers, m/s² (len(rngs), n_time).

        The spectral method draws its phases uniform on (0, 2π), the others
        their standard normals, in the order the generators always drew them.
        """
        if self.method == "spectral":
            values = spectral_samples(self.process, self.n_time, self.dt, rngs, self.band_limit)
        elif self.method == "filter":
            values = filter_samples(self.process, self.n_time, self.dt, rngs)
        else:
            values = self._stationary(np.array([rng.standard_normal(self.n_time) for rng in rngs]).reshape(len(rngs), self.n_time))
        return self._modulated(values)

    def _stationary(self, normals: np.ndarray) -> np.ndarray:
        if self.method == "white":
            return math.sqrt(2.0 * math.pi * self.level / self.dt) * normals
        return filter_from_normals(self.process, self.n_time, self.dt, normals)

    def _modulated(self, values: np.ndarray) -> np.ndarray:
        if self.envelope is not None:
            values *= self.envelope(self.time)
        if self.baseline:
            values = baseline_correct(values, self.dt)
        return values
