"""The one reader of an experiment file's tables (stochpound.store.TomlTable): each field declared, each error one line naming it."""

from __future__ import annotations

import math

import pytest

from stochpound._errors import SceneError
from stochpound.store import TomlTable


def _error(read) -> str:
    with pytest.raises(SceneError) as error:
        read()
    return str(error.value)


def test_unknown_keys_are_refused_naming_the_table_the_key_and_the_allowed_keys():
    assert _error(lambda: TomlTable({"sds": 1.0, "colour": 2}, "design", {"sds", "sd1"})) == "design.colour: unknown field (allowed: sd1, sds)"
    assert _error(lambda: TomlTable({"bogus": 1}, "", {"grid"})) == "bogus: unknown field (allowed: grid)"
    table = TomlTable({"a": 1}, "t")
    assert "a" in table and "b" not in table and list(table) == ["a"]


def test_a_number_is_read_within_its_range_or_named_with_it():
    table = TomlTable({"x": 2, "big": 7.0, "zero": 0.0, "word": "two", "nan": math.nan, "inf": math.inf}, "design.ec8")
    assert table.number("x", low=0.0) == 2.0 and isinstance(table.number("x"), float)
    assert table.number("absent", 8.0) == 8.0 and table.number("absent", None) is None
    assert _error(lambda: table.number("absent")) == "design.ec8.absent: missing (a number is required)"
    assert _error(lambda: table.number("big", high=5.0)) == "design.ec8.big: must be <= 5, got 7"
    assert _error(lambda: table.number("zero", low=0.0, low_open=True)) == "design.ec8.zero: must be > 0, got 0"
    assert _error(lambda: table.number("word")) == "design.ec8.word: must be a number, got str 'two'"
    assert _error(lambda: table.number("nan")) == "design.ec8.nan: must be a number, got nan"
    assert _error(lambda: table.number("inf")) == "design.ec8.inf: must be finite, got inf"
    assert table.number("inf", allow_inf=True) == math.inf


def test_an_integer_a_string_with_its_choices_a_boolean_and_a_list_of_numbers():
    table = TomlTable({"count": 0, "flag": True, "half": 1.5, "method": "euler", "on": "yes", "periods": [0.5, -1.0]}, "synthetic.kt")
    assert _error(lambda: table.integer("count", low=1, high=10)) == "synthetic.kt.count: must be an integer in [1, 10], got 0"
    assert _error(lambda: table.integer("flag", low=0)) == "synthetic.kt.flag: must be an integer >= 0, got True"
    assert _error(lambda: table.integer("half")) == "synthetic.kt.half: must be an integer, got 1.5"
    assert _error(lambda: table.integer("n", low=1, high=10, meaning="the number")) == "synthetic.kt.n: missing (the number, an integer in [1, 10])"
    assert table.integer("start", 0, low=0) == 0
    assert _error(lambda: table.string("method", choices=("exact", "ivp"))) == "synthetic.kt.method: must be one of exact, ivp, got 'euler'"
    assert _error(lambda: table.string("method", choices=("a",), hint="see docs")) == "synthetic.kt.method: must be one of a (see docs), got 'euler'"
    assert table.string("integrator", "DOP853", choices=("DOP853",)) == "DOP853" and table.string("absent", None) is None
    assert _error(lambda: table.boolean("on", False)) == "synthetic.kt.on: must be true or false, got 'yes'"
    assert table.boolean("absent", True) is True
    assert _error(lambda: table.numbers("periods", low=0.0, low_open=True)) == "synthetic.kt.periods[1]: must be > 0, got -1"
    assert table.numbers("absent", ()) == ()


def test_sub_tables_and_lists_of_tables_carry_their_dotted_names():
    file = TomlTable({"design": {"ec8": {"q": 9.0}}, "records": [{"record": "a"}, {"name": 3}], "solver": 1}, "")
    ec8 = file.table("design").table("ec8", {"q", "ag"})
    assert ec8.name == "design.ec8" and ec8.field("q") == "design.ec8.q"
    assert _error(lambda: ec8.number("q", high=8.0)) == "design.ec8.q: must be <= 8, got 9"
    assert file.table("hazard") is None and file.table_or_empty("output").name == "output" and list(file.table_or_empty("output")) == []
    assert _error(lambda: file.table("solver")) == "solver: must be a table, got int"
    assert _error(lambda: file.table("solver", hint="{ method = ... }")) == "solver: must be a table { method = ... }, got 1"
    records = file.tables("records")
    assert [r.name for r in records] == ["records[0]", "records[1]"] and file.tables("motions") == []
    assert _error(lambda: records[1].string("name")) == "records[1].name: must be a non-empty string, got 3"
    assert _error(lambda: file.tables("solver", hint="name and type")) == "solver: must be an array of tables ([[solver]] with name and type)"
    assert str(file.error("grid", "unknown axis")) == "grid: unknown axis" and file.raw("absent", 4) == 4


def test_a_parser_of_its_own_error_class_gets_the_same_messages_raised_as_that_class():
    from stochpound._errors import SiteError

    table = TomlTable({"motions": 1, "site": {"seeds": [0.5, "x"]}, "rows": [{"gap": -1.0}]}, "intensity", raises=SiteError)
    with pytest.raises(SiteError, match=r"^intensity\.motions: must be an integer >= 2, got 1$") as caught:
        table.integer("motions", low=2)
    assert not isinstance(caught.value, SceneError)
    with pytest.raises(SiteError, match=r"^intensity\.site\.seeds\[1\]: must be a number, got str 'x'$"):
        table.table_or_empty("site").numbers("seeds")
    with pytest.raises(SiteError, match=r"^intensity\.rows\[0\]\.gap: must be >= 0, got -1$"):
        table.tables("rows")[0].number("gap", low=0.0)
    with pytest.raises(SiteError, match=r"^intensity\.kind: must be one of a, b, got 'c'$"):
        TomlTable({"kind": "c"}, "intensity", {"kind"}, SiteError).string("kind", choices=("a", "b"))
    with pytest.raises(SiteError, match=r"^intensity\.other: unknown field \(allowed: kind\)$"):
        TomlTable({"other": 1}, "intensity", {"kind"}, SiteError)
    assert _error(lambda: TomlTable({"motions": 1}, "intensity").integer("motions", low=2)) == "intensity.motions: must be an integer >= 2, got 1"
