"""The experiment's ground motions, resolved once on the client before anything runs.

* A record is read (and checked) here and shipped to the workers with its
  batches, so record files need not exist on a remote cluster.
* A synthetic ensemble is generated on the workers, realization by
  realization, from its table. Its intensity (S0, from ``pga`` or ``rms``) is
  computed once here and passed as ``S0``: the realizations are bit for bit
  those of the original table, without recomputing the peak factor per case.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from stochpound import motions as synthetic_motions
from stochpound.experiment._experiment import Experiment
from stochpound.experiment._intensity import check_resolution, ensemble_intensity
from stochpound.experiment._stripe_pools import simulated_motions
from stochpound.store import CASE, MotionSource, canonical_json, with_motion
from stochpound.experiment._spec import ExperimentError, field_errors
from stochpound.motions.ground import GroundMotion, SampledMotion
from stochpound.model.scene_file import scene_from_dict

_INTENSITY_KEYS = ("pga", "rms", "peak_factor", "S0")


@dataclass(frozen=True)
class ResolvedMotion:
    """A motion of the experiment, ready to run.

    Attributes
    ----------
    label : str
        Its coordinate on ``record``.
    motion : GroundMotion or None
        The record's motion (None for an ensemble).
    table : dict or None
        An ensemble's ``[motion]`` table for the workers (``realization`` set per case).
    grid : tuple of (float, int)
        Sample spacing (s) and number of samples.
    expected_intensity : float or None
        An ensemble's mean intensity measure over its realizations, units of
        ``levels`` (``[intensity] synthetic = "expected"`` only).
    """

    label: str
    motion: GroundMotion | None
    table: dict[str, Any] | None
    grid: tuple[float, int]
    expected_intensity: float | None = None


def resolve_motions(experiment: Experiment) -> dict[str, ResolvedMotion]:
    """Read every record and check every ensemble's parameters.

    Raises
    ------
    ExperimentError
        Naming the field (``records[1].record: ...``, ``synthetic.firm.pga: ...``).
    """
    structure = experiment.structure(experiment.points(CASE)[0])  # every building: the memory check counts them all
    resolved = {}
    simulated = _simulated(experiment)
    for label, source in experiment.motions.items():
        table = experiment.motion_table(label)
        if label in simulated:
            motion = simulated[label]
        else:
            with field_errors(scene_prefix=source.field):
                motion = scene_from_dict(with_motion(structure, table), base_dir=experiment.base_dir).motion
        grid = (float(motion.times[1] - motion.times[0]), len(motion.times))
        if experiment.intensity is not None:
            with field_errors():
                check_resolution(experiment.intensity, grid[0], f"{source.field} ({label})")
                if not isinstance(motion, SampledMotion):
                    raise ExperimentError(f"{source.field}: a {type(motion).__name__} cannot be scaled to an intensity level; [intensity] takes records, suites and synthetic ensembles")
        if source.kind in ("record", "simulated"):
            resolved[label] = ResolvedMotion(label, motion, None, grid)
        else:
            worker_table = table if table["type"] == "scenario_motions" else _worker_table(table, motion, structure)  # no S0 to resolve
            expected = None
            if experiment.intensity is not None and experiment.intensity.synthetic == "expected":
                expected = ensemble_intensity(experiment.intensity, worker_table, experiment.realizations(label), experiment.definition.g)
            resolved[label] = ResolvedMotion(label, None, worker_table, grid, expected)
    return resolved


def _simulated(experiment: Experiment) -> dict[str, GroundMotion]:
    """The chosen simulated motions, regenerated from their tables (one call per stripe's scenario), by label."""
    sources = list(experiment.selection.simulated.values()) if experiment.selection is not None else []
    groups: dict[str, list[MotionSource]] = {}
    for source in sources:
        groups.setdefault(canonical_json({k: v for k, v in source.motion.items() if k != "realization"}), []).append(source)
    return {source.label: motion for group in groups.values() for source, motion in zip(group, simulated_motions(group))}


def _worker_table(table: dict[str, Any], motion: GroundMotion, structure: dict[str, Any]) -> dict[str, Any]:
    """The ensemble's table with its intensity given as S0 (falls back to the table if that changed any bit)."""
    parameters = {k: v for k, v in table.items() if k not in ("type", "realization", "interpolation")}
    generator = getattr(synthetic_motions, table["type"])
    level = generator(1, start=table["realization"], **parameters).attrs["S0"]
    fixed = {k: v for k, v in table.items() if k not in _INTENSITY_KEYS}
    fixed["S0"] = float(level)
    again = scene_from_dict(with_motion(structure, fixed)).motion
    return fixed if np.array_equal(again.values, motion.values) else table
