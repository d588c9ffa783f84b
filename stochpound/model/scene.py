"""The scene: buildings in a row, their bases, the contact elements and the ground motion.

A :class:`Scene` is a validated, immutable description of one physical
situation (docs/model.md). It is built from a scene file by
:func:`stochpound.model.scene_file.load_scene`, or directly in Python from
the laws' objects: :class:`~stochpound.model.building.Building` (with its
:class:`~stochpound.model.friction.Base`) and
:class:`~stochpound.model.contact.Contact`. All quantities are SI (kg, N/m,
N·s/m, m, s).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from stochpound.model import laws
from stochpound.model.building import Building
from stochpound.model.contact import Contact
from stochpound.model.wall import Wall
from stochpound.motions import DEFAULT_G
from stochpound.motions.ground import GroundMotion


@dataclass(frozen=True)
class Scene:
    """One physical situation: buildings left to right, contacts, ground motion.

    Attributes
    ----------
    buildings : tuple of Building
        The row, left to right.
    contacts : tuple of Contact
        Contact elements between neighbours.
    motion : GroundMotion
        The ground acceleration shared by all buildings.
    g : float
        Gravitational acceleration, m/s² (weights of sliding buildings).
    study_compat : bool
        Drop the impact forces from the base equation, as the reference study did.
    walls : tuple of Wall
        Rigid walls moving with the ground.
    source : str
        Where the scene came from (file name or "python"), for provenance.
    """

    buildings: tuple[Building, ...]
    contacts: tuple[Contact, ...]
    motion: GroundMotion
    g: float = DEFAULT_G
    study_compat: bool = False
    walls: tuple[Wall, ...] = ()
    source: str = field(default="python", compare=False)

    @property
    def building_names(self) -> list[str]:
        """Names of the buildings, left to right."""
        return [b.name for b in self.buildings]

    @property
    def max_floors(self) -> int:
        """Largest number of floors of any building."""
        return max(b.n_floors for b in self.buildings)

    def nonlinear_laws(self) -> list[str]:
        """The laws of the scene that are not piecewise linear (the exact solver cannot take them), each named by its field.

        E.g. ``contact[0].law = 'hertz'``, ``building[0].base.mu`` (velocity-dependent friction).
        """
        found = [f"contact[{p}].law = {c.law!r}" for p, c in enumerate(self.contacts) if not laws.contact_law(c.law).piecewise_linear]
        found += [f"wall[{p}].law = {w.law!r}" for p, w in enumerate(self.walls) if not laws.contact_law(w.law).piecewise_linear]
        found += [f"building[{b}].base.mu ({laws.friction_law(building.base.friction_law).title})" for b, building in enumerate(self.buildings)
                  if building.base is not None and not laws.friction_law(building.base.friction_law).piecewise_linear]
        return found
