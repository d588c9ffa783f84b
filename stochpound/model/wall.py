"""Rigid walls that move with the ground: a moat's retaining wall around an isolated building, or a neighbour treated as rigid.

Scene keys (``[[wall]]``): ``building`` (its name), ``side`` (``"left"`` or
``"right"`` of the building), ``level`` (0: the base, a moat wall, under a
sliding base only; or a floor number), ``gap`` (m, ≥ 0; ``inf``: never
reached, the run still records the closure), and the impact element's
fields as for a contact (:mod:`stochpound.model.contact`): ``law`` and the
law's keys (:mod:`stochpound.model.laws`).

The law (docs/model.md, "Walls"). With y the level's displacement relative
to the ground (s for the base, s + u_i for floor i), the penetration is
δ = y − d for a wall on the right and δ = −y − d on the left; while δ > 0 the
element pushes the level away from the wall with its law's force (Kelvin–Voigt
by default, F = k δ + c δ̇). The wall is infinitely massive, so its effective
mass is the level's mass m (the floor's, or the base's at level 0): a
restitution r gives a Kelvin–Voigt element c = 2 ξ(r) √(k m). The force acts on that level only (at the base through the base
equation; the study's ``study_compat`` switch concerns building contacts,
not walls). A wall is an impact element like a contact: the same guards,
impact table rows (``impact_wall``), energy term and closure monitor. With
a piecewise-linear law it is piecewise linear (the exact solver takes it).

Mass scaling (experiment variants): its law's, with m_eff = m.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Sequence

from stochpound.model import fields
from stochpound.model.fields import TomlTable
from stochpound.model.building import Building
from stochpound.model.contact import ELEMENT_KEYS, ImpactElement, element_from_table

WALL_KEYS = {"building", "side", "level", "gap"} | ELEMENT_KEYS
SIDES = {"left": -1, "right": 1}


@dataclass(frozen=True, kw_only=True)
class Wall(ImpactElement):
    """A rigid wall moving with the ground, beside one level of a building (the element's fields: :class:`~stochpound.model.contact.ImpactElement`).

    Attributes
    ----------
    building : int
        Index (0-based) of the building in the scene.
    side : int
        +1: the wall is on the building's right; −1: on its left.
    level : int
        0: the base (a moat wall); i ≥ 1: floor i.
    """

    building: int
    side: int
    level: int

    @property
    def side_name(self) -> str:
        """``"left"`` or ``"right"``."""
        return "right" if self.side > 0 else "left"


def walls_from_tables(tables: list[TomlTable], buildings: Sequence[Building]) -> list[Wall]:
    """The ``[[wall]]`` tables of a scene, validated; two beside the same level on the same side are refused (they would add their stiffnesses)."""
    walls = [wall_from_table(table, buildings) for table in tables]
    fields.reject_repeated(
        [((w.building, w.side, w.level), f"building {buildings[w.building].name!r}, side {w.side_name!r}, level {w.level}") for w in walls],
        "wall", "", "two walls beside the same level on the same side add their forces (two equal ones act as one of twice the stiffness)",
    )
    return walls


def wall_from_table(table: TomlTable, buildings: Sequence[Building]) -> Wall:
    """One ``[[wall]]`` table beside one of ``buildings``, validated."""
    table.reject_unknown(WALL_KEYS)
    names = [b.name for b in buildings]
    name = table.string("building")
    if name not in names:
        raise table.error("building", f"unknown building {name!r} (buildings: {', '.join(names)})")
    building = buildings[names.index(name)]
    side = table.string("side")
    if side not in SIDES:
        raise table.error("side", f"must be 'left' or 'right', got {side!r}")
    level = table.raw("level")
    if not isinstance(level, int) or isinstance(level, bool) or not 0 <= level <= building.n_floors:
        raise table.error("level", f"must be 0 (the base) or a floor number in 1..{building.n_floors} for building {name!r}, got {level!r}")
    if level == 0 and building.base is None:
        raise table.error("level", f"0 is the base, and building {name!r} has a fixed base (a moat wall needs a [building.base])")
    mass = building.base.mass if level == 0 else building.mass[level - 1]
    return Wall(building=names.index(name), side=SIDES[side], level=level, **asdict(element_from_table(table, mass)))
