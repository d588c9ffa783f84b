"""The registry of published studies, by id and parts, at the bottom of the house: the plug-in point of the studies.

An experiment file may declare the part of a study it reproduces
(``[experiment] reproduces = "<study>:<part>"``); reading the file checks
the declaration against :data:`STUDIES` here, and the report asks
:func:`claims` which stores each study claims and :func:`load_study` for the
study's package (``stochpound.studies.<key>``, imported by its registered
name on first use). So neither the experiment reader, nor the report, nor
the deprecated names of ``stochpound.motions.records`` import the studies'
packages, which build their reports on top of the report package:
``stochpound.studies`` re-exports these names.
"""

from __future__ import annotations

import importlib
from collections.abc import Mapping
from dataclasses import dataclass
from types import ModuleType
from typing import Any

from stochpound._errors import StochpoundError

__all__ = ["STUDIES", "Study", "claims", "load_study", "parse_reproduces"]


@dataclass(frozen=True)
class Study:
    """A published study that experiments reproduce.

    Attributes
    ----------
    key : str
        Its id, the package name under ``stochpound.studies`` and the part
        of ``reproduces`` before the colon (the package's docstring cites the publication).
    parts : tuple of str
        The parts an experiment may reproduce (after the colon), one store each.
    """

    key: str
    parts: tuple[str, ...]


STUDIES: dict[str, Study] = {
    study.key: study
    for study in (
        # V. K. Agarwal, "Pounding and impact of base isolated buildings due to earthquakes", M.S. thesis, Texas A&M University, 2004
        Study("agarwal2004", ("harmonic", "gap", "single", "pair_mu", "pair_records")),
    )
}
"""The registered studies, by key."""


def _allowed() -> str:
    return ", ".join(f"{study.key}:{part}" for study in STUDIES.values() for part in study.parts)


def parse_reproduces(value: Any) -> tuple[str, str]:
    """The (study, part) of a ``reproduces`` declaration.

    Parameters
    ----------
    value : str
        ``"<study>:<part>"``, a registered study (:data:`STUDIES`) and one of its parts.

    Returns
    -------
    tuple of str
        The study's key and the part.

    Raises
    ------
    ValueError
        If the value is not one of the registered studies' parts (the message lists them).
    """
    study, _, part = value.partition(":") if isinstance(value, str) else ("", "", "")
    if study not in STUDIES or part not in STUDIES[study].parts:
        raise ValueError(f"must be one of {_allowed()}, got {value!r}")
    return study, part


def claims(declared: Mapping[str, str | None]) -> dict[str, dict[str, str]]:
    """Which stores each study claims, by their declarations.

    Parameters
    ----------
    declared : mapping of str to str or None
        Each store's experiment name and its ``reproduces`` declaration (None: none).

    Returns
    -------
    dict
        For each study with at least one store, in the order of first appearance:
        the experiment name of each part present, by part.

    Raises
    ------
    StochpoundError
        If a declaration is not a registered part, or two stores reproduce the same part.
    """
    claimed: dict[str, dict[str, str]] = {}
    for name, reproduces in declared.items():
        if reproduces is None:
            continue
        try:
            study, part = parse_reproduces(reproduces)
        except ValueError as error:
            raise StochpoundError(f"experiment {name}: reproduces {error}") from None
        parts = claimed.setdefault(study, {})
        if part in parts:
            raise StochpoundError(f"experiments {parts[part]} and {name} both reproduce {study}:{part}; report one of them at a time")
        parts[part] = name
    return claimed


def load_study(key: str) -> ModuleType:
    """The package of the study ``key`` (:data:`STUDIES`), imported on first use: a :class:`stochpound.studies.StudyReport`."""
    if key not in STUDIES:
        raise StochpoundError(f"unknown study {key!r} (studies: {', '.join(STUDIES)})")
    return importlib.import_module(f"stochpound.studies.{key}")
