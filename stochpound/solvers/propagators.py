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
energy quadrature of :class:`stochpound.results.record.Recorder`), and a Chebyshev
expansion of exp(𝒜 τ) on [0, h] that evaluates the exact flow anywhere inside
a sub-step (event location, peak forces). The rows of a stuck base are set to
exactly s(τ) = s(0), ṡ(τ) = 0 (docs/model.md, numerical traps).

The sub-step h = dt / m is the largest with ρ h ≤ :data:`SCREEN_ANGLE`, where
ρ bounds the mode's frequencies (spectral radius of A, and Ω of a harmonic
input): the cubic Hermite screen of :func:`stochpound.solvers.engine._first_crossing`
then resolves any guard excursion, including contacts shorter than a sample
interval.

Two things keep a mode's build cheap in large scenes:

* buildings that no closed contact joins do not interact, so A is block
  diagonal (:func:`coupled_blocks`) and every block is propagated on its own
  (exp of a block diagonal matrix is the block diagonal of the blocks'
  exponentials); blocks recur across modes (a mode differs from the
  previous one in one contact or base) and are cached by their matrices
  (:class:`BlockCache`);
* all propagators of a block come from one Taylor series of exp(𝒜 τ) on
  [0, h] (:func:`_exponential_series`): ρ h ≤ 0.5 makes it converge in ~15
  terms once 𝒜 is balanced, and its terms give exp(𝒜 h), the node values
  and the exact Chebyshev coefficients by fixed weights.

Propagators are built lazily for the modes a run visits and cached per
(system, exosystem, dt) across runs (:func:`propagator_library`), within a
memory budget: large scenes visit thousands of modes.
"""

from __future__ import annotations

import hashlib
import math
from collections import OrderedDict
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from functools import cache, partial

import numpy as np
from scipy.linalg import matrix_balance

from stochpound._errors import StochpoundError
from stochpound.model.modes import BoundedCache, Mode, ModeDynamics, ModeLibrary, array_bytes
from stochpound.motions.ground import GroundMotion, HarmonicMotion, SampledMotion
from stochpound.model.system import System

SCREEN_ANGLE = 0.5
"""Largest phase ρ·h (rad) swept by any mode frequency in one sub-step."""
EXO_SIZE = 4
"""Length of the exosystem state w = [a_g, ȧ_g, ä_g, a⃛_g]."""
CHEBYSHEV_DEGREE = 16
"""Least degree of the Chebyshev expansion of exp(𝒜 τ) on one sub-step (higher when the series needs it)."""
SERIES_TOLERANCE = np.finfo(float).eps / 16
"""Size (∞-norm, balanced) of the last Taylor term of exp(𝒜 τ) kept."""
GAUSS_NODES, GAUSS_WEIGHTS = np.polynomial.legendre.leggauss(5)
_CACHE_SIZE = 16
PROPAGATOR_BUDGET = 128 * 2**20
"""Largest size of the cached :class:`ModePropagator` of one library, bytes.

The exact engine keeps its own copies of the modes it runs in (its slots,
``solvers.tables.TABLE_BUDGET``), so this cache only spares rebuilding a mode
evicted from the slots; dropped propagators are rebuilt from the block cache."""
BLOCK_BUDGET = 64 * 2**20
"""Largest size of the cached block flows of one library, bytes."""


class UnsupportedMotionError(StochpoundError, ValueError):
    """The solvers cannot run this ground motion (they take sampled and harmonic motions)."""


# ---------------------------------------------------------------- exosystem


def exosystem(motion: GroundMotion) -> np.ndarray:
    """Matrix S (4 × 4, 1/s) with ẇ = S w for w = [a_g, ȧ_g, ä_g, a⃛_g] inside every interval.

    Raises
    ------
    UnsupportedMotionError
        For motions other than :class:`~stochpound.motions.ground.SampledMotion` (linear or spline) and
        :class:`~stochpound.motions.ground.HarmonicMotion`: the event engine of both solvers evaluates
        a_g interval by interval as a cubic or a sine.
    """
    if isinstance(motion, HarmonicMotion):
        rotation = np.array([[0.0, 1.0], [-motion.omega**2, 0.0]])
        return np.kron(np.eye(2), rotation)
    if isinstance(motion, SampledMotion):
        return np.eye(EXO_SIZE, k=1)
    raise UnsupportedMotionError(
        f"the solvers run sampled (linear or spline) and harmonic ground motions, not {type(motion).__name__}"
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
    """a_g at every output time, as :meth:`Recorder.sample_at <stochpound.results.record.Recorder.sample_at>` evaluates it (m/s²)."""
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
    if np.abs(steps - dt).max() > 1e-9 * abs(dt):  # np.allclose(steps, dt, rtol=1e-9, atol=0), cheaper
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


def _augmented(A: np.ndarray, B: np.ndarray, c: np.ndarray, exo: np.ndarray) -> np.ndarray:
    """𝒜 = [[A, B e₀ᵀ, c], [0, S, 0], [0, 0, 0]] of the rate ẋ = A x + B a_g + c and the exosystem S."""
    size = len(A)
    matrix = np.zeros((size + EXO_SIZE + 1, size + EXO_SIZE + 1))
    matrix[:size, :size] = A
    matrix[:size, size] = B
    matrix[:size, -1] = c
    matrix[size : size + EXO_SIZE, size : size + EXO_SIZE] = exo
    return matrix


def _hold_stuck(propagator: np.ndarray, stuck: np.ndarray, n_dof: int) -> np.ndarray:
    """Make the rows of stuck bases exact: s(τ) = s(0), ṡ(τ) = 0 (last two axes: rows, Z)."""
    propagator[..., stuck, :] = 0.0
    propagator[..., n_dof + stuck, :] = 0.0
    propagator[..., stuck, stuck] = 1.0
    return propagator


# ---------------------------------------------------------------- exponential series


def _exponential_series(matrix: np.ndarray, rows: int) -> np.ndarray:
    """Taylor terms Tₘ = (matrix^m / m!)[:rows], m = 0..K, of exp(matrix u), u ∈ [0, 1], (K+1, rows, Z).

    The matrix is first balanced by a diagonal similarity D of powers of two
    (exact in floating point), D⁻¹ matrix D, which brings its norm near its
    spectral radius (≤ :data:`SCREEN_ANGLE` here); the terms are returned
    scaled back. Terms are added until ‖Tₘ‖ ≤ eps/16 once m + 1 ≥ 2‖D⁻¹ matrix D‖:
    from there each term is at most half the previous one, so the rest of
    the series is below ‖Tₘ‖ (∞-norms, of the balanced terms).
    """
    balanced, (scale, _) = matrix_balance(matrix, permute=False, separate=True)
    norm = np.abs(balanced).sum(axis=1).max()
    terms = [np.eye(rows, len(matrix))]
    while len(terms) < 2 * norm or np.abs(terms[-1]).sum(axis=1).max() > SERIES_TOLERANCE:
        terms.append(terms[-1] @ balanced / len(terms))
    return np.array(terms) * (scale[:rows, None] / scale)


@cache
def _series_weights(order: int) -> np.ndarray:
    """Weights turning the Taylor terms 0..``order`` into the flows (see :func:`_flows`).

    Rows: u^m at u = 1 (the sub-step), at the Gauss–Legendre nodes
    u = (1 + ξᵢ)/2, then the Chebyshev coefficients of u^m = ((1 + s)/2)^m in
    s ∈ [−1, 1] up to degree max(:data:`CHEBYSHEV_DEGREE`, ``order``), exact
    (dyadic rationals): u Tⱼ = Tⱼ/2 + (Tⱼ₊₁ + T_abs(j−1))/4, u T₀ = (T₀ + T₁)/2.
    """
    degree = max(CHEBYSHEV_DEGREE, order)
    times_u = 0.5 * np.eye(degree + 1) + 0.25 * (np.eye(degree + 1, k=-1) + np.eye(degree + 1, k=1))
    times_u[1, 0] = 0.5
    chebyshev = np.zeros((degree + 1, order + 1))
    chebyshev[0, 0] = 1.0
    for m in range(1, order + 1):
        chebyshev[:, m] = times_u @ chebyshev[:, m - 1]
    points = np.concatenate([[1.0], 0.5 * (1.0 + GAUSS_NODES)])
    return np.vstack([points[:, None] ** np.arange(order + 1), chebyshev])


@dataclass(frozen=True)
class _Flows:
    """Rows of exp(𝒜 τ) of one augmented matrix: at τ = h, at the Gauss nodes, and its Chebyshev expansion on [0, h]."""

    transition: np.ndarray
    nodes: np.ndarray
    chebyshev: np.ndarray


def _flows(matrix: np.ndarray, step: float, rows: int) -> _Flows:
    """The first ``rows`` rows of the sub-step, node and dense propagators of ``matrix`` over ``step`` (s)."""
    terms = _exponential_series(matrix * step, rows)
    values = np.tensordot(_series_weights(len(terms) - 1), terms, axes=1)
    nodes = 1 + len(GAUSS_NODES)
    return _Flows(values[0], values[1:nodes], values[nodes:])


def _held_flows(matrix: np.ndarray, step: float, stuck: np.ndarray, n_dof: int) -> _Flows:
    """:func:`_flows` of the 2N state rows of an augmented matrix, stuck bases held exactly."""
    flows = _flows(matrix, step, 2 * n_dof)
    chebyshev = flows.chebyshev
    chebyshev[1:, stuck, :] = 0.0
    chebyshev[1:, n_dof + stuck, :] = 0.0
    _hold_stuck(chebyshev[0], stuck, n_dof)
    return _Flows(_hold_stuck(flows.transition, stuck, n_dof), _hold_stuck(flows.nodes, stuck, n_dof), chebyshev)


# ---------------------------------------------------------------- blocks of coupled DOFs


def coupled_blocks(A: np.ndarray, n_dof: int) -> list[np.ndarray]:
    """The DOFs of ``A`` (2N × 2N) grouped into blocks that no entry of ``A`` couples.

    DOFs i and j are coupled when any of the entries of A between (q_i, v_i)
    and (q_j, v_j) is non-zero. A permuted to the blocks is block diagonal, so
    exp(A τ) is the block diagonal of the blocks' exponentials: buildings that
    no closed contact joins are propagated separately.

    Returns
    -------
    list of np.ndarray
        Sorted DOF indices of each block.
    """
    n = n_dof
    coupling = (A[:n, :n] != 0) | (A[:n, n:] != 0) | (A[n:, :n] != 0) | (A[n:, n:] != 0)
    coupling |= coupling.T
    labels = np.arange(n)  # each DOF's block is named by its lowest DOF: label propagation with pointer jumping
    while True:
        lowered = np.minimum(labels, np.where(coupling, labels, n).min(axis=1, initial=n))
        lowered = lowered[lowered]
        if np.array_equal(lowered, labels):
            break
        labels = lowered
    return [np.flatnonzero(labels == label) for label in np.unique(labels)]


class BlockCache:
    """Spectral radii and flows of the blocks of coupled DOFs, keyed by their matrices.

    Modes that differ only in one part of a scene share the flows of the
    other parts; equal blocks in different places (identical buildings) share
    theirs too. Flows are kept within :data:`BLOCK_BUDGET`.
    """

    def __init__(self) -> None:
        self._radius: dict[bytes, float] = {}
        self._flows: BoundedCache[tuple[bytes, float], _Flows] = BoundedCache(BLOCK_BUDGET, array_bytes)

    def radius(self, key: bytes, A: np.ndarray) -> float:
        """Largest abs(eigenvalue) of the block matrix ``A`` (rad/s)."""
        radius = self._radius.get(key)
        if radius is None:
            radius = self._radius[key] = float(np.abs(np.linalg.eigvals(A)).max(initial=0.0))
        return radius

    def flows(self, key: bytes, step: float, build: Callable[[], _Flows]) -> _Flows:
        """The flows of the block ``key`` over ``step`` (built by ``build`` on first use)."""
        flows = self._flows.get((key, step))
        if flows is None:
            flows = build()
            self._flows.put((key, step), flows)
        return flows


@dataclass(frozen=True)
class _Block:
    """One block of coupled DOFs of a mode: its DOFs, local rate matrices, local stuck DOFs and key."""

    dofs: np.ndarray
    A: np.ndarray
    B: np.ndarray
    c: np.ndarray
    stuck: np.ndarray
    key: bytes

    @classmethod
    def of(cls, dynamics: ModeDynamics, dofs: np.ndarray, stuck: np.ndarray) -> _Block:
        """The block of ``dynamics`` on ``dofs`` (sorted); ``stuck`` flags the stuck DOFs of the whole state."""
        rows = np.concatenate([dofs, len(stuck) + dofs])
        A, B, c = dynamics.A[np.ix_(rows, rows)], dynamics.B[rows], dynamics.c[rows]
        stuck = np.flatnonzero(stuck[dofs])
        digest = hashlib.blake2b(digest_size=20)
        for array in (A, B, c, stuck):
            digest.update(np.ascontiguousarray(array).tobytes())
        return cls(dofs, A, B, c, stuck, digest.digest())

    def flows(self, exo: np.ndarray, step: float) -> _Flows:
        """Propagators of the block's augmented system over ``step`` (rows of its state)."""
        return _held_flows(_augmented(self.A, self.B, self.c, exo), step, self.stuck, len(self.dofs))


# ---------------------------------------------------------------- one mode


def build_propagator(
    dynamics: ModeDynamics, exo: np.ndarray, dt: float, n_dof: int, block_cache: BlockCache | None = None
) -> ModePropagator:
    """Exact sub-step, node and dense propagators of one mode for sample spacing ``dt`` (s).

    The mode is split into :func:`coupled_blocks`, each propagated on its own
    (with ``block_cache``, blocks already met in other modes are reused), and
    the blocks' propagators are assembled into those of the whole state.
    """
    cache = BlockCache() if block_cache is None else block_cache
    stuck = np.zeros(n_dof, bool)
    stuck[dynamics.stuck_dofs] = True
    blocks = [_Block.of(dynamics, dofs, stuck) for dofs in coupled_blocks(dynamics.A, n_dof)]
    radius = max([cache.radius(b.key, b.A) for b in blocks] + [cache.radius(exo.tobytes(), exo)])
    substeps = max(1, math.ceil(radius * dt / SCREEN_ANGLE - 1e-9))
    step = dt / substeps
    exo_matrix = _augmented(np.zeros((0, 0)), np.zeros(0), np.zeros(0), exo)
    inputs = cache.flows(exo.tobytes(), step, partial(_flows, exo_matrix, step, EXO_SIZE + 1))
    flows = [cache.flows(b.key, step, partial(b.flows, exo, step)) for b in blocks]
    return ModePropagator(dynamics, substeps, step, *_assemble(blocks, flows, inputs, n_dof))


def _assemble(blocks: list[_Block], flows: list[_Flows], inputs: _Flows, n_dof: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Transition, node and Chebyshev arrays of the whole state from its blocks' and the inputs' (exosystem, 1) flows."""
    size = 2 * n_dof + EXO_SIZE + 1
    exo = np.arange(2 * n_dof, size)
    transition, nodes = np.zeros((size, size)), np.zeros((len(GAUSS_NODES), size, size))
    chebyshev = np.zeros((max(len(f.chebyshev) for f in flows), 2 * n_dof, size))
    transition[exo[:, None], exo], nodes[:, exo[:, None], exo] = inputs.transition, inputs.nodes
    for block, flow in zip(blocks, flows):
        rows = np.concatenate([block.dofs, n_dof + block.dofs])
        columns = np.concatenate([rows, exo])
        transition[rows[:, None], columns] = flow.transition
        nodes[:, rows[:, None], columns] = flow.nodes
        chebyshev[: len(flow.chebyshev), rows[:, None], columns] = flow.chebyshev
    return transition, nodes, chebyshev


# ---------------------------------------------------------------- library


class PropagatorLibrary:
    """Lazily built :class:`ModePropagator` of every visited mode of one system, exosystem and dt.

    Propagators are cached within :data:`PROPAGATOR_BUDGET`; one dropped from
    the cache is rebuilt when asked for again (from the cached blocks, see
    :class:`BlockCache`). ``len`` counts the distinct modes built, and
    iterating gives them in the order they were first built.

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
        self.blocks = BlockCache()
        self._cache: BoundedCache[Mode, ModePropagator] = BoundedCache(PROPAGATOR_BUDGET, array_bytes)
        self._order: dict[Mode, None] = {}

    def __getitem__(self, mode: Mode) -> ModePropagator:
        propagator = self._cache.get(mode)
        if propagator is None:
            propagator = build_propagator(self.modes[mode], self.exo, self.dt, self.system.n_dof, self.blocks)
            self._cache.put(mode, propagator)
            self._order.setdefault(mode)
        return propagator

    def __len__(self) -> int:
        return len(self._order)

    def __iter__(self) -> Iterator[Mode]:
        return iter(self._order)


_LIBRARIES: OrderedDict[bytes, PropagatorLibrary] = OrderedDict()


def propagator_library(system: System, motion: GroundMotion) -> PropagatorLibrary:
    """The cached :class:`PropagatorLibrary` of ``system`` driven by ``motion`` (built on first use).

    Libraries are shared by every run with an equal system, the same kind of
    motion (exosystem) and the same sample spacing; the least recently used
    is dropped beyond 16 entries.
    """
    exo = exosystem(motion)
    dt = uniform_step(motion)
    key = system.fingerprint + exo.tobytes() + np.float64(dt).tobytes()
    library = _LIBRARIES.get(key)
    if library is None:
        library = _LIBRARIES[key] = PropagatorLibrary(system, exo, dt)
        while len(_LIBRARIES) > _CACHE_SIZE:
            _LIBRARIES.popitem(last=False)
    _LIBRARIES.move_to_end(key)
    return library
