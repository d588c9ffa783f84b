"""Shared scene builders for the tests (the reference study's buildings, docs/model.md)."""

from __future__ import annotations

import copy

import pytest

REFERENCE_MASS = [26268.0, 17512.0]
REFERENCE_STIFFNESS = [24516800.0, 17512000.0]
REFERENCE_DAMPING = [23634.2, 16881.57]


def reference_building(name: str = "B1", mass_factor: float = 1.0, mu: float | None = None, **extra) -> dict:
    """The study's 2-storey building (masses scaled by ``mass_factor``), isolated when ``mu`` is given."""
    building = {
        "name": name,
        "mass": [m * mass_factor for m in REFERENCE_MASS],
        "stiffness": list(REFERENCE_STIFFNESS),
    }
    if mass_factor == 1.0:
        building["damping"] = list(REFERENCE_DAMPING)
    else:
        building["damping_ratio"] = 0.01
    if mu is not None:
        building["base"] = {"mass": 0.5 * building["mass"][0], "mu": mu}
    building.update(extra)
    return building


def study_contacts(gap: float, left: str = "B1", right: str = "B2", mass_factor: float = 2.0) -> list[dict]:
    """Impact elements at both floors with sqrt(k/m_eff) = 57.05 rad/s and r = 0.5."""
    contacts = []
    for floor, m1 in ((1, REFERENCE_MASS[0]), (2, REFERENCE_MASS[1])):
        m2 = m1 * mass_factor
        effective = m1 * m2 / (m1 + m2)
        contacts.append(
            {"between": [[left, floor], [right, floor]], "gap": gap, "stiffness": 57.05**2 * effective, "restitution": 0.5}
        )
    return contacts


def study_scene(mu1: float | None = 0.2, mu2: float | None = None, factor: float = 2.0, gap: float = 0.02, motion: dict | None = None) -> dict:
    """Building 1 (isolated when mu1) next to Building 2 (mass factor 2 flexible, 0.5 stiff), El Centro as in the study."""
    return {
        "g": 9.814,
        "building": [reference_building("B1", 1.0, mu1), reference_building("B2", factor, mu2)],
        "contact": study_contacts(gap, mass_factor=factor),
        "motion": copy.deepcopy(motion) if motion else {"record": "el_centro_1940_study"},
    }


@pytest.fixture
def reference_scene_dict():
    return study_scene
