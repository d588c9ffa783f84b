"""The study's buildings and pairs as scene dicts (the fields of a scene file, docs/scene-files.md).

Building 1 is the study's two-storey shear building; Building 2 has its
storey stiffnesses and its masses times a factor (2: flexible, 0.5: stiff).
The impact elements at both floors keep √(k_imp/m_eff) = 57.05 rad/s with
restitution 0.5, and the motion is El Centro 1940 as the study used it.
"""

from __future__ import annotations

import copy

from stochpound.model.scene_tables import BuildingEntry, ContactEntry, MotionEntry, SceneEntry
from stochpound.studies.agarwal2004._records import STUDY_G

#: Floor masses of Building 1, kg (floor 1 upwards).
REFERENCE_MASS = [26268.0, 17512.0]
#: Storey stiffnesses of Building 1, N/m (storey 1 upwards).
REFERENCE_STIFFNESS = [24516800.0, 17512000.0]
#: Storey dampers of Building 1, N·s/m (1 % in its first mode).
REFERENCE_DAMPING = [23634.2, 16881.57]
#: √(k_imp/m_eff) of the study's impact elements, rad/s.
IMPACT_FREQUENCY = 57.05


def reference_building(name: str = "B1", mass_factor: float = 1.0, mu: float | None = None, **extra: object) -> BuildingEntry:
    """The study's two-storey building as a scene file's ``[[building]]`` table.

    Parameters
    ----------
    name : str
        The building's name.
    mass_factor : float
        Factor on the floor masses; with a factor other than 1 the damping
        is 1 % of critical in every mode instead of the study's dampers.
    mu : float, optional
        Friction coefficient of a sliding base of half the first floor's
        mass; a fixed base if omitted.
    **extra
        Further fields of the table.

    Returns
    -------
    dict
        ``name``, ``mass`` (kg), ``stiffness`` (N/m), ``damping`` (N·s/m) or
        ``damping_ratio``, and ``base`` when ``mu`` is given.
    """
    building: BuildingEntry = {
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


def study_contacts(gap: float, left: str = "B1", right: str = "B2", mass_factor: float = 2.0) -> list[ContactEntry]:
    """The impact elements at both floors between Building 1 and Building 2 (masses times ``mass_factor``).

    Parameters
    ----------
    gap : float
        Gap at both floors, m.
    left, right : str
        The buildings' names.
    mass_factor : float
        Mass factor of the right-hand building.

    Returns
    -------
    list of dict
        ``[[contact]]`` tables: √(k/m_eff) = 57.05 rad/s (k in N/m) and restitution 0.5.
    """
    contacts: list[ContactEntry] = []
    for floor, m1 in ((1, REFERENCE_MASS[0]), (2, REFERENCE_MASS[1])):
        m2 = m1 * mass_factor
        effective = m1 * m2 / (m1 + m2)
        contacts.append(
            {"between": [[left, floor], [right, floor]], "gap": gap, "stiffness": IMPACT_FREQUENCY**2 * effective, "restitution": 0.5}
        )
    return contacts


def study_scene(mu1: float | None = 0.2, mu2: float | None = None, factor: float = 2.0, gap: float = 0.02, motion: MotionEntry | None = None) -> SceneEntry:
    """A pair of the study: Building 1 next to Building 2, with the study's g and El Centro 1940.

    Parameters
    ----------
    mu1, mu2 : float, optional
        Friction coefficients of the buildings' sliding bases (fixed bases if omitted).
    factor : float
        Mass factor of Building 2 (2: flexible, 0.5: stiff).
    gap : float
        Gap at both floors, m.
    motion : MotionEntry, optional
        The scene's ``[motion]`` table (default: the study's El Centro 1940).

    Returns
    -------
    dict
        A scene dict for :func:`stochpound.scene_from_dict`, g = 9.814 m/s².
    """
    return {
        "g": STUDY_G,
        "building": [reference_building("B1", 1.0, mu1), reference_building("B2", factor, mu2)],
        "contact": study_contacts(gap, mass_factor=factor),
        "motion": copy.deepcopy(motion) if motion else {"record": "el_centro_1940_study"},
    }
