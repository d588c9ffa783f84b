"""A resume never adds cases that ran another choice of the stripes' motions than the finished ones.

The choice depends on the definition and on the selection's code (a constant of the pools, another version): the same
definition, and so the same store identity, can choose other motions after an upgrade. The parts folder records the choice's
identity; a run that would choose otherwise refuses to add cases to it (one line, nothing lost), and the same choice resumes."""

from __future__ import annotations

import json

import pytest

from stochpound.experiment import _stripe_pools, load_experiment, run_experiment, store_status
from stochpound.experiment._parts import DEFINITION_FILE, parts_folder, part_paths, read_experiment_json
from stochpound.experiment._session import check_choice, experiment_choice, stored_choice
from stochpound.experiment._spec import ExperimentError
from tests.helpers import tilted_site_text, write_experiment


def _run(path, pilot: int, monkeypatch):
    monkeypatch.setattr(_stripe_pools, "TILT_PILOT", pilot)  # the pilot's size sets the tilt: another pilot, other motions
    experiment = load_experiment(path)
    return experiment, run_experiment(experiment, workers=0, progress=False)


def test_a_resume_that_would_choose_other_motions_is_refused_and_the_same_choice_resumes(tmp_path, monkeypatch):
    path = write_experiment(tmp_path, tilted_site_text(), "tilted.toml")
    experiment, report = _run(path, 48, monkeypatch)
    store, folder = report.store, parts_folder(report.store)
    assert report.complete and not report.failed
    choice = experiment_choice(experiment)
    assert choice and read_experiment_json(folder).choice_sha256 == choice == stored_choice(store)

    store.unlink()  # as a run killed before its store file was written: the finished cases are in the parts folder
    parts = sorted(part_paths(folder))
    with pytest.raises(ExperimentError, match=r"tilted\.nc: its finished cases ran another choice of the stripes' motions .*--restart"):
        _run(path, 40, monkeypatch)
    assert sorted(part_paths(folder)) == parts and not store.exists()  # nothing lost, nothing written
    status = store_status(store)  # nor does `status`, which would write the file with the choice it makes now
    assert not status.rebuilt and "another choice of the stripes' motions" in status.not_rebuilt and not store.exists()
    assert status.n_done == report.total  # the finished cases, all of them in the parts

    experiment, report = _run(path, 48, monkeypatch)
    assert report.complete and report.done_before == report.total and stored_choice(store) == choice


def test_a_folder_of_an_earlier_version_is_checked_against_its_store_file(tmp_path, monkeypatch):
    """A parts folder written before the choice was recorded: the store file's recorded choice is the reference."""
    path = write_experiment(tmp_path, tilted_site_text(), "tilted.toml")
    experiment, report = _run(path, 48, monkeypatch)
    folder = parts_folder(report.store)
    written = json.loads((folder / DEFINITION_FILE).read_text())
    del written["choice_sha256"]
    (folder / DEFINITION_FILE).write_text(json.dumps(written))
    record = read_experiment_json(folder)
    assert record.choice_sha256 == ""
    check_choice(report.store, record, experiment_choice(experiment))  # the same choice: nothing to say
    with pytest.raises(ExperimentError, match="another choice of the stripes' motions"):
        check_choice(report.store, record, "0" * 64)


def test_an_experiment_without_a_selection_records_no_choice(tmp_path):
    from tests.helpers import laws_pair_text

    experiment = load_experiment(write_experiment(tmp_path, laws_pair_text(), "laws.toml"))
    assert experiment_choice(experiment) == ""
