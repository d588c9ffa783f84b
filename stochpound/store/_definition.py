"""The experiment definition as typed, frozen records: what an experiment runs, read one way.

Each table of an experiment file parses to one of these records
(``stochpound.experiment._spec.parse_experiment``): the grid's axes
(:class:`GapAxis`, :class:`MuAxis`, :class:`VariantAxis`), the motions
(:class:`MotionSource`), the outputs (:class:`Output`), the solver settings
(:class:`Solver`), the intensity setting (:class:`Intensity`, its measure a
:class:`stochpound.motions.Measure`), the site's hazard (:class:`Hazard`), the
code design (:class:`Design`), the limit states (:class:`LimitStates`) and how
the stripes' scenario was obtained (:class:`Site`), gathered in a
:class:`Definition`. The *canonical definition*, a JSON-able dict stored with
every store as its ``definition`` attribute and hashed, is only written from
them (:meth:`Definition.to_dict`, each record's ``entry()``) and read back by
:func:`read_definition` (each record's ``from_entry``); written and read, it is
unchanged, so stored definitions and their sha256 are. Each entry's shape (its
keys, those written only when set) is declared once (:mod:`stochpound.store._definition_entries`).
The scene itself and a variant's overrides stay the scene file's tables as written
(:class:`~stochpound.model.scene_tables.SceneEntry`, :class:`~stochpound.model.scene_tables.OverridesEntry`:
what the model's scene builder reads). The scene's g is read in one place (:func:`scene_g`).

**The identity.** :func:`definition_sha256` hashes the canonical JSON
(:func:`canonical_json`) without the entries that no run depends on
(:data:`NOT_IN_IDENTITY`: the ``hazard``, the ``design`` and the ``limit_states``, read by the risk chain only, and
the ``scene_source``, the name and sha256 of the file a base scene was read from, whose content
the ``scene`` entry holds), so a store's runs stay valid when only its hazard changes, and an
experiment that inlines a scene file's content has the identity of one that names the file. A definition without
those entries hashes exactly as before.

The rules that name parts of a grid live once, and the store's namespace
gives them with the definition: that a gap axis is ``gap`` or ``gap_<name>``
(``is_gap_axis``, ``stochpound.store._gap_axes``, which selects contact-free
cases too); that μ = ∞ is a fixed base (``FIXED_BASE``, ``is_fixed_base``) is
the model's rule (:mod:`stochpound.model.friction`).
"""

from __future__ import annotations

import copy
import dataclasses
import hashlib
import json
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, TypeVar

from stochpound._errors import ExperimentError
from stochpound.model.fields import TomlTable
from stochpound.model.friction import is_fixed_base
from stochpound.model.scene_tables import MotionEntry, OverridesEntry, SceneEntry, SceneOverrides, SceneTables
from stochpound.motions import MEASURE_KINDS, Measure
from stochpound.store._design_isolation import DesignIsolation
from stochpound.store._definition_entries import (
    DefinitionEntry,
    DesignEntry,
    GapAxisEntry,
    HazardEntry,
    IntensityEntry,
    LimitStatesEntry,
    MotionSourceEntry,
    MuAxisEntry,
    OutputEntry,
    SceneSourceEntry,
    SiteEntry,
    SolverEntry,
    VariantAxisEntry,
)
from stochpound.store._stripe_selection import Selection

_Record = TypeVar("_Record")

NOT_IN_IDENTITY = ("hazard", "design", "scene_source", "site", "limit_states")
"""Entries of a canonical definition that no run depends on, left out of its identity (:func:`~stochpound.store.definition_sha256`)."""


def canonical_json(value: Any) -> str:
    """Deterministic JSON (sorted keys, inf as the string "inf")."""
    return json.dumps(_jsonable(value), sort_keys=True, separators=(",", ":"))


def _jsonable(value: Any) -> Any:
    if isinstance(value, float) and math.isinf(value):
        return "inf" if value > 0 else "-inf"
    if isinstance(value, Mapping):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_jsonable(v) for v in value]
    return value


def definition_sha256(definition: DefinitionEntry) -> str:
    """The experiment's identity: sha256 of the canonical definition's JSON without :data:`~stochpound.store.NOT_IN_IDENTITY`.

    What the runs depend on, and nothing else: a store is refused by an
    experiment of another identity, and kept (its runs valid) when only its
    ``hazard`` changed. A definition without a hazard hashes as it always did.
    """
    runs = {key: value for key, value in definition.items() if key not in NOT_IN_IDENTITY}
    return hashlib.sha256(canonical_json(runs).encode()).hexdigest()


MEASURES = MEASURE_KINDS
"""The intensity measures an ``[intensity]`` (and a ``[hazard]``) table may name (:data:`stochpound.motions.MEASURE_KINDS`)."""


def scene_g(scene: SceneEntry) -> float:
    """A scene dict's acceleration of gravity, m/s²: its ``g``, or ``stochpound.motions.DEFAULT_G`` (9.81) when it leaves it out
    (:attr:`stochpound.model.scene_tables.SceneTables.g`, the one reader)."""
    return SceneTables.of(scene).g




@dataclass(frozen=True)
class Intensity:
    """The ``[intensity]`` setting: the measure the motions were scaled to, and how (docs/intensity.md).

    Attributes
    ----------
    measure : Measure
        The intensity measure (:class:`stochpound.motions.Measure`; its ``kind`` is ``pga``, ``pgv``, ``psa`` or ``sa_avg``).
    units : str
        Units of the levels (and of the measure).
    levels : tuple of float
        Target levels, ascending.
    method : str
        The method asked for (``stripes`` or ``ida``).
    ran : str
        The method that ran (``stripes`` or ``ida``).
    note : str
        Why that method ran (with a conditional-spectrum selection: how the stripes' motions were chosen).
    synthetic : str or None
        How a synthetic ensemble is scaled (``each`` or ``expected``); None for a definition stored before the field.
    selection : Selection or None
        How a conditional-spectrum selection chooses the stripes' motions (:class:`~stochpound.store.Selection`);
        None for the default ``scale``, which adds nothing to the entry.
    """

    measure: Measure
    units: str
    levels: tuple[float, ...]
    method: str
    ran: str
    note: str
    synthetic: str | None = None
    selection: Selection | None = None

    @classmethod
    def from_entry(cls, entry: IntensityEntry) -> Intensity:
        """The typed setting of a canonical ``intensity`` entry."""
        return cls(Measure.from_entry(entry), entry["units"], tuple(float(x) for x in entry["levels"]), entry["method"], entry["ran"],
                   entry["note"], TomlTable(entry).raw("synthetic"), Selection.from_entry(entry))

    def entry(self) -> IntensityEntry:
        """The canonical ``intensity`` entry (as definitions store it)."""
        written: IntensityEntry = {**self.measure.entry(), "levels": list(self.levels), "units": self.units, "method": self.method}
        if self.synthetic is not None:
            written["synthetic"] = self.synthetic
        written.update(ran=self.ran, note=self.note)
        written.update(self.selection.entry() if self.selection is not None else {})
        return written

    @property
    def description(self) -> str:
        """The measure in words (:attr:`stochpound.motions.Measure.description`)."""
        return self.measure.description

    @property
    def selection_method(self) -> str:
        """How the stripes' motions were chosen: ``scale`` (every motion scaled to every level) or ``conditional_spectrum``."""
        return self.selection.method if self.selection is not None else "scale"


@dataclass(frozen=True)
class Hazard:
    """The site's hazard curve a store carries (the ``[hazard]`` table, docs/risk.md): its values and provenance.

    Not part of the runs' identity (:data:`~stochpound.store.NOT_IN_IDENTITY`): a new curve
    replaces the stored one without touching the runs.

    Attributes
    ----------
    source : str
        ``file``, ``bundled``, ``power_law`` or ``ruptures`` (the site of a rupture table).
    measure : Measure
        The curve's intensity measure (the ``[intensity]`` measure).
    units : str
        Units of the intensities (the ``[intensity]`` levels').
    extrapolate : bool
        Whether the curve is extrapolated beyond its table.
    provenance : str
        Where the curve came from, in words (the file's comment lines, the bundled curve's source).
    im, rate : tuple of float
        The table: intensities and their annual rates of exceedance, 1/yr (empty for a power law).
    power_law : mapping or None
        ``k0`` (1/yr) and ``k`` of λ(x) = k0 x^(−k), for a power law.
    file, file_sha256 : str or None
        A file's path as given and the sha256 of its bytes when read.
    bundled : str or None
        A bundled curve's name.
    ruptures : str or None
        The rupture table (a file or a bundled site's name) of a ``ruptures`` source.
    """

    source: str
    measure: Measure
    units: str
    extrapolate: bool
    provenance: str
    im: tuple[float, ...] = ()
    rate: tuple[float, ...] = ()
    power_law: Mapping[str, float] | None = None
    file: str | None = None
    file_sha256: str | None = None
    bundled: str | None = None
    ruptures: str | None = None

    @classmethod
    def from_entry(cls, entry: HazardEntry) -> Hazard:
        """The typed hazard of a canonical ``hazard`` entry."""
        given = TomlTable(entry, "hazard")
        return cls(entry["source"], Measure.from_entry(entry), entry["units"], entry["extrapolate"], entry["provenance"],
                   tuple(given.raw("im", ())), tuple(given.raw("rate", ())), given.raw("power_law"), given.raw("file"),
                   given.raw("file_sha256"), given.raw("bundled"), given.raw("ruptures"))

    def entry(self) -> HazardEntry:
        """The canonical ``hazard`` entry (as definitions store it)."""
        written: HazardEntry = {"source": self.source, **self.measure.entry(), "units": self.units, "extrapolate": self.extrapolate}
        sources = {"bundled": self.bundled, "file": self.file, "file_sha256": self.file_sha256, "ruptures": self.ruptures,
                   "power_law": dict(self.power_law) if self.power_law is not None else None}
        written.update({key: value for key, value in sources.items() if value is not None})
        if self.im:
            written.update(im=list(self.im), rate=list(self.rate))
        written["provenance"] = self.provenance
        return written

    @property
    def description(self) -> str:
        """Its measure in words (:attr:`stochpound.motions.Measure.description`)."""
        return self.measure.description


@dataclass(frozen=True)
class DesignEc8:
    """The ``ec8`` part of a ``[design]`` table: Eurocode 8's design of the buildings.

    Attributes
    ----------
    ag : float
        Design ground acceleration on type A ground (g).
    ground : str
        Ground type, ``A`` to ``E`` (Type 1 spectrum).
    q : float
        Behaviour factor (≥ 1).
    """

    ag: float
    ground: str
    q: float


@dataclass(frozen=True)
class Design:
    """The ``[design]`` table: the code design the buildings were given, for the codes' own separations (docs/risk.md).

    Not part of the runs' identity (:data:`~stochpound.store.NOT_IN_IDENTITY`).

    Attributes
    ----------
    sds, sd1 : float
        ASCE 7-16 design spectral accelerations S_DS and S_D1 (g).
    tl : float
        Long-period transition period T_L (s).
    r, cd, omega0 : float
        The system's R, C_d and Ω0.
    ie : float
        Importance factor I_e.
    sm1 : float or None
        MCE_R spectral acceleration at 1 s, S_M1 (g), for a building on a friction pendulum; None: not given.
    ec8 : DesignEc8 or None
        Eurocode 8's design, if given.
    isolation : DesignIsolation or None
        ASCE 7-16 chapter 17's inputs for a building on a sliding base, if given.
    """

    sds: float
    sd1: float
    tl: float
    r: float
    cd: float
    omega0: float
    ie: float
    sm1: float | None = None
    ec8: DesignEc8 | None = None
    isolation: DesignIsolation | None = None

    @classmethod
    def from_entry(cls, entry: DesignEntry) -> Design:
        """The typed design of a canonical ``design`` entry."""
        given = TomlTable(entry, "design")
        ec8 = given.raw("ec8")
        isolation = given.raw("isolation")
        return cls(entry["sds"], entry["sd1"], entry["tl"], entry["r"], entry["cd"], entry["omega0"], entry["ie"], given.raw("sm1"),
                   DesignEc8(ec8["ag"], ec8["ground"], ec8["q"]) if ec8 is not None else None,
                   DesignIsolation.from_entry(isolation) if isolation is not None else None)

    def entry(self) -> DesignEntry:
        """The canonical ``design`` entry (as definitions store it)."""
        written: DesignEntry = {"sds": self.sds, "sd1": self.sd1, "tl": self.tl, "r": self.r, "cd": self.cd, "omega0": self.omega0, "ie": self.ie}
        if self.sm1 is not None:
            written["sm1"] = self.sm1
        if self.ec8 is not None:
            written["ec8"] = {"ag": self.ec8.ag, "ground": self.ec8.ground, "q": self.ec8.q}
        if self.isolation is not None:
            written["isolation"] = self.isolation.entry()
        return written


@dataclass(frozen=True)
class LimitStateCapacities:
    """The capacities one ``[limit_states]`` key gives, for one building or for any.

    Attributes
    ----------
    kind : str
        The kind of limit state (:data:`~stochpound.store.LIMIT_STATE_DEMANDS`).
    capacities : tuple of float
        Its capacities, in the kind's units.
    building : str or None
        The building they apply to; None: any building.
    targets : tuple of float or None
        Each capacity's performance objective, a probability in 50 years; None: not given.
    """

    kind: str
    capacities: tuple[float, ...]
    building: str | None = None
    targets: tuple[float, ...] | None = None


@dataclass(frozen=True)
class LimitStates:
    """The ``[limit_states]`` table: the capacities a report's Damage section evaluates (docs/risk.md).

    Not part of the runs' identity (:data:`~stochpound.store.NOT_IN_IDENTITY`).

    Attributes
    ----------
    source : str or None
        Where the capacities come from, as the table states; None: not stated.
    states : tuple of LimitStateCapacities
        The capacities, in the table's order (by kind, then building).
    """

    source: str | None
    states: tuple[LimitStateCapacities, ...]

    @classmethod
    def from_entry(cls, entry: LimitStatesEntry) -> LimitStates:
        """The typed limit states of a canonical ``limit_states`` entry."""
        states = []
        for kind, value in entry["capacities"].items():
            per_building = value.items() if isinstance(value, Mapping) else [(None, value)]
            states += [LimitStateCapacities(kind, tuple(float(c) for c in capacities), building) for building, capacities in per_building]
        if "targets" in entry:  # shaped as the capacities: per kind a list, or per building a list
            targets = entry["targets"]
            states = [dataclasses.replace(state, targets=_state_targets(targets, state)) for state in states]
        return cls(entry["source"], tuple(states))

    def entry(self) -> LimitStatesEntry:
        """The canonical ``limit_states`` entry (as definitions store it)."""
        capacities: dict[str, list[float] | dict[str, list[float]]] = {}
        for state in self.states:
            if state.building is None:
                capacities[state.kind] = list(state.capacities)
            else:
                capacities.setdefault(state.kind, {})[state.building] = list(state.capacities)
        written = {"source": self.source, "capacities": capacities}
        targets: dict[str, list[float] | dict[str, list[float]]] = {}
        for state in (state for state in self.states if state.targets is not None):
            if state.building is None:
                targets[state.kind] = list(state.targets)
            else:
                targets.setdefault(state.kind, {})[state.building] = list(state.targets)
        if targets:
            written["targets"] = targets
        return written


def _state_targets(targets: Mapping[str, list[float] | Mapping[str, list[float]]], state: LimitStateCapacities) -> tuple[float, ...] | None:
    """A state's targets in a canonical ``limit_states`` entry's ``targets`` (shaped as its capacities), None where not given."""
    given = targets[state.kind] if state.kind in targets else None
    if isinstance(given, Mapping):
        given = given[state.building] if state.building in given else None
    return None if given is None else tuple(float(t) for t in given)


@dataclass(frozen=True)
class Site:
    """How the stripes' scenario was obtained, with a ``[site]`` table (docs/intensity.md).

    Not part of the runs' identity (:data:`~stochpound.store.NOT_IN_IDENTITY`): the runs depend on the scenarios
    themselves (the ``intensity`` entry's ``site``).

    Attributes
    ----------
    scenario : str
        ``given``, ``fitted`` or ``ruptures`` (:data:`~stochpound.store.SCENARIO_KINDS`).
    curves : tuple of str or None
        The site's hazard curves a fitted scenario was fitted to; None otherwise.
    ruptures : str or None
        The rupture table (a file or a bundled site's name) of a site of ruptures; None otherwise.
    """

    scenario: str
    curves: tuple[str, ...] | None = None
    ruptures: str | None = None

    @classmethod
    def from_entry(cls, entry: SiteEntry) -> Site:
        """The typed site of a canonical ``site`` entry."""
        given = TomlTable(entry, "site")
        curves = given.raw("curves")
        return cls(entry["scenario"], tuple(curves) if curves is not None else None, given.raw("ruptures"))

    def entry(self) -> SiteEntry:
        """The canonical ``site`` entry (as definitions store it)."""
        written: SiteEntry = {"scenario": self.scenario}
        if self.ruptures is not None:
            written["ruptures"] = self.ruptures
        if self.curves is not None:
            written["curves"] = list(self.curves)
        return written


@dataclass(frozen=True)
class GapAxis:
    """A grid axis of at-rest gaps, set on some contacts and walls.

    Attributes
    ----------
    name : str
        The axis (store dimension): ``gap`` or ``gap_<name>``.
    values : tuple of float
        Gaps, m (∞: never closes, contact-free).
    contacts : tuple of int
        Indices of the scene's contacts whose gap the axis sets.
    walls : tuple of int
        Indices of the scene's walls whose gap the axis sets.
    """

    name: str
    values: tuple[float, ...]
    contacts: tuple[int, ...]
    walls: tuple[int, ...] = ()

    def entry(self) -> GapAxisEntry:
        """The canonical entry of the axis (``walls`` only when it sets walls)."""
        written: GapAxisEntry = {"name": self.name, "values": list(self.values), "contacts": list(self.contacts)}
        if self.walls:
            written["walls"] = list(self.walls)
        return written

    @property
    def targets(self) -> str:
        """What the axis sets, in words: ``contacts 0, 1``, ``walls 0`` or both."""
        parts = [f"{what} {', '.join(map(str, indices))}" for what, indices in (("contacts", self.contacts), ("walls", self.walls)) if indices]
        return " and ".join(parts)


@dataclass(frozen=True)
class MuAxis:
    """The grid's friction coefficients.

    Attributes
    ----------
    values : tuple of float
        Friction coefficients μ (kinetic and static), dimensionless; :data:`FIXED_BASE` removes the base.
    buildings : tuple of str or None
        The buildings it sets; None: every building on a sliding base.
    """

    values: tuple[float, ...]
    buildings: tuple[str, ...] | None

    def entry(self) -> MuAxisEntry:
        """The canonical entry of the axis."""
        return {"values": list(self.values), "buildings": list(self.buildings) if self.buildings is not None else None}

    def sets(self, building: str, has_base: bool) -> bool:
        """Whether the axis sets this building's friction (a building in ``buildings``, or any building on a base)."""
        return building in self.buildings if self.buildings is not None else has_base

    @property
    def finite_values(self) -> tuple[float, ...]:
        """The values that keep a sliding base (not :data:`FIXED_BASE`)."""
        return tuple(v for v in self.values if not is_fixed_base(v))

    @property
    def has_fixed_base(self) -> bool:
        """Whether :data:`FIXED_BASE` is one of the values."""
        return len(self.finite_values) < len(self.values)


@dataclass(frozen=True)
class VariantAxis:
    """A grid axis of named variants of the base scene.

    Attributes
    ----------
    name : str
        The axis (store dimension).
    values : tuple of str
        The variants run, in grid order.
    overrides : mapping
        Each declared variant's overrides (``building``, ``scene``, ``contact`` tables), by name.
    """

    name: str
    values: tuple[str, ...]
    overrides: Mapping[str, OverridesEntry]

    def entry(self) -> VariantAxisEntry:
        """The canonical entry of the axis (its overrides copied)."""
        return {"name": self.name, "values": list(self.values), "overrides": copy.deepcopy(dict(self.overrides))}

    @property
    def edits(self) -> dict[str, SceneOverrides]:
        """Each declared variant's overrides read as typed parts (:class:`~stochpound.model.scene_tables.SceneOverrides`), by name."""
        return {value: SceneOverrides.of(overrides, f"{self.name}.{value}") for value, overrides in self.overrides.items()}


@dataclass(frozen=True)
class MotionSource:
    """One ground motion of the experiment: a record (or analytic motion), or a synthetic ensemble.

    Attributes
    ----------
    label : str
        Its value on the ``record`` dimension.
    kind : str
        ``record`` (one realization, 0) or ``synthetic`` (realizations ``start`` .. ``start + count − 1``).
    field : str
        The experiment file's field that declared it (for messages).
    motion : mapping
        The scene ``[motion]`` table (a record's ``file_sha256`` included).
    start, count : int
        First realization and number of realizations (0 and 1 for a record).
    suite : str or None
        The suite (or folder) the record came from, if any.
    """

    label: str
    kind: str
    field: str
    motion: MotionEntry
    start: int = 0
    count: int = 1
    suite: str | None = None

    def entry(self) -> MotionSourceEntry:
        """The canonical entry of the motion (``start`` and ``count`` for an ensemble, ``suite`` for a suite's record)."""
        written: MotionSourceEntry = {"label": self.label, "kind": self.kind, "field": self.field, "motion": copy.deepcopy(dict(self.motion))}
        if self.kind == "synthetic":
            written.update(start=self.start, count=self.count)
        if self.suite is not None:
            written["suite"] = self.suite
        return written

    @property
    def type(self) -> str:
        """The ``[motion]`` table's ``type``: ``record`` when it gives none (as the scene's reader takes it)."""
        return TomlTable(self.motion).raw("type", "record")

    @property
    def realizations(self) -> range:
        """Realization indices: 0 for a record, ``start`` .. ``start + count − 1`` for an ensemble."""
        return range(self.start, self.start + self.count)


@dataclass(frozen=True)
class Output:
    """What a store keeps.

    Attributes
    ----------
    time_histories : tuple of str
        Time-history variables kept (``spec.TIME_HISTORY_VARIABLES``).
    buildings : tuple of str
        Buildings whose time histories are kept.
    impacts : bool
        Whether the table of impacts is kept.
    demands : bool
        Whether the demand summaries are kept.
    """

    time_histories: tuple[str, ...]
    buildings: tuple[str, ...]
    impacts: bool
    demands: bool = False

    def entry(self) -> OutputEntry:
        """The canonical ``output`` entry (``demands`` only when kept)."""
        written: OutputEntry = {"time_histories": list(self.time_histories), "buildings": list(self.buildings), "impacts": self.impacts}
        if self.demands:
            written["demands"] = True
        return written


@dataclass(frozen=True)
class Solver:
    """Solver settings of every case.

    Attributes
    ----------
    method : str
        ``auto`` or a method of :func:`stochpound.simulate`.
    integrator : str
        The ODE integrator of the ``ivp`` method.
    rtol, atol : float
        Relative and absolute tolerances (absolute in m and m/s).
    """

    method: str
    integrator: str
    rtol: float
    atol: float

    def entry(self) -> SolverEntry:
        """The canonical ``solver`` entry."""
        return {"method": self.method, "integrator": self.integrator, "rtol": self.rtol, "atol": self.atol}


@dataclass(frozen=True)
class Definition:
    """An experiment's definition, typed (:func:`read_definition`).

    Attributes
    ----------
    name, description : str
        The experiment's name and description.
    scene : mapping
        The base scene's dict (its ``[motion]`` included when it has one).
    studied : str
        The studied building.
    variants : tuple of VariantAxis
        Variant axes, in grid order.
    gaps : tuple of GapAxis
        Gap axes, in grid order.
    mu : MuAxis or None
        The μ axis, if any.
    motions : tuple of MotionSource
        The motions, in ``record`` order.
    output : Output
        What the store keeps.
    solver : Solver
        Solver settings.
    intensity : Intensity or None
        The ``[intensity]`` setting, if any.
    format : int
        Format version of the canonical definition.
    reproduces : str or None
        The part of a published study the experiment reproduces, ``"<study>:<part>"``
        (``stochpound.studies.STUDIES``); None: none (and for definitions stored before the field).
    hazard : Hazard or None
        The site's hazard curve, if any (not part of the identity).
    design : Design or None
        The ``[design]`` table, the buildings' code design, if any (not part of the identity).
    limit_states : LimitStates or None
        The ``[limit_states]`` table (its ``source`` and capacities), if any (not part of the identity).
    scene_source : mapping or None
        Where the base scene was read from: ``file`` (its path, relative to the experiment file) or
        ``bundled`` (a bundled scene's name), and ``sha256`` (of the file's bytes); None: an inline
        scene (not part of the identity: ``scene`` holds the file's content).
    site : Site or None
        How the stripes' scenario was obtained, with a ``[site]`` table (not part of the identity: the
        runs depend on the scenarios themselves, the intensity's ``site``); None: no ``[site]`` table (and for
        definitions stored before the field).
    """

    name: str
    description: str
    scene: SceneEntry
    studied: str
    variants: tuple[VariantAxis, ...]
    gaps: tuple[GapAxis, ...]
    mu: MuAxis | None
    motions: tuple[MotionSource, ...]
    output: Output
    solver: Solver
    intensity: Intensity | None
    format: int
    reproduces: str | None = None
    hazard: Hazard | None = None
    design: Design | None = None
    limit_states: LimitStates | None = None
    scene_source: SceneSourceEntry | None = None
    site: Site | None = None

    def to_dict(self) -> DefinitionEntry:
        """The canonical definition, written from the records: what ``parse_experiment`` returns (``stochpound.experiment._spec``).

        Optional entries are written only when set, so the definitions (and identities) of files without them are unchanged.
        """
        written: DefinitionEntry = {
            "format": self.format, "name": self.name, "description": self.description, "scene": copy.deepcopy(dict(self.scene)),
            "studied": self.studied, "variants": [axis.entry() for axis in self.variants], "gaps": [axis.entry() for axis in self.gaps],
            "mu": self.mu.entry() if self.mu is not None else None, "motions": [motion.entry() for motion in self.motions],
            "output": self.output.entry(), "solver": self.solver.entry(),
        }
        optional = {"scene_source": dict(self.scene_source) if self.scene_source is not None else None, "reproduces": self.reproduces,
                    **{key: record.entry() if record is not None else None for key, record in
                       (("intensity", self.intensity), ("hazard", self.hazard), ("design", self.design), ("limit_states", self.limit_states),
                        ("site", self.site))}}
        written.update({key: value for key, value in optional.items() if value is not None})
        return written

    @property
    def sha256(self) -> str:
        """The experiment's identity (:func:`~stochpound.store.definition_sha256`: what its runs depend on)."""
        return definition_sha256(self.to_dict())

    @property
    def tables(self) -> SceneTables:
        """The base scene read as typed parts (:class:`~stochpound.model.scene_tables.SceneTables`: its buildings, contacts, walls, g)."""
        return SceneTables.of(self.scene)

    @property
    def g(self) -> float:
        """The scene's acceleration of gravity, m/s² (``stochpound.motions.DEFAULT_G`` (9.81) when the scene leaves it out)."""
        return self.tables.g

    @property
    def building_names(self) -> tuple[str, ...]:
        """Buildings of the base scene, left to right."""
        return self.tables.building_names

    def gap_axis(self, name: str) -> GapAxis:
        """The gap axis called ``name`` (KeyError if none)."""
        for axis in self.gaps:
            if axis.name == name:
                return axis
        raise KeyError(name)

    def contact_gap_axis(self, contact: int) -> GapAxis | None:
        """The gap axis that sets a contact's gap, if any."""
        return next((g for g in self.gaps if contact in g.contacts), None)

    def wall_gap_axis(self, wall: int) -> GapAxis | None:
        """The gap axis that sets a wall's gap, if any."""
        return next((g for g in self.gaps if wall in g.walls), None)

    def motion(self, label: str) -> MotionSource:
        """The motion labelled ``label`` (KeyError if none)."""
        for motion in self.motions:
            if motion.label == label:
                return motion
        raise KeyError(label)


def read_definition(source: Any) -> Definition:
    """The typed definition of a store, a canonical dict, or its JSON text.

    Parameters
    ----------
    source : xarray.Dataset, mapping, str or Definition
        A store (its ``definition`` attribute, JSON), a canonical definition
        (``stochpound.experiment._spec.parse_experiment``), its JSON text,
        or a :class:`Definition` (returned as is).

    Returns
    -------
    Definition
        Axis values are floats again (JSON spells ∞ ``"inf"``); the sha256 is unchanged.

    Raises
    ------
    ExperimentError
        If a store has no ``definition`` attribute or the definition lacks a field.
    """
    if isinstance(source, Definition):
        return source
    if hasattr(source, "attrs"):
        if "definition" not in source.attrs:
            raise ExperimentError("not a stochpound experiment store (no definition attribute)")
        source = source.attrs["definition"]
    data = json.loads(source) if isinstance(source, str) else copy.deepcopy(dict(source))
    try:
        return _from_dict(TomlTable(data, "definition"))
    except (KeyError, TypeError, ValueError) as error:
        raise ExperimentError(f"definition: missing or malformed field {error}") from None


def _from_dict(data: TomlTable) -> Definition:
    """The typed definition of a canonical one (a copy: its axes' values become floats again; a missing field raises KeyError)."""
    given = data.values
    for axis in [given["mu"], *given["gaps"]]:
        if axis is not None:
            axis["values"] = [float(v) for v in axis["values"]]
    mu, output = given["mu"], TomlTable(given["output"], "output")
    return Definition(
        name=given["name"],
        description=given["description"],
        scene=given["scene"],
        studied=given["studied"],
        variants=tuple(VariantAxis(v["name"], tuple(v["values"]), v["overrides"]) for v in given["variants"]),
        gaps=tuple(_gap_axis(TomlTable(gap)) for gap in given["gaps"]),
        mu=MuAxis(tuple(mu["values"]), tuple(mu["buildings"]) if mu["buildings"] is not None else None) if mu is not None else None,
        motions=tuple(_motion_source(TomlTable(motion)) for motion in given["motions"]),
        output=Output(tuple(output.values["time_histories"]), tuple(output.values["buildings"]), output.values["impacts"], output.raw("demands", False)),
        solver=Solver(**given["solver"]),
        intensity=_optional(data, "intensity", Intensity.from_entry),
        format=given["format"],
        reproduces=data.raw("reproduces"),
        hazard=_optional(data, "hazard", Hazard.from_entry),
        design=_optional(data, "design", Design.from_entry),
        limit_states=_optional(data, "limit_states", LimitStates.from_entry),
        scene_source=data.raw("scene_source"),
        site=_optional(data, "site", Site.from_entry),
    )


def _gap_axis(entry: TomlTable) -> GapAxis:
    """The gap axis of a canonical ``gaps`` entry."""
    return GapAxis(entry.values["name"], tuple(entry.values["values"]), tuple(entry.values["contacts"]), tuple(entry.raw("walls", ())))


def _motion_source(entry: TomlTable) -> MotionSource:
    """The motion of a canonical ``motions`` entry."""
    given = entry.values
    return MotionSource(given["label"], given["kind"], given["field"], given["motion"], entry.raw("start", 0), entry.raw("count", 1), entry.raw("suite"))


def _optional(data: TomlTable, key: str, read: Callable[..., _Record]) -> _Record | None:
    """The record of an optional entry (None when absent; ``read``: the record's ``from_entry``)."""
    entry = data.raw(key)
    return read(entry) if entry is not None else None
