"""The canonical definition's shape: the JSON payload a store's ``definition`` attribute holds, entry by entry.

Each typed record of :mod:`stochpound.store._definition` writes one of these
entries (its ``entry()``) and reads it back (its ``from_entry``); they declare the
keys written, so what a record writes and reads is a known shape, not a loose dict.
The keys a record writes only when set are ``NotRequired`` (an entry without them
hashes as before; annotations here are not postponed, so Python reads ``NotRequired``,
and tests/test_definition_entries.py checks every shipped definition against these shapes).
The scene and a variant's overrides are the scene file's tables as written (:class:`~stochpound.model.scene_tables.SceneEntry`,
:class:`~stochpound.model.scene_tables.OverridesEntry`).
"""

from collections.abc import Mapping
from typing import NotRequired, TypedDict

from stochpound.model.scene_tables import MotionEntry, OverridesEntry, SceneEntry
from stochpound.store._design_isolation import IsolationValue


class ScenarioEntry(TypedDict):
    """One stripe's scenario in an ``intensity`` entry's ``site`` (:meth:`stochpound.motions.Scenario.loose`)."""

    magnitude: float
    distance_km: float
    vs30: float
    mechanism: str


class SimulatedMotionsEntry(TypedDict):
    """The ``simulated_motions`` of a conditional-spectrum selection."""

    count: int
    model: str
    calibration: str
    seed: int
    dt: float
    sampling: NotRequired[str]


class IntensityEntry(TypedDict):
    """The ``intensity`` entry: the measure's keys, the levels and the method; a selection's keys only with one."""

    measure: str
    period: NotRequired[float]
    periods: NotRequired[list[float]]
    damping: NotRequired[float]
    levels: list[float]
    units: str
    method: str
    synthetic: NotRequired[str]
    ran: str
    note: str
    selection: NotRequired[str]
    motions: NotRequired[int]
    max_scale_factor: NotRequired[float]
    seed: NotRequired[int]
    max_per_earthquake: NotRequired[int]
    exclude_pulses: NotRequired[bool]
    tolerance_first: NotRequired[bool]
    site: NotRequired[list[ScenarioEntry]]
    ruptures: NotRequired[Mapping[str, object]]  # a site of ruptures' own entry (stochpound.analysis.RuptureSite.to_entry)
    simulated_motions: NotRequired[SimulatedMotionsEntry]


class PowerLawEntry(TypedDict):
    """A power-law hazard curve λ(x) = k0 x^(−k)."""

    k0: float
    k: float


class HazardEntry(TypedDict):
    """The ``hazard`` entry: the curve's source, measure, units and provenance; its table or power law."""

    source: str
    measure: str
    period: NotRequired[float]
    periods: NotRequired[list[float]]
    damping: NotRequired[float]
    units: str
    extrapolate: bool
    bundled: NotRequired[str]
    file: NotRequired[str]
    file_sha256: NotRequired[str]
    ruptures: NotRequired[str]
    power_law: NotRequired[PowerLawEntry]
    im: NotRequired[list[float]]
    rate: NotRequired[list[float]]
    provenance: str


class DesignEc8Entry(TypedDict):
    """The ``ec8`` part of a ``design`` entry."""

    ag: float
    ground: str
    q: float


class DesignEntry(TypedDict):
    """The ``design`` entry: ASCE 7-16's design values; ``sm1``, ``ec8`` and ``isolation`` (chapter 17's inputs) only when given."""

    sds: float
    sd1: float
    tl: float
    r: float
    cd: float
    omega0: float
    ie: float
    sm1: NotRequired[float]
    ec8: NotRequired[DesignEc8Entry]
    isolation: NotRequired[dict[str, IsolationValue]]


class LimitStatesEntry(TypedDict):
    """The ``limit_states`` entry: its source and, by kind, the capacities (and, when given, the target rates) for any building or by building name."""

    source: str | None
    capacities: dict[str, list[float] | dict[str, list[float]]]
    targets: NotRequired[dict[str, list[float] | dict[str, list[float]]]]


class SiteEntry(TypedDict):
    """The ``site`` entry: how the stripes' scenario was obtained."""

    scenario: str
    ruptures: NotRequired[str]
    curves: NotRequired[list[str]]


class GapAxisEntry(TypedDict):
    """One ``gaps`` entry (``walls`` only when the axis sets walls)."""

    name: str
    values: list[float]
    contacts: list[int]
    walls: NotRequired[list[int]]


class MuAxisEntry(TypedDict):
    """The ``mu`` entry (``buildings`` None: every building on a sliding base)."""

    values: list[float]
    buildings: list[str] | None


class VariantAxisEntry(TypedDict):
    """One ``variants`` entry: the values run and each declared variant's overrides, by name."""

    name: str
    values: list[str]
    overrides: dict[str, OverridesEntry]


class MotionSourceEntry(TypedDict):
    """One ``motions`` entry (``start`` and ``count`` for an ensemble, ``suite`` for a suite's record)."""

    label: str
    kind: str
    field: str
    motion: MotionEntry
    start: NotRequired[int]
    count: NotRequired[int]
    suite: NotRequired[str]


class OutputEntry(TypedDict):
    """The ``output`` entry (``demands`` only when kept)."""

    time_histories: list[str]
    buildings: list[str]
    impacts: bool
    demands: NotRequired[bool]


class SolverEntry(TypedDict):
    """The ``solver`` entry."""

    method: str
    integrator: str
    rtol: float
    atol: float


class SceneSourceEntry(TypedDict, total=False):
    """The ``scene_source`` entry: a scene file's path (``file``) or a bundled scene's name (``bundled``), and its ``sha256``."""

    file: str
    bundled: str
    sha256: str


class DefinitionEntry(TypedDict):
    """The canonical definition (:meth:`~stochpound.store.Definition.to_dict`); the optional entries only when set."""

    format: int
    name: str
    description: str
    scene: SceneEntry
    studied: str
    variants: list[VariantAxisEntry]
    gaps: list[GapAxisEntry]
    mu: MuAxisEntry | None
    motions: list[MotionSourceEntry]
    output: OutputEntry
    solver: SolverEntry
    scene_source: NotRequired[SceneSourceEntry]
    reproduces: NotRequired[str]
    intensity: NotRequired[IntensityEntry]
    hazard: NotRequired[HazardEntry]
    design: NotRequired[DesignEntry]
    limit_states: NotRequired[LimitStatesEntry]
    site: NotRequired[SiteEntry]
