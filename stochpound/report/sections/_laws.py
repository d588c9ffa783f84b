"""The "Contact laws compared" section of a report: the laws of a store side by side.

A store compares contact laws when a variant axis of its definition gives its
values different contact laws (:func:`law_axis`: read from the stored
definition, whatever the experiment's name). For each synthetic ensemble of
such a store the section draws one figure per quantity, every law in the
same panel against the gap (one panel per combination of the other axes):

* the probability of pounding with its Clopper–Pearson band;
* the mean peak impact force of the runs that pounded, the mean number of
  impacts and, when the store keeps demands, the mean peak floor
  acceleration of the studied building, each with a percentile-bootstrap interval
  over the realizations, which stays within the quantity's support (≥ 0);

and states, at every gap of every panel, which law gives the largest value,
by how much it exceeds the smallest, with the intervals and the number of
runs, and whether the laws' intervals overlap. A mean from fewer than
:data:`~stochpound.analysis._intervals.MIN_RUNS` runs is neither drawn nor compared.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
import xarray as xr

from stochpound.analysis import MIN_RUNS, CellLabels
from stochpound.experiment import is_gap_axis
from stochpound.store import Definition, TomlTable
from stochpound.model import laws
from stochpound.report.render import Block, FigureItem, Paragraph, Section, figures
from stochpound.report.sections._ensembles import Ensemble
from stochpound.report.sections._facets import dim_text, labels_text, line_colours, plain


@dataclass(frozen=True)
class LawQuantity:
    """A per-run summary compared across the laws.

    Attributes
    ----------
    variable : str
        The store variable.
    text : str
        Its name in prose and in titles.
    axis : str
        Its short name on the y axis.
    unit : str
        The unit shown.
    factor : float
        From the store's SI unit to the unit shown.
    pounding_only : bool
        Averaged over the runs that pounded only (the quantity is undefined without an impact).
    """

    variable: str
    text: str
    axis: str
    unit: str
    factor: float
    pounding_only: bool = False


QUANTITIES = (
    LawQuantity("peak_impact_force", "mean peak impact force of the runs that pounded", "peak impact force", "kN", 1e-3, pounding_only=True),
    LawQuantity("impacts", "mean number of impacts", "impacts", "", 1.0),
    LawQuantity("peak_floor_acceleration", "mean peak floor acceleration of the studied building", "peak floor acceleration", "m/s²", 1.0),
)


def law_axis(store: xr.Dataset) -> str | None:
    """The variant axis whose values give the contacts different laws (from the stored definition), or None."""
    definition = store.pound.definition
    for axis in definition.variants:
        named = variant_laws(definition, axis.name) if axis.name in store.dims else {}
        if len({named[plain(v)] for v in store[axis.name].values}) > 1:
            return axis.name
    return None


def variant_laws(definition: Definition, axis: str) -> dict[str, str]:
    """Each value of variant ``axis`` -> the contact laws of its scene (joined with "/" when the contacts differ)."""
    scene_laws = [contact.string("law", laws.DEFAULT_CONTACT_LAW) for contact in TomlTable(definition.scene, "scene").tables("contact")]
    variant = next(v for v in definition.variants if v.name == axis)
    result = {}
    for value in variant.values:
        edit = TomlTable(variant.overrides[value], f"variants.{axis}.{value}")
        part = edit.raw("contact")  # one table for every contact, or a list of one table per contact
        tables = edit.tables("contact") if isinstance(part, list) else [edit.table_or_empty("contact")] * len(scene_laws)
        names = [table.string("law", own) for table, own in zip(tables, scene_laws)]
        result[value] = "/".join(dict.fromkeys(names))
    return result


def laws_section(name: str, store: xr.Dataset) -> Section:
    """The "Contact laws compared" section of one store (call when :func:`law_axis` is not None)."""
    axis = law_axis(store)
    assert axis is not None
    section = Section(f"Contact laws compared: experiment {name}", key=f"laws-{name}")
    definition = store.pound.definition
    named = variant_laws(definition, axis)
    overrides = next(v for v in definition.variants if v.name == axis).overrides
    same_until_contact = (
        "A law acts only once the floors touch, and this axis changes nothing else: up to its first impact a run is the "
        "same under every law, so the laws can differ in P(pounding) only within the solvers' tolerances, and they differ "
        "in what follows the first impact. " if all(set(o) <= {"contact"} for o in overrides.values()) else "")
    section.add(Paragraph(
        f"The {dim_text(axis)} axis gives the contacts different laws: "
        + "; ".join(f"{value}: {' / '.join(laws.CONTACT_LAWS[law].title for law in named[value].split('/'))}"
                    for value in map(plain, store[axis].values))
        + f". Methods gives each element's parameters and units. {same_until_contact}Below, every law is drawn in the same "
        "panel; means are "
        f"shown and compared only from at least {MIN_RUNS} runs, with 95 % bootstrap intervals over the realizations "
        "(percentile), and P(pounding) with its 95 % Clopper–Pearson interval."
    ))
    kinds = dict(zip(store["record"].values.tolist(), store["record_kind"].values.tolist()))
    for label in [label for label, kind in kinds.items() if kind == "synthetic"]:
        section.blocks += _ensemble_blocks(Ensemble(name, store, label), axis)
    return section


def _ensemble_blocks(ensemble: Ensemble, axis: str) -> list[Block]:
    gap = next((d for d in ensemble.grid if is_gap_axis(d)), None)
    others = [d for d in ensemble.grid if d not in (axis, gap)]
    panels = [dict(zip(others, values)) for values in itertools.product(*(ensemble.grid[d] for d in others))]
    estimates = {"pounding": ensemble.pounding()}
    estimates |= {q.variable: ensemble.means(q.variable, q.factor, q.pounding_only) for q in QUANTITIES if q.variable in ensemble.data}
    blocks: list[Block] = []
    for key, table in estimates.items():
        quantity = next((q for q in QUANTITIES if q.variable == key), None)
        text = "P(pounding)" if quantity is None else quantity.text
        unit = "" if quantity is None or not quantity.unit else f" ({quantity.unit})"
        y_label = "P(pounding)" if quantity is None else quantity.axis
        blocks.append(_figure(ensemble, axis, gap, panels, table, f"{text}{unit}", f"{y_label}{unit}", key))
        blocks.append(Paragraph(_comparison(ensemble, axis, gap, panels, table, text, "" if quantity is None else quantity.unit)))
    return blocks


def _figure(ensemble: Ensemble, axis: str, gap: str | None, panels: list[CellLabels], table: xr.Dataset, text: str, y_label: str,
            key: str) -> FigureItem:
    values = ensemble.grid[axis]
    colours = line_colours(axis, values)
    x_values = np.asarray(ensemble.grid[gap], dtype=float) * 100.0 if gap else np.zeros(1)
    drawn = {}
    for panel in panels:
        curves = []
        for value, colour in zip(values, colours):
            cell = table.sel({**panel, axis: value})
            curves.append(figures.Curve(str(value), x_values, np.atleast_1d(cell["estimate"].values), np.atleast_1d(cell["lower"].values),
                                        np.atleast_1d(cell["upper"].values), color=colour, marker="o",
                                        gid=ensemble.gid({**panel, axis: value})))
        drawn[labels_text(panel) or ensemble.label] = curves
    title = f"{text}, every {dim_text(axis)} in each panel ({ensemble.label}, {ensemble.size} realizations)"
    figure = figures.panel_grid(drawn, title, "gap (cm)" if gap else "", y_label, legend_title=dim_text(axis),
                                x_ticks={x: f"{x:g}" for x in x_values} if gap else None)
    caption = (f"{text} of ensemble {ensemble.label} against the gap, one line per {dim_text(axis)} ({', '.join(map(str, values))}) "
               "with its 95 % interval as a band; " + ("one panel per " + ", ".join(map(dim_text, [d for d in panels[0]])) if panels[0] else "one panel") + ".")
    return FigureItem(f"laws-{ensemble.name}-{ensemble.label}-{key}", caption, figure)


def _comparison(ensemble: Ensemble, axis: str, gap: str | None, panels: list[CellLabels], table: xr.Dataset, text: str, unit: str) -> str:
    """Which law gives the largest ``text`` at each gap of each panel, by how much, and whether the laws' intervals overlap."""
    sentences = []
    for panel in panels:
        for gap_value in (ensemble.grid[gap] if gap else [None]):
            where = {**panel, **({gap: gap_value} if gap else {})}
            cells = table.sel(where)
            rows = {plain(v): cells.sel({axis: v}) for v in ensemble.grid[axis]}
            rows = {v: c for v, c in rows.items() if np.isfinite(float(c["estimate"]))}
            context = labels_text(where) or ensemble.label
            if len(rows) < 2:
                sentences.append(f"At {context}, fewer than two {dim_text(axis)} values have {MIN_RUNS} runs to compare.")
                continue
            ranked = sorted(rows, key=lambda v: float(rows[v]["estimate"]), reverse=True)
            top, bottom = ranked[0], ranked[-1]
            largest, smallest = float(rows[top]["estimate"]), float(rows[bottom]["estimate"])
            if largest == smallest:
                sentences.append(f"At {context}, every {dim_text(axis)} gives the same {text}, {_value(rows[top], unit)}.")
                continue
            by = f"{largest / smallest:.2f} times that of {bottom}" if smallest > 0 else f"against none for {bottom}"
            below = [str(v) for v in ranked[1:] if float(rows[v]["upper"]) < float(rows[top]["lower"])]
            sentences.append(
                f"At {context}, {top} gives the largest {text}, {_value(rows[top], unit)}, {by}, {_value(rows[bottom], unit)}; "
                + (f"the intervals of {', '.join(below)} lie below that of {top}"
                   + ("." if len(below) == len(ranked) - 1 else ", the others' overlap it.") if below else
                   "every interval overlaps the largest one: the laws agree within their intervals.")
            )
    return " ".join(sentences)


def _value(cell: xr.Dataset, unit: str) -> str:
    """``812 kN [770, 860] (n = 140)``."""
    suffix = f" {unit}" if unit else ""
    return (f"{float(cell['estimate']):.3g}{suffix} [{float(cell['lower']):.3g}, {float(cell['upper']):.3g}] "
            f"(n = {int(cell['count'])})")
