"""The registry of published studies, by id and parts: metadata only, at the bottom of the house.

An experiment file may declare the part of a study it reproduces
(``[experiment] reproduces = "<study>:<part>"``); reading the file checks
the declaration against :data:`STUDIES` here, without importing the studies'
packages (``stochpound.studies``, which builds their reports on top of the
report package, re-exports these names and loads a study's package on use).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

__all__ = ["STUDIES", "Study", "parse_reproduces"]


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
