"""The answer first: the "Summary" section that opens every report, and the appendix of per-cell tables.

For an experiment's stores the summary states the questions they answer,
each with its number and interval, computed from the stores:

* how wide the gap must be: the separation needed for P(pounding) = 5 % and
  1 % with its upper confidence bound, from the contact-free runs
  (:func:`stochpound.analysis.required_separation`);
* how likely pounding is at the grid's gaps: P(pounding) with its
  Clopper–Pearson bounds, over the cells of each synthetic ensemble;
* under records (one realization each), in how many cases each pounded;
* which mechanisms the runs show: ratcheting of a sliding base, the
  amplification of demands by pounding and by a moat wall, the walls'
  largest penetration (``stochpound.report.sections._mechanism_findings``);
* the risk-targeted gap of a store with a hazard, from its risk chain
  (:class:`~stochpound.risk.StoreRisk`, computed once by the assembler);

and where the details are (the sections by number and title).
Tables with one row per cell of a grid (``Table.per_cell``) move to an
appendix at the end (:func:`move_per_cell_tables`).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

import pandas as pd
import xarray as xr

from stochpound.analysis import CONTACTS, WALLS, Closure, Needed, RecordPounding, StoreSeparation
from stochpound.report.render import Paragraph, Section, Table
from stochpound.report.sections._ensembles import MIN_RUNS, Ensemble
from stochpound.report.sections._facets import dim_text, labels_text, value_text
from stochpound.report.sections._mechanism_findings import mechanism_answer
from stochpound.store import gap_dims, has_contact_free, has_wall_free, wall_gap_dims, with_contacts, with_walls
from stochpound.report.sections._risk import summary_answer
from stochpound.report.sections._separation import span, span_cm
from stochpound.risk import StoreRisk

CM = 100.0
SEPARATION_TARGETS = (0.05, 0.01)
"""Probabilities of pounding for which the summary gives the separation needed."""
APPENDIX_TITLE = "Appendix: per-cell tables"


def experiment_summary(stores: dict[str, xr.Dataset], sections: list[Section], confidence: float = 0.95,
                       risks: Mapping[str, StoreRisk] | None = None) -> Section:
    """The summary of the stores of experiments (those no study claims), given the report's other sections in their final order (after the summary).

    ``risks`` holds the risk chain of each store that has one (by name): its g* answers "which gap meets a target risk?".
    """
    risks = risks or {}
    summary = Section("Summary", key="summary")
    for name, store in stores.items():
        description = store.pound.provenance.experiment_description.strip()
        summary.add(Paragraph(f"Experiment {name}{': ' + description if description else ''}. The questions its runs answer:".replace(".. ", ". ")))
        kinds = dict(zip(store["record"].values.tolist(), store["record_kind"].values.tolist()))
        ensembles = [label for label, kind in kinds.items() if kind == "synthetic"]
        if has_wall_free(store) and ensembles:
            summary.add(Paragraph(_clearance_answer(name, store, ensembles, confidence)))
        if has_contact_free(store) and ensembles:
            summary.add(Paragraph(_separation_answer(name, store, ensembles, confidence)))
        finite = _finite(store)
        axes = [d for d in gap_dims(store) if finite.sizes[d]]
        if ensembles and axes:
            closure = WALLS if axes[0] in wall_gap_dims(store) else CONTACTS
            summary.add(Paragraph(
                f"How likely is {'a wall hit' if closure.walls else 'pounding'} at the grid's {closure.gap}s? The table below gives, at each "
                f"{closure.gap} of the grid, the fraction of its runs with {'a wall hit' if closure.walls else 'pounding'}, P({closure.event}), "
                f"over the cells of each ensemble (the lowest and the highest cell) with the highest upper {confidence:.0%} Clopper–Pearson bound."
            ))
            summary.add(_probability_table(name, finite, ensembles, axes[0], confidence, closure))
        records = [label for label, kind in kinds.items() if kind != "synthetic"]
        if records and len(axes) == len(gap_dims(store)) and "intensity" not in store.dims:
            # with no finite gap there is nothing to count; over intensity stripes the Intensity and Risk sections answer
            summary.add(Paragraph(_records_answer(store, records)))
        mechanisms = mechanism_answer(name, store)
        if mechanisms is not None:
            summary.add(Paragraph(mechanisms))
        if name in risks:
            for block in summary_answer(name, risks[name]):
                summary.add(block)
        summary.add(Paragraph(_where(name, sections)))
    return summary


def _finite(store: xr.Dataset) -> xr.Dataset:
    """The store's runs at finite gaps and clearances: its contact-free and wall-free runs left out (those it has)."""
    finite = with_contacts(store) if has_contact_free(store) else store
    return with_walls(finite) if has_wall_free(store) else finite


def _clearance_answer(name: str, store: xr.Dataset, ensembles: list[str], confidence: float) -> str:
    """How likely a wall hit is at each clearance of the grid, from the wall-free runs (against the runs there), and the clearance
    for each target probability with its upper bound, per ensemble over its cells."""
    parts = []
    for label in ensembles:
        separation = StoreSeparation(name, store, label, confidence, closure=WALLS)
        needed = separation.needed(SEPARATION_TARGETS)
        n, cells = needed.fewest_runs, needed.cells
        few = f"; fewer than {MIN_RUNS}, so indicative only" if n < MIN_RUNS else ""
        text = f"ensemble {label} ({n} wall-free realizations {_in_cells(cells)}{few}): "
        axis = separation.gap_axis
        if axis is not None:
            curve, direct = separation.curve_at_grid(), separation.hit_probability()
            at = []
            for c in curve[axis].values:
                cell = curve.sel({axis: c})
                at.append(f"{value_text(axis, c)}: {span(cell['probability'])} (upper bound {span(cell['upper'])}; runs there {span(direct['probability'].sel({axis: c}))})")
            text += "P(wall hit | c) = P(D ≥ c) at " + "; ".join(at) + ". "
        answers = _target_answers(needed, lambda p: f"P(wall hit) ≤ {p:.0%} needs a clearance of ", confidence)
        parts.append(text + "; ".join(answers))
    return ("How likely is the moat wall hit at each clearance c, and what clearance keeps it rare? From the wall-free runs "
            "(clearance ∞, the closure toward the walls located), D the largest closure toward a wall: " + "; ".join(parts) + ".")


def _separation_answer(name: str, store: xr.Dataset, ensembles: list[str], confidence: float) -> str:
    """How wide the gap must be: the separation for each target probability, its upper bound, per ensemble over its cells."""
    parts = []
    for label in ensembles:
        needed = StoreSeparation(name, store, label, confidence).needed(SEPARATION_TARGETS)
        n, cells = needed.fewest_runs, needed.cells
        answers = _target_answers(needed, lambda p: f"for P(pounding) = {p:.0%}, ", confidence)
        few = f"; fewer than {MIN_RUNS}, so indicative only" if n < MIN_RUNS else ""
        parts.append(f"ensemble {label} ({n} contact-free realizations {_in_cells(cells)}{few}): " + "; ".join(answers))
    return "How wide must the gap be? The separation needed, the 1 − p quantile of the contact-free peak closure D: " + "; ".join(parts) + "."


def _in_cells(cells: int) -> str:
    """"in each of 6 cells", "in its one cell"."""
    return f"in each of {cells} cells" if cells > 1 else "in its one cell"


def _target_answers(needed: Needed, lead: Callable[[float], str], confidence: float) -> list[str]:
    """For each target of ``SEPARATION_TARGETS``: ``lead(p)``, the separation needed over the cells (cm) with its extremes and upper
    bound, and, where some cells have none, why (``needed``: :meth:`~stochpound.analysis.StoreSeparation.needed`)."""
    n, cells = needed.fewest_runs, needed.cells
    answers = []
    for p in SEPARATION_TARGETS:
        estimate, upper = needed["separation"].sel(probability=p), needed["upper"].sel(probability=p)
        text = f"{lead(p)}{span_cm(estimate)}{_extremes(needed, p)}"
        missing = needed.missing_upper(p)
        if missing < upper.size:
            text += f", upper {confidence:.0%} bound {span_cm(upper)}"
        if missing:
            text += (f" (no upper bound{f' in {missing} of {cells} cells' if cells > 1 else ''}: {n} realizations are too few, it needs "
                     f"(1 − p)ⁿ ≤ {(1 - confidence) / 2:g})")
        answers.append(text)
    return answers


def _records_answer(store: xr.Dataset, records: list[str]) -> str:
    """What the records' cases answer: in how many cases each record pounded (one realization each: no probability)."""
    cases = RecordPounding.of(_finite(store), records)
    counts = "; ".join(f"{label}: {pounded} of {done}" for label, pounded, done in zip(cases.records, cases.pounded, cases.done))
    return (f"Does a record make the buildings pound? Cases with at least one impact, per record: {counts}. A record is one "
            "realization: it answers yes or no per case, not with a probability.")


def _extremes(needed: Needed, probability: float) -> str:
    """" (smallest at …, largest at …)" naming the cells of the extremes of the separation needed for ``probability``, "" for one cell."""
    extremes = needed.extremes(probability)
    if extremes is None:
        return ""
    low, high = extremes
    return f" (smallest at {labels_text(low)}, largest at {labels_text(high)})"


def _probability_table(name: str, store: xr.Dataset, ensembles: list[str], axis: str, confidence: float, closure: Closure) -> Table:
    """P(pounding) (P(wall hit)) at each gap (clearance) of the grid, per ensemble: its range over the other cells and the highest upper bound."""
    rows = {}
    for label in ensembles:
        others, along = Ensemble(name, store, label, confidence).probability_along(axis, closure.events)
        for at in along:
            rows[(label, value_text(axis, at.value))] = [at.cells, at.fewest, at.lowest, at.highest, at.highest_upper]
        cells = ", ".join(dim_text(d) for d in others) or "one cell"
    frame = pd.DataFrame.from_dict(rows, orient="index", columns=["cells", "n", "P lowest", "P highest", "highest upper bound"])
    frame.index = pd.MultiIndex.from_tuples(list(rows), names=["ensemble", dim_text(axis)])
    return Table(
        key=f"table-{name}-summary-{'wall-hit' if closure.walls else 'pounding'}",
        caption=(f"Experiment {name}: the probability of {'a wall hit' if closure.walls else 'pounding'} at each {closure.gap} of the grid, "
                 f"over the cells ({cells}) of each ensemble."),
        frame=frame,
        note=f"n: realizations per cell (the fewest); bounds: {confidence:.0%} Clopper–Pearson (exact binomial). Per-cell values: the appendix.",
        formats={"cells": "{:.0f}", "n": "{:.0f}", "P lowest": "{:.3f}", "P highest": "{:.3f}", "highest upper bound": "{:.3f}"},
    )


def _where(name: str, sections: list[Section]) -> str:
    """Where the details of experiment ``name`` are: its sections by number (the summary is section 1) and title."""
    wanted = {f"{kind}-{name}" for kind in ("risk", "damage", "experiment", "laws", "clearance", "separation", "intensity")} | {"appendix", "methods"}
    found = [f"section {number} ({section.title})" for number, section in enumerate(sections, start=2) if section.key in wanted]
    return "Details: " + ", ".join(found) + "."


def move_per_cell_tables(sections: list[Section]) -> Section | None:
    """Move every per-cell table (``Table.per_cell``) of ``sections`` to an appendix section, leaving a pointer where they were; None if there are none."""
    appendix = Section(APPENDIX_TITLE, key="appendix")
    for section in sections:
        moved = [block for block in section.blocks if isinstance(block, Table) and block.per_cell]
        if not moved:
            continue
        first = section.blocks.index(moved[0])
        section.blocks = [block for block in section.blocks if not (isinstance(block, Table) and block.per_cell)]
        section.blocks.insert(first, Paragraph(f"The per-cell tables of this section ({len(moved)}) are in the last section, {APPENDIX_TITLE}."))
        appendix.blocks += moved
    return appendix if appendix.blocks else None

