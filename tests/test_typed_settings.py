"""Settings travel as typed values, not string-keyed dicts (issue 47; docs/contributing.md, "Settings as typed values").

Two counts over ``stochpound/``, each with a ceiling that only comes down:

* **dict annotations**: ``dict[str, Any]``, ``Mapping[str, Any]`` (or ``object``
  for ``Any``) and bare ``dict`` / ``Mapping`` annotations of arguments and
  returns, the shape of a setting passed around untyped;
* **string-keyed reads**: ``.get("key")`` / ``.get('key')``, a setting read by
  its name where a typed record would hold it as an attribute.

A change that adds one fails here: give the value a typed record (a frozen
dataclass, :class:`stochpound.store.TomlTable` for a table being parsed)
instead. A change that removes some lowers the ceiling with it (the test
says so), so the count cannot creep back. The targets of issue 47 are < 100
and < 60.
"""

from __future__ import annotations

import re
from pathlib import Path

PACKAGE = Path(__file__).parents[1] / "stochpound"
DICT_ANNOTATION = re.compile(r"dict\[str, *(Any|object)\]|Mapping\[str, *(Any|object)\]|(:|->) *(dict|Mapping)( |,|\)|:|$)")
STRING_KEYED_READ = re.compile(r"\.get\([\"']")
#: The ceilings: today's counts. Lower them when a change lowers a count; never raise them.
CEILINGS = {"dict annotations": 78, "string-keyed reads": 54}


def _count(pattern: re.Pattern[str]) -> int:
    return sum(1 for path in sorted(PACKAGE.rglob("*.py")) for line in path.read_text().splitlines() if pattern.search(line))


def _counts() -> dict[str, int]:
    return {"dict annotations": _count(DICT_ANNOTATION), "string-keyed reads": _count(STRING_KEYED_READ)}


def test_no_new_untyped_settings() -> None:
    counts = _counts()
    over = {name: (counts[name], ceiling) for name, ceiling in CEILINGS.items() if counts[name] > ceiling}
    assert not over, f"more untyped settings than the ceiling (count, ceiling): {over}; give them typed records"


def test_the_ceilings_follow_the_counts_down() -> None:
    counts = _counts()
    slack = {name: (counts[name], ceiling) for name, ceiling in CEILINGS.items() if counts[name] < ceiling}
    assert not slack, f"counts below their ceilings (count, ceiling): {slack}; lower CEILINGS in {Path(__file__).name}"


def test_the_patterns_find_what_they_name() -> None:
    assert DICT_ANNOTATION.search("def f(table: Mapping[str, Any]) -> dict[str, Any]:")
    assert DICT_ANNOTATION.search("def f(table: dict) -> None:")
    assert not DICT_ANNOTATION.search("def f(table: TomlTable) -> Design:")
    assert STRING_KEYED_READ.search('name = table.get("name", "B1")')
    assert not STRING_KEYED_READ.search("value = cache.get(key)")
