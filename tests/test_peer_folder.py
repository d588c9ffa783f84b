"""A folder of PEER NGA-West2 downloads as a selection pool with its metadata (issue 43, item 5).

The fixture tests/data/peer_nga_west2 is made up (its make_fixture.py says how): PEER's layout, fictitious data.
"""

from __future__ import annotations

import importlib.util
import re
import shutil
from pathlib import Path

import numpy as np
import pytest

from stochpound import RecordError
from stochpound.experiment._file_layout import _suite_coordinates
from stochpound.experiment._runner import load_experiment
from stochpound.experiment._spec import ExperimentError
from stochpound.motions.records import (folder_metadata, load_record, load_suite, load_suite_member, record_metadata, select_members,
                                       suite_members)
from tests.helpers import SITE_SCENE, write_experiment

FIXTURE = Path(__file__).parent / "data" / "peer_nga_west2"
_SPEC = importlib.util.spec_from_file_location("make_fixture", FIXTURE / "make_fixture.py")
MAKE = importlib.util.module_from_spec(_SPEC)
_SPEC.loader.exec_module(MAKE)


def _peer(tmp_path: Path) -> Path:
    folder = tmp_path / "peer"
    shutil.copytree(FIXTURE, folder, ignore=shutil.ignore_patterns("*.py"))
    return folder


def test_every_component_of_a_row_gets_the_row_s_metadata() -> None:
    metadata = folder_metadata(FIXTURE)
    assert len(metadata) == 3 * len(MAKE.ROWS) - 1  # one recording without its vertical file ("-----")
    for rsn, name, year, _, station, magnitude, mechanism, rjb, rrup, vs30, tp, event, code, _ in MAKE.ROWS:
        for component, orientation in zip(MAKE.COMPONENTS[:2], ("H1", "H2")):
            got = metadata[f"RSN{rsn}_{event}_{code}{component}.AT2"]
            assert got["event"] == f"{name.replace('_ ', ', ')} {year}" and got["station"] == station.replace("_ ", ", ")
            assert (got["rsn"], got["year"], got["magnitude"], got["distance"], got["distance_joyner_boore"], got["vs30"]) == (
                rsn, year, magnitude, rrup, rjb, vs30)
            assert got["fault_type"] == mechanism and got["orientation"] == orientation and got["component"] == f"{event}/{code}{component}"
            assert got["pulse"] is (tp is not None) and (np.isnan(got["pulse_period"]) if tp is None else got["pulse_period"] == tp)
    assert metadata["RSN90003_IMAGVAL_GAM000.AT2"]["station"] == "Station Gamma, North"  # PEER writes "_" for a comma


def test_a_component_is_named_as_the_fema_p695_sets_name_the_same_recording(tmp_path) -> None:
    """Real NGA-West2 file names of two FEMA P695 far-field motions (05a: RSN 169, 01a: RSN 953): the same recording key."""
    folder = tmp_path / "real_names"
    folder.mkdir()
    report = (FIXTURE / "_SearchResults.csv").read_text()
    for name, real in (("RSN90001_IMAGVAL_ALP000.AT2", "RSN169_IMPVALL.H_H-DLT262.AT2"), ("RSN90001_IMAGVAL_ALP090.AT2", "RSN953_NORTHR_MUL009.AT2")):
        report = report.replace(name, real)
    (folder / "_SearchResults.csv").write_text(report)
    metadata = folder_metadata(folder)
    for member, file in (("05a", "RSN169_IMPVALL.H_H-DLT262.AT2"), ("01a", "RSN953_NORTHR_MUL009.AT2")):
        assert metadata[file]["component"] == load_suite_member(f"fema_p695_far_field/{member}").metadata["component"]


def test_a_spreadsheet_s_copy_of_the_report_reads_the_same(tmp_path) -> None:
    """Saved again by a spreadsheet: lines padded with commas to 31 fields, names quoted twice (a quote, a space, the name in doubled quotes)."""
    folder = tmp_path / "copy"
    folder.mkdir()
    lines = []
    for line in (FIXTURE / "_SearchResults.csv").read_text().splitlines():
        line = re.sub(r', "([^"]*)"', r'," ""\1"""', line)
        lines.append(line + "," * max(0, 30 - line.count(",")))
    (folder / "_SearchResults.csv").write_bytes(("\r\n".join(lines) + "\r\n").encode())  # and Windows line ends
    assert '" ""Imaginary Valley-01"""' in (folder / "_SearchResults.csv").read_text()
    assert folder_metadata(folder) == folder_metadata(FIXTURE)


@pytest.mark.parametrize(("edit", "message"), [
    (lambda text: text.replace("Rrup (km)", "R (km)"), r"_SearchResults\.csv, line 34: no column 'Rrup \(km\)' in the metadata table"),
    (lambda text: text.replace("6.5, Reverse Oblique", "six, Reverse Oblique"), r"_SearchResults\.csv, line 39: 'Magnitude' must be a number, got 'six'"),
    (lambda text: text.replace("Summary of Metadata", "Summary of"), r"no '-- Summary of Metadata of Selected Records --' table"),
])
def test_a_malformed_report_is_refused_naming_the_line_and_column(tmp_path, edit, message) -> None:
    folder = _peer(tmp_path)
    report = folder / "_SearchResults.csv"
    report.write_text(edit(report.read_text()))
    with pytest.raises(RecordError, match=message):
        folder_metadata(folder)


def test_a_folder_of_downloads_is_a_suite_of_its_horizontal_components_with_their_metadata(tmp_path) -> None:
    names = [Path(name).name for name in suite_members(FIXTURE)]
    assert len(names) == 10 and not any("-UP" in name for name in names)  # the report's verticals are left out
    records = load_suite(FIXTURE)
    assert [r.metadata["rsn"] for r in records] == [row[0] for row in MAKE.ROWS for _ in range(2)]
    assert load_record(FIXTURE / names[0]).metadata == record_metadata(names[0], FIXTURE) == folder_metadata(FIXTURE)[names[0]]
    assert [Path(n).name for n in select_members(FIXTURE, event=["atlantis"])] == ["RSN90004_ATLANT_HBR000.AT2", "RSN90004_ATLANT_HBR090.AT2"]
    assert len(select_members(FIXTURE, magnitude=(6.8, 7.0), distance=(0.0, 25.0))) == 4
    folder = _peer(tmp_path)
    shutil.copy(folder / names[0], folder / "mine.AT2")  # a file the report does not list
    with pytest.raises(RecordError, match=r"^magnitude: mine of .* not in its _SearchResults\.csv \(no metadata to choose by\)$"):
        select_members(folder, magnitude=(6.0, 7.0))


SELECTION = ('measure = "psa"\nperiod = 0.5\nlevels = [0.3, 0.15]\nselection = "conditional_spectrum"\nmotions = 3\nmax_scale_factor = 10.0\n'
             'seed = 3\nmax_per_earthquake = 2\nexclude_pulses = true\n')
SITE = '[site]\nvs30 = 400.0\nmagnitude = 6.9\ndistance_km = 15.0\nmechanism = "strike_slip"\n'


def _experiment(records: str) -> str:
    return f'[experiment]\nname = "peer"\n{SITE_SCENE}\n[grid]\ngap = ["inf"]\n{records}\n[intensity]\n{SELECTION}\n{SITE}\n[solver]\nmethod = "exact"\n'


def test_a_peer_folder_pool_feeds_the_selection_rules_and_the_stripe_counts(tmp_path) -> None:
    folder = _peer(tmp_path)
    experiment = load_experiment(write_experiment(tmp_path, _experiment('[[records]]\nsuite = "peer"\nname = "peer"'), "peer.toml"))
    selection = experiment.selection
    metadata = folder_metadata(folder)
    counts = selection.stripe_counts()
    for j, chosen in enumerate(selection.selections):
        files = [f"{label.partition('/')[2]}.AT2" for label in chosen.motion.values.astype(str)]
        events = [metadata[file]["event"] for file in files]
        assert list(chosen.earthquake.values) == events
        assert max(events.count(event) for event in events) <= 2  # max_per_earthquake
        assert not any(metadata[file]["pulse"] for file in files)  # exclude_pulses: RSN 90002 never
        assert len(set(files)) == 3
        assert int(counts["selection_earthquakes"].values[j]) == len(set(events)) and int(counts["selection_recorded"].values[j]) == 3
    # the rule counts the report's earthquakes: 3 of them (not 8 unpulsed motions, each its own) hold at most 3 motions at 1 each
    strict = _experiment('[[records]]\nsuite = "peer"\nname = "peer"').replace("motions = 3", "motions = 4").replace("max_per_earthquake = 2", "max_per_earthquake = 1")
    with pytest.raises(ExperimentError, match=r"the 8 motions of the pool .* make only 3 distinct motions with at most max_per_earthquake = 1 of an earthquake, fewer than motions = 4"):
        load_experiment(write_experiment(tmp_path, strict, "strict.toml")).selection
    coordinates = _suite_coordinates(experiment)  # the store's metadata of its motions
    files = [f"{label.partition('/')[2]}.AT2" for label in experiment.motions]
    for name, key in (("record_event", "event"), ("record_magnitude", "magnitude"), ("record_distance", "distance"), ("record_rsn", "rsn")):
        assert list(coordinates[name].values) == [metadata[file][key] for file in files]


def test_records_without_metadata_are_refused_by_the_selection_naming_them(tmp_path) -> None:
    folder = _peer(tmp_path)
    shutil.copy(folder / "RSN90001_IMAGVAL_ALP000.AT2", folder / "unlisted.AT2")
    records = '[[records]]\nsuite = "peer"\n[[records]]\nrecord = "el_centro_1940"\n'
    with pytest.raises(ExperimentError, match=r"^records: the conditional-spectrum selection takes records with metadata .*, "
                                              r"2 have none: unlisted, el_centro_1940 \(use a named suite, or a folder of PEER "
                                              r"downloads with its _SearchResults\.csv\)$"):
        load_experiment(write_experiment(tmp_path, _experiment(records), "peer.toml")).selection
