"""The typed records that read a store's attributes, a motion's table and a run history line (issue 47)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import xarray as xr

from stochpound._errors import SceneError
from stochpound.experiment._parts import RunEntry, append_run, read_runs
from stochpound.store import MotionSource, MotionTable, Provenance, TomlTable, VariableAttributes


def test_provenance_reads_the_attributes_typed_with_their_defaults():
    store = xr.Dataset(attrs={"experiment_name": "quickstart", "cases_done": np.int64(3), "cases_total": np.int64(4), "definition_sha256": "ab"})
    written = Provenance.of(store)
    assert (written.experiment_name, written.cases_done, written.cases_total, written.definition_sha256) == ("quickstart", 3, 4, "ab")
    assert type(written.cases_done) is int
    assert (written.experiment_description, written.git_commit) == ("", "unknown")  # absent: the defaults
    assert store.pound.provenance == written and store.pound.sha256 == "ab"
    assert Provenance.of(xr.Dataset()) == Provenance()


def test_variable_attributes_take_the_callers_defaults_for_what_is_absent():
    data = xr.DataArray([1.0], dims="x", name="gap", attrs={"units": "m"})
    assert VariableAttributes.of(data) == VariableAttributes("m", None, None)
    assert VariableAttributes.of(data, units="1", long_name="value") == VariableAttributes("m", "value", None)  # a stored value wins
    assert VariableAttributes.of(data.assign_attrs(units=""), units="1").units == ""  # an empty value is a value


def test_a_motion_table_reads_a_record_and_a_generator_with_the_scene_files_defaults():
    record = MotionTable.of_source(MotionSource("elcentro", "record", "records[0]", {"record": "elcentro", "scale": 2, "file_sha256": None}))
    assert record == MotionTable("record", "elcentro", 2.0, math.inf, "linear", None, 0.0) and record.is_record
    ensemble = MotionTable.of(TomlTable({"type": "kanai_tajimi", "pga": 3.0, "duration": 20.0, "seed": 1}, "synthetic.firm"))
    assert (ensemble.type, ensemble.record, ensemble.duration, ensemble.is_record) == ("kanai_tajimi", None, 20.0, False)
    with pytest.raises(SceneError, match=r"^records\[1\]\.scale: must be a number"):
        MotionTable.of(TomlTable({"record": "x", "scale": "two"}, "records[1]"))


def test_a_run_entry_writes_and_reads_back_its_line(tmp_path):
    entry = RunEntry("2026-12-02T09:00:00+00:00", "host", "2 local workers", "1.0", "abc", "sha")
    append_run(tmp_path, entry)
    with (tmp_path / "runs.jsonl").open("a") as stream:
        stream.write('{"started": "old", "machine": "m"}\n{"cut by a ki')  # an older stochpound's line, a line cut by a kill
    runs = read_runs(tmp_path)
    assert runs == [entry, RunEntry("old", "m")] and runs[1].git_commit == "none"
    assert json.loads((tmp_path / "runs.jsonl").read_text().splitlines()[0]) == entry.to_json()
    assert list(entry.to_json()) == ["started", "machine", "executor", "stochpound_version", "git_commit", "sources_sha256"]
