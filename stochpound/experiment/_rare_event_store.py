"""The store of a rare-event experiment: its parts folder (finished levels and batches) and its netCDF file.

A run keeps, in ``<store>.parts/``:

``definition.json``
    The canonical definition (a store of another definition is refused).
``level-LL.npz``
    A finished level: its responses (chains, states a chain), the sample of
    the previous level that seeded each chain, its acceptance, runs and λ
    at its end (aCS's spread scale; a level file without it: 0.6); and,
    unless it is the last, the next level's threshold, seeds and their normals.
``batch-LL-BBBBB.npz``
    A finished batch of the level under way: its chains' responses, accepted
    moves, and the normals of its states that may seed the next level (its
    own p0·N largest responses, ties included). Removed once the level is written.

Every file is written atomically; the store file is rebuilt from the level
files alone (:func:`write_store`), so it is the same, bit for bit, whatever
the workers and interruptions.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from stochpound._atomic import replacing
from stochpound._text_files import attribute_text
from stochpound.analysis import INITIAL_SCALE, PROPOSALS, SubsetLevel, curve_dataset, curve_thresholds, exceedance, exceedance_quantiles, level_attributes, level_probability
from stochpound.experiment._parts import parts_folder
from stochpound.experiment._rare_event_table import RareEventDefinition
from stochpound.store import Provenance

DEFINITION_FILE = "definition.json"
KIND = "rare_event"
"""The ``kind`` attribute of a rare-event store."""
INTERVAL_Z = 1.96
"""The standard normal quantile of the report's intervals: p·exp(±z δ), a lognormal estimate's 95 % interval."""
SEPARATION_PROBABILITIES = (1e-3, 1e-4, 1e-6)
"""The probabilities per event whose response (for a closure, the separation) the report states."""


@dataclass(frozen=True)
class FinishedLevel:
    """A finished level as its file holds it (``scale``: aCS's λ at its end; ``next_*``: the next level's threshold, seeds and their
    normals; None for the last)."""

    level: SubsetLevel
    seeds: np.ndarray
    runs: int
    scale: float = INITIAL_SCALE
    next_threshold: float | None = None
    next_seeds: np.ndarray | None = None
    next_states: np.ndarray | None = None


def level_path(store: Path, level: int) -> Path:
    return parts_folder(store) / f"level-{level:02d}.npz"


def batch_path(store: Path, level: int, batch: int) -> Path:
    return parts_folder(store) / f"batch-{level:02d}-{batch:05d}.npz"


def save_arrays(path: Path, **arrays: Any) -> None:
    """Write ``arrays`` to ``path`` (npz) atomically."""
    with replacing(path) as temporary:
        with open(temporary, "wb") as stream:
            np.savez(stream, **arrays)


def load_arrays(path: Path) -> dict[str, np.ndarray]:
    with np.load(path) as data:
        return {key: data[key] for key in data.files}


def save_level(store: Path, index: int, finished: FinishedLevel) -> None:
    """Write a finished level and remove its batches."""
    arrays = {"threshold": finished.level.threshold, "responses": finished.level.responses, "acceptance": finished.level.acceptance,
              "seeds": finished.seeds, "runs": finished.runs, "scale": finished.scale}
    if finished.next_threshold is not None:
        arrays |= {"next_threshold": finished.next_threshold, "next_seeds": finished.next_seeds, "next_states": finished.next_states}
    save_arrays(level_path(store, index), **arrays)
    for batch in parts_folder(store).glob(f"batch-{index:02d}-*.npz"):
        batch.unlink()


def finished_levels(store: Path) -> list[FinishedLevel]:
    """The finished levels in the store's parts folder, in order."""
    levels = []
    while level_path(store, len(levels)).is_file():
        data = load_arrays(level_path(store, len(levels)))
        nxt = {key: data.get(f"next_{key}") for key in ("threshold", "seeds", "states")}
        seeds = data["seeds"] if len(levels) else None
        levels.append(FinishedLevel(SubsetLevel(float(data["threshold"]), data["responses"], float(data["acceptance"]), seeds), data["seeds"], int(data["runs"]),
                                    float(data["scale"]) if "scale" in data else INITIAL_SCALE, None if nxt["threshold"] is None else float(nxt["threshold"]),
                                    nxt["seeds"], nxt["states"]))
    return levels


def stored_definition(store: Path) -> dict[str, Any] | None:
    """The definition a store's parts were run with (None without one)."""
    path = parts_folder(store) / DEFINITION_FILE
    return json.loads(path.read_text()) if path.is_file() else None


def write_store(store: Path, definition: RareEventDefinition, levels: list[FinishedLevel], units: str) -> None:
    """Write the store file from the finished levels (a run under way: ``complete`` 0, the curve of the levels so far)."""
    table = definition.table
    complete = bool(levels) and levels[-1].next_threshold is None
    samples = max(f.level.responses.size for f in levels) if levels else 0
    chains = max(len(f.seeds) for f in levels) if levels else 0
    response = np.full((len(levels), samples), np.nan)
    seeds = np.full((len(levels), chains), -1, dtype=np.int64)
    for index, finished in enumerate(levels):
        response[index, : finished.level.responses.size] = finished.level.responses.reshape(-1)
        seeds[index, : len(finished.seeds)] = finished.seeds
    subset = [f.level for f in levels]
    attrs = {
        "kind": KIND, "experiment_name": definition.name, "experiment_description": definition.description, "experiment_file": definition.path,
        "definition": json.dumps(definition.to_dict(), sort_keys=True), "definition_sha256": definition.sha256, "method": PROPOSALS[table.proposal],
        "response": table.response, "target_probability": table.target_probability, "samples_per_level": table.samples_per_level, "p0": table.p0,
        "seed": table.seed, "complete": int(complete), "runs": int(sum(f.runs for f in levels)),
    }
    curve = xr.Dataset()
    if levels:
        attrs["reached_probability"] = level_probability(subset) * table.p0 if complete else level_probability(subset)
        attrs["target_reached"] = int(complete and attrs["reached_probability"] <= table.target_probability * (1.0 + 1e-9))
        thresholds = curve_thresholds(subset, table.target_probability if complete else None) if len(levels) > 1 or complete else np.array([])
        curve = curve_dataset(thresholds, *exceedance(subset, thresholds), units, {})
        attrs |= {key: value for key, value in level_attributes(subset, round(table.p0 * table.samples_per_level)).items() if key != "level_thresholds"}
    data = xr.Dataset(
        {
            "level_threshold": ("level", np.array([f.level.threshold for f in levels], dtype=float), {"units": units, "long_name": "level's conditioning threshold (-inf: level 0)"}),
            "level_chains": ("level", np.array([f.level.responses.shape[0] for f in levels], dtype=np.int64)),
            "level_length": ("level", np.array([f.level.responses.shape[1] for f in levels], dtype=np.int64), {"long_name": "states a chain"}),
            "level_acceptance": ("level", np.array([f.level.acceptance for f in levels], dtype=float)),
            "level_runs": ("level", np.array([f.runs for f in levels], dtype=np.int64)),
            "response": (("level", "sample"), response, {"units": units, "long_name": "the level's responses, chain by chain"}),
            "seed_sample": (("level", "chain"), seeds, {"long_name": "the previous level's sample that seeded the chain (-1: none)"}),
            **{name: curve[name] for name in curve.data_vars},
        },
        attrs=attrs,
    )
    with replacing(store) as temporary:
        data.to_netcdf(temporary, engine="h5netcdf", invalid_netcdf=False)


def is_rare_event_store(path: str | Path) -> bool:
    """Whether a file is a rare-event experiment's store (False for any other file).

    Read from the file's ``kind`` attribute alone (HDF5), not by opening it as a dataset: a report asks it of every store
    it is given, and a grid's store has hundreds of variables to index.
    """
    import h5py

    try:
        with h5py.File(path, "r") as handle:
            kind = handle.attrs.get("kind")
    except (OSError, ValueError):
        return False
    return kind is not None and attribute_text(kind) == KIND


def open_rare_event_store(path: str | Path) -> xr.Dataset:
    """A rare-event store, loaded (it is small: the levels' responses)."""
    with xr.open_dataset(path, engine="h5netcdf") as data:
        return data.load()


def store_levels(data: xr.Dataset) -> list[SubsetLevel]:
    """A rare-event store's levels, as the sampler made them."""
    levels = []
    for index in range(data.sizes["level"]):
        chains, length = int(data["level_chains"].values[index]), int(data["level_length"].values[index])
        responses = data["response"].values[index, : chains * length].reshape(chains, length)
        seeds = data["seed_sample"].values[index, :chains] if index else None
        levels.append(SubsetLevel(float(data["level_threshold"].values[index]), responses, float(data["level_acceptance"].values[index]), seeds))
    return levels


@dataclass(frozen=True)
class RareEventResults:
    """What a rare-event store answers (computed from its levels).

    Attributes
    ----------
    curve : xarray.Dataset
        ``probability``, ``cov`` and the 95 % interval ``lower`` .. ``upper`` (p·exp(∓1.96 δ)) over
        ``threshold`` (the response's units), down to the target.
    separations : dict of np.ndarray
        For 1e-3, 1e-4 and 1e-6 per event (``probability``): ``value``, ``low``, ``high`` (the
        response exceeded with that probability and its 95 % interval) and ``cov``.
    definition : RareEventDefinition
        The experiment's definition.
    runs : int
        Solver runs used.
    levels : int
        Levels run (level 0 included).
    complete : bool
        The run ended (its last level is written).
    target_reached : bool
        It ended at the target probability (not at ``max_levels``).
    """

    curve: xr.Dataset
    separations: dict[str, np.ndarray]
    definition: RareEventDefinition
    runs: int
    levels: int
    complete: bool
    target_reached: bool


def stored_rare_event(data: xr.Dataset) -> RareEventDefinition:
    """The definition a rare-event store was run with."""
    return RareEventDefinition.from_dict(json.loads(data.attrs["definition"]), Provenance.of(data).experiment_file)


def rare_event_results(data: xr.Dataset) -> RareEventResults:
    """The exceedance curve and the separations for 1e-3, 1e-4 and 1e-6 per event of a rare-event store."""
    levels = store_levels(data)
    quantiles = exceedance_quantiles(levels, SEPARATION_PROBABILITIES, INTERVAL_Z)
    curve = data[["probability", "cov"]].load() if "probability" in data else xr.Dataset({"probability": ("threshold", []), "cov": ("threshold", [])})
    spread = np.exp(INTERVAL_Z * curve["cov"].fillna(np.inf))
    curve = curve.assign(lower=curve["probability"] / spread, upper=np.minimum(curve["probability"] * spread, 1.0))
    return RareEventResults(curve, {"probability": np.array(SEPARATION_PROBABILITIES), **quantiles}, stored_rare_event(data),
                            int(data.attrs["runs"]), len(levels), bool(data.attrs["complete"]),
                            bool(data.attrs.get("target_reached", 0)))
