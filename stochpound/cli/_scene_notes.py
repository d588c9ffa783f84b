"""What the commands print about a scene before they run it: its buildings' periods and the fields that look like slips."""

from __future__ import annotations

from typing import TYPE_CHECKING, Mapping

import click

if TYPE_CHECKING:
    from stochpound.experiment import Experiment


def periods_text(periods: Mapping[str, float]) -> str:
    """Named periods (s) on one line: ``B1 first mode 0.396 s, B2 first mode 0.259 s``."""
    return ", ".join(f"{name} {period:.3g} s" for name, period in periods.items())


def say_scene_warnings(warnings: list[str]) -> None:
    """Each of a scene's warnings (:func:`~stochpound.model.scene_warnings`) on stderr, one line each."""
    for line in warnings:
        click.echo(f"warning: {line}", err=True)


def experiment_warnings(experiment: Experiment) -> list[str]:
    """The warnings of the scenes of every grid point of an experiment (fields named ``scene.<field>``), each once."""
    from stochpound.experiment import CASE
    from stochpound.model import scene_warnings
    from stochpound.model.scene_file import scene_from_dict

    found: dict[str, None] = {}
    for point in experiment.points(CASE):
        found.update(dict.fromkeys(scene_warnings(scene_from_dict(experiment.structure(point), base_dir=experiment.base_dir), "scene")))
    return list(found)
