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

from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, Protocol

from stochpound._studies import STUDIES, Study, claims, load_study, parse_reproduces

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
