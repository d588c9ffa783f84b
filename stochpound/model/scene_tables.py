"""A scene as written, read as typed parts: what an experiment reads and edits of a scene before the model builds it.

An experiment keeps its scene, and each variant's overrides, as written: its
definition's canonical dict and sha256 hold every field given and each
number as it was spelled (``0`` and ``0.0`` hash differently), and its scene
is edited (variants, gaps, μ) before it is validated, so a variant may
complete a table the base scene leaves incomplete. :class:`SceneTables` reads
such a scene as values: its ``g``, its buildings (:class:`BuildingTable`,
found by name, default names B1, B2, ... included), its contacts and walls
(:class:`WallTable`), each an attribute; :class:`SceneOverrides` reads one
variant's overrides the same way. They check shape where they read (a
``[[building]]`` is a table); ranges are the builder's
(:func:`~stochpound.scene_from_dict`, whose errors name the field), and
:meth:`SceneTables.to_dict` gives the scene back exactly as written.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass
from functools import cached_property
from typing import TypedDict

from stochpound.model.building import default_name
from stochpound.model.fields import TomlTable
from stochpound.motions import DEFAULT_G


class BaseEntry(TypedDict, total=False):
    """A ``[building.base]`` table as written (``stochpound.model.friction.BASE_KEYS``); ``mu`` a number or ``{ slow, fast, rate }``."""

    mass: float
    mu: float | dict[str, float]
    mu_static: float
    restoring_stiffness: float
    radius: float


class InitialEntry(TypedDict, total=False):
    """A ``[building.initial]`` table as written (``stochpound.model.building.INITIAL_KEYS``)."""

    displacement: list[float]
    velocity: list[float]
    base_displacement: float
    base_velocity: float


class _BuildingFields(TypedDict, total=False):
    """The fields a ``[[building]]`` table and a variant's ``building.<name>`` table share (``stochpound.model.building.BUILDING_KEYS``)."""

    name: str
    mass: list[float]
    stiffness: list[float]
    damping: list[float]
    damping_ratio: float
    initial: InitialEntry
    storey_height: float | list[float]
    yield_force: list[float]
    hardening: float
    p_delta: bool


class BuildingEntry(_BuildingFields, total=False):
    """A ``[[building]]`` table as written (``stochpound.model.building.BUILDING_KEYS``)."""

    base: BaseEntry


class BuildingOverridesEntry(_BuildingFields, total=False):
    """A variant's ``building.<name>`` table as written: a building's fields, ``mass_factor``, and ``base = false`` to remove its base."""

    base: BaseEntry | bool
    mass_factor: float


class ContactEntry(TypedDict, total=False):
    """A ``[[contact]]`` or ``[[wall]]`` table as written (``stochpound.model.contact.CONTACT_KEYS``, ``stochpound.model.wall.WALL_KEYS``)."""

    between: list[list[str | int]]
    building: str
    side: str
    level: int
    gap: float
    law: str
    stiffness: float
    damping: float
    restitution: float
    tensile: bool


class MotionEntry(TypedDict, total=False):
    """A ``[motion]`` table as written: a record's, an analytic motion's or a synthetic ensemble's fields (docs/motions.md);
    an experiment's motions add the record's ``file_sha256`` (None when it has no file of its own)."""

    type: str
    record: str
    file_sha256: str | None
    scale: float
    dt: float
    duration: float
    units: str
    interpolation: str
    amplitude: float
    omega: float
    phase: float
    acceleration: float
    magnitude: float
    distance_km: float
    vs30: float
    mechanism: str
    n: int
    seed: int
    model: str
    calibration: str
    realization: int
    omega_g: float
    zeta_g: float
    omega_f: float
    zeta_f: float
    S0: float
    pga: float
    envelope: str | dict[str, float]
    method: str
    rms: float
    peak_factor: float | str
    baseline: bool
    band_limit: bool


class SceneEntry(TypedDict, total=False):
    """A scene as written: a scene file's tables and fields (docs/scene-files.md), as an experiment's definition holds its ``scene``."""

    g: float
    study_compat: bool
    building: list[BuildingEntry]
    contact: list[ContactEntry]
    wall: list[ContactEntry]
    motion: MotionEntry


class OverridesEntry(TypedDict, total=False):
    """One variant's overrides as written: fields by building name, scene-level fields, and a contact table (or one per contact)."""

    building: dict[str, BuildingOverridesEntry]
    scene: SceneEntry
    contact: ContactEntry | list[ContactEntry]


@dataclass(frozen=True)
class BuildingTable:
    """One ``[[building]]`` table of a scene, as written.

    Attributes
    ----------
    table : TomlTable
        The table, named ``building[i]``.
    index : int
        Its place in the scene, left to right (0-based).
    """

    table: TomlTable
    index: int

    @property
    def name(self) -> str:
        """Its ``name``, or its default name (B1, B2, ...)."""
        return self.table.raw("name", default_name(self.index))

    @property
    def floors(self) -> int:
        """Its number of floors (the length of its ``mass``; 0 when it gives none)."""
        mass = self.table.raw("mass", [])
        return len(mass) if isinstance(mass, list) else 0

    @property
    def base(self) -> TomlTable | None:
        """Its ``[building.base]`` table, None when it has none (or ``base`` is not a table: the builder names it)."""
        base = self.table.raw("base")
        return TomlTable(base, self.table.field("base")) if isinstance(base, dict) else None

    @property
    def yields(self) -> bool:
        """Whether it gives yielding storeys (``yield_force``)."""
        return "yield_force" in self.table

    @property
    def has_storey_summaries(self) -> bool:
        """Whether it gives what storey summaries read: ``yield_force`` or ``storey_height``."""
        return self.yields or "storey_height" in self.table


@dataclass(frozen=True)
class WallTable:
    """One ``[[wall]]`` table of a scene, as written.

    Attributes
    ----------
    table : TomlTable
        The table, named ``wall[i]``.
    """

    table: TomlTable

    @property
    def building(self) -> str | None:
        """The building it stands beside (None when not given)."""
        return self.table.raw("building")

    @property
    def level(self) -> int:
        """The level it stands at: 0 (the base, a moat wall) unless given."""
        return self.table.raw("level", 0)

    @property
    def gap(self) -> float:
        """Its at-rest gap, m, as written (KeyError when not given)."""
        return self.table.values["gap"]

    def at_base_of(self, building: str | None) -> bool:
        """Whether it is a moat wall at the base of ``building``."""
        return self.building == building and self.level == 0


@dataclass(frozen=True)
class SceneTables:
    """A scene as written (the structure of a scene file, docs/scene-files.md), its parts read as attributes.

    Attributes
    ----------
    table : TomlTable
        The scene's top-level table (its fields and its ``[[building]]``, ``[[contact]]``, ``[[wall]]`` and ``[motion]`` tables).
    """

    table: TomlTable

    # read each time, never cached: a scene being edited may be given new tables (:mod:`stochpound.store`'s scene edits)

    @classmethod
    def of(cls, scene: SceneEntry, name: str = "") -> SceneTables:
        """The scene dict ``scene`` (a parsed scene file, or an experiment's ``scene``), its tables named under ``name``."""
        return cls(TomlTable(scene, name))

    @property
    def g(self) -> float:
        """Its acceleration of gravity, m/s²: its ``g``, or ``stochpound.motions.DEFAULT_G`` (9.81) when it leaves it out (the one reader)."""
        return float(self.table.raw("g", DEFAULT_G))

    @property
    def buildings(self) -> tuple[BuildingTable, ...]:
        """Its ``[[building]]`` tables, left to right."""
        return tuple(BuildingTable(table, i) for i, table in enumerate(self.table.tables("building")))

    @property
    def building_names(self) -> tuple[str, ...]:
        """The names of its buildings, left to right (default names B1, B2, ... included)."""
        return tuple(building.name for building in self.buildings)

    def building(self, name: str) -> BuildingTable:
        """The building called ``name`` (KeyError if none)."""
        for building in self.buildings:
            if building.name == name:
                return building
        raise KeyError(name)

    @property
    def contacts(self) -> tuple[TomlTable, ...]:
        """Its ``[[contact]]`` tables, in order."""
        return tuple(self.table.tables("contact"))

    @property
    def walls(self) -> tuple[WallTable, ...]:
        """Its ``[[wall]]`` tables, in order."""
        return tuple(WallTable(table) for table in self.table.tables("wall"))

    @property
    def max_floors(self) -> int:
        """The most floors of any of its buildings (0 without buildings)."""
        return max((building.floors for building in self.buildings), default=0)

    def to_dict(self) -> SceneEntry:
        """The scene exactly as written (a deep copy: every field given, each number as spelled)."""
        return copy.deepcopy(dict(self.table.values))


@dataclass(frozen=True)
class SceneOverrides:
    """One variant's overrides of a scene, as written: ``building.<name>`` tables, a ``scene`` table and ``contact`` fields.

    Attributes
    ----------
    table : TomlTable
        The variant's table of overrides.
    """

    table: TomlTable

    @classmethod
    def of(cls, overrides: OverridesEntry, name: str = "") -> SceneOverrides:
        """The overrides dict of one variant (as an experiment's definition holds it)."""
        return cls(TomlTable(overrides, name))

    @cached_property
    def buildings(self) -> dict[str, TomlTable]:
        """The fields it gives each building, by the building's name (``mass_factor``, ``base`` and a building's own fields)."""
        given = self.table.table_or_empty("building")
        return {name: TomlTable(given.values[name], given.field(name)) for name in given}

    @cached_property
    def scene(self) -> SceneTables:
        """The scene-level fields it gives (``g``, ``[[wall]]``, ...), read as a scene."""
        return SceneTables(self.table.table_or_empty("scene"))

    @property
    def contacts(self) -> tuple[TomlTable, ...] | TomlTable | None:
        """The impact-element fields it gives: one table for every contact, one table per contact (a list), or None."""
        given = self.table.raw("contact")
        if isinstance(given, list):
            return tuple(self.table.tables("contact"))
        return None if given is None else TomlTable(given, self.table.field("contact"))

    def gives(self, building: str) -> set[str]:
        """The fields it gives building ``building`` (empty when it leaves the building as it is)."""
        return set(self.buildings[building]) if building in self.buildings else set()
