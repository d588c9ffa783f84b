"""Assemble a report from experiment stores.

The study's experiments (``experiments/study/*.toml``; recognised by their
experiment names) give the study's tables and figures, with the findings
and the methods; any other store gets a section of its own
(:mod:`stochpound.report.generic`). Sections whose store is missing are left
out, so a report can be built from any subset of the study's stores.
Every report opens with a summary, the answers first
(:mod:`stochpound.report.summary`); the report of experiments ends with an
appendix of its per-cell tables.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from datetime import date
from pathlib import Path

import xarray as xr

from stochpound.report import findings, study_figures, study_notes, study_tables
from stochpound.report.document import Block, Paragraph, Report, Section
from stochpound.report.ensembles import INTERVAL_NOTE
from stochpound.report.generic import store_section
from stochpound.report.intensity import intensity_section, intensity_setting
from stochpound.experiment.selections import has_contact_free, with_contacts
from stochpound.report.separation import separation_section
from stochpound.report.risk import has_risk, risk_section
from stochpound.report.laws import law_axis, laws_section
from stochpound.report.methods import methods_section
from stochpound.report.stores import open_stores
from stochpound.report.summary import experiment_summary, move_per_cell_tables, study_summary

#: Experiment names of the study's stores (``experiments/study/``).
STUDY_EXPERIMENTS = ("study_harmonic", "study_gap", "study_single", "study_pair_mu", "study_pair_records")
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


def assemble_report(paths: Sequence[str | Path], progress: Callable[[str], None] | None = None) -> Report:
    """Build the report of the given stores.

    Parameters
    ----------
    paths : sequence of path
        Experiment store files.
    progress : callable, optional
        Called with a short message before each step.

    Returns
    -------
    Report
    """
    say = progress or (lambda message: None)
    say("reading stores")
    stores = open_stores(paths)
    study = {name: store for name, store in stores.items() if name in STUDY_EXPERIMENTS}
    others = {name: store for name, store in stores.items() if name not in STUDY_EXPERIMENTS}
    report = Report(
        title="Pounding of base-isolated buildings: the reference study regenerated" if study else f"Pounding experiments: {', '.join(others)}",
        subtitle=f"stochpound report of {', '.join(stores)}, built {date.today().isoformat()}",
        sources=[f"{name}: {store.attrs.get('experiment_file', '')}, definition sha256 {store.attrs.get('definition_sha256', '')}" for name, store in stores.items()],
    )
    if study:
        report.sections.append(Section("About this report", [Paragraph(INTRODUCTION), Paragraph(f"Regenerate it from a fresh clone with: {STUDY_COMMAND}")], key="about"))
        for title, key, build in _study_sections(study):
            say(title)
            report.sections.append(Section(title, build(), key=key))
        findings_section = next((section for section in report.sections if section.key == "findings"), None)
        if findings_section is not None:
            report.sections.insert(0, study_summary(findings_section, report.sections))
    if others and not study:
        report.sections.append(Section("About this report", [Paragraph(_about(others))], key="about"))
    for name, store in others.items():  # the answer first: each store's risk at its site, right after the introduction
        if has_risk(store):
            say(f"experiment {name}: risk")
            report.sections.append(risk_section(name, store))
    for name, store in others.items():
        say(f"experiment {name}")
        contact_free = has_contact_free(store)
        finite = with_contacts(store) if contact_free else store
        if law_axis(store) is not None:
            report.sections.append(laws_section(name, finite))
        if all(finite.sizes[d] for d in finite["case_status"].dims):
            report.sections.append(store_section(name, finite, contact_free, store))
        if contact_free and not has_risk(store):  # with a hazard, the Risk section gives the separation at every intensity
            say(f"experiment {name}: separation")
            report.sections.append(separation_section(name, store))
        if intensity_setting(store) is not None:
            say(f"experiment {name}: intensity")
            report.sections.append(intensity_section(name, store))
    say("methods")
    report.sections.append(methods_section(stores))
    if others and not study:
        appendix = move_per_cell_tables(report.sections)
        if appendix is not None:
            report.sections.append(appendix)
        say("summary")
        report.sections.insert(0, experiment_summary(others, report.sections))
    return report


def _about(stores: dict[str, xr.Dataset]) -> str:
    """What the report of stores that are not the study's holds, and how to read it."""
    described = "; ".join(f"{name}: {store.attrs.get('experiment_description', '')}" for name, store in stores.items())
    return (
        f"This report describes the experiment stores {described}. Each experiment has a section: the cases run under "
        "records one by one, and each synthetic ensemble by the statistics of its realizations in every cell of the grid "
        f"(every combination of the grid's axes): means with 95 % confidence intervals ({INTERVAL_NOTE}), quantiles of the peaks, and "
        "the probability of pounding (at least one impact) with its 95 % Clopper–Pearson interval, followed by findings "
        "computed from them, tables (also written as CSV files) and figures in which every cell is drawn. An ECDF gives, for "
        "each value, the fraction of realizations at or below it; a convergence figure shows an estimate over the first n "
        "realizations, so that one sees whether the ensemble is large enough. The Methods section describes every building, "
        "contact and motion from the stores' own definitions and checks the solver while the report is built."
    )


def _study_sections(stores: dict[str, xr.Dataset]) -> list[tuple[str, str, Callable[[], list[Block]]]]:
    """(title, key, builder) of each study section whose stores are present."""
    gap, single, pair_mu, pair_records, harmonic = (stores.get(name) for name in ("study_gap", "study_single", "study_pair_mu", "study_pair_records", "study_harmonic"))
    sections = []
    if pair_mu is not None or gap is not None:
        sections.append(("Findings", "findings", lambda: _findings(gap, pair_mu, pair_records)))
    sections.append(("The records", "records", lambda: [study_tables.records_table(), study_figures.accelerograms()]))
    if harmonic is not None:
        sections.append(("Harmonic check", "harmonic", lambda: study_figures.harmonic_check(harmonic)))
    if gap is not None:
        sections.append(("Both fixed: pounding against the gap", "gap", lambda: [study_tables.building_2_table(gap), study_figures.gap_time_history(gap), *study_figures.against_gap(gap)]))
    if single is not None:
        sections.append(("Single isolated building against μ", "single", lambda: [*study_figures.single_against_mu(single), study_figures.single_histograms(single)]))
    if pair_mu is not None:
        sections.append(("The pair against μ (El Centro, gap 2 cm)", "pair-mu", lambda: _pair_mu(pair_mu)))
    if pair_records is not None:
        sections.append(("The pair by record (μ = 0.2)", "pair-records", lambda: _pair_records(pair_records, pair_mu, single)))
    return sections


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
    tables = [study_tables.mu_table(number, store) for number in ("4.1", "4.3", "4.5", "4.7")]
    return [*tables, *study_figures.pair_against_mu(store), study_tables.correlation_table(store), *study_notes.scaling_sensitivity(store)]


def _pair_records(store: xr.Dataset, pair_mu: xr.Dataset | None, single: xr.Dataset | None) -> list[Block]:
    blocks: list[Block] = [study_tables.by_record_table(number, store) for number in ("4.2", "4.4", "4.6", "4.8")]
    blocks += study_notes.northridge_means(store, single)
    blocks += study_figures.by_record_histograms(store)
    if pair_mu is not None:
        blocks.append(study_figures.configurations_time_history(pair_mu))
    return blocks
