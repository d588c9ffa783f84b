"""The public report API (``stochpound.report``) and the thesis's names moved to its study (issue #32, item 6)."""

import warnings

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

import stochpound.motions.records as records
from stochpound import report
from stochpound.cli import main
from stochpound.motions.records import load_record, record_statistics
from stochpound.studies import agarwal2004


def test_a_report_built_from_the_public_blocks_is_written(tmp_path):
    frame = pd.DataFrame({"gap (cm)": [1.0, 2.0], "impacts": [3, 0]})
    section = report.Section("Gaps", key="gaps")
    section.add(report.Paragraph("Two gaps."))
    section.add(report.Table(key="table-gaps", caption="Impacts by gap.", frame=frame))
    written = report.write_report(report.Report(title="A report", sections=[section]), tmp_path / "out", formats=["html"])
    html = written["html"].read_text()
    assert "Two gaps." in html and "Impacts by gap." in html
    assert pd.read_csv(written["tables"] / "table-gaps.csv", index_col=0).equals(frame)


def test_build_report_is_the_entry_point_of_report_build():
    from stochpound.report.assemble import assemble_report

    assert report.build_report is assemble_report


@pytest.mark.parametrize("name", ["STUDY_G", "study_table_3_2"])
def test_the_old_records_names_still_work_and_warn(name):
    with pytest.warns(DeprecationWarning, match=f"stochpound.studies.agarwal2004.{name}"):
        old = getattr(records, name)
    assert old is getattr(agarwal2004, name)


def test_an_unknown_records_name_is_still_an_attribute_error():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(AttributeError, match="no_such_name"):
            getattr(records, "no_such_name")


def test_the_study_owns_its_g_and_table():
    assert agarwal2004.STUDY_G == 9.814
    assert agarwal2004.study_table_3_2("el_centro")["npts"] == 2500
    assert set(agarwal2004.study_table_3_2()) == {"mexico_city", "el_centro", "loma_prieta", "northridge"}


def test_record_tools_default_to_a_neutral_g():
    record = load_record("el_centro_1940_study")
    assert record_statistics(record).g == 9.81
    assert record.units == "g"
    assert record_statistics(record).peak_g == pytest.approx(np.max(np.abs(record.values)), rel=1e-12)
    shown = CliRunner().invoke(main, ["records", "show", "el_centro_1940_study"])
    assert shown.exit_code == 0, shown.output
    assert "g = 9.81 m/s2" in shown.output and "study Table 3.2" in shown.output
    told = CliRunner().invoke(main, ["records", "show", "el_centro_1940_study", "--g", "9.814"])
    assert "g = 9.814 m/s2" in told.output
    assert told.output != shown.output
