"""Reproductions of published studies, and the registry that finds them.

An experiment declares the part of a study it reproduces in its file,
``[experiment] reproduces = "<study>:<part>"`` (e.g.
``"agarwal2004:pair_mu"``; checked by :func:`parse_reproduces` when the file
is read). The report (``stochpound.report.assemble``) asks :func:`claims`
which of its stores each study claims by that declaration, and hands them to
the study (:func:`load_study`), which builds its sections; the other
stores get the generic report. Neither side names an experiment.

A study is a package ``stochpound.studies.<key>`` registered in
:data:`STUDIES` with the parts an experiment may reproduce. Its package
gives (see :class:`StudyReport`):

* ``TITLE``: the report's title;
* ``sections(parts)``: the (title, key, builder) of each section, given the
  stores of the parts present (by part);
* ``summary(sections)``: the summary section opening the report, given its
  sections, or None.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, Protocol

from stochpound._errors import StochpoundError
from stochpound._studies import STUDIES, Study, parse_reproduces

if TYPE_CHECKING:
    import xarray as xr

    from stochpound.report.render import Block, Section

__all__ = ["STUDIES", "Study", "StudyReport", "claims", "parse_reproduces", "load_study"]


class StudyReport(Protocol):
    """What a study's package gives the report (module docstring)."""

    TITLE: str

    def sections(self, parts: Mapping[str, xr.Dataset]) -> list[tuple[str, str, Callable[[], list[Block]]]]:
        """(title, key, builder) of each section, given the stores of the parts present (by part)."""

    def summary(self, sections: list[Section]) -> Section | None:
        """The summary that opens the report, given its sections; None: no summary."""


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


def load_study(key: str) -> StudyReport:
    """The package of the study ``key`` (:data:`STUDIES`), imported on first use."""
    if key not in STUDIES:
        raise StochpoundError(f"unknown study {key!r} (studies: {', '.join(STUDIES)})")
    return importlib.import_module(f"{__name__}.{key}")  # type: ignore[return-value]
