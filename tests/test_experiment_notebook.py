"""The quick-start experiment runs, and the notebook of docs/notebooks/ executes on its store."""

from __future__ import annotations

import shutil
import signal

import nbformat
import pytest
from nbclient import NotebookClient

from stochpound._signals import handling
from stochpound.experiment import load_experiment, open_store, run_experiment
from tests.helpers import REPOSITORY

pytestmark = pytest.mark.slow

NOTEBOOK = REPOSITORY / "docs" / "notebooks" / "explore_store.ipynb"


@pytest.fixture(scope="module")
def quickstart_store(tmp_path_factory):
    folder = tmp_path_factory.mktemp("quickstart")
    experiment = folder / "quickstart.toml"
    shutil.copy(REPOSITORY / "experiments" / "quickstart.toml", experiment)
    report = run_experiment(load_experiment(experiment), workers=0, progress=False)
    assert report.complete and not report.failed
    return report.store


def test_quickstart_store(quickstart_store):
    with open_store(quickstart_store) as ds:
        assert {"neighbour": 2, "gap": 2, "mu": 3, "record": 2, "realization": 3}.items() <= dict(ds.sizes).items()
        assert int(ds.attrs["cases_done"]) == 52


def test_notebook_executes(quickstart_store, monkeypatch):
    monkeypatch.setenv("STOCHPOUND_STORE", str(quickstart_store))
    monkeypatch.setenv("MPLBACKEND", "Agg")
    notebook = nbformat.read(NOTEBOOK, as_version=4)
    with handling(signal.getsignal(signal.SIGINT)):  # the client installs Python's SIGINT handler: the test run's is restored after
        NotebookClient(notebook, timeout=300, kernel_name="python3", resources={"metadata": {"path": str(NOTEBOOK.parent)}}).execute()
    outputs = [o for cell in notebook.cells if cell.cell_type == "code" for o in cell.get("outputs", [])]
    assert not [o for o in outputs if o.get("output_type") == "error"]
    text = "".join(o.get("text", "") for o in outputs if o.get("output_type") == "stream")
    assert "cases done: 52 of 52" in text
