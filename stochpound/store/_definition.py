"""The experiment definition as typed, frozen records: what an experiment runs, read one way.

``stochpound.experiment._spec.parse_experiment`` validates an experiment
file and returns the *canonical definition*, a JSON-able dict (stored with
every store as the ``definition`` attribute). Everything that reads a
definition — a parsed file, a store's attribute, a dict — goes through
:func:`read_definition`, once, which returns a :class:`Definition`: the
grid's axes (:class:`GapAxis`, :class:`MuAxis`, :class:`VariantAxis`), the
motions (:class:`MotionSource`), the outputs (:class:`Output`), the solver
settings (:class:`Solver`), the intensity setting (:class:`Intensity`) and
the site's hazard (:class:`Hazard`). The canonical dict stays the stored
form; :meth:`Definition.to_dict` gives it back unchanged.

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
import hashlib
import json
import math
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from typing import Any

from stochpound._errors import ExperimentError
from stochpound.model.friction import is_fixed_base
from stochpound.motions import MEASURE_KINDS, Measure

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


def definition_sha256(definition: Mapping[str, Any]) -> str:
    """The experiment's identity: sha256 of the canonical definition's JSON without :data:`~stochpound.store.NOT_IN_IDENTITY`.

    What the runs depend on, and nothing else: a store is refused by an
    experiment of another identity, and kept (its runs valid) when only its
    ``hazard`` changed. A definition without a hazard hashes as it always did.
    """
    runs = {key: value for key, value in definition.items() if key not in NOT_IN_IDENTITY}
    return hashlib.sha256(canonical_json(runs).encode()).hexdigest()


MEASURES = MEASURE_KINDS
"""The intensity measures an ``[intensity]`` (and a ``[hazard]``) table may name (:data:`stochpound.motions.MEASURE_KINDS`)."""


def describe_measure(intensity: Mapping[str, Any]) -> str:
    """An intensity measure in words, e.g. ``PSA(T = 1 s, 5 % damping)`` or ``PGA`` (:attr:`~stochpound.motions.Measure.description`).

    Parameters
    ----------
    intensity : mapping
        ``measure`` (``pga``, ``pgv``, ``psa``, ``sa_avg``) and, for a spectral
        measure, ``period`` or ``periods`` (s) and ``damping`` (fraction of critical).
    """
    return Measure.from_entry(intensity).description


class _Entry(Mapping[str, Any]):
    """A typed record that reads as its canonical entry too (``setting["levels"]`` and ``setting.levels``)."""

    entry: Mapping[str, Any]

    def __getitem__(self, key: str) -> Any:
        return self.entry[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self.entry)

    def __len__(self) -> int:
        return len(self.entry)


@dataclass(frozen=True, eq=False)
class Intensity(_Entry):
    """The ``[intensity]`` setting: the measure the motions were scaled to, and how (docs/intensity.md).

    Attributes
    ----------
    measure : str
        ``pga``, ``pgv``, ``psa`` or ``sa_avg``.
    units : str
        Units of the levels (and of the measure).
    levels : tuple of float
        Target levels, ascending.
    method : str
        The method asked for (``stripes``, ``ida`` or ``auto``).
    ran : str
        The method that ran (``stripes`` or ``ida``).
    note : str
        Why that method ran.
    period : float or None
        Period of ``psa``, s.
    periods : tuple of float
        Periods of ``sa_avg``, s (empty otherwise).
    damping : float or None
        Damping ratio of a spectral measure.
    entry : mapping
        The canonical ``intensity`` entry (the record reads as it: ``setting["levels"]``).
    """

    measure: str
    units: str
    levels: tuple[float, ...]
    method: str
    ran: str
    note: str
    period: float | None
    periods: tuple[float, ...]
    damping: float | None
    entry: Mapping[str, Any] = field(repr=False)

    @classmethod
    def from_entry(cls, entry: Mapping[str, Any]) -> Intensity:
        """The typed setting of a canonical ``intensity`` entry."""
        return cls(entry["measure"], entry["units"], tuple(float(x) for x in entry["levels"]), entry["method"], entry["ran"], entry["note"],
                   entry.get("period"), tuple(entry.get("periods", ())), entry.get("damping"), entry)

    @property
    def description(self) -> str:
        """The measure in words (:func:`~stochpound.store.describe_measure`)."""
        return describe_measure(self.entry)


@dataclass(frozen=True, eq=False)
class Hazard(_Entry):
    """The site's hazard curve a store carries (the ``[hazard]`` table, docs/risk.md): its values and provenance.

    Not part of the runs' identity (:data:`~stochpound.store.NOT_IN_IDENTITY`): a new curve
    replaces the stored one without touching the runs.

    Attributes
    ----------
    source : str
        ``file``, ``bundled``, ``power_law`` or ``ruptures`` (the site of a rupture table, the entry's ``ruptures``).
    units : str
        Units of the intensities (the ``[intensity]`` levels').
    im, rate : tuple of float
        The table: intensities and their annual rates of exceedance, 1/yr (empty for a power law).
    power_law : mapping or None
        ``k0`` (1/yr) and ``k`` of λ(x) = k0 x^(−k), for a power law.
    extrapolate : bool
        Whether the curve is extrapolated beyond its table.
    provenance : str
        Where the curve came from, in words (the file's comment lines, the bundled curve's source).
    file, file_sha256 : str or None
        A file's path as given and the sha256 of its bytes when read.
    bundled : str or None
        A bundled curve's name.
    entry : mapping
        The canonical ``hazard`` entry (the record reads as it).
    """

    source: str
    units: str
    im: tuple[float, ...]
    rate: tuple[float, ...]
    power_law: Mapping[str, float] | None
    extrapolate: bool
    provenance: str
    file: str | None
    file_sha256: str | None
    bundled: str | None
    entry: Mapping[str, Any] = field(repr=False)

    @classmethod
    def from_entry(cls, entry: Mapping[str, Any]) -> Hazard:
        """The typed hazard of a canonical ``hazard`` entry."""
        return cls(entry["source"], entry["units"], tuple(entry.get("im", ())), tuple(entry.get("rate", ())), entry.get("power_law"),
                   entry["extrapolate"], entry["provenance"], entry.get("file"), entry.get("file_sha256"), entry.get("bundled"), entry)

    @property
    def description(self) -> str:
        """Its measure in words (:func:`~stochpound.store.describe_measure`)."""
        return describe_measure(self.entry)


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
    overrides: Mapping[str, Mapping[str, Any]]


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
    motion: Mapping[str, Any]
    start: int = 0
    count: int = 1
    suite: str | None = None

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
    canonical : mapping
        The canonical dict itself (every field, later ones included): :meth:`Definition.to_dict`.
    reproduces : str or None
        The part of a published study the experiment reproduces, ``"<study>:<part>"``
        (``stochpound.studies.STUDIES``); None: none (and for definitions stored before the field).
    hazard : Hazard or None
        The site's hazard curve, if any (not part of the identity).
    design : mapping or None
        The ``[design]`` table's canonical entry, the buildings' code design, if any (not part of the identity).
    limit_states : mapping or None
        The ``[limit_states]`` table's canonical entry (``source``, ``capacities``), if any (not part of the identity).
    scene_source : mapping or None
        Where the base scene was read from: ``file`` (its path, relative to the experiment file) or
        ``bundled`` (a bundled scene's name), and ``sha256`` (of the file's bytes); None: an inline
        scene (not part of the identity: ``scene`` holds the file's content).
    site : mapping or None
        How the stripes' scenario was obtained, with a ``[site]`` table: ``scenario`` (``"given"`` or
        ``"fitted"``) and, when fitted, the ``curves`` it was fitted to (not part of the identity: the
        runs depend on the scenarios themselves, ``intensity.site``); None: no ``[site]`` table (and for
        definitions stored before the field).
    """

    name: str
    description: str
    scene: Mapping[str, Any]
    studied: str
    variants: tuple[VariantAxis, ...]
    gaps: tuple[GapAxis, ...]
    mu: MuAxis | None
    motions: tuple[MotionSource, ...]
    output: Output
    solver: Solver
    intensity: Intensity | None
    format: int
    canonical: Mapping[str, Any]
    reproduces: str | None = None
    hazard: Hazard | None = None
    design: Mapping[str, Any] | None = None
    limit_states: Mapping[str, Any] | None = None
    scene_source: Mapping[str, str] | None = None
    site: Mapping[str, Any] | None = None

    def to_dict(self) -> dict[str, Any]:
        """The canonical definition (a copy): what ``parse_experiment`` returned (``stochpound.experiment._spec``)."""
        return copy.deepcopy(dict(self.canonical))

    @property
    def sha256(self) -> str:
        """The experiment's identity (:func:`~stochpound.store.definition_sha256`: what its runs depend on)."""
        return definition_sha256(self.canonical)

    @property
    def building_names(self) -> tuple[str, ...]:
        """Buildings of the base scene, left to right."""
        return tuple(b.get("name", f"B{i + 1}") for i, b in enumerate(self.scene.get("building", [])))

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
        return _from_dict(data)
    except (KeyError, TypeError) as error:
        raise ExperimentError(f"definition: missing or malformed field {error}") from None


def _from_dict(data: dict[str, Any]) -> Definition:
    for axis in [data["mu"], *data["gaps"]]:
        if axis is not None:
            axis["values"] = [float(v) for v in axis["values"]]
    mu = data["mu"]
    output = data["output"]
    return Definition(
        name=data["name"],
        description=data["description"],
        scene=data["scene"],
        studied=data["studied"],
        variants=tuple(VariantAxis(v["name"], tuple(v["values"]), v["overrides"]) for v in data["variants"]),
        gaps=tuple(GapAxis(g["name"], tuple(g["values"]), tuple(g["contacts"]), tuple(g.get("walls", ()))) for g in data["gaps"]),
        mu=MuAxis(tuple(mu["values"]), tuple(mu["buildings"]) if mu["buildings"] is not None else None) if mu is not None else None,
        motions=tuple(
            MotionSource(m["label"], m["kind"], m["field"], m["motion"], m.get("start", 0), m.get("count", 1), m.get("suite")) for m in data["motions"]
        ),
        output=Output(tuple(output["time_histories"]), tuple(output["buildings"]), output["impacts"], output.get("demands", False)),
        solver=Solver(**data["solver"]),
        intensity=Intensity.from_entry(data["intensity"]) if data.get("intensity") is not None else None,
        format=data["format"],
        canonical=data,
        reproduces=data.get("reproduces"),
        hazard=Hazard.from_entry(data["hazard"]) if data.get("hazard") is not None else None,
        design=data.get("design"),
        limit_states=data.get("limit_states"),
        scene_source=data.get("scene_source"),
        site=data.get("site"),
    )
