"""Readers: PEER .AT2 (both header styles) and text columns; round trips and malformed input."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from stochpound._errors import RecordError
from stochpound.motions.records import load_record, read_at2, read_record_file, read_text, records_dir, registry_entries
from tests.helpers import invoke


def _write_at2(path: Path, values: np.ndarray, dt: float, style: str, per_line: int = 5, units: str = "G", units_line: str | None = None) -> Path:
    if style == "west2":
        npts_line = f"NPTS={len(values):7d}, DT={dt:9.4f} SEC,"
    else:
        npts_line = f"{len(values):7d} {dt:10.4f}    NPTS, DT"
    third = f"ACCELERATION TIME SERIES IN UNITS OF {units}" if units_line is None else units_line
    lines = ["PEER NGA STRONG MOTION DATABASE RECORD", "Test event, test station, 090", third, npts_line]
    for start in range(0, len(values), per_line):
        lines.append("".join(f"{float(v)!r:>26s}" for v in values[start : start + per_line]))
    path.write_text("\n".join(lines) + "\n")
    return path


def _write_text(path: Path, columns: list[np.ndarray], header: str = "") -> Path:
    rows = ["  ".join(repr(float(c[k])) for c in columns) for k in range(len(columns[0]))]
    path.write_text((header + "\n" if header else "") + "\n".join(rows) + "\n")
    return path


def _bundled_files() -> list[tuple[str, dict]]:
    return [(name, e.to_dict()) for name, e in registry_entries().items() if not e.is_variant]


# ---------------------------------------------------------------- round trips of every bundled file


_ROUND_TRIPS = [
    pytest.param(name, fields, style, id=f"{name}-{style}")
    for name, fields in _bundled_files()
    for style in ("west2", "west1", "two_column", "one_column")
    if not (style.startswith("west") and fields.get("units") != "g")  # PEER .AT2 files are in g
]


@pytest.mark.parametrize("name,fields,style", _ROUND_TRIPS)
def test_bundled_files_round_trip(tmp_path, name, fields, style):
    original = read_record_file(records_dir() / fields["file"], column=fields.get("column"), units=fields.get("units"), dt=fields.get("dt"))
    values, dt = original.values, original.dt
    if style in ("west2", "west1"):
        back = read_at2(_write_at2(tmp_path / "r.AT2", values, dt, style), dt=None)
    elif style == "two_column":
        times = original.source_start_time + dt * np.arange(values.size)
        back = read_text(_write_text(tmp_path / "r.txt", [times, values]), units=original.units)
        assert back.source_start_time == pytest.approx(original.source_start_time)
    else:
        back = read_text(_write_text(tmp_path / "r.txt", [values], header=f"# units: {original.units}"), dt=dt)
    np.testing.assert_array_equal(back.values, values)
    assert back.dt == pytest.approx(dt, rel=1e-9)
    assert back.units == original.units


def test_at2_reader_matches_the_file_text():
    """The Peknold file (8F10.5, last line short, no final newline) read value by value."""
    path = records_dir() / "elcentro1940_NS_peknold_chopra_dt0.02_1559.AT2"
    series = read_at2(path)
    lines = path.read_text().splitlines()
    expected = [float(tok) for line in lines[4:] for tok in line.split()]
    assert series.values.size == 1559 == len(expected)
    np.testing.assert_array_equal(series.values, expected)
    assert series.dt == 0.02 and series.units == "g"


def test_three_component_file_columns_equal_the_single_component_file():
    three = records_dir() / "mexico1985_SCT_3comp_dt0.02_original.txt"
    ns = read_text(three, column=1)
    single = load_record("mexico_city_1985_sct")
    np.testing.assert_array_equal(ns.values, single.values)
    assert ns.source_start_time == pytest.approx(0.02)
    assert ns.dt == pytest.approx(0.02, rel=1e-6)


def test_first_sample_at_dt_is_shifted_to_zero(tmp_path):
    values = np.array([0.1, -0.2, 0.3, 0.05])
    path = _write_text(tmp_path / "late.txt", [0.02 + 0.02 * np.arange(4), values])
    rec = load_record(path)
    assert rec.source_start_time == pytest.approx(0.02)
    np.testing.assert_allclose(rec.time, [0.0, 0.02, 0.04, 0.06])
    np.testing.assert_array_equal(rec.values, values)


def test_units_and_comment_header(tmp_path):
    values = np.array([1.0, -2.0, 3.0])
    cm = _write_text(tmp_path / "cm.txt", [values], header="# station X\n# units: cm/s^2")
    rec = load_record(cm, dt=0.01)
    assert rec.units == "cm/s2"
    np.testing.assert_allclose(rec.acceleration(), values / 100.0)
    plain = _write_text(tmp_path / "plain.txt", [values])
    assert load_record(plain, dt=0.01).units == "g"  # documented default
    assert load_record(plain, dt=0.01, units="m/s^2").units == "m/s2"
    with pytest.raises(RecordError, match="cm.txt: units='g' was given but the file states 'cm/s2'"):
        load_record(cm, dt=0.01, units="g")


def test_at2_units_from_header(tmp_path):
    path = _write_at2(tmp_path / "gal.AT2", np.array([1.0, 2.0]), 0.01, "west2", units="CM/S/S")
    assert read_at2(path).units == "cm/s2"


# ---------------------------------------------------------------- units: every spelling, unknown units, implausible peaks

#: m/s² per unit of each canonical name, written out independently of the reader (g taken as 9.81).
SI = {"g": 9.81, "m/s2": 1.0, "cm/s2": 0.01}
#: A record of peak 632 cm/s² (0.64 g) in each unit: read as g it would be 632 g.
PEAK_632_GAL = {units: np.array([0.0, 300.0, -632.0, 150.0]) * 0.01 / factor for units, factor in SI.items()}

AT2_SPELLINGS = [
    ("ACCELERATION TIME SERIES IN GAL", "cm/s2"),
    ("ACCELERATION TIME SERIES IN UNITS OF GALS", "cm/s2"),
    ("ACCELERATION (cm/s^2)", "cm/s2"),
    ("ACCELERATION IN CM/SEC2", "cm/s2"),
    ("Acceleration in cm/s²", "cm/s2"),
    ("acceleration [cm s-2], baseline corrected", "cm/s2"),
    ("UNITS: cm/s**2", "cm/s2"),
    ("ACCELERATION TIME HISTORY IN CM/SEC/SEC", "cm/s2"),
    ("ACCELERATION TIME HISTORY IN M/S/S", "m/s2"),
    ("acceleration (m/s²)", "m/s2"),
    ("the units are m/s^2", "m/s2"),
    ("ACCELERATION TIME HISTORY IN UNITS OF G", "g"),
    ("ACCELERATION TIME HISTORY IN G", "g"),
    ("Acceleration [g]", "g"),
    ("acceleration as a fraction of g", "g"),
]


@pytest.mark.parametrize("line, units", AT2_SPELLINGS, ids=[line for line, _ in AT2_SPELLINGS])
def test_at2_units_read_in_every_spelling(tmp_path, line, units):
    values = PEAK_632_GAL[units]
    path = _write_at2(tmp_path / "r.AT2", values, 0.01, "west2", units_line=line)
    record = load_record(path)
    assert record.units == units
    np.testing.assert_allclose(record.acceleration(g=9.81), values * SI[units])
    assert np.max(np.abs(record.acceleration(g=9.81))) == pytest.approx(6.32)


@pytest.mark.parametrize("header, units", [
    ("# station X, acceleration in gal", "cm/s2"),
    ("# t (s), a (cm/s^2)", "cm/s2"),
    ("# t [s]  a [m/s/s]", "m/s2"),
    ("# units: m/s^2 (divide by 9.81 for g)", "m/s2"),
    ("# acceleration in g", "g"),
])
def test_text_comment_units_read_in_every_spelling(tmp_path, header, units):
    values = PEAK_632_GAL[units]
    path = _write_text(tmp_path / "r.txt", [0.01 * np.arange(values.size), values], header=header)
    record = load_record(path)
    assert record.units == units
    np.testing.assert_allclose(record.acceleration(g=9.81), values * SI[units])


@pytest.mark.parametrize("line, spelling", [
    ("ACCELERATION IN MM/S2", "MM/S2"),
    ("ACCELERATION IN IN/S/S", "IN/S/S"),
    ("ACCELERATION TIME SERIES IN UNITS OF FT/SEC2", "FT/SEC2"),
    ("UNITS: counts", "counts"),
])
def test_at2_header_naming_unknown_units_is_refused(tmp_path, line, spelling):
    path = _write_at2(tmp_path / "odd.AT2", np.array([0.1, -0.2]), 0.01, "west2", units_line=line)
    message = _error(path)
    assert message.startswith(f"{path}, line 3: the header names units {spelling!r}") and "\n" not in message


def test_text_comment_naming_unknown_units_is_refused(tmp_path):
    path = _write_text(tmp_path / "odd.txt", [np.array([0.1, -0.2])], header="# units: mm/s^2")
    assert _error(path, dt=0.01).startswith(f"{path}, line 1: the header names units 'mm/s^2'")


def test_header_naming_two_units_is_refused(tmp_path):
    path = _write_at2(tmp_path / "two.AT2", np.array([0.1, -0.2]), 0.01, "west2", units_line="ACCELERATION IN GAL, PEAK GIVEN (g)")
    message = _error(path)
    assert message.startswith(f"{path}: the header names two units") and "'GAL' (line 3)" in message and "(g)" in message


def test_stated_units_win_over_units_named_elsewhere(tmp_path):
    path = _write_text(tmp_path / "r.txt", [PEAK_632_GAL["cm/s2"]], header="# units: cm/s2\n# peak 0.64 in g")
    assert load_record(path, dt=0.01).units == "cm/s2"


def test_at2_in_gal_labelled_g_is_refused_for_its_peak(tmp_path):
    """The newcomer's file: values in gal under a header saying g; its 632 g peak is refused, naming the units that fit."""
    path = _write_at2(tmp_path / "gal.AT2", PEAK_632_GAL["cm/s2"], 0.01, "west2")
    message = _error(path)
    assert message.startswith(f"{path}: peak 632 g") and "the file's header" in message
    assert "more than 5 g" in message and "cm/s2" in message and "\n" not in message


def test_implausible_peaks_are_refused_whatever_gave_the_units(tmp_path):
    plain = _write_text(tmp_path / "plain.txt", [PEAK_632_GAL["cm/s2"]])
    message = _error(plain, dt=0.01)
    assert "peak 632 g" in message and "the default, g (the file names no units)" in message and "cm/s2" in message
    message = _error(plain, dt=0.01, units="m/s2")
    assert "peak 632 m/s2 (64.4 g; units from units='m/s2')" in message and "cm/s2" in message
    assert load_record(plain, dt=0.01, units="cm/s2").units == "cm/s2"


def test_the_plausible_peak_is_5_g(tmp_path):
    below = _write_text(tmp_path / "below.txt", [np.array([0.0, 4.99, -1.0])], header="# units: g")
    assert load_record(below, dt=0.01).units == "g"
    above = _write_text(tmp_path / "above.txt", [np.array([0.0, 5.01 * 9.81, -1.0])], header="# units: m/s2")
    assert "more than 5 g" in _error(above, dt=0.01)


@pytest.mark.parametrize("name,fields", _bundled_files(), ids=[name for name, _ in _bundled_files()])
def test_bundled_files_read_in_the_registry_units_without_being_told(name, fields):
    """Each bundled file's own header (or the default, g) gives the units the registry states."""
    series = read_record_file(records_dir() / fields["file"], column=fields.get("column"), dt=fields.get("dt"), fmt=fields.get("format"))
    assert series.units == fields["units"]


def test_records_list_shows_each_files_units(tmp_path):
    listed = {line.split()[0]: line.split()[1] for line in invoke("records", "list").stdout.splitlines() if line[:1].strip() and " " in line.strip()}
    assert listed["northridge_1994_sylmar_hospital_360"] == "m/s2" and listed["northridge_1994_substitute"] == "m/s2"
    assert listed["el_centro_1940_ngaw2_rsn6"] == "g" and listed["el_centro_1940_study"] == "g"
    _write_at2(tmp_path / "a_gal.AT2", PEAK_632_GAL["cm/s2"], 0.01, "west2", units_line="ACCELERATION IN GAL")
    _write_text(tmp_path / "b_g.txt", [0.01 * np.arange(4), PEAK_632_GAL["g"]])
    rows = invoke("records", "list", "--suite", str(tmp_path)).stdout.splitlines()
    assert rows[0].split()[-1] == "units"
    assert [row.split()[-1] for row in rows[1:]] == ["cm/s2", "g"]


def test_comma_separated_and_fortran_exponents(tmp_path):
    path = tmp_path / "csv.txt"
    path.write_text("# time, acc\n0.0, 1.0D-02\n0.01, -2.5e-3\n0.02, 3\n")
    rec = load_record(path)
    np.testing.assert_allclose(rec.values, [0.01, -0.0025, 3.0])
    assert rec.dt == pytest.approx(0.01)


# ---------------------------------------------------------------- malformed input


def _error(path, **kwargs) -> str:
    with pytest.raises(RecordError) as info:
        load_record(path, **kwargs)
    return str(info.value)


def test_wrong_point_count(tmp_path):
    path = _write_at2(tmp_path / "short.AT2", np.arange(7.0), 0.01, "west2")
    path.write_text(path.read_text().replace("NPTS=      7", "NPTS=      9"))
    message = _error(path)
    assert "short.AT2" in message and "NPTS=9" in message and "7 values" in message


def test_wrong_point_count_west1(tmp_path):
    path = _write_at2(tmp_path / "old.AT2", np.arange(12.0), 0.01, "west1")
    path.write_text(path.read_text().replace("     12 ", "     11 "))
    assert "NPTS=11 but 12 values" in _error(path)


def test_non_numeric_value_names_file_and_line(tmp_path):
    path = tmp_path / "bad.txt"
    path.write_text("# header\n0.1\n0.2\n0.3x\n0.4\n")
    message = _error(path, dt=0.02)
    assert message.startswith(f"{path}, line 4:") and "'0.3x'" in message


def test_non_numeric_in_at2(tmp_path):
    path = _write_at2(tmp_path / "bad.AT2", np.arange(10.0), 0.01, "west2")
    lines = path.read_text().splitlines()
    lines[5] = lines[5].replace("6.0", "six", 1)
    path.write_text("\n".join(lines))
    assert "bad.AT2, line 6: cannot read 'six'" in _error(path)


@pytest.mark.parametrize("token", ["nan", "NaN", "inf", "-Infinity"])
def test_non_finite_values(tmp_path, token):
    path = tmp_path / "nan.txt"
    path.write_text(f"0.1\n{token}\n0.3\n")
    message = _error(path, dt=0.01)
    assert "line 2" in message and "non-finite" in message


def test_missing_dt(tmp_path):
    path = _write_text(tmp_path / "one.txt", [np.array([0.1, 0.2, 0.3])])
    message = _error(path)
    assert "one.txt: missing dt" in message


def test_non_uniform_time_step(tmp_path):
    times = np.array([0.0, 0.02, 0.04, 0.07, 0.09, 0.11])
    path = _write_text(tmp_path / "jitter.txt", [times, np.ones(6)])
    message = _error(path)
    assert "jitter.txt, line 4: non-uniform time step" in message


def test_decreasing_time(tmp_path):
    path = _write_text(tmp_path / "back.txt", [np.array([0.0, 0.02, 0.01]), np.ones(3)])
    assert "back.txt, line 3: time 0.01 s does not increase" in _error(path)


def test_zero_length(tmp_path):
    empty = tmp_path / "empty.txt"
    empty.write_text("# only a header\n\n")
    assert "no data lines" in _error(empty, dt=0.01)
    at2 = _write_at2(tmp_path / "empty.AT2", np.array([]), 0.01, "west2")
    assert "empty" in _error(at2)


def test_ragged_columns(tmp_path):
    path = tmp_path / "ragged.txt"
    path.write_text("0.0 1.0\n0.01 2.0\n0.02\n")
    assert "ragged.txt, line 3: 1 column(s), but the first data line (line 1) has 2" in _error(path)


def test_many_columns_need_a_column(tmp_path):
    three = records_dir() / "mexico1985_SCT_3comp_dt0.02_original.txt"
    with pytest.raises(RecordError, match="4 columns; column 0 is taken as time, say which column"):
        read_text(three)
    with pytest.raises(RecordError, match=r"column must be an integer in 1\.\.3"):
        read_text(three, column=4)


def test_missing_at2_header(tmp_path):
    path = tmp_path / "nohead.AT2"
    path.write_text("just\nsome text\n1 2 3\n")
    assert "no PEER header line" in _error(path)


def test_velocity_file_is_refused(tmp_path):
    path = _write_at2(tmp_path / "vel.VT2", np.arange(3.0), 0.01, "west2")
    path.write_text(path.read_text().replace("ACCELERATION TIME SERIES IN UNITS OF G", "VELOCITY TIME SERIES IN UNITS OF CM/S"))
    assert "velocity or displacement" in _error(path, fmt="at2")


def test_dt_disagreeing_with_the_file(tmp_path):
    path = _write_at2(tmp_path / "dt.AT2", np.arange(3.0), 0.01, "west2")
    assert "dt=0.02 s was given but its header says dt=0.01 s" in _error(path, dt=0.02)


def test_missing_file_lists_the_bundled_names(tmp_path):
    message = _error(tmp_path / "nowhere.AT2")
    assert "no bundled record of that name and no such file" in message
    assert "el_centro_1940" in message and "northridge_1994_substitute" in message


def test_format_detection_by_content(tmp_path):
    """A PEER file with another extension is read as AT2; a NPTS/DT comment does not make a text file AT2."""
    peer = _write_at2(tmp_path / "peer.dat", np.array([0.1, 0.2, 0.3]), 0.01, "west1")
    series = read_record_file(peer)
    assert series.fmt == "at2" and series.values.size == 3
    text = tmp_path / "commented.txt"
    text.write_text("# NPTS= 3, DT= 0.01 SEC\n0.1\n0.2\n0.3\n")
    series = read_record_file(text, dt=0.01)
    assert series.fmt == "text" and series.values.size == 3
