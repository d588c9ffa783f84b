"""The section of a rare-event store: its exceedance curve down to the target and the response exceeded with 1e-3, 1e-4 and 1e-6 per event.

It formats :class:`~stochpound.experiment.RareEventResults` (computed from
the store's levels by :func:`~stochpound.experiment.rare_event_results`); it
computes nothing.
"""

from __future__ import annotations

from typing import Any

import pandas as pd
from matplotlib.figure import Figure

from stochpound.experiment import RareEventResults
from stochpound.report.render import FigureItem, Paragraph, Section, Table


def rare_event_section(name: str, results: RareEventResults) -> Section:
    """The section of the rare-event experiment ``name``: conditions and n, the exceedance curve with its 95 % interval, the separations."""
    table = results.table
    closure = table["response"] == "closure"
    units = results.curve["threshold"].attrs.get("units", "")
    section = Section(f"Rare events: {name}", key=f"rare-{name}")
    section.add(Paragraph(_conditions(results)))
    section.add(FigureItem(f"rare-{name}-curve", _caption(results, closure, units), _curve_figure(results, closure, units)))
    section.add(Table(f"rare-{name}-separation", _table_caption(closure, units), _frame(results, closure, units),
                      note="Per event: per motion of the ensemble. The interval is the response at which the estimated curve crosses "
                           "p·exp(±1.96 δ), δ the estimate's coefficient of variation at p (Au & Beck's, from the chains' correlation); "
                           "a probability below the run's reach has no value.",
                      formats={"probability per event": "{:.0e}", "coefficient of variation": "{:.2f}", "runs (n)": "{:.0f}"}))
    return section


def _conditions(results: RareEventResults) -> str:
    table, motion = results.table, results.definition["motion"]
    what = {"closure": f"the closure of contact {table.get('contact', 0)} of the contact-free scene (every gap infinite): by the gap identity, "
                       "P(closure > g) is the probability of pounding at a gap g",
            "limit_state": f"the ratio of the {table.get('limit_state')} demand to its capacity {table.get('capacity')}"}.get(
        table["response"], f"the run's {table['response'].replace('_', ' ')}" + "".join(f", {key} {table[key]}" for key in ("building", "floor", "contact") if key in table))
    parameters = ", ".join(f"{key} = {_text(value)}" for key, value in motion.items() if key != "type")
    state = "reached" if results.complete else "not reached (the run is incomplete: rerun it)"
    return (f"One subset simulation (Au & Beck 2001; component-wise modified Metropolis) of {what}, under a {motion.get('type', '')} "
            f"ground motion ({parameters}), its randomness a vector of standard normals. N = {table['samples_per_level']} samples a level, "
            f"p0 = {table['p0']}, seed {table['seed']}: {results.levels} levels and n = {results.runs} runs in all, down to the target "
            f"probability {table['target_probability']:g} per event ({state}).")


def _text(value: Any) -> str:
    return f"{value:g}" if isinstance(value, float) else str(value)


def _caption(results: RareEventResults, closure: bool, units: str) -> str:
    what = "probability of pounding per event against the gap" if closure else "probability per event of exceeding each value"
    return (f"The {what} ({units or 'ratio'}) by subset simulation, down to {results.table['target_probability']:g}, with its 95 % interval "
            f"(shaded); n = {results.runs} runs.")


def _curve_figure(results: RareEventResults, closure: bool, units: str) -> Figure:
    curve = results.curve
    figure = Figure(figsize=(6.0, 3.6), layout="constrained")
    ax = figure.add_subplot()
    ax.set_yscale("log")
    ax.fill_between(curve["threshold"].values, curve["lower"].values, curve["upper"].values, color="C0", alpha=0.25, linewidth=0, label="95 % interval")
    ax.plot(curve["threshold"].values, curve["probability"].values, color="C0", label="subset simulation")
    ax.set_xlabel(f"{'gap' if closure else 'threshold'} ({units or 'ratio'})")
    ax.set_ylabel("probability per event")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    return figure


def _table_caption(closure: bool, units: str) -> str:
    what = "The separation (the gap) for each probability of pounding per event" if closure else "The response exceeded with each probability per event"
    return f"{what} ({units or 'ratio'}), with its 95 % interval and the estimate's coefficient of variation"


def _frame(results: RareEventResults, closure: bool, units: str) -> pd.DataFrame:
    found = results.separations
    value = f"{'separation' if closure else 'value'} ({units or 'ratio'})"
    return pd.DataFrame({
        "probability per event": found["probability"],
        value: found["value"],
        "95 % interval, low": found["low"],
        "95 % interval, high": found["high"],
        "coefficient of variation": found["cov"],
        "runs (n)": [results.runs] * len(found["probability"]),
    }).set_index("probability per event")
