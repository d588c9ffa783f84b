"""Assemble a report from experiment stores.

A store whose experiment declares that it reproduces part of a published
study (``[experiment] reproduces = "<study>:<part>"``) is claimed by that
study (:func:`stochpound.studies.claims`), which builds the study's sections
(:mod:`stochpound.studies`); any other store gets sections of its own
(:mod:`stochpound.report.sections`). Every report opens with a summary, the
answers first (the study's, or :mod:`stochpound.report.sections._summary`);
the report of experiments no study claims ends with an appendix of its
per-cell tables.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from datetime import date
from pathlib import Path

import xarray as xr

from stochpound.experiment import read_definition
from stochpound.experiment._selections import has_contact_free, has_wall_free, with_contacts, with_walls
from stochpound.report.render import Paragraph, Report, Section
from stochpound.report.sections import (
    INTERVAL_NOTE,
    WALLS,
    experiment_summary,
    intensity_section,
    intensity_setting,
    law_axis,
    laws_section,
    methods_section,
    move_per_cell_tables,
    open_stores,
    separation_section,
    store_section,
)
from stochpound.report.sections._risk import has_risk, risk_section
from stochpound.studies import claims, load_study


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
    claimed = claims({name: read_definition(store).reproduces for name, store in stores.items()})
    studied = {name for parts in claimed.values() for name in parts.values()}
    others = {name: store for name, store in stores.items() if name not in studied}
    studies = {key: load_study(key) for key in claimed}
    report = Report(
        title="; ".join(study.TITLE for study in studies.values()) if studies else f"Pounding experiments: {', '.join(others)}",
        subtitle=f"stochpound report of {', '.join(stores)}, built {date.today().isoformat()}",
        sources=[f"{name}: {store.attrs.get('experiment_file', '')}, definition sha256 {store.attrs.get('definition_sha256', '')}" for name, store in stores.items()],
    )
    for key, study in studies.items():
        for title, section_key, build in study.sections({part: stores[name] for part, name in claimed[key].items()}):
            say(title)
            report.sections.append(Section(title, build(), key=section_key))
        summary = study.summary(report.sections)
        if summary is not None:
            report.sections.insert(0, summary)
    if others and not studies:
        report.sections.append(Section("About this report", [Paragraph(_about(others))], key="about"))
    for name, store in others.items():  # the answer first: each store's risk at its site, right after the introduction
        if has_risk(store):
            say(f"experiment {name}: risk")
            report.sections.append(risk_section(name, store))
    for name, store in others.items():
        say(f"experiment {name}")
        contact_free, wall_free = has_contact_free(store), has_wall_free(store)
        finite = with_contacts(store) if contact_free else store
        finite = with_walls(finite) if wall_free else finite
        if law_axis(store) is not None:
            report.sections.append(laws_section(name, finite))
        if all(finite.sizes[d] for d in finite["case_status"].dims):
            report.sections.append(store_section(name, finite, contact_free or wall_free, store))
        if wall_free and not has_risk(store):
            say(f"experiment {name}: moat clearance")
            report.sections.append(separation_section(name, store, WALLS))
        if contact_free and not has_risk(store):  # with a hazard, the Risk section gives the separation at every intensity
            say(f"experiment {name}: separation")
            report.sections.append(separation_section(name, store))
        if intensity_setting(store) is not None:
            say(f"experiment {name}: intensity")
            report.sections.append(intensity_section(name, store))
    say("methods")
    report.sections.append(methods_section(stores))
    if others and not studies:
        appendix = move_per_cell_tables(report.sections)
        if appendix is not None:
            report.sections.append(appendix)
        say("summary")
        report.sections.insert(0, experiment_summary(others, report.sections))
    return report


def _about(stores: dict[str, xr.Dataset]) -> str:
    """What the report of stores no study claims holds, and how to read it."""
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
