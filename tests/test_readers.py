"""Readers: PEER .AT2 (both header styles) and text columns; round trips and malformed input."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from stochpound._errors import RecordError
from stochpound.motions.records import load_record, read_at2, read_record_file, read_text, records_dir, registry_entries


def _write_at2(path: Path, values: np.ndarray, dt: float, style: str, per_line: int = 5, units: str = "G") -> Path:
    if style == "west2":
        npts_line = f"NPTS={len(values):7d}, DT={dt:9.4f} SEC,"
    else:
        npts_line = f"{len(values):7d} {dt:10.4f}    NPTS, DT"
    lines = ["PEER NGA STRONG MOTION DATABASE RECORD", "Test event, test station, 090", f"ACCELERATION TIME SERIES IN UNITS OF {units}", npts_line]
    for start in range(0, len(values), per_line):
        lines.append("".join(f"{float(v)!r:>26s}" for v in values[start : start + per_line]))
    path.write_text("\n".join(lines) + "\n")
    return path


def _write_text(path: Path, columns: list[np.ndarray], header: str = "") -> Path:
    rows = ["  ".join(repr(float(c[k])) for c in columns) for k in range(len(columns[0]))]
    path.write_text((header + "\n" if header else "") + "\n".join(rows) + "\n")
    return path


def _bundled_files() -> list[tuple[str, dict]]:
    return [(name, dict(e.fields)) for name, e in registry_entries().items() if not e.is_variant]


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
