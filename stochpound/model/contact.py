"""Impact elements between neighbouring floors: the element every contact law acts through, its rows, guards and mode terms.

Scene keys (``[[contact]]``): ``between`` ([[left building, floor], [right
building, floor]], neighbours, the left one first), ``gap`` (m, ≥ 0; ``inf``:
the contact never closes, and a run still records its closure), ``law``
(default ``kelvin``; :mod:`stochpound.model.laws`) and the law's own keys
(``stiffness``, and ``restitution``, ``damping`` or ``tensile`` as the law
takes them).

With the penetration δ = y_left − y_right − d (d the gap), the element's
force F pushes the left floor left and the right floor right while closed;
m_eff = m₁m₂/(m₁ + m₂) of the two floor masses. A law that is piecewise
linear (the Kelvin–Voigt element, :mod:`stochpound.model.laws.kelvin`: F = k δ + c δ̇)
adds to a mode in which the contact is closed h k gᵀ to the stiffness,
h c gᵀ to the damping and h k d to the constant load, where δ = g·q − d and
the generalised load of F is −F h (h = g without base entries in the
study's ``study_compat`` model); a nonlinear law's force is a read-out
(:mod:`stochpound.model.readouts`). Guards: ``CLOSE`` (δ crosses 0 upwards),
``RECLOSE`` (non-tensile: trial force k δ + c δ̇ crosses 0 upwards while
δ > 0) and ``OPEN`` (δ or F crosses 0 downwards). Power: F (h · v).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any, Sequence

import numpy as np

from stochpound._errors import SceneError
from stochpound.model import fields, laws
from stochpound.model.fields import TomlTable
from stochpound.model.building import Building
from stochpound.model.guards import Guard
from stochpound.model.laws.contract import ElementParameters

ELEMENT_KEYS = {"law"}.union(*(law.keys for law in laws.CONTACT_LAWS.values()))
"""The keys of the impact element itself, in a ``[[contact]]`` or a ``[[wall]]`` table (each law takes some of them)."""
CONTACT_KEYS = {"between", "gap"} | ELEMENT_KEYS


@dataclass(frozen=True)
class ImpactElement:
    """The impact element itself, the same for a contact between floors and a wall (:mod:`stochpound.model.wall`).

    Attributes
    ----------
    gap : float
        At-rest gap d, m (>= 0; inf: the element never closes, and a run
        still records its closure).
    stiffness : float
        Impact spring k, N/m (> 0); N/m^1.5 for the Hertz family.
    damping : float
        Impact dashpot c, N·s/m (>= 0); derived from ``restitution`` when given.
    restitution : float or None
        Coefficient of restitution r in (0, 1] the damping was derived from.
    tensile : bool
        True: the element separates when δ returns to 0 and may pull just
        before (the study's choice). False: it separates when its force
        returns to 0 and never pulls. The nonlinear laws separate at δ = 0
        and never pull (True).
    law : str
        The contact law (a name of ``stochpound.model.laws.CONTACT_LAWS``).
    """

    gap: float
    stiffness: float
    damping: float
    restitution: float | None = None
    tensile: bool = True
    law: str = laws.DEFAULT_CONTACT_LAW

    def parameters(self, mass: float) -> ElementParameters:
        """The law's parameters of this element, whose collision has effective mass ``mass`` (kg)."""
        return ElementParameters(self.stiffness, self.damping, self.restitution, self.tensile, mass)


@dataclass(frozen=True, kw_only=True)
class Contact(ImpactElement):
    """An impact element between neighbouring floors (the element's fields: :class:`ImpactElement`).

    Attributes
    ----------
    left, right : int
        Indices (0-based, in the scene's building list) of the left building
        and its right-hand neighbour (``right == left + 1``).
    left_floor, right_floor : int
        Floors (1-based) that can collide. The penetration is
        δ = y_left − y_right − d.
    """

    left: int
    left_floor: int
    right: int
    right_floor: int


def effective_mass(mass_1: float, mass_2: float) -> float:
    """m_eff = m1 m2 / (m1 + m2), kg."""
    return mass_1 * mass_2 / (mass_1 + mass_2)


# ---------------------------------------------------------------- scene file


def contacts_from_tables(tables: list[TomlTable], buildings: Sequence[Building]) -> list[Contact]:
    """The ``[[contact]]`` tables of a scene, validated; two at the same floors are refused (they would add their stiffnesses)."""
    contacts = [contact_from_table(table, buildings) for table in tables]
    fields.reject_repeated(
        [((c.left, c.left_floor, c.right, c.right_floor), f"{buildings[c.left].name!r} floor {c.left_floor} and {buildings[c.right].name!r} floor {c.right_floor}")
         for c in contacts],
        "contact", "between", "two contacts between the same floors add their forces (two equal ones act as one of twice the stiffness)",
    )
    return contacts


def contact_from_table(table: TomlTable, buildings: Sequence[Building]) -> Contact:
    """One ``[[contact]]`` table between ``buildings``, validated."""
    table.reject_unknown(CONTACT_KEYS)
    between = table.raw("between")
    if not isinstance(between, list) or len(between) != 2:
        raise table.error("between", f"must be [[left building, floor], [right building, floor]], got {between!r}")
    left, left_floor = _contact_end(between[0], f"{table.field('between')}[0]", buildings)
    right, right_floor = _contact_end(between[1], f"{table.field('between')}[1]", buildings)
    if right != left + 1:
        raise table.error(
            "between", "contacts join neighbours, left building first; "
            f"{buildings[left].name!r} and {buildings[right].name!r} are not left/right neighbours"
        )
    mass = effective_mass(buildings[left].mass[left_floor - 1], buildings[right].mass[right_floor - 1])
    return Contact(left=left, left_floor=left_floor, right=right, right_floor=right_floor, **asdict(element_from_table(table, mass)))


def element_from_table(table: TomlTable, mass: float) -> ImpactElement:
    """The impact element of a ``[[contact]]`` or ``[[wall]]`` table, validated by its law (:mod:`stochpound.model.laws`).

    ``mass`` is the effective mass m_eff of the collision (kg), from which a
    Kelvin–Voigt element derives its dashpot from a restitution.
    """
    gap = table.number("gap", low=0.0, allow_inf=True)
    law = laws.contact_law(table.string("law", laws.DEFAULT_CONTACT_LAW), table.field("law"))
    for key in sorted(ELEMENT_KEYS - law.keys - {"law"}):
        if key in table:
            raise table.error(key, law.refuse(key))
    stiffness, damping, restitution, tensile, _ = law.read(table, mass)
    return ImpactElement(gap, stiffness, damping, restitution, tensile, law.name)


def _contact_end(value: Any, path: str, buildings: Sequence[Building]) -> tuple[int, int]:
    names = [b.name for b in buildings]
    if not (isinstance(value, list) and len(value) == 2 and isinstance(value[0], str) and isinstance(value[1], int) and not isinstance(value[1], bool)):
        raise SceneError(f"{path}: must be [building name, floor number], got {value!r}")
    name, floor = value
    if name not in names:
        raise SceneError(f"{path}: unknown building {name!r} (buildings: {', '.join(names)})")
    index = names.index(name)
    n_floors = buildings[index].n_floors
    if not 1 <= floor <= n_floors:
        raise SceneError(f"{path}: floor must be in 1..{n_floors} for building {name!r}, got {floor}")
    return index, floor


# ---------------------------------------------------------------- modes


@dataclass(frozen=True)
class ContactRows:
    """Every contact's penetration row [g, 0] and force row [k g, c g] over the state x = [q, v] (n_contacts × 2N)."""

    penetration: np.ndarray
    force: np.ndarray


def contact_rows(geometry: np.ndarray, stiffness: np.ndarray, damping: np.ndarray) -> ContactRows:
    """The rows of every contact (``geometry``: g as rows; ``stiffness``, ``damping``: k, c per contact), shared by all modes."""
    zeros = np.zeros_like(geometry)
    return ContactRows(np.hstack([geometry, zeros]), np.hstack([stiffness[:, None] * geometry, damping[:, None] * geometry]))


def closed_terms(geometry: np.ndarray, load: np.ndarray, stiffness: np.ndarray, damping: np.ndarray, gap: np.ndarray,
                 closed: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """What the ``closed`` contacts add to a mode: stiffness h k gᵀ (N/m), damping h c gᵀ (N·s/m) and constant load h k d (N).

    ``geometry`` and ``load`` hold g and h as rows (n_contacts × N).
    """
    g, h = geometry[closed], load[closed]
    return (h.T * stiffness[closed]) @ g, (h.T * damping[closed]) @ g, h.T @ (stiffness[closed] * gap[closed])


def force_rows(rows: ContactRows, stiffness: np.ndarray, gap: np.ndarray, closed: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Contact forces F = matrix · x + constant (N) in a mode: k δ + c δ̇ for closed contacts, 0 for open ones."""
    matrix = np.zeros_like(rows.force)
    matrix[closed] = rows.force[closed]
    constant = np.zeros(len(gap))
    constant[closed] = -stiffness[closed] * gap[closed]
    return matrix, constant


def guards(rows: ContactRows, stiffness: np.ndarray, gap: np.ndarray, tensile: np.ndarray, closed: np.ndarray) -> tuple[np.ndarray, ...]:
    """Every contact's guards in a mode, in contact order: CLOSE (and RECLOSE if non-tensile) of open contacts, OPEN of closed ones.

    Returns
    -------
    matrix, ground, constant, kind, target, direction : np.ndarray
        Guard rows over x (none depends on a_g), their constants, kinds
        (:class:`~stochpound.model.guards.Guard`), contacts, and 0 directions.
    """
    # a contact with an infinite gap never closes: it has no guard (its closure is still monitored)
    guarded = np.flatnonzero(closed | np.isfinite(gap))
    closed, tensile, gap, stiffness = closed[guarded], tensile[guarded], gap[guarded], stiffness[guarded]
    penetration, force = rows.penetration[guarded], rows.force[guarded]
    # first guard of each contact: CLOSE when open; OPEN (on δ when tensile, on F when not) when closed
    first = np.where(closed[:, None], -np.where(tensile[:, None], penetration, force), penetration)
    first_constant = np.where(closed, np.where(tensile, gap, stiffness * gap), -gap)
    first_kind = np.where(closed, Guard.OPEN, Guard.CLOSE)
    reclose = np.flatnonzero(~closed & ~tensile)
    order = np.argsort(np.concatenate([2 * np.arange(len(guarded)), 2 * reclose + 1]), kind="stable")
    matrix = np.concatenate([first, force[reclose]])[order]
    constant = np.concatenate([first_constant, -stiffness[reclose] * gap[reclose]])[order]
    kind = np.concatenate([first_kind, np.full(len(reclose), Guard.RECLOSE)])[order]
    target = np.concatenate([guarded, guarded[reclose]])[order]
    return matrix.reshape(len(order), rows.penetration.shape[1]), np.zeros(len(order)), constant, kind.astype(int), target, np.zeros(len(order), int)
