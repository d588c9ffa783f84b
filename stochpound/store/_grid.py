"""What an experiment is: its grid's dimensions, cases with stable ids, and each case's scene.

Two kinds of case exist:

* ``case``: one point of the grid (variant axes × gap axes × μ × intensity) under one
  motion (``record``, ``realization``);
* ``reference``: the studied building alone on a fixed base under the same
  motion, on the dimensions ``record`` and ``realization`` (plus the variant
  axes that change the studied building itself, and ``intensity``).

A case id is the first 16 hex digits of the sha256 of its kind and labels, so
it does not depend on the order of the grid or on how the run is split.

The grid is read from the typed definition alone (:class:`ExperimentGrid`),
with one exception: with ``[intensity] selection = "conditional_spectrum"``
which motions each stripe runs is chosen when the experiment runs
(``stochpound.experiment.Experiment``, the grid that chooses them when first
asked), and a store records it (``selection_scale_factor``, the simulated motions' tables
on ``record``), from which :class:`StoredChoice` reads it back, so that a
store's grid (``ds.pound.grid``) needs nothing above this layer.
"""

from __future__ import annotations

import hashlib
import itertools
import json
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import Any, Protocol

import numpy as np
import xarray as xr

from stochpound._errors import ExperimentError, SceneError
from stochpound.model.scene_file import scene_from_dict
from stochpound.model.scene_tables import BuildingTable, MotionEntry, SceneEntry, SceneOverrides, SceneTables
from stochpound.store._catalogue import CASE, KINDS, REFERENCE
from stochpound.store._definition import (Definition, Intensity, MotionSource, Output, Solver, VariantAxis, canonical_json, definition_sha256,
                                          read_definition)
from stochpound.store._definition_entries import DefinitionEntry
from stochpound.store._scene_edits import (
    apply_overrides,
    reference_scene,
    set_gaps,
    set_mu,
    with_motion,
    without_motion,
)

CONDITIONAL_SPECTRUM = "conditional_spectrum"
"""``[intensity] selection`` that chooses the motions of every stripe (docs/intensity.md)."""
SIMULATED = "simulated"
"""The kind of a motion simulated for a stripe's pool (``[site] simulated_motions``) and chosen."""
Label = str | float | int
"""A case's label on one dimension: a variant or a motion (str), a gap, μ or a level (float), a realization (int)."""
SIMULATED_FIELD = "site.simulated_motions"
"""The field that declares the simulated motions (how messages name a chosen one)."""


@dataclass(frozen=True)
class Dim:
    """One dimension of the store.

    Attributes
    ----------
    name : str
        Dimension name (``gap``, ``mu``, a variant axis, ``intensity``, ``record``, ``realization``).
    kind : str
        ``variant``, ``gap``, ``mu``, ``intensity``, ``record`` or ``realization``.
    values : tuple
        Coordinate values, in grid order.
    """

    name: str
    kind: str
    values: tuple[Any, ...]


@dataclass(frozen=True)
class Case:
    """One simulation of the experiment.

    Attributes
    ----------
    case_id : str
        Stable id (16 hex digits).
    kind : str
        ``case`` or ``reference``.
    labels : tuple of (str, value)
        Its coordinate on each dimension of its kind, in dimension order.
    position : tuple of int
        Index along each of those dimensions.
    """

    case_id: str
    kind: str
    labels: tuple[tuple[str, Label], ...]
    position: tuple[int, ...]

    @property
    def label_dict(self) -> dict[str, Label]:
        """The labels as a dict."""
        return dict(self.labels)

    @property
    def mu(self) -> float | None:
        """Its value on the grid's μ axis (dimensionless; ∞: a fixed base), None without a μ axis."""
        return next((float(value) for name, value in self.labels if name == "mu"), None)

    @property
    def record(self) -> str:
        """The label of its motion (its ``record`` coordinate; every case has one)."""
        return next(str(value) for name, value in self.labels if name == "record")

    @property
    def realization(self) -> int | None:
        """Its realization of a synthetic ensemble's motion (its ``realization`` coordinate), None where the grid has none."""
        return next((int(value) for name, value in self.labels if name == "realization"), None)

    def describe(self) -> str:
        """``kind dim=value ...``, e.g. ``case neighbour=stiff gap=0.02 mu=inf record=el_centro realization=0``."""
        return " ".join([self.kind] + [f"{name}={_format(value)}" for name, value in self.labels])


@dataclass(frozen=True)
class Point:
    """One point of a kind's structural grid (its dimensions without ``record`` and ``realization``): one scene.

    Attributes
    ----------
    kind : str
        ``case`` or ``reference``.
    position : tuple of int
        Index along each structural dimension of the kind.
    labels : tuple of (str, value)
        Its coordinate on each of them.
    """

    kind: str
    position: tuple[int, ...]
    labels: tuple[tuple[str, Label], ...]

    def describe(self) -> str:
        """``case neighbour=stiff, gap=0.01, mu=0.1`` (``(base scene)`` without structural dimensions)."""
        return "case " + (", ".join(f"{name}={_format(value)}" for name, value in self.labels) or "(base scene)")


def _format(value: Any) -> str:
    return f"{value:g}" if isinstance(value, float) else str(value)


def case_id(kind: str, labels: Mapping[str, Label]) -> str:
    """Stable id of a case from its kind and labels."""
    return hashlib.sha256(canonical_json({"kind": kind, "labels": dict(labels)}).encode()).hexdigest()[:16]


def case_ids(kind: str, labels: Mapping[str, Label], realizations: Sequence[int]) -> list[str]:
    """:func:`case_id` of the cases with ``labels`` at each of ``realizations`` (the JSON around the number is built once)."""
    marker = -7340912358  # a number that no other label renders as
    text = canonical_json({"kind": kind, "labels": {**labels, "realization": marker}})
    head, *tail = text.split(str(marker))
    if len(tail) != 1:
        return [case_id(kind, {**labels, "realization": r}) for r in realizations]
    return [hashlib.sha256(f"{head}{int(r)}{tail[0]}".encode()).hexdigest()[:16] for r in realizations]


class StripeChoice(Protocol):
    """Which motions each stripe runs, chosen for a conditional-spectrum selection (:attr:`ExperimentGrid.selection`).

    ``stochpound.experiment`` chooses them when it runs; a store's grid reads
    them back from the store (:class:`StoredChoice`).
    """

    @property
    def chosen(self) -> np.ndarray:
        """Which motions run at every level (bool, level × motion on ``record``)."""

    @property
    def simulated(self) -> Mapping[str, MotionSource]:
        """The chosen simulated motions' sources, by label, in ``record`` order."""


@dataclass(frozen=True)
class StoredChoice:
    """The motions each stripe ran, as a store records them (:class:`StripeChoice`).

    Attributes
    ----------
    runs : tuple of tuple of bool
        Per level, per motion on ``record``: whether the motion ran in the stripe
        (its ``selection_scale_factor`` is finite).
    tables : tuple of (str, str)
        The simulated motions on ``record``: label and ``[motion]`` table (JSON, the ``record_motion`` coordinate).
    """

    runs: tuple[tuple[bool, ...], ...]
    tables: tuple[tuple[str, str], ...]

    @classmethod
    def from_store(cls, store: xr.Dataset, levels: Sequence[float]) -> StoredChoice:
        """The choice a store records, on the definition's ``levels`` (a level or motion the dataset lacks runs nothing)."""
        scale = store["selection_scale_factor"]
        if "record" not in scale.dims:
            scale = scale.expand_dims("record")
        if "intensity" not in scale.dims:
            scale = scale.expand_dims("intensity")
        finite = np.isfinite(scale.transpose("intensity", "record").values)
        rows = {float(level): row for level, row in zip(np.atleast_1d(scale["intensity"].values), finite)}
        empty = np.zeros(finite.shape[1], dtype=bool)
        runs = tuple(tuple(bool(x) for x in rows.get(float(level), empty)) for level in levels)
        kinds = np.atleast_1d(store["record_kind"].values)
        tables = zip(np.atleast_1d(store["record"].values), kinds, np.atleast_1d(store["record_motion"].values))
        return cls(runs, tuple((str(label), str(table)) for label, kind, table in tables if kind == SIMULATED))

    @cached_property
    def chosen(self) -> np.ndarray:
        """Which motions run at every level (bool, level × motion on ``record``)."""
        return np.array(self.runs, dtype=bool).reshape(len(self.runs), -1)

    @cached_property
    def simulated(self) -> dict[str, MotionSource]:
        """The simulated motions' sources, by label, in ``record`` order."""
        return {label: MotionSource(label, SIMULATED, SIMULATED_FIELD, json.loads(table)) for label, table in self.tables}


class ExperimentGrid:
    """What an experiment is: its typed definition, dimensions, cases and their scenes.

    Parameters
    ----------
    definition : mapping or Definition
        Canonical definition (``stochpound.experiment._spec.parse_experiment``), or
        its typed form (:func:`~stochpound.experiment.read_definition`).
    text : str
        The experiment file's text (provenance).
    base_dir : str or Path
        Folder of the experiment file (record files are resolved against it).
    path : str, optional
        The experiment file, for provenance.
    choice : StripeChoice, optional
        The motions chosen for every stripe, when ``[intensity] selection =
        "conditional_spectrum"`` (:attr:`selection`); ignored otherwise.
    """

    def __init__(
        self, definition: DefinitionEntry | Definition, text: str = "", base_dir: str | Path = ".", path: str = "", choice: StripeChoice | None = None
    ) -> None:
        self.definition: Definition = read_definition(definition)
        written = self.definition.to_dict()
        self.definition_json = canonical_json(written)
        """The canonical definition's JSON, written once (a store's ``definition`` attribute)."""
        self.sha256 = definition_sha256(written)
        self.text = text
        self.base_dir = Path(base_dir)
        self.path = path
        self.name: str = self.definition.name
        self.studied: str = self.definition.studied
        self.variants: tuple[VariantAxis, ...] = self.definition.variants
        self.recorded_motions: dict[str, MotionSource] = {m.label: m for m in self.definition.motions}
        self.output: Output = self.definition.output
        self.solver: Solver = self.definition.solver
        self.intensity: Intensity | None = self.definition.intensity
        self._choice = choice
        self._grid_case_ids: dict[str, np.ndarray] = {}

    @property
    def contract(self) -> Definition:
        """The typed definition (``definition``; the name older code reads)."""
        return self.definition

    # ------------------------------------------------------------ dimensions

    @cached_property
    def building_names(self) -> list[str]:
        """Buildings of the base scene, left to right."""
        return list(self.definition.building_names)

    @cached_property
    def max_floors(self) -> int:
        """Largest number of floors of any building, in the base scene or a variant."""
        counts = [self.definition.tables.max_floors] + [len(fields.raw("mass")) for override in self._overrides for fields in override.buildings.values()
                                                        if isinstance(fields.raw("mass"), list)]
        return max(counts + [1])

    @cached_property
    def _overrides(self) -> list[SceneOverrides]:
        """Every variant's overrides, typed (:class:`~stochpound.model.scene_tables.SceneOverrides`)."""
        return [override for variant in self.variants for override in variant.edits.values()]

    @cached_property
    def has_walls(self) -> bool:
        """Whether a case's scene can have walls: the base scene's or a variant's ``[[wall]]``."""
        return bool(self.definition.tables.walls) or any(override.scene.walls for override in self._overrides)

    @cached_property
    def has_storey_summaries(self) -> bool:
        """Whether a case's buildings can have yielding storeys or storey heights (``yield_force``, ``storey_height``), in the base scene or a variant."""
        given = [BuildingTable(fields, 0) for override in self._overrides for fields in override.buildings.values()]
        return any(building.has_storey_summaries for building in [*self.definition.tables.buildings, *given])

    @cached_property
    def motions(self) -> dict[str, MotionSource]:
        """The motions on ``record``, by label: the definition's, then the simulated motions a selection chose (``[site] simulated_motions``)."""
        if self.selection is None:
            return self.recorded_motions
        return {**self.recorded_motions, **self.selection.simulated}

    @cached_property
    def motion_dims(self) -> list[Dim]:
        """``record`` (motion labels) and ``realization`` (union of realization indices)."""
        realizations = np.sort(np.concatenate([self.realization_numbers(label) for label in self.motions]))
        realizations = realizations[np.concatenate([[True], realizations[1:] != realizations[:-1]])]  # unique (np.unique hashes: slower)
        return [Dim("record", "record", tuple(self.motions)), Dim("realization", "realization", tuple(realizations.tolist()))]

    @cached_property
    def grid_dims(self) -> list[Dim]:
        """Variant axes, gap axes and μ, in that order (the structural dimensions)."""
        dims = [Dim(v.name, "variant", v.values) for v in self.variants]
        dims += [Dim(g.name, "gap", g.values) for g in self.definition.gaps]
        if self.definition.mu is not None:
            dims.append(Dim("mu", "mu", self.definition.mu.values))
        return dims + self.intensity_dims

    @cached_property
    def intensity_dims(self) -> list[Dim]:
        """``intensity`` (the target levels) when stripes run; none otherwise."""
        if self.intensity is None or self.intensity.ran != "stripes":
            return []
        return [Dim("intensity", "intensity", self.intensity.levels)]

    @cached_property
    def dims(self) -> list[Dim]:
        """Dimensions of the cases: grid dimensions, then ``record``, ``realization``."""
        return self.grid_dims + self.motion_dims

    @cached_property
    def reference_dims(self) -> list[Dim]:
        """Dimensions of the fixed-base reference: variant axes that change the studied building, then the motion."""
        return self._reference_grid_dims + self.motion_dims

    @cached_property
    def _reference_grid_dims(self) -> list[Dim]:
        """:attr:`reference_dims` but the motion (so that the structure's grid points need no motion: a selection reads them)."""
        touched = [d for d in self.grid_dims if d.kind == "variant" and self._touches_studied(d.name)]
        return touched + self.intensity_dims

    def _touches_studied(self, axis: str) -> bool:
        variant = next(v for v in self.variants if v.name == axis)
        return any(override.gives(self.studied) - {"base"} for override in variant.edits.values())

    def realizations(self, label: str) -> range:
        """Realization indices of a motion: 0 for a record (and a simulated motion), start .. start+count−1 for an ensemble."""
        return self.motions[label].realizations

    def realization_numbers(self, label: str) -> np.ndarray:
        """:meth:`realizations` as an array."""
        numbers = self.realizations(label)
        return np.arange(numbers.start, numbers.stop)

    # ------------------------------------------------------------ grids and cases

    def kind_dims(self, kind: str) -> list[Dim]:
        """Dimensions of the cases of ``kind``: :attr:`dims` or :attr:`reference_dims`."""
        return self.reference_dims if kind == REFERENCE else self.dims

    def grid_shape(self, kind: str) -> tuple[int, ...]:
        """Shape of the grid of ``kind`` (its dimensions' sizes)."""
        return tuple(len(d.values) for d in self.kind_dims(kind))

    def points(self, kind: str) -> list[Point]:
        """The structural grid points of ``kind``, in grid order."""
        return self._points[kind]

    @cached_property
    def _points(self) -> dict[str, list[Point]]:
        points = {}
        for kind in KINDS:
            structural = self.grid_dims if kind != REFERENCE else self._reference_grid_dims
            points[kind] = [
                Point(kind, position, tuple((d.name, d.values[i]) for d, i in zip(structural, position)))
                for position in itertools.product(*(range(len(d.values)) for d in structural))
            ]
        return points

    def realization_positions(self, label: str) -> np.ndarray:
        """Indices along ``realization`` of a motion's realizations, in order."""
        return self._realization_positions[label]

    @cached_property
    def _realization_positions(self) -> dict[str, np.ndarray]:
        values = np.asarray(self.motion_dims[1].values)
        return {label: np.searchsorted(values, self.realization_numbers(label)) for label in self.motions}

    def in_grid(self, kind: str) -> np.ndarray:
        """Which positions of the grid of ``kind`` hold a case (bool, :meth:`grid_shape`): a record has realization 0 only;
        with a conditional-spectrum selection, a stripe holds its chosen motions only."""
        mask = np.zeros(self.grid_shape(kind)[-2:], dtype=bool)
        for m, label in enumerate(self.motions):
            mask[m, self.realization_positions(label)] = True
        if self.selection is not None:  # intensity is the dimension before record
            mask = mask & self.selection.chosen[:, :, None]
        return np.broadcast_to(mask, self.grid_shape(kind))

    @property
    def selects_motions(self) -> bool:
        """Whether every stripe runs motions chosen for it (``[intensity] selection = "conditional_spectrum"``)."""
        return self.intensity is not None and self.intensity.selection_method == CONDITIONAL_SPECTRUM

    @cached_property
    def selection(self) -> StripeChoice | None:
        """The motions chosen for every stripe (:attr:`selects_motions`); None otherwise.

        Raises
        ------
        ExperimentError
            If the stripes choose their motions and the grid was built without the choice.
        """
        if not self.selects_motions:
            return None
        if self._choice is None:
            raise ExperimentError(f"{self.name}: the stripes' choice of motions is not known here: a store's grid reads it from the store (ds.pound.grid), "
                                  "an experiment file's from stochpound.experiment.load_experiment")
        return self._choice

    def _runs(self, point: Point, record: int) -> bool:
        """Whether the motion numbered ``record`` runs at ``point`` (not where a selection left it out of the stripe)."""
        if self.selection is None:
            return True
        return bool(self.selection.chosen[self.intensity.levels.index(dict(point.labels)["intensity"]), record])

    @cached_property
    def n_cases(self) -> int:
        """Number of cases, references included."""
        return sum(int(self.in_grid(kind).sum()) for kind in KINDS)

    def case_at(self, kind: str, position: Sequence[int]) -> Case:
        """The case of ``kind`` at a (full) grid position."""
        position = tuple(int(i) for i in position)
        labels = tuple((d.name, d.values[i]) for d, i in zip(self.kind_dims(kind), position))
        return Case(case_id(kind, dict(labels)), kind, labels, position)

    def point_case_ids(self, point: Point, record: int) -> list[str]:
        """Ids of the cases at ``point`` under motion number ``record``, one per realization of the motion."""
        label = self.motion_dims[0].values[record]
        return case_ids(point.kind, {**dict(point.labels), "record": label}, self.realizations(label))

    def grid_case_ids(self, kind: str) -> np.ndarray:
        """Ids of the cases of ``kind`` on its grid (``S16``, empty where no case is), computed once (16 bytes a case)."""
        if kind not in self._grid_case_ids:
            ids = np.zeros(self.grid_shape(kind), dtype="S16")
            for point in self.points(kind):
                for m in range(len(self.motion_dims[0].values)):
                    if not self._runs(point, m):
                        continue
                    label = self.motion_dims[0].values[m]
                    ids[point.position + (m,)][self.realization_positions(label)] = self.point_case_ids(point, m)
            self._grid_case_ids[kind] = ids
        return self._grid_case_ids[kind]

    def iter_cases(self) -> Iterator[Case]:
        """Every case, lazily: the references first, then the grid, realization varying fastest."""
        for kind in KINDS:
            for point in self.points(kind):
                for m, label in enumerate(self.motion_dims[0].values):
                    if not self._runs(point, m):
                        continue
                    ids = self.point_case_ids(point, m)
                    for identifier, realization, r in zip(ids, self.realizations(label), self.realization_positions(label)):
                        labels = (*point.labels, ("record", label), ("realization", realization))
                        yield Case(identifier, point.kind, labels, (*point.position, m, int(r)))

    @cached_property
    def cases(self) -> list[Case]:
        """Every case, in the order of :meth:`iter_cases` (a list: for small experiments and look-ups)."""
        return list(self.iter_cases())

    @cached_property
    def case_index(self) -> dict[str, Case]:
        """Cases by id (builds :attr:`cases`)."""
        return {case.case_id: case for case in self.cases}

    def structure(self, case: Case | Point) -> SceneEntry:
        """The scene dict of a case or a grid point without its motion (a placeholder motion is set).

        Raises
        ------
        ExperimentError
            If μ is finite for a building without a sliding base.
        """
        point = self._point_of(case)
        labels = dict(point.labels)
        scene = without_motion(self.definition.scene)
        overrides = [v.overrides[labels[v.name]] for v in self.variants if v.name in labels]
        scene = apply_overrides(scene, overrides)
        if point.kind == REFERENCE:
            scene = reference_scene(scene, self.studied)
        else:
            draft = SceneTables.of(scene)
            for gap in self.definition.gaps:
                set_gaps(draft, gap.contacts, labels[gap.name], gap.walls)
            if self.intensity is not None and self.intensity.ran == "ida":  # contact-free: capacities come from the closures
                set_gaps(draft, range(len(draft.contacts)), float("inf"))
            mu = self.definition.mu
            if mu is not None:
                missing = set_mu(draft, mu.buildings, labels["mu"])
                if missing:
                    raise ExperimentError(
                        f"grid.mu: building(s) {', '.join(missing)} have no [building.base] in {point.describe()}; "
                        "give them a base (in the scene or a variant) or leave them out of grid.mu.buildings"
                    )
        return with_motion(scene)

    def _point_of(self, case: Case | Point) -> Point:
        if isinstance(case, Point):
            return case
        n = len(case.position) - 2
        return Point(case.kind, case.position[:n], case.labels[:n])

    def reference_structure(self, case: Case | Point) -> SceneEntry:
        """The scene dict of the fixed-base reference of a case or grid point (placeholder motion)."""
        return self.structure(self.reference_point(self._point_of(case)))

    def reference_point(self, point: Point) -> Point:
        """The reference grid point of a case grid point (the variant axes that change the studied building)."""
        if point.kind == REFERENCE:
            return point
        labels = dict(point.labels)
        structural = self.reference_dims[:-2]
        position = tuple(d.values.index(labels[d.name]) for d in structural)
        return Point(REFERENCE, position, tuple((d.name, labels[d.name]) for d in structural))

    @cached_property
    def scene_field(self) -> str:
        """How errors name the base scene: its file's path, else ``scene`` (inline, or a bundled scene: an error is its edits')."""
        source = self.definition.scene_source
        return str(self.base_dir / source["file"]) if source is not None and "file" in source else "scene"

    def validate(self) -> None:
        """Validate the scene of every grid point (cases, then references) before anything runs.

        Raises
        ------
        ExperimentError
            Naming the scene field: in the base scene (``scene.building[1].damping_ratio: ...``,
            or the scene file) when the base scene alone has the same error, else in the grid point.
        """
        for point in self.points(CASE) + self.points(REFERENCE):
            try:
                scene_from_dict(self.structure(point), base_dir=self.base_dir)
            except ExperimentError:
                raise
            except (SceneError, ValueError) as error:
                if str(error) == self._base_scene_error():
                    separator = "." if self.scene_field == "scene" else ": "
                    raise ExperimentError(f"{self.scene_field}{separator}{error}") from None
                raise ExperimentError(f"{point.describe()}: {error}") from None

    def _base_scene_error(self) -> str | None:
        """The error of the base scene on its own (with a placeholder motion), if any."""
        try:
            scene_from_dict(with_motion(without_motion(self.definition.scene)), base_dir=self.base_dir)
        except (SceneError, ValueError) as error:
            return str(error)
        return None

    def motion_table(self, label: str, realization: int | None = None) -> MotionEntry:
        """The scene ``[motion]`` table of a motion (with ``realization`` for an ensemble)."""
        motion = self.recorded_motions[label] if label in self.recorded_motions else self.motions[label]
        table: MotionEntry = {k: v for k, v in motion.motion.items() if k != "file_sha256"}
        if motion.kind == "synthetic":
            table["realization"] = motion.start if realization is None else realization
        return table

    def seeds(self) -> dict[str, int]:
        """Seeds of the synthetic ensembles, by label."""
        return {label: m.motion["seed"] for label, m in self.motions.items() if m.kind == "synthetic"}
