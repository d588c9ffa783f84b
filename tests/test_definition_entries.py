"""The canonical definition's declared shape (``stochpound.store._definition_entries``) is the one written.

Every shipped experiment's canonical definition, and its scene as written, holds exactly the keys
its ``TypedDict`` entries declare (every required one, no undeclared one) with values of the declared
types, so the declared shape cannot drift from what the records write.
"""

from __future__ import annotations

import types
import typing
from collections.abc import Mapping
from pathlib import Path

import pytest

from stochpound.experiment import is_rare_event_file
from stochpound.experiment._spec import load_definition
from stochpound.model.scene_tables import BuildingEntry, SceneEntry
from stochpound.store import read_definition
from stochpound.store._definition_entries import DefinitionEntry, IntensityEntry
from stochpound.studies.agarwal2004._scenes import reference_building, study_scene

ROOT = Path(__file__).resolve().parents[1]
EXPERIMENTS = sorted(p for p in (ROOT / "experiments").rglob("*.toml") if "scenes" not in p.parts and not is_rare_event_file(p))  # rare-event files: their own definition


def _misfits(value: object, hint: object, path: str) -> list[str]:
    """Where ``value`` departs from the type ``hint`` (a TypedDict, list, dict, union or plain type), one line each."""
    if typing.is_typeddict(hint):
        if not isinstance(value, Mapping):
            return [f"{path}: {value!r} is not a table"]
        hints = typing.get_type_hints(hint)
        found = [f"{path}.{key}: not declared in {hint.__name__}" for key in value if key not in hints]
        found += [f"{path}.{key}: missing" for key in sorted(hint.__required_keys__) if key not in value]
        return found + [line for key, item in value.items() if key in hints for line in _misfits(item, hints[key], f"{path}.{key}")]
    origin, arguments = typing.get_origin(hint), typing.get_args(hint)
    if origin in (typing.Union, types.UnionType):
        return [] if any(not _misfits(value, argument, path) for argument in arguments) else [f"{path}: {value!r} is none of {hint}"]
    if origin is list:
        return [f"{path}: {value!r} is not a list"] if not isinstance(value, list) else \
            [line for i, item in enumerate(value) for line in _misfits(item, arguments[0], f"{path}[{i}]")]
    if origin in (dict, Mapping):
        return [f"{path}: {value!r} is not a table"] if not isinstance(value, Mapping) else \
            [line for key, item in value.items() for line in _misfits(item, arguments[1], f"{path}.{key}")]
    if hint is object:
        return []
    if hint is type(None):
        return [] if value is None else [f"{path}: {value!r} is not None"]
    if hint is float:  # a TOML integer spells a float too
        return [] if isinstance(value, (int, float)) and not isinstance(value, bool) else [f"{path}: {value!r} is not a number"]
    return [] if isinstance(value, hint) else [f"{path}: {value!r} is not a {hint.__name__}"]


@pytest.mark.parametrize("path", EXPERIMENTS, ids=lambda p: str(p.relative_to(ROOT / "experiments")))
def test_every_shipped_definition_has_the_declared_shape(path):
    parsed, _ = load_definition(path)
    assert _misfits(parsed, DefinitionEntry, "definition") == []
    assert _misfits(read_definition(parsed).to_dict(), DefinitionEntry, "definition") == []


def test_the_shape_check_names_an_undeclared_a_missing_and_a_mistyped_key():
    entry = {"measure": "psa", "period": "1 s", "levels": [0.1], "units": "g", "method": "stripes", "ran": "stripes", "extra": 1}
    assert _misfits(entry, IntensityEntry, "intensity") == [
        "intensity.extra: not declared in IntensityEntry", "intensity.note: missing", "intensity.period: '1 s' is not a number"]


def test_the_study_scenes_have_the_declared_shape():
    assert _misfits(study_scene(0.2, 0.1, factor=0.5, gap=0.0), SceneEntry, "scene") == []
    assert _misfits(reference_building("B2", 2.0, None, storey_height=[3.0, 3.0]), BuildingEntry, "building") == []
