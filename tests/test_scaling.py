"""Large scenes: modes split into blocks of coupled buildings, propagators from one series, bounded caches."""

import dataclasses
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.linalg import expm

import stochpound
from numpy.polynomial import chebyshev

from stochpound.model import modes
from stochpound.model.friction import SLIP_LEFT, STUCK
from stochpound.model.modes import ModeLibrary, initial_mode
from stochpound.solvers import propagators
from stochpound.motions.ground import HarmonicMotion
from stochpound.solvers.propagators import GAUSS_NODES, PropagatorLibrary, build_propagator, coupled_blocks, exosystem, uniform_step
from stochpound.model.scene import Scene
from stochpound.model.system import build_system
from stochpound.studies.agarwal2004 import reference_building, study_contacts


def row_scene(motion: dict | None = None) -> Scene:
    """Three of the study's buildings in a row (B1 and B3 isolated), contacts at both floors of both neighbours."""
    contacts = study_contacts(0.01, "B1", "B2", mass_factor=2.0) + study_contacts(0.01, "B2", "B3", mass_factor=0.5)
    buildings = [reference_building("B1", 1.0, 0.2), reference_building("B2", 2.0), reference_building("B3", 0.5, 0.1)]
    return stochpound.scene_from_dict({
        "g": 9.814, "building": buildings, "contact": contacts,
        "motion": motion or {"record": "el_centro_1940_study", "duration": 1.0},
    })


def sample_modes(system) -> list:
    """Modes with contacts open and closed, bases stuck, slipping and mixed."""
    start = initial_mode(system)  # B1 and B3 stuck
    return [
        start,
        start.with_contact(1, True),
        start.with_contact(0, True).with_contact(3, True).with_base(0, SLIP_LEFT),
        start.with_contact(2, True).with_base(1, SLIP_LEFT).with_base(0, SLIP_LEFT),
    ]


def test_blocks_are_the_buildings_joined_by_closed_contacts():
    system = build_system(row_scene())
    library = ModeLibrary(system)
    b1 = set(system.floor_dofs[0]) | {system.base_dofs[0]}
    b2 = set(system.floor_dofs[1])
    b3 = set(system.floor_dofs[2]) | {system.base_dofs[1]}
    slipping = initial_mode(system).with_base(0, SLIP_LEFT).with_base(1, SLIP_LEFT)
    blocks = [set(block) for block in coupled_blocks(library[slipping].A, system.n_dof)]
    assert sorted(blocks, key=min) == [b1, b2, b3]
    joined = [set(block) for block in coupled_blocks(library[slipping.with_contact(3, True)].A, system.n_dof)]
    assert sorted(joined, key=min) == [b1, b2 | b3]


def test_blocks_are_the_connected_components_of_the_coupling():
    """Random sparse couplings: the blocks are scipy's connected components, each sorted, ordered by lowest DOF."""
    from scipy.sparse import csr_matrix
    from scipy.sparse.csgraph import connected_components

    rng = np.random.default_rng(7)
    for _ in range(300):
        n = int(rng.integers(1, 40))
        A = np.zeros((2 * n, 2 * n))
        entries = int(rng.integers(0, 3 * n))
        A[rng.integers(0, 2 * n, entries), rng.integers(0, 2 * n, entries)] = 1.0
        coupling = sum(A[i * n : (i + 1) * n, j * n : (j + 1) * n] != 0 for i in (0, 1) for j in (0, 1)) > 0
        count, labels = connected_components(csr_matrix(coupling), directed=False)
        expected = sorted((np.flatnonzero(labels == label) for label in range(count)), key=min)
        blocks = coupled_blocks(A, n)
        assert len(blocks) == count
        for block, component in zip(blocks, expected):
            np.testing.assert_array_equal(block, component)


@pytest.mark.parametrize("motion", [None, "harmonic"])
def test_propagators_equal_the_exponential_of_the_whole_mode(motion):
    """exp(𝒜 τ) of the full augmented matrix (scipy) at h, at the Gauss nodes and anywhere in the sub-step."""
    scene = row_scene()
    if motion == "harmonic":
        scene = dataclasses.replace(scene, motion=HarmonicMotion(3.0, 40.0, 1.0, 0.01))
    system = build_system(scene)
    exo, dt, n = exosystem(scene.motion), uniform_step(scene.motion), system.n_dof
    library = ModeLibrary(system)
    for mode in sample_modes(system):
        dynamics = library[mode]
        propagator = build_propagator(dynamics, exo, dt, n)
        matrix = np.zeros((2 * n + 5, 2 * n + 5))
        matrix[: 2 * n, : 2 * n], matrix[: 2 * n, 2 * n], matrix[: 2 * n, -1] = dynamics.A, dynamics.B, dynamics.c
        matrix[2 * n : -1, 2 * n : -1] = exo
        moving = np.setdiff1d(np.arange(2 * n), np.concatenate([dynamics.stuck_dofs, n + dynamics.stuck_dofs]))
        scale = np.abs(expm(matrix * propagator.step)[moving]).max(axis=1)[:, None]
        flows = [(propagator.transition, propagator.step)]
        flows += [(node, 0.5 * propagator.step * (1.0 + xi)) for node, xi in zip(propagator.nodes, GAUSS_NODES)]
        for values, tau in flows:
            np.testing.assert_allclose(values[moving] / scale, expm(matrix * tau)[moving] / scale, rtol=0, atol=1e-13)
        z0 = np.random.default_rng(1).normal(size=2 * n + 5)
        coefficients = propagator.chebyshev @ np.append(z0[:-1], 1.0)  # (degree + 1, 2N) on s ∈ [-1, 1]
        for tau in (0.0, 0.3 * propagator.step, propagator.step):
            expected = expm(matrix * tau)[: 2 * n] @ np.append(z0[:-1], 1.0)
            dense = chebyshev.chebval(2.0 * tau / propagator.step - 1.0, coefficients)
            np.testing.assert_allclose(dense[moving], expected[moving], rtol=1e-12, atol=1e-12 * np.abs(expected).max())


def test_stuck_bases_are_held_exactly():
    system = build_system(row_scene())
    scene = row_scene()
    library = PropagatorLibrary(system, exosystem(scene.motion), uniform_step(scene.motion))
    mode = sample_modes(system)[1]
    assert mode.base[0] == STUCK
    propagator, s, n = library[mode], system.base_dofs[0], system.n_dof
    for flow in (propagator.transition, *propagator.nodes, propagator.chebyshev[0]):
        np.testing.assert_array_equal(flow[s], np.eye(len(flow[s]))[s])
        np.testing.assert_array_equal(flow[n + s], 0.0)
    np.testing.assert_array_equal(propagator.chebyshev[1:, [s, n + s]], 0.0)


def test_dropped_propagators_and_dynamics_are_rebuilt_identically(monkeypatch):
    """With caches too small for one mode, every access rebuilds: the same arrays, and len counts distinct modes."""
    scene = row_scene()
    system = build_system(scene)
    exo, dt = exosystem(scene.motion), uniform_step(scene.motion)
    unbounded = PropagatorLibrary(system, exo, dt)
    for name, module in (("MODE_BUDGET", modes), ("PROPAGATOR_BUDGET", propagators), ("BLOCK_BUDGET", propagators)):
        monkeypatch.setattr(module, name, 1)
    bounded = PropagatorLibrary(system, exo, dt)
    visits = sample_modes(system) * 2
    for mode in visits:
        a, b = bounded[mode], unbounded[mode]
        for name in ("transition", "nodes", "chebyshev"):
            np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
        np.testing.assert_array_equal(a.dynamics.A, b.dynamics.A)
    assert len(bounded) == len(bounded.modes) == len(set(visits))
    assert list(bounded) == list(unbounded) == list(dict.fromkeys(visits))


def test_identical_buildings_share_their_blocks(monkeypatch):
    """Two equal isolated buildings, apart: four blocks (floors and stuck base of each), two distinct ones built."""
    built = []
    held_flows = propagators._held_flows
    monkeypatch.setattr(propagators, "_held_flows", lambda *args: built.append(args) or held_flows(*args))
    data = {
        "building": [reference_building("B1", 1.0, 0.2), reference_building("B2", 1.0, 0.2)],
        "contact": study_contacts(0.05, mass_factor=1.0),
        "motion": {"record": "el_centro_1940_study", "duration": 1.0},
    }
    scene = stochpound.scene_from_dict(data)
    system = build_system(scene)
    library = PropagatorLibrary(system, exosystem(scene.motion), uniform_step(scene.motion))
    propagator = library[initial_mode(system)]
    blocks = coupled_blocks(propagator.dynamics.A, system.n_dof)
    assert [list(dofs) for dofs in blocks] == [[0, 1], [2], [3, 4], [5]]
    assert len(built) == 2
    first, second = (np.concatenate([dofs, system.n_dof + dofs]) for dofs in (blocks[0], blocks[2]))
    np.testing.assert_array_equal(propagator.transition[np.ix_(first, first)], propagator.transition[np.ix_(second, second)])


LARGE_ROW = """
import json
import stochpound
from stochpound.studies.agarwal2004 import reference_building, study_contacts

buildings = [reference_building(f"B{{j + 1}}", (1.0, 2.0, 0.5)[j % 3], 0.2 if j % 2 == 0 else None) for j in range({n})]
for building in buildings:  # {floors} floors: the study's lower floor repeated under its top floor
    for key in ("mass", "stiffness", "damping"):
        if key in building:
            building[key] = [building[key][0]] * ({floors} - 1) + [building[key][1]]
contact = study_contacts(0.015)[0]
contacts = [
    dict(contact, between=[[left["name"], floor], [right["name"], floor]])
    for left, right in zip(buildings, buildings[1:])
    for floor in range(1, {floors} + 1)
]
scene = stochpound.scene_from_dict({{"g": 9.814, "building": buildings, "contact": contacts,
                                     "motion": {{"record": "el_centro_1940_study", "duration": {duration}}}}})
run = stochpound.simulate(scene)
print(json.dumps({{"impacts": run.sizes["impact"], "modes": run.attrs["modes_visited"]}}))
"""


@pytest.mark.slow
def test_a_row_of_ten_ten_storey_buildings_runs():
    """10 buildings × 10 floors, contacts at every floor: more than a hundred modes in the first 2 s of El Centro (154 there)."""
    script = LARGE_ROW.format(n=10, floors=10, duration=2.0)
    output = subprocess.run([sys.executable, "-c", script], cwd=Path(__file__).parents[1], check=True, timeout=600,
                            capture_output=True, text=True).stdout
    result = json.loads(output.strip().splitlines()[-1])
    assert result["impacts"] > 0 and result["modes"] > 100
