"""An experiment's grid: dimensions, cases with stable ids, and each case's scene.

Two kinds of case exist:

* ``case``: one point of the grid (variant axes × gap axes × μ) under one
  motion (``record``, ``realization``);
* ``reference``: the studied building alone on a fixed base under the same
  motion, on the dimensions ``record`` and ``realization`` (plus the variant
  axes that change the studied building itself).

A case id is the first 16 hex digits of the sha256 of its kind and labels, so
it does not depend on the order of the grid or on how the run is split.
"""

from __future__ import annotations

import hashlib
import itertools
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import Any, Mapping

from stochpound.experiment.spec import ExperimentError, canonical_json, definition_sha256, field_errors
from stochpound.experiment.variants import (
    PLACEHOLDER_MOTION,
    apply_overrides,
    reference_scene,
    set_gaps,
    set_mu,
)
from stochpound.model.scene_file import scene_from_dict

CASE = "case"
REFERENCE = "reference"


@dataclass(frozen=True)
class Dim:
    """One dimension of the store.

    Attributes
    ----------
    name : str
        Dimension name (``gap``, ``mu``, a variant axis, ``record``, ``realization``).
    kind : str
        ``variant``, ``gap``, ``mu``, ``record`` or ``realization``.
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
    index : int
        Position in :attr:`Experiment.cases`.
    case_id : str
        Stable id (16 hex digits).
    kind : str
        ``case`` or ``reference``.
    labels : tuple of (str, value)
        Its coordinate on each dimension of its kind, in dimension order.
    position : tuple of int
        Index along each of those dimensions.
    """

    index: int
    case_id: str
    kind: str
    labels: tuple[tuple[str, Any], ...]
    position: tuple[int, ...]

    @property
    def label_dict(self) -> dict[str, Any]:
        """The labels as a dict."""
        return dict(self.labels)

    def describe(self) -> str:
        """``kind dim=value ...``, e.g. ``case neighbour=stiff gap=0.02 mu=inf record=el_centro realization=0``."""
        return " ".join([self.kind] + [f"{name}={_format(value)}" for name, value in self.labels])


def _format(value: Any) -> str:
    return f"{value:g}" if isinstance(value, float) else str(value)


def case_id(kind: str, labels: Mapping[str, Any]) -> str:
    """Stable id of a case from its kind and labels."""
    return hashlib.sha256(canonical_json({"kind": kind, "labels": dict(labels)}).encode()).hexdigest()[:16]


class Experiment:
    """A validated experiment: its definition, dimensions, cases and their scenes.

    Parameters
    ----------
    definition : mapping
        Canonical definition (:func:`stochpound.experiment.spec.parse_experiment`).
    text : str
        The experiment file's text (provenance).
    base_dir : str or Path
        Folder of the experiment file (record files are resolved against it).
    path : str, optional
        The experiment file, for provenance.
    """

    def __init__(self, definition: Mapping[str, Any], text: str = "", base_dir: str | Path = ".", path: str = "") -> None:
        self.definition = dict(definition)
        self.text = text
        self.base_dir = Path(base_dir)
        self.path = path
        self.sha256 = definition_sha256(self.definition)
        self.name: str = self.definition["name"]
        self.studied: str = self.definition["studied"]
        self.variants: list[dict[str, Any]] = self.definition["variants"]
        self.motions: dict[str, dict[str, Any]] = {m["label"]: m for m in self.definition["motions"]}
        self.output: dict[str, Any] = self.definition["output"]
        self.solver: dict[str, Any] = self.definition["solver"]

    # ------------------------------------------------------------ dimensions

    @cached_property
    def building_names(self) -> list[str]:
        """Buildings of the base scene, left to right."""
        return [b.get("name", f"B{i + 1}") for i, b in enumerate(self.definition["scene"]["building"])]

    @cached_property
    def max_floors(self) -> int:
        """Largest number of floors of any building, in the base scene or a variant."""
        counts = [len(b.get("mass", [])) for b in self.definition["scene"]["building"]]
        for variant in self.variants:
            for override in variant["overrides"].values():
                counts += [len(f["mass"]) for f in override.get("building", {}).values() if isinstance(f.get("mass"), list)]
        return max(counts + [1])

    @cached_property
    def motion_dims(self) -> list[Dim]:
        """``record`` (motion labels) and ``realization`` (union of realization indices)."""
        realizations = sorted({r for label in self.motions for r in self.realizations(label)})
        return [Dim("record", "record", tuple(self.motions)), Dim("realization", "realization", tuple(realizations))]

    @cached_property
    def grid_dims(self) -> list[Dim]:
        """Variant axes, gap axes and μ, in that order (the structural dimensions)."""
        dims = [Dim(v["name"], "variant", tuple(v["values"])) for v in self.variants]
        dims += [Dim(g["name"], "gap", tuple(g["values"])) for g in self.definition["gaps"]]
        if self.definition["mu"] is not None:
            dims.append(Dim("mu", "mu", tuple(self.definition["mu"]["values"])))
        return dims

    @cached_property
    def dims(self) -> list[Dim]:
        """Dimensions of the cases: grid dimensions, then ``record``, ``realization``."""
        return self.grid_dims + self.motion_dims

    @cached_property
    def reference_dims(self) -> list[Dim]:
        """Dimensions of the fixed-base reference: variant axes that change the studied building, then the motion."""
        return [d for d in self.grid_dims if d.kind == "variant" and self._touches_studied(d.name)] + self.motion_dims

    def _touches_studied(self, axis: str) -> bool:
        variant = next(v for v in self.variants if v["name"] == axis)
        for override in variant["overrides"].values():
            fields = override.get("building", {}).get(self.studied, {})
            if set(fields) - {"base"}:
                return True
        return False

    def realizations(self, label: str) -> list[int]:
        """Realization indices of a motion: ``[0]`` for a record, start .. start+count−1 for an ensemble."""
        motion = self.motions[label]
        if motion["kind"] == "record":
            return [0]
        return list(range(motion["start"], motion["start"] + motion["count"]))

    # ------------------------------------------------------------ cases

    @cached_property
    def cases(self) -> list[Case]:
        """Every case: the references first, then the grid, realization varying fastest."""
        cases: list[Case] = []
        for kind, dims in ((REFERENCE, self.reference_dims), (CASE, self.dims)):
            structural = dims[:-2]
            for grid_position in itertools.product(*(range(len(d.values)) for d in structural)):
                for m, label in enumerate(self.motion_dims[0].values):
                    for realization in self.realizations(label):
                        r = self.motion_dims[1].values.index(realization)
                        position = (*grid_position, m, r)
                        labels = tuple((d.name, d.values[i]) for d, i in zip(dims, position))
                        cases.append(Case(len(cases), case_id(kind, dict(labels)), kind, labels, position))
        return cases

    @cached_property
    def case_index(self) -> dict[str, Case]:
        """Cases by id."""
        return {case.case_id: case for case in self.cases}

    def structure(self, case: Case) -> dict[str, Any]:
        """The scene dict of a case without its motion (a placeholder motion is set).

        Raises
        ------
        ExperimentError
            If μ is finite for a building without a sliding base.
        """
        labels = case.label_dict
        scene = {k: v for k, v in self.definition["scene"].items() if k != "motion"}
        overrides = [v["overrides"][labels[v["name"]]] for v in self.variants if v["name"] in labels]
        scene = apply_overrides(scene, overrides)
        if case.kind == REFERENCE:
            scene = reference_scene(scene, self.studied)
        else:
            for gap in self.definition["gaps"]:
                set_gaps(scene, gap["contacts"], labels[gap["name"]])
            mu = self.definition["mu"]
            if mu is not None:
                missing = set_mu(scene, mu["buildings"], labels["mu"])
                if missing:
                    raise ExperimentError(
                        f"grid.mu: building(s) {', '.join(missing)} have no [building.base] in {self._where(case)}; "
                        "give them a base (in the scene or a variant) or leave them out of grid.mu.buildings"
                    )
        scene["motion"] = dict(PLACEHOLDER_MOTION)
        return scene

    def reference_structure(self, case: Case) -> dict[str, Any]:
        """The scene dict of the fixed-base reference of a case (placeholder motion)."""
        return self.structure(self.reference_of(case))

    def reference_of(self, case: Case) -> Case:
        """The fixed-base reference case under the same motion as ``case``."""
        labels = case.label_dict
        return self.case_index[case_id(REFERENCE, {d.name: labels[d.name] for d in self.reference_dims})]

    def _where(self, case: Case) -> str:
        structural = [(n, v) for n, v in case.labels if n not in ("record", "realization")]
        return "case " + (", ".join(f"{n}={_format(v)}" for n, v in structural) or "(base scene)")

    def validate(self) -> None:
        """Validate the scene of every distinct grid point (and the reference) before anything runs.

        Raises
        ------
        ExperimentError
            Naming the grid point and the scene field.
        """
        seen = set()
        for case in self.cases:
            key = (case.kind, case.position[:-2])
            if key in seen:
                continue
            seen.add(key)
            with field_errors(f"{self._where(case)}: "):
                scene_from_dict(self.structure(case), base_dir=self.base_dir)

    def motion_table(self, label: str, realization: int | None = None) -> dict[str, Any]:
        """The scene ``[motion]`` table of a motion (with ``realization`` for an ensemble)."""
        motion = self.motions[label]
        table = {k: v for k, v in motion["motion"].items() if k != "file_sha256"}
        if motion["kind"] == "synthetic":
            table["realization"] = motion["start"] if realization is None else realization
        return table

    def seeds(self) -> dict[str, int]:
        """Seeds of the synthetic ensembles, by label."""
        return {label: m["motion"]["seed"] for label, m in self.motions.items() if m["kind"] == "synthetic"}
