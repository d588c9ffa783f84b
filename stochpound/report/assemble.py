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

from stochpound.report.render import FigureItem, Paragraph, Report, Section
from stochpound.report.sections import (
    INTERVAL_NOTE,
    WALLS,
    damage_section,
    definition_source,
    experiment_summary,
    intensity_section,
    law_axis,
    laws_section,
    measure_free_section,
    methods_section,
    move_per_cell_tables,
    open_stores,
    rare_event_section,
    risk_section,
    separation_section,
    store_section,
)
from stochpound.analysis import MEASURE_FREE_RUNS, RuptureSite, StoreSufficiency, store_measure_free, store_sufficiency
from stochpound.experiment import crude_check, is_rare_event_store, measure_choice, open_rare_event_store, rare_event_results
from stochpound.risk import RiskInputError, check_alternative, collapse_risk, has_risk, separation_sensitivity, store_damage, store_demands, store_risk
from stochpound.store import check_finished, has_contact_free, has_wall_free, with_contacts, with_walls
from stochpound._errors import ExperimentError
from stochpound._studies import claims, load_study


def assemble_report(paths: Sequence[str | Path], progress: Callable[[str], None] | None = None, partial: bool = False,
                    edited: str = "warn", ruptures: RuptureSite | None = None, ruptures_runs: int = MEASURE_FREE_RUNS,
                    alternatives: Sequence[tuple[str, str | Path]] = ()) -> Report:
    """Build the report of the given stores.

    Parameters
    ----------
    paths : sequence of path
        Experiment store files.
    progress : callable, optional
        Called with a short message before each step.
    partial : bool
        Report a store with missing cases from the cases that ran (its
        sections say how many ran); without it such a store is refused.
    edited : {"warn", "refuse", "accept"}
        A store whose definition does not match its recorded sha256 (:func:`~stochpound.open_store`;
        ``stochpound report build`` refuses it without ``--accept-edited``).
    ruptures : RuptureSite, optional
        A site of ruptures: each store with a Risk section also gets the answer without an intensity measure there
        (:func:`~stochpound.analysis.store_measure_free`, ``ruptures_runs`` runs a configuration, seed 0).
    alternatives : sequence of (str, path)
        Other stores for the sensitivity table of g*, each with its kind (``seed``, ``measure``, ``wall``:
        ``stochpound.risk.ALTERNATIVES``): each serves every Risk section's store it differs from only in that choice
        (:func:`~stochpound.risk.check_alternative`); one that serves none is refused.

    Returns
    -------
    Report

    Raises
    ------
    ValueError
        (``UnfinishedStoreError``) A store with missing cases without ``partial``: ``<name>: 288/704 cases done: ...``.
    ExperimentError
        A rare-event store of a closure beside stores with contact-free cases of which it is no cell (``crude_check``'s reason).
    """
    say = progress or (lambda message: None)
    say("reading stores")
    rare = {Path(path): open_rare_event_store(path) for path in paths if is_rare_event_store(path)}  # a rare-event store: a section of its own
    stores = open_stores([path for path in paths if Path(path) not in rare], edited)
    for name, store in stores.items():
        check_finished(store, Path(store.encoding.get("source", name)).name, partial, option="--partial (partial=True from Python)")
    claimed = claims({name: store.pound.definition.reproduces for name, store in stores.items()})
    studied = {name for parts in claimed.values() for name in parts.values()}
    others = {name: store for name, store in stores.items() if name not in studied}
    studies = {key: load_study(key) for key in claimed}
    report = Report(
        title="; ".join(study.TITLE for study in studies.values()) if studies else f"Pounding experiments: {', '.join([*others, *_rare_names(rare)])}",
        subtitle=f"stochpound report of {', '.join(stores)}, built {date.today().isoformat()}",
        sources=[f"{name}: {definition_source(store)}, definition sha256 {store.pound.sha256}" for name, store in stores.items()],
    )
    for key, study in studies.items():
        for title, section_key, build in study.sections({part: stores[name] for part, name in claimed[key].items()}):
            say(title)
            report.sections.append(Section(title, build(), key=section_key))
        summary = study.summary(report.sections)
        if summary is not None:
            report.sections.insert(0, summary)
    risks = {}
    serving = _alternatives({name: store for name, store in others.items() if has_risk(store)}, alternatives, edited)
    for name, store in others.items():  # the answer first: each store's risk at its site, right after the introduction
        if has_risk(store):
            say(f"experiment {name}: risk")
            risks[name] = store_risk(store, partial=partial)
            damage = store_damage(store)
            collapse = None if risks[name].method != "stripes" else collapse_risk(
                store, risks[name].hazard, risks[name].fragility["gap"].values, risks[name].separation["target"].values, risks[name].years)
            sensitivity = None if risks[name].method != "stripes" else separation_sensitivity(risks[name], store, collapse,
                                                                                               alternatives=serving.get(name, []))
            report.sections.append(risk_section(name, risks[name], store_demands(store), damage, measure_choice(store), collapse, sensitivity))
            if ruptures is not None:
                say(f"experiment {name}: without an intensity measure")
                answer = store_measure_free(store, ruptures, runs=ruptures_runs)
                report.sections.append(measure_free_section(name, answer, risks[name].hazard.describe(), *_sufficiency(store)))
            if damage is not None:
                report.sections.append(damage_section(name, damage))
    for name, store in others.items():
        say(f"experiment {name}")
        contact_free, wall_free = has_contact_free(store), has_wall_free(store)
        finite = with_contacts(store) if contact_free else store
        finite = with_walls(finite) if wall_free else finite
        if law_axis(store) is not None:
            report.sections.append(laws_section(name, finite))
        if all(finite.sizes[d] for d in finite["case_status"].dims):
            report.sections.append(store_section(name, finite, contact_free or wall_free, store))
        if wall_free and name not in risks:
            say(f"experiment {name}: moat clearance")
            report.sections.append(separation_section(name, store, WALLS))
        if contact_free and name not in risks:  # with a hazard, the Risk section gives the separation at every intensity
            say(f"experiment {name}: separation")
            report.sections.append(separation_section(name, store))
        if store.pound.intensity is not None:
            say(f"experiment {name}: intensity")
            near = risks[name].separation["separation"].values.ravel() if name in risks else ()  # g*: where the contact-free runs pound
            report.sections.append(intensity_section(name, store, near))
    for data in rare.values():
        say(f"rare events {data.attrs['experiment_name']}")
        report.sections.append(rare_event_section(data.attrs["experiment_name"], rare_event_results(data), _crude_check(data, stores)))
    if stores:
        say("methods")
        report.sections.append(methods_section(stores))
    if others and not studies:
        appendix = move_per_cell_tables(report.sections)
        if appendix is not None:
            report.sections.append(appendix)
        report.sections.insert(0, Section("About this report", [Paragraph(_about(others, report.sections))], key="about"))
        say("summary")
        report.sections.insert(0, experiment_summary(others, report.sections, risks=risks))
    return report


def _rare_names(rare: dict[Path, xr.Dataset]) -> list[str]:
    """The rare-event experiments as the title names them: each by its name, or their number beyond two."""
    names = [data.attrs["experiment_name"] for data in rare.values()]
    return names if len(names) <= 2 else [f"{len(names)} rare-event experiments"]


def _crude_check(rare: xr.Dataset, stores: dict[str, xr.Dataset]) -> xr.Dataset | None:
    """The crude Monte Carlo check of a rare-event store by the first store given that ran its runs (one of its cells): None
    when no store given could (no contact-free cases, or the rare event is not a closure).

    Raises
    ------
    ExperimentError
        In one line, when stores with contact-free cases are given and none of them ran its runs (the first one's reason).
    """
    refusals = []
    for store in stores.values():
        try:
            check = crude_check(rare, store)
        except ExperimentError as error:
            refusals.append(str(error))
            continue
        if check is not None:
            return check
    if refusals:
        others = f" (and {len(refusals) - 1} other store(s) given)" if len(refusals) > 1 else ""
        raise ExperimentError(f"{refusals[0]}{others}: give the store of the stochastic experiment it is a cell of, or report it on its own")
    return None


def _alternatives(stores: dict[str, xr.Dataset], alternatives: Sequence[tuple[str, str | Path]], edited: str) -> dict[str, list[tuple[str, xr.Dataset]]]:
    """Per store of ``stores`` (those with a Risk section), the alternatives of its sensitivity table that serve it (each differs
    from it only in its kind's choice); an alternative that serves none is refused with the reason it does not serve the first."""
    serving: dict[str, list[tuple[str, xr.Dataset]]] = {}
    for kind, path in alternatives:
        (other,) = open_stores([path], edited).values()  # one at a time: an alternative shares its experiment's name
        fits, reasons = [], []
        for name, store in stores.items():
            try:
                check_alternative(store, other, kind)
            except RiskInputError as error:
                reasons.append(str(error))
                continue
            fits.append(name)
        if not fits:
            reason = reasons[0] if reasons else "no store of the report has a Risk section"
            raise RiskInputError(f"--sensitivity-store {kind}={Path(path).name}: {reason}")
        for name in fits:
            serving.setdefault(name, []).append((kind, other))
    return serving


def _sufficiency(store: xr.Dataset) -> tuple[StoreSufficiency | None, str]:
    """The sufficiency test of a store's measure, or why there is none (the store's motions or stripes do not allow it)."""
    try:
        return store_sufficiency(store), ""
    except ValueError as error:
        return None, str(error)


def _about(stores: dict[str, xr.Dataset], sections: list[Section]) -> str:
    """What the report of stores no study claims holds, and how to read it: only what its ``sections`` contain."""
    described = "; ".join(f"{name}: {store.pound.provenance.experiment_description}" for name, store in stores.items())
    kinds = {section.key.split("-", 1)[0] for section in sections}
    figures = [block.key for section in sections for block in section.blocks if isinstance(block, FigureItem)]
    parts = [f"This report describes the experiment stores {described}."]
    if "risk" in kinds:
        parts.append("A Risk section per experiment with a site hazard gives the risk-targeted separation g* first, then the "
                     "fragility at every gap, the mean annual frequency of pounding and the code rules in risk terms.")
    if "measure" in kinds:
        parts.append("A section 'Without an intensity measure' follows a Risk section with the same question's answer at a site of "
                     "ruptures, from simulated motions of each rupture and no intensity measure.")
    if "damage" in kinds:
        parts.append("A Damage section per experiment of yielding buildings gives their ductility and residual drift demands at the "
                     "stripes of 10 % and 2 % in 50 yr, the runs beyond what the model represents, and the limit state that governs.")
    if "experiment" in kinds:
        parts.append("An experiment section gives the cases run under records one by one, and each synthetic ensemble by the "
                     "statistics of its realizations in every cell of the grid (every combination of the grid's axes): means with "
                     f"95 % confidence intervals ({INTERVAL_NOTE}), quantiles of the peaks, and the probability of pounding (at least one "
                     "impact) with its 95 % Clopper–Pearson interval, followed by findings computed from them and tables (also written "
                     "as CSV files).")
    if any("-ecdf-" in key for key in figures):
        parts.append("An ECDF gives, for each value, the fraction of realizations at or below it.")
    if any("-convergence-" in key for key in figures):
        parts.append("A convergence figure shows an estimate over the first n realizations, so that one sees whether the ensemble "
                     "is large enough.")
    if kinds & {"separation", "clearance"}:
        parts.append("A separation or moat-clearance section answers the gap question from the contact-free (or wall-free) runs.")
    if "intensity" in kinds:
        parts.append("An Intensity section describes the motions' intensity measures, the stripes and their scale factors.")
    rare = sum(1 for section in sections if section.key.startswith("rare-"))
    if rare:
        parts.append(f"{'A Rare events section gives' if rare == 1 else f'{rare} Rare events sections each give'} one "
                     "subset simulation's exceedance curve per event, down to its target probability, with its 95 % interval and the "
                     "response (for a closure, the separation) exceeded with 10⁻³, 10⁻⁴ and 10⁻⁶ per event; beside the stochastic "
                     "experiment of which it is a cell, the curve is checked against that cell's crude Monte Carlo at the grid's gaps.")
    parts.append("The Methods section describes every building, contact and motion from the stores' own definitions and checks "
                 "the solver while the report is built; the build stops if a check fails.")
    return " ".join(parts)
