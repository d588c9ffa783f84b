"""A rare-event store's closure curve against a stochastic experiment's crude Monte Carlo: the cell of the same runs, at its own gaps.

A stochastic experiment's grid may have several axes (variants, μ, gaps)
and several synthetic ensembles; the rare-event experiment is one of its
cells when its scene is the cell's (but for the contacts' gaps: both are
compared contact-free, as built models) and its motion is one of the
ensembles' (but for their seed and count). The check is crude Monte Carlo
of that cell's contact-free runs at the grid's own finite gaps.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import xarray as xr

from stochpound._errors import ExperimentError
from stochpound.analysis import exceedance, pounding_curve
from stochpound.experiment._rare_event_store import store_levels, stored_rare_event
from stochpound.experiment._rare_event_table import CLOSURES, RareEventDefinition
from stochpound.model.scene_file import scene_from_dict
from stochpound.model.scene_tables import SceneEntry
from stochpound.store import CASE, Provenance, TomlTable, contact_free, contact_gap_dims, has_contact_free, is_fixed_base, with_motion, with_open_gaps

_NOT_THE_MOTION = ("count", "seed", "start", "realization", "interpolation")
"""A synthetic ensemble's fields that name its realizations, not its motion."""


def crude_check(rare: xr.Dataset, store: xr.Dataset) -> xr.Dataset | None:
    """A rare-event store's closure curve against the crude Monte Carlo of the cell of a stochastic experiment that ran the same runs.

    The cell: a contact-free grid point of ``store`` whose scene is the
    rare-event experiment's (compared as built models, every contact's gap
    infinite) under an ensemble of the same synthetic motion (but for its
    seed and count). Its runs' closure (the rare event's contact's, or the
    largest of every contact's for ``max_closure``) gives the fraction that
    reaches each finite gap of the store's contact gap axis.

    Parameters
    ----------
    rare : xarray.Dataset
        A rare-event store (:func:`~stochpound.experiment.open_rare_event_store`).
    store : xarray.Dataset
        A stochastic experiment's store, any grid.

    Returns
    -------
    xarray.Dataset or None
        Over ``gap`` (m, the store's finite gaps): ``crude``, ``crude_lower``, ``crude_upper`` (the fraction of
        the cell's contact-free runs whose closure reaches the gap, with its 95 % Clopper–Pearson interval),
        ``realizations``; ``subset`` and ``subset_cov`` (the rare-event curve there); attrs ``experiment``,
        ``record`` (the ensemble's label) and ``cell`` (the cell's labels, ``neighbour stiff, μ 0.05``, ``μ fixed``; empty
        without other axes). None when there is nothing to check: the rare event is not a closure, or the store
        has no contact-free cases.

    Raises
    ------
    ExperimentError
        In one line, when the store has contact-free cases but none of them is the rare-event experiment's
        runs (no ensemble of its motion, no cell of its scene, a gap axis that does not set its contact).
    """
    definition = stored_rare_event(rare)
    table = definition.table
    if table.response not in CLOSURES or not has_contact_free(store):
        return None
    experiment = Provenance.of(store).experiment_name
    where = f"rare-event experiment {definition.name} against experiment {experiment}"
    axes = contact_gap_dims(store)
    if len(axes) != 1:
        raise ExperimentError(f"{where}: its crude check needs one contact gap axis, got {len(axes)} ({', '.join(axes)})")
    stochastic = store.pound.definition
    axis = next(gap for gap in stochastic.gaps if gap.name == axes[0])
    every_contact = table.response == "max_closure"
    contacts = range(len(TomlTable(definition.scene, "scene").tables("contact"))) if every_contact else [table.contact]
    if set(contacts) - set(axis.contacts):
        raise ExperimentError(f"{where}: its gap axis {axis.name} sets contacts {', '.join(map(str, axis.contacts))}, "
                              f"not every contact of the closure ({', '.join(map(str, contacts))})")
    motion = _motion_fields(definition.motion)
    labels = [m.label for m in stochastic.motions if m.kind == "synthetic" and _motion_fields(m.motion) == motion]
    if not labels:
        raise ExperimentError(f"{where}: none of its ensembles has the motion {_describe(definition)} (but for seed and count)")
    cell = _cell(store, definition.scene, axes)
    if cell is None:
        raise ExperimentError(f"{where}: none of its contact-free cells has the scene of {definition.name} (compared with every gap infinite)")
    closure = contact_free(store)["peak_contact_closure"].sel(cell).sel(record=labels[0])
    runs = closure if every_contact else closure.isel(contact=table.contact)
    gaps = store[axes[0]].values[np.isfinite(store[axes[0]].values)]
    crude = pounding_curve(runs, gaps, contact_dim="contact" if every_contact else None)
    probability, cov = exceedance(store_levels(rare), gaps)
    return xr.Dataset(
        {"crude": ("gap", crude["probability"].values), "crude_lower": ("gap", crude["lower"].values), "crude_upper": ("gap", crude["upper"].values),
         "realizations": ("gap", np.broadcast_to(crude["realizations"].values, gaps.shape)), "subset": ("gap", probability), "subset_cov": ("gap", cov)},
        coords={"gap": ("gap", gaps, {"units": "m"})},
        attrs={"experiment": experiment, "record": labels[0], "cell": ", ".join(_cell_label(dim, value) for dim, value in cell.items())},
    )


def _cell(store: xr.Dataset, scene: SceneEntry, gap_dims: list[str]) -> dict[str, float | str] | None:
    """The labels (gap axes left out) of the first contact-free grid point of ``store`` whose model is ``scene``'s, or None."""
    grid = store.pound.grid
    target = _model(scene)
    for point in grid.points(CASE):
        labels = dict(point.labels)
        if all(math.isinf(labels[dim]) for dim in gap_dims) and _model(grid.structure(point)) == target:
            return {dim: value for dim, value in labels.items() if dim not in gap_dims}
    return None


def _model(scene: SceneEntry) -> tuple[Any, ...]:
    """What a scene table builds, every contact's gap infinite and its motion left out: buildings, contacts, walls, g, study_compat."""
    built = scene_from_dict(with_motion(with_open_gaps({key: value for key, value in scene.items() if key != "motion"})))
    return built.buildings, built.contacts, built.walls, built.g, built.study_compat


def _motion_fields(motion: Any) -> dict[str, Any]:
    return {key: value for key, value in dict(motion).items() if key not in _NOT_THE_MOTION}


def _describe(definition: RareEventDefinition) -> str:
    """The rare-event experiment's motion in words: ``white_noise (S0 = 0.02, duration = 2, dt = 0.02)``."""
    motion = definition.motion
    return f"{motion['type']} ({', '.join(f'{key} = {_label(value)}' for key, value in motion.items() if key != 'type')})"


def _cell_label(dim: str, value: float | str) -> str:
    """``neighbour stiff``, ``μ 0.05``, ``μ fixed`` (μ = inf)."""
    if dim == "mu":
        return f"μ {'fixed' if is_fixed_base(value) else _label(value)}"
    return f"{dim} {_label(value)}"


def _label(value: Any) -> str:
    return f"{value:g}" if isinstance(value, float) else str(value)
