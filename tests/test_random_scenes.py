"""Random scenes: the exact solver against the ivp path (DOP853 at rtol 1e-13), and against an independent integration.

Every scene is drawn from a seeded generator covering what a scene file can
hold: one to four buildings of one to four floors, fixed or on sliding bases
(μ = 0 free bases, static above kinetic friction, restoring springs), contacts
at any shared floor (zero and small gaps, stiff to very stiff springs,
restitution or a given dashpot, tensile or not), storey damping by ratio or
per storey, records (linear or spline), Kanai–Tajimi realizations or harmonic
motions, and the study's equations (``study_compat``). Both solvers must give
the same events and impacts, and the same displacements to 1e-9 of the
largest displacement (1e-9 m below 1 m): harmonic inputs slide some bases by
metres, and there the problem itself is that sensitive (exact runs with
different sub-steps, DOP853 and Radau differ from each other by ~5e-10 of the
peak on seed 2; at rtol 1e-12 DOP853 itself is off by 2e-9 m on seed 151).
Impact starts agree to 1e-8 s, plus 1e-12 m over the onset velocity for the
slow, barely touching impacts of zero-gap contacts (seed 21: 4e-9 m/s), whose
start times are that ill-conditioned.

The ivp path shares the event engine with the exact solver, so the two are
not independent in their event logic: :func:`test_an_independent_integration_agrees_on_fixed_buildings`
checks random fixed-base scenes against a reference written here from the
scene dictionary alone (its own matrices, Kelvin–Voigt forces and
separation rules, scipy's DOP853 with its own event location, restarted at
every sample of the ground motion and at every event).

Seeds 16 and 25 found disarmed guards that dipped below zero and came back
within one exact sub-step (a contact closing again 56 µs after it opened; a
non-tensile contact's force passing through zero just after the start): the
exact solver fired them at their small positive threshold, 2.7 µs and 0.9 ms
late, instead of at zero after the dip. ``events._locate`` now arms a guard
at a sampled dip before anything else and looks for a dip between samples
before firing at the threshold (``events._after_dip``).
"""

from __future__ import annotations

import os

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.linalg import eigh

import stochpound
from tests.helpers import random_scene


TOLERANCE = 1e-9  # of max(1 m, largest |y|), every floor's total displacement over the whole record
#: The seeds the docstring names: scenes that once found a fault or are ill-conditioned; always run.
NAMED_SEEDS = {2, 16, 21, 25}
#: The scenes' seeds: 0 to 19 and the named ones in the suite (22 scenes); STOCHPOUND_RANDOM_SCENES=N sweeps seeds 0 to N - 1
#: (and the named ones): 60 passed (docs/solvers.md).
SEEDS = sorted(set(range(int(os.environ.get("STOCHPOUND_RANDOM_SCENES", "20")))) | NAMED_SEEDS)
MAX_STEP = 2e-4  # s: the independent integration's largest step, so that no gap closes and opens again unseen within one


def test_random_scenes_are_reproducible():
    assert random_scene(3) == random_scene(3)
    assert random_scene(3) != random_scene(4)


@pytest.mark.parametrize("seed", SEEDS)
def test_exact_matches_ivp_on_a_random_scene(seed):
    scene = stochpound.scene_from_dict(random_scene(seed))
    exact = stochpound.simulate(scene)
    reference = stochpound.simulate(scene, method="ivp", rtol=1e-13, atol=1e-16)
    assert exact.sizes.get("impact", 0) == reference.sizes.get("impact", 0)
    assert exact.attrs["events_total"] == reference.attrs["events_total"]
    scale = max(1.0, float(np.nanmax(np.abs(reference.total_displacement.values))))
    np.testing.assert_allclose(exact.total_displacement.values, reference.total_displacement.values, rtol=0, atol=TOLERANCE * scale)
    # a start is as sharp as the approach is fast: 1e-12 m of state difference moves it by 1e-12 m / |onset velocity|
    start_tolerance = 1e-8 + 1e-12 * scale / np.maximum(np.abs(reference.impact_onset_velocity.values), 1e-300)
    np.testing.assert_array_less(np.abs(exact.impact_start.values - reference.impact_start.values), start_tolerance)


def _storey(values: list[float]) -> np.ndarray:
    """Dᵀ diag(k) D: storey springs (or dashpots) k_i acting on the storey drifts D u = u_i − u_{i−1} (u_0 = 0, the ground)."""
    drifts = np.eye(len(values)) - np.eye(len(values), k=-1)
    return drifts.T @ np.diag(values) @ drifts


def _fixed_base_scene(seed: int) -> dict:
    """random_scene(seed) on fixed bases, gaps ≥ 2 mm, linear interpolation, momentum-consistent equations."""
    scene = random_scene(seed)
    for building in scene["building"]:
        building.pop("base", None)
    for contact in scene["contact"]:
        contact["gap"] = max(contact["gap"], 0.002)
    scene["motion"].pop("interpolation", None)
    scene["study_compat"] = False
    return scene


def independent_run(scene: dict, times: np.ndarray, ground) -> tuple[np.ndarray, list[float]]:
    """Floor displacements relative to the ground at ``times`` (DOF × time) and impact starts, from the scene dict alone.

    M ü + C u̇ + K u = −M 1 a_g − Σ F_p (e_left − e_right), F_p = k δ + c δ̇ while closed, δ = u_left − u_right − d;
    a tensile contact opens when δ falls through 0, a non-tensile one when F does, and that one closes again
    when δ rises through 0 or, still penetrated, when k δ + c δ̇ rises through 0: when min(k δ, k δ + c δ̇) does.
    """
    offsets = np.cumsum([0] + [len(b["mass"]) for b in scene["building"]])
    n = offsets[-1]
    mass, stiffness, damping = np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n))
    for b, building in enumerate(scene["building"]):
        block = slice(offsets[b], offsets[b + 1])
        mass[block, block], stiffness[block, block] = np.diag(building["mass"]), _storey(building["stiffness"])
        if "damping_ratio" in building:  # C = a1 K with ζ1 the first mode's ratio: a1 = 2 ζ1 / ω1
            omega = np.sqrt(eigh(stiffness[block, block], mass[block, block], eigvals_only=True)[0])
            damping[block, block] = 2.0 * building["damping_ratio"] / omega * stiffness[block, block]
        else:
            damping[block, block] = _storey(building["damping"])
    names = [b["name"] for b in scene["building"]]
    contacts = []
    for contact in scene["contact"]:
        (left, floor), (right, _) = contact["between"]
        i, j = offsets[names.index(left)] + floor - 1, offsets[names.index(right)] + floor - 1
        k = contact["stiffness"]
        if "restitution" in contact:
            m_eff = mass[i, i] * mass[j, j] / (mass[i, i] + mass[j, j])
            log_r = np.log(contact["restitution"])
            c = 2.0 * (-log_r / np.sqrt(np.pi**2 + log_r**2)) * np.sqrt(k * m_eff)
        else:
            c = contact["damping"]
        contacts.append((i, j, contact["gap"], k, c, contact.get("tensile", True)))
    inverse = np.linalg.inv(mass)
    closed = [False] * len(contacts)

    def penetration(p, y):
        i, j, gap, k, c, _ = contacts[p]
        return y[i] - y[j] - gap, y[n + i] - y[n + j]

    def rate(t, y):
        force = -mass @ np.ones(n) * ground(t) - stiffness @ y[:n] - damping @ y[n:]
        for p, (i, j, _, k, c, _) in enumerate(contacts):
            if closed[p]:
                delta, delta_rate = penetration(p, y)
                force[i] -= k * delta + c * delta_rate
                force[j] += k * delta + c * delta_rate
        return np.concatenate([y[n:], inverse @ force])

    def guard(p, kind):
        k, c = contacts[p][3], contacts[p][4]

        def value(t, y):
            delta, delta_rate = penetration(p, y)
            if kind == "delta":
                return delta
            force = k * delta + c * delta_rate
            return force if kind == "force" else min(k * delta, force)  # "close": > 0 exactly when penetrated with a positive trial force

        value.terminal, value.direction = True, (-1 if closed[p] else 1)
        return value

    state, starts, out = np.zeros(2 * n), [], np.zeros((n, len(times)))
    samples = list(ground.breaks) + [times[-1]]
    t = 0.0
    for end in sorted(set(x for x in samples if x > 0.0)):
        while t < end:
            events = []
            for p, (*_, tensile) in enumerate(contacts):
                events.append((p, guard(p, "delta" if tensile else ("force" if closed[p] else "close"))))
            solution = solve_ivp(rate, (t, end), state, method="DOP853", rtol=1e-12, atol=1e-15, events=[e for _, e in events] or None, max_step=MAX_STEP,
                                 dense_output=True)
            inside = (times >= t) & (times <= solution.t[-1])
            if inside.any():
                out[:, inside] = solution.sol(times[inside])[:n]
            t, state = solution.t[-1], solution.y[:, -1]
            if solution.status == 1:
                fired = next(index for index, found in enumerate(solution.t_events) if len(found))
                p = events[fired][0]
                closed[p] = not closed[p]
                if closed[p]:
                    starts.append(t)
    return out, sorted(starts)


class _Ground:
    """a_g(t) of a scene's motion by its own definition: a harmonic, or linear interpolation of the samples (breaks at the samples)."""

    def __init__(self, scene: dict, motion) -> None:
        table = scene["motion"]
        if table.get("type") == "harmonic":
            self.breaks = []
            self.value = lambda t: table["amplitude"] * np.sin(table["omega"] * t + table.get("phase", 0.0))
        else:
            self.breaks = list(motion.times)
            self.value = lambda t: np.interp(t, motion.times, motion.values)

    def __call__(self, t: float) -> float:
        return self.value(t)


@pytest.mark.slow
@pytest.mark.parametrize("seed", [1, 3, 21])  # 3: sustained contacts; 21: zero-gap, barely touching impacts (5, 8 and 13 passed too)
def test_an_independent_integration_agrees_on_fixed_buildings(seed):
    """Fixed-base random scenes: the exact solver against :func:`independent_run`, the same impacts and displacements.

    Displacements to 1e-6 of the peak, impact starts to 1e-6 s: the reference
    is DOP853 at rtol 1e-12 through up to 225 events, and sustained contacts
    amplify its error (seed 3: 4e-8 m of 0.11 m; the other seeds agree to
    1e-12 m); a wrong event rule moves a run by millimetres.
    """
    table = _fixed_base_scene(seed)
    scene = stochpound.scene_from_dict(table)
    exact = stochpound.simulate(scene)
    times = exact.time.values
    reference, starts = independent_run(table, times, _Ground(table, scene.motion))
    computed = np.concatenate([exact.total_displacement.sel(building=b["name"]).values[: len(b["mass"])] for b in table["building"]])
    scale = max(1e-3, float(np.abs(reference).max()))
    np.testing.assert_allclose(computed, reference, rtol=0, atol=1e-6 * scale)
    assert len(starts) == exact.sizes.get("impact", 0) > 0
    np.testing.assert_allclose(np.sort(exact.impact_start.values), starts, rtol=0, atol=1e-6)
