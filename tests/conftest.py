"""Shared fixtures of the tests (shared builders and helpers are in ``tests/helpers.py``)."""

import pytest

from stochpound.experiment import load_experiment, run_experiment
from tests.helpers import laws_pair_text, write_experiment


@pytest.fixture(scope="module")
def laws_store(tmp_path_factory):
    """An experiment over contact laws and walls, run (``tests.helpers.PAIR``): its file and its store."""
    folder = tmp_path_factory.mktemp("laws")
    report = run_experiment(load_experiment(write_experiment(folder, laws_pair_text(), "laws.toml")), workers=0, progress=False)
    assert report.complete and not report.failed
    return folder / "laws.toml", report.store
