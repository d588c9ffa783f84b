"""The fixed-base twin: the studied building alone on a fixed base, a linear system without events.

Its response to a sampled (or harmonic) ground motion is one exact
discrete-time recursion over the sample intervals. With the state
x = [q, v] (2N) and the exosystem state w_k = [a_g, ȧ_g, ä_g, a⃛_g] at the start
of interval k (:func:`stochpound.solvers.propagators.interval_forcing`: a first-order
hold gives [a_k, (a_{k+1} − a_k)/dt, 0, 0]),

    x_{k+1} = Φ x_k + Γ w_k + γ,

where [Φ, Γ, γ] are the state rows of exp(𝒜 dt), the solver's own
transition over one sub-step (``stochpound.solvers.propagators.ModePropagator.transition``)
raised to the number of sub-steps in a sample interval. No second matrix
exponential is computed: the propagator is the one the exact solver uses for
the same mode.

Many realizations run at once (:func:`fixed_base_displacements`), one after
the other in a compiled loop whose arithmetic per realization is fixed: a
realization's response is bit for bit the same whatever batch it is computed
in, which keeps the store independent of how a run is split.

A building with yielding storeys is not linear: its twin runs each motion
through the exact solver's event engine instead (:func:`~stochpound.solvers.exact.run_exact`).
"""

from __future__ import annotations

from dataclasses import replace
from typing import Sequence

import numpy as np

from stochpound._jit import cached_njit
from stochpound.model.modes import initial_mode
from stochpound.motions.ground import GroundMotion
from stochpound.solvers.propagators import EXO_SIZE, interval_forcing, propagator_library
from stochpound.model.scene import Scene
from stochpound.model.system import build_system
from stochpound.solvers.compiling import NO_RUNTIME
from stochpound.solvers.exact import run_exact


def fixed_base_displacements(scene: Scene, motions: Sequence[GroundMotion]) -> np.ndarray:
    """Floor displacements of a single fixed-base building under each motion, m.

    Parameters
    ----------
    scene : Scene
        One building on a fixed base, no contacts (its own motion is not used).
    motions : sequence of GroundMotion
        Motions with the same sample times (e.g. realizations of one ensemble).

    Returns
    -------
    np.ndarray
        (len(motions), n_floors, n_samples): displacement of every floor
        relative to the ground at the motions' samples (for a fixed base the
        total and the relative displacement are the same).

    Raises
    ------
    ValueError
        If the scene has a sliding base or contacts (its response has events).
    """
    if len(scene.buildings) != 1 or scene.contacts or scene.buildings[0].base is not None:
        raise ValueError("the fixed-base twin is one building on a fixed base, without contacts")
    if not motions:
        return np.zeros((0, scene.buildings[0].n_floors, 0))
    system = build_system(scene)
    if system.storeys:  # yield and unloading are events: no recursion without them
        return np.stack([run_exact(replace(scene, motion=motion))[0].states[:, system.floor_dofs[0]].T for motion in motions])
    propagator = propagator_library(system, motions[0])[initial_mode(system)]
    step = np.linalg.matrix_power(propagator.transition, propagator.substeps)[: 2 * system.n_dof]
    forcing = np.stack([interval_forcing(motion) for motion in motions])
    floors = np.asarray(system.floor_dofs[0], dtype=np.int64)
    out = np.empty((len(motions), len(floors), forcing.shape[1] + 1))
    _recursion(np.ascontiguousarray(step), np.ascontiguousarray(forcing, dtype=float), system.initial_state.astype(float), floors, out,
               np.empty((2, step.shape[0])))
    return out


@cached_njit(error_model="numpy", **NO_RUNTIME)
def _recursion(step: np.ndarray, forcing: np.ndarray, x0: np.ndarray, rows: np.ndarray, out: np.ndarray,
               work: np.ndarray) -> None:  # pragma: no cover - compiled
    """x_{k+1} = Φ x_k + Γ w_k + γ for every realization; ``out[r, j, k]`` = x_k[rows[j]] of realization r.

    ``step`` holds [Φ, Γ, γ] (2N × (2N + 5)); ``forcing`` is (realizations, intervals, 4); ``work`` (2 × 2N) holds x_k and x_{k+1}.
    Like the engine (:mod:`stochpound.solvers.engine`), it allocates nothing and assigns no slice, so that it compiles in a
    fraction of a second, without numba's runtime.
    """
    n = step.shape[0]
    x = work[0]
    following = work[1]
    for r in range(forcing.shape[0]):
        for i in range(n):
            x[i] = x0[i]
        for j in range(rows.size):
            out[r, j, 0] = x[rows[j]]
        for k in range(forcing.shape[1]):
            for i in range(n):
                total = step[i, n + EXO_SIZE]
                for j in range(n):
                    total += step[i, j] * x[j]
                for e in range(EXO_SIZE):
                    total += step[i, n + e] * forcing[r, k, e]
                following[i] = total
            for i in range(n):
                x[i] = following[i]
            for j in range(rows.size):
                out[r, j, k + 1] = x[rows[j]]
