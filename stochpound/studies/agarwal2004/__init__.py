"""The reproduction of V. K. Agarwal's M.S. thesis (Texas A&M University, 2004): its report.

The stores of ``experiments/study/*.toml`` declare the part of the study each
reproduces (``[experiment] reproduces = "agarwal2004:<part>"``, the parts of
:data:`stochpound.studies.STUDIES`); the report hands them here by part. The
study's tables and figures (:mod:`~stochpound.studies.agarwal2004._tables`,
:mod:`~stochpound.studies.agarwal2004._figures`), beside its published values
(:mod:`~stochpound.studies.agarwal2004._published`), with its conclusions
checked (:mod:`~stochpound.studies.agarwal2004._findings`) and the
explanations the report owes its reader
(:mod:`~stochpound.studies.agarwal2004._notes`). Sections whose store is
missing are left out, so a report can be built from any subset of the
study's stores.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping

import xarray as xr

from stochpound.report import Block, Paragraph, Section
from stochpound.studies.agarwal2004 import _figures as figures, _findings as findings, _notes as notes, _tables as tables
from stochpound.studies.agarwal2004._records import STUDY_G, record_report, study_table_3_2
from stochpound.studies.agarwal2004._scenes import (
    IMPACT_FREQUENCY,
    REFERENCE_DAMPING,
    REFERENCE_MASS,
    REFERENCE_STIFFNESS,
    reference_building,
    study_contacts,
    study_scene,
)

__all__ = [
    "IMPACT_FREQUENCY",
    "REFERENCE_DAMPING",
    "REFERENCE_MASS",
    "REFERENCE_STIFFNESS",
    "STUDY_COMMAND",
    "STUDY_G",
    "TITLE",
    "record_report",
    "reference_building",
    "sections",
    "study_contacts",
    "study_scene",
    "study_table_3_2",
    "summary",
]

TITLE = "Pounding of base-isolated buildings: the reference study regenerated"
"""The title of the study's report."""
#: The command that regenerates the committed study report (README, docs/reports.md).
STUDY_COMMAND = "stochpound experiment run experiments/study/*.toml && stochpound report build experiments/study/*.nc --out reports/study/"

INTRODUCTION = (
    "This report regenerates the tables and figures of V. K. Agarwal, \"Pounding and impact of base isolated buildings "
    "due to earthquakes\" (M.S. thesis, Texas A&M University, 2004) with stochpound, and sets the study's published "
    "values beside those of the corrected model (see Methods). Each comparison table has, for every quantity, the "
    "study's value, ours, their difference and, where it explains the study, the result of the study's own equations "
    "(study_compat). Loma Prieta and Northridge are substitutes for the study's records, which were not found: they "
    "are labelled so wherever they appear, and their rows are not comparable with the study's."
)


def sections(parts: Mapping[str, xr.Dataset]) -> list[tuple[str, str, Callable[[], list[Block]]]]:
    """(title, key, builder) of each section of the study's report whose stores are present.

    Parameters
    ----------
    parts : mapping of str to xarray.Dataset
        The stores present, by the part of the study they reproduce.

    Returns
    -------
    list of tuple
        The title, key and builder (called to build the section's blocks) of each section, in the report's order.
    """
    gap, single, pair_mu, pair_records, harmonic = (parts.get(part) for part in ("gap", "single", "pair_mu", "pair_records", "harmonic"))
    built: list[tuple[str, str, Callable[[], list[Block]]]] = [
        ("About this report", "about", lambda: [Paragraph(INTRODUCTION), Paragraph(f"Regenerate it from a fresh clone with: {STUDY_COMMAND}")]),
    ]
    if pair_mu is not None or gap is not None:
        built.append(("Findings", "findings", lambda: _findings(gap, pair_mu, pair_records)))
    built.append(("The records", "records", lambda: [tables.records_table(), figures.accelerograms()]))
    if harmonic is not None:
        built.append(("Harmonic check", "harmonic", lambda: figures.harmonic_check(harmonic)))
    if gap is not None:
        built.append(("Both fixed: pounding against the gap", "gap", lambda: [tables.building_2_table(gap), figures.gap_time_history(gap), *figures.against_gap(gap)]))
    if single is not None:
        built.append(("Single isolated building against μ", "single", lambda: [*figures.single_against_mu(single), figures.single_histograms(single)]))
    if pair_mu is not None:
        built.append(("The pair against μ (El Centro, gap 2 cm)", "pair-mu", lambda: _pair_mu(pair_mu)))
    if pair_records is not None:
        built.append(("The pair by record (μ = 0.2)", "pair-records", lambda: _pair_records(pair_records, pair_mu, single)))
    return built


def summary(sections: list[Section]) -> Section | None:
    """The summary of the study's report: each conclusion of the study with its verdict (the first sentence of each finding).

    Parameters
    ----------
    sections : list of Section
        The report's sections in their final order (after the summary).

    Returns
    -------
    Section or None
        None when the report has no findings (neither the gap nor the pair-against-μ store).
    """
    found = next((section for section in sections if section.key == "findings"), None)
    if found is None:
        return None
    number = next(n for n, section in enumerate(sections, start=2) if section is found)
    opening = Section("Summary", key="summary")
    opening.add(Paragraph(
        f"The study's conclusions, each checked against the corrected model; section {number} ({found.title}) gives the numbers "
        "behind each verdict, the later sections every table and figure of the study regenerated:"
    ))
    for block in found.blocks:
        if isinstance(block, Paragraph):
            opening.add(Paragraph(_first_sentence(block.text)))
    return opening


def _first_sentence(text: str) -> str:
    """The text up to its first full stop followed by a space and a capital (a decimal point is followed by a digit)."""
    return re.split(r"\. (?=[A-Z])", text, maxsplit=1)[0].rstrip(".") + "."


def _findings(gap: xr.Dataset | None, pair_mu: xr.Dataset | None, pair_records: xr.Dataset | None) -> list[Block]:
    blocks: list[Block] = []
    if pair_mu is not None:
        blocks += [findings.fixed_columns(pair_mu), findings.isolated_columns(pair_mu)]
    if gap is not None:
        blocks += [findings.gap_effect(gap), findings.small_gaps(gap)]
        blocks.append(findings.phase(gap, pair_mu))
    if pair_mu is not None:
        blocks += [findings.worst_case(pair_mu, pair_records), findings.correlation_collapse(pair_mu)]
    return blocks


def _pair_mu(store: xr.Dataset) -> list[Block]:
    built = [tables.mu_table(number, store) for number in ("4.1", "4.3", "4.5", "4.7")]
    return [*built, *figures.pair_against_mu(store), tables.correlation_table(store), *notes.scaling_sensitivity(store)]


def _pair_records(store: xr.Dataset, pair_mu: xr.Dataset | None, single: xr.Dataset | None) -> list[Block]:
    blocks: list[Block] = [tables.by_record_table(number, store) for number in ("4.2", "4.4", "4.6", "4.8")]
    blocks += notes.northridge_means(store, single)
    blocks += figures.by_record_histograms(store)
    if pair_mu is not None:
        blocks.append(figures.configurations_time_history(pair_mu))
    return blocks
