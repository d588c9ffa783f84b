"""Exact discrete propagators of the modes: the flow of ẋ = A x + B a_g + c over a step.

Inside a motion interval the ground acceleration is generated exactly by a
small linear *exosystem* ẇ = S w with w = [a_g, ȧ_g, ä_g, a⃛_g]:

* a sampled motion (first-order hold or natural cubic spline) is a cubic
  polynomial in every interval, so S is the nilpotent shift (a⃛_g constant);
* a harmonic motion A sin(Ω t + φ) obeys ä_g = −Ω² a_g, so S holds two
  rotation blocks for (a_g, ȧ_g) and (ä_g, a⃛_g).

With the augmented state z = [x, w, 1] (length Z = 2N + 5) the mode is the
autonomous linear system ż = 𝒜 z,

    𝒜 = [[A, B e₀ᵀ, c],
         [0, S,     0],
         [0, 0,     0]],

so z(t₀ + τ) = exp(𝒜 τ) z(t₀) exactly. For every visited mode a
:class:`ModePropagator` holds exp(𝒜 h) for the sub-step h used inside a
sample interval, exp(𝒜 τᵢ) at the 5 Gauss–Legendre nodes of a sub-step (the
energy quadrature of :class:`stochpound.recorder.Recorder`), and a Chebyshev
expansion of exp(𝒜 τ) on [0, h] that evaluates the exact flow anywhere inside
a sub-step (event location, peak forces). The rows of a stuck base are set to
exactly s(τ) = s(0), ṡ(τ) = 0 (MODEL.md §6).

The sub-step h = dt / m is the largest with ρ h ≤ :data:`SCREEN_ANGLE`, where
ρ bounds the mode's frequencies (spectral radius of A, and Ω of a harmonic
input): the cubic Hermite screen of :func:`stochpound.events.first_crossing`
then resolves any guard excursion, including contacts shorter than a sample
interval.

Propagators are built lazily for the modes a run visits and cached per
(system, exosystem, dt) across runs (:func:`propagator_library`).
"""

from __future__ import annotations

import hashlib
import math
from collections import OrderedDict
from dataclasses import dataclass, fields

import numpy as np
from scipy.linalg import expm

from stochpound.errors import StochpoundError
from stochpound.events import Dense
from stochpound.modes import Mode, ModeDynamics, ModeLibrary
from stochpound.motion import GroundMotion, HarmonicMotion, SampledMotion
from stochpound.system import System

SCREEN_ANGLE = 0.5
"""Largest phase ρ·h (rad) swept by any mode frequency in one sub-step."""
EXO_SIZE = 4
"""Length of the exosystem state w = [a_g, ȧ_g, ä_g, a⃛_g]."""
CHEBYSHEV_DEGREE = 16
"""Degree of the Chebyshev expansion of exp(𝒜 τ) on one sub-step."""
CHEBYSHEV_TAIL = 1e-15
"""Largest relative size of the last two Chebyshev coefficients accepted."""
GAUSS_NODES, GAUSS_WEIGHTS = np.polynomial.legendre.leggauss(5)
_CACHE_SIZE = 16


class UnsupportedMotionError(StochpoundError, ValueError):
    """The exact solver cannot generate this ground motion exactly."""


# ---------------------------------------------------------------- exosystem


def exosystem(motion: GroundMotion) -> np.ndarray:
    """Matrix S (4 × 4, 1/s) with ẇ = S w for w = [a_g, ȧ_g, ä_g, a⃛_g] inside every interval.

    Raises
    ------
    UnsupportedMotionError
        For motions other than :class:`SampledMotion` (linear or spline) and
        :class:`HarmonicMotion`; simulate those with ``method="ivp"``.
    """
    if isinstance(motion, HarmonicMotion):
        rotation = np.array([[0.0, 1.0], [-motion.omega**2, 0.0]])
        return np.kron(np.eye(2), rotation)
    if isinstance(motion, SampledMotion):
        return np.eye(EXO_SIZE, k=1)
    raise UnsupportedMotionError(
        f"method='exact' supports sampled (linear or spline) and harmonic ground motions, "
        f"not {type(motion).__name__}; use method='ivp'"
    )


def interval_forcing(motion: GroundMotion) -> np.ndarray:
    """Exosystem state w = [a_g, ȧ_g, ä_g, a⃛_g] at the start of every interval, (n_intervals, 4)."""
    times = motion.times[:-1]
    if isinstance(motion, HarmonicMotion):
        return motion.derivatives(times, 0).T
    if isinstance(motion, SampledMotion):
        return motion.coefficients * np.array([1.0, 1.0, 2.0, 6.0])
    exosystem(motion)  # raises
    raise AssertionError("unreachable")


def sample_ground(motion: GroundMotion) -> np.ndarray:
    """a_g at every output time, as :meth:`Recorder.sample` evaluates it (m/s²)."""
    if isinstance(motion, HarmonicMotion):
        return np.asarray(motion.acceleration(motion.times, 0), float)
    if isinstance(motion, SampledMotion):
        ground = motion.coefficients[:, 0].copy()
        return np.append(ground, motion.acceleration(motion.times[-1], len(ground) - 1))
    exosystem(motion)  # raises
    raise AssertionError("unreachable")


def uniform_step(motion: GroundMotion) -> float:
    """The motion's sample spacing dt (s); raises if the output times are not uniform."""
    steps = np.diff(motion.times)
    dt = float(steps[0])
    if not np.allclose(steps, dt, rtol=1e-9, atol=0.0):
        raise UnsupportedMotionError("method='exact' needs uniformly spaced motion samples; use method='ivp'")
    return dt


# ---------------------------------------------------------------- one mode


@dataclass(frozen=True)
class ModePropagator:
    """Exact propagators of one mode over its sub-step.

    Attributes
    ----------
    dynamics : ModeDynamics
        The mode's matrices, guards and read-outs.
    substeps : int
        Sub-steps m per sample interval.
    step : float
        Sub-step length h = dt / m, s.
    transition : np.ndarray
        exp(𝒜 h), (Z × Z).
    nodes : np.ndarray
        exp(𝒜 τᵢ) at the Gauss–Legendre nodes τᵢ = h (1 + ξᵢ) / 2, (5 × Z × Z).
    chebyshev : np.ndarray
        Chebyshev coefficients of exp(𝒜 τ)[:2N] for τ ∈ [0, h], ((d+1) × 2N × Z).
    """

    dynamics: ModeDynamics
    substeps: int
    step: float
    transition: np.ndarray
    nodes: np.ndarray
    chebyshev: np.ndarray

    def dense(self, t0: float, x0: np.ndarray, ground0: np.ndarray) -> Dense:
        """Exact state x(t) for t ∈ [t0, t0 + h] from x(t0) and w(t0) = ``ground0``.

        Returns a callable: scalar t → (2N,), array of times → (2N, n_times).
        """
        z0 = np.concatenate([x0, ground0, [1.0]])
        coefficients = self.chebyshev @ z0  # (d+1, 2N)
        orders = np.arange(len(coefficients))
        scale = 2.0 / self.step

        def evaluate(t: np.ndarray | float) -> np.ndarray:
            s = np.clip((np.asarray(t, float) - t0) * scale - 1.0, -1.0, 1.0)
            basis = np.cos(np.multiply.outer(np.arccos(s), orders))
            return (basis @ coefficients).T

        return evaluate


def augmented_matrix(dynamics: ModeDynamics, exo: np.ndarray) -> np.ndarray:
    """𝒜 (Z × Z) of the mode driven by the exosystem ``exo`` (see module docstring)."""
    size = len(dynamics.A)
    matrix = np.zeros((size + EXO_SIZE + 1, size + EXO_SIZE + 1))
    matrix[:size, :size] = dynamics.A
    matrix[:size, size] = dynamics.B
    matrix[:size, -1] = dynamics.c
    matrix[size : size + EXO_SIZE, size : size + EXO_SIZE] = exo
    return matrix


def _hold_stuck(propagator: np.ndarray, stuck: np.ndarray, n_dof: int) -> np.ndarray:
    """Make the rows of stuck bases exact: s(τ) = s(0), ṡ(τ) = 0 (last two axes: rows, Z)."""
    propagator[..., stuck, :] = 0.0
    propagator[..., n_dof + stuck, :] = 0.0
    propagator[..., stuck, stuck] = 1.0
    return propagator


def _frequency_bound(dynamics: ModeDynamics, exo: np.ndarray) -> float:
    """ρ (rad/s): largest |eigenvalue| of A and of the exosystem."""
    return float(max(np.abs(np.linalg.eigvals(dynamics.A)).max(initial=0.0), np.abs(np.linalg.eigvals(exo)).max()))


def _chebyshev_fit(matrix: np.ndarray, step: float, rows: int, stuck: np.ndarray, n_dof: int) -> np.ndarray:
    """Chebyshev coefficients of exp(matrix τ)[:rows] on τ ∈ [0, step] from values at Chebyshev points."""
    degree = CHEBYSHEV_DEGREE
    while True:
        angles = np.pi * (np.arange(degree + 1) + 0.5) / (degree + 1)
        samples = np.array([expm(matrix * (0.5 * step * (1.0 + np.cos(a))))[:rows] for a in angles])
        cosines = np.cos(np.outer(np.arange(degree + 1), angles))
        coefficients = np.tensordot(cosines, samples, axes=1) * (2.0 / (degree + 1))
        coefficients[0] *= 0.5
        tail = np.abs(coefficients[-2:]).max() / max(np.abs(coefficients).max(), np.finfo(float).tiny)
        if tail <= CHEBYSHEV_TAIL or degree >= 64:
            break
        degree *= 2
    coefficients[1:, stuck, :] = 0.0
    coefficients[1:, n_dof + stuck, :] = 0.0
    _hold_stuck(coefficients[0], stuck, n_dof)
    return coefficients


def build_propagator(dynamics: ModeDynamics, exo: np.ndarray, dt: float, n_dof: int) -> ModePropagator:
    """Exact sub-step, node and dense propagators of one mode for sample spacing ``dt`` (s)."""
    matrix = augmented_matrix(dynamics, exo)
    substeps = max(1, math.ceil(_frequency_bound(dynamics, exo) * dt / SCREEN_ANGLE - 1e-9))
    step = dt / substeps
    stuck = dynamics.stuck_dofs
    transition = _hold_stuck(expm(matrix * step), stuck, n_dof)
    nodes = np.array([expm(matrix * (0.5 * step * (1.0 + xi))) for xi in GAUSS_NODES])
    nodes = _hold_stuck(nodes, stuck, n_dof)
    chebyshev = _chebyshev_fit(matrix, step, 2 * n_dof, stuck, n_dof)
    return ModePropagator(dynamics, substeps, step, transition, nodes, chebyshev)


# ---------------------------------------------------------------- library


class PropagatorLibrary:
    """Lazily built :class:`ModePropagator` of every visited mode of one system, exosystem and dt.

    Parameters
    ----------
    system : System
    exo : np.ndarray
        Exosystem matrix S (see :func:`exosystem`).
    dt : float
        Sample spacing, s.
    """

    def __init__(self, system: System, exo: np.ndarray, dt: float) -> None:
        self.system = system
        self.exo = exo
        self.dt = dt
        self.modes = ModeLibrary(system)
        self._cache: dict[Mode, ModePropagator] = {}

    def __getitem__(self, mode: Mode) -> ModePropagator:
        propagator = self._cache.get(mode)
        if propagator is None:
            propagator = build_propagator(self.modes[mode], self.exo, self.dt, self.system.n_dof)
            self._cache[mode] = propagator
        return propagator

    def __len__(self) -> int:
        return len(self._cache)

    def built(self) -> list[tuple[Mode, ModePropagator]]:
        """Every built mode and its propagator, in the order they were built."""
        return list(self._cache.items())


_LIBRARIES: OrderedDict[bytes, PropagatorLibrary] = OrderedDict()


def system_fingerprint(system: System) -> bytes:
    """Digest of every matrix and layout entry of ``system`` (equal systems share propagators)."""
    digest = hashlib.blake2b(digest_size=20)
    for item in fields(system):
        value = getattr(system, item.name)
        arrays = value if isinstance(value, list) else [value]
        for array in arrays:
            array = np.ascontiguousarray(array)
            digest.update(f"{item.name}{array.dtype}{array.shape}".encode())
            digest.update(array.tobytes())
    return digest.digest()


def propagator_library(system: System, motion: GroundMotion) -> PropagatorLibrary:
    """The cached :class:`PropagatorLibrary` of ``system`` driven by ``motion`` (built on first use).

    Libraries are shared by every run with an equal system, the same kind of
    motion (exosystem) and the same sample spacing; the least recently used
    is dropped beyond 16 entries.
    """
    exo = exosystem(motion)
    dt = uniform_step(motion)
    key = system_fingerprint(system) + exo.tobytes() + np.float64(dt).tobytes()
    library = _LIBRARIES.get(key)
    if library is None:
        library = _LIBRARIES[key] = PropagatorLibrary(system, exo, dt)
        while len(_LIBRARIES) > _CACHE_SIZE:
            _LIBRARIES.popitem(last=False)
    _LIBRARIES.move_to_end(key)
    return library
