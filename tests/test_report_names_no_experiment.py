"""The generic report names no experiment: a store is a study's because its experiment declares the part it reproduces.

The report package (``stochpound/report/``) is read as text: it must not
name any experiment of ``experiments/`` nor a registered study, and it must
not import a study's package (only the registry, :mod:`stochpound.studies`).
The registry hands a study the stores that claim its parts, and refuses two
stores that claim the same one.
"""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

import pytest

from stochpound._errors import StochpoundError
from stochpound.studies import STUDIES, claims, parse_reproduces

ROOT = Path(__file__).resolve().parents[1]
REPORT_SOURCES = sorted((ROOT / "stochpound" / "report").rglob("*.py"))
#: "study_" names the generic report may use: the scene's field study_compat (docs/scene-files.md; a case's own equations)
#: and the records registry's field study_relation (a record's relation to a study), both contract names.
CONTRACT_FIELDS = re.compile(r"^study_(compat\w*|relation)$")


def _experiment_names() -> set[str]:
    files = [p for p in (ROOT / "experiments").glob("**/*.toml") if "scenes" not in p.parts]
    return {tomllib.loads(p.read_text())["experiment"]["name"] for p in files}


def test_the_generic_report_names_no_experiment_and_no_study() -> None:
    names = _experiment_names()
    assert {"study_harmonic", "study_gap", "study_single", "study_pair_mu", "study_pair_records", "quickstart"} <= names
    assert len(REPORT_SOURCES) > 10
    forbidden = sorted(names | set(STUDIES))
    found = []
    for path in REPORT_SOURCES:
        text = path.read_text()
        where = path.relative_to(ROOT)
        found += [f"{where}: {name}" for name in forbidden if re.search(rf"\b{re.escape(name)}\b", text)]
        found += [f"{where}: {name}" for name in sorted(set(re.findall(r"\bstudy_\w+", text))) if not CONTRACT_FIELDS.match(name)]
        found += [f"{where}: imports {module}" for module in re.findall(r"(?:from|import)\s+stochpound\.studies\.\w+", text)]
    assert not found, "the generic report names experiments or studies:\n" + "\n".join(found)


def test_the_study_files_declare_the_parts_they_reproduce() -> None:
    """Every part of every registered study has one experiment file that declares it, and only the study's files declare one."""
    declared = {}
    for path in (p for p in (ROOT / "experiments").glob("**/*.toml") if "scenes" not in p.parts):
        header = tomllib.loads(path.read_text())["experiment"]
        if "reproduces" in header:
            declared[header["name"]] = header["reproduces"]
    assert sorted(declared.values()) == sorted(f"{study.key}:{part}" for study in STUDIES.values() for part in study.parts)
    assert claims(declared) == {"agarwal2004": {parse_reproduces(r)[1]: name for name, r in declared.items()}}


def test_claims_refuses_two_stores_for_one_part_and_an_unknown_part() -> None:
    assert claims({"mine": None}) == {}
    with pytest.raises(StochpoundError, match="experiments a and b both reproduce agarwal2004:gap"):
        claims({"a": "agarwal2004:gap", "b": "agarwal2004:gap"})
    with pytest.raises(StochpoundError, match="experiment a: reproduces must be one of agarwal2004:harmonic"):
        claims({"a": "agarwal2004:figure_3"})
