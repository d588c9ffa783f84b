"""The section of a rare-event store: its exceedance curve down to the target and the response exceeded with 1e-3, 1e-4 and 1e-6 per event.

It formats :class:`~stochpound.experiment.RareEventResults` (computed from
the store's levels by :func:`~stochpound.experiment.rare_event_results`); it
computes nothing.
"""

from __future__ import annotations

from typing import Any

import pandas as pd
import xarray as xr
from matplotlib.figure import Figure

from stochpound.experiment import CLOSURES, RareEventResults
from stochpound.report.render import FigureItem, Paragraph, Section, Table


def rare_event_section(name: str, results: RareEventResults, crude: xr.Dataset | None = None) -> Section:
    """The section of the rare-event experiment ``name``: conditions and n, the exceedance curve with its 95 % interval, the separations;
    with ``crude`` (:func:`~stochpound.experiment.crude_check`), the curve against a stochastic experiment's crude Monte Carlo at its gaps."""
    closure = results.definition.table.response in CLOSURES
    units = results.curve["threshold"].attrs.get("units", "")
    section = Section(f"Rare events: {name}", key=f"rare-{name}")
    section.add(Paragraph(_conditions(results)))
    section.add(FigureItem(f"rare-{name}-curve", _caption(results, closure, units, crude), _curve_figure(results, closure, units, crude)))
    section.add(Table(f"rare-{name}-separation", _table_caption(closure, units), _frame(results, closure, units),
                      note="Per event: per motion of the ensemble. The interval is the response at which the estimated curve crosses "
                           "p·exp(±1.96 δ), δ the estimate's coefficient of variation at p (from the levels' genealogy, which counts the correlation between levels); "
                           "a value, or an interval's end, below the run's reach is left blank.",
                      formats={"probability per event": "{:.0e}", "coefficient of variation": "{:.2f}", "runs (n)": "{:.0f}"}))
    if crude is not None:
        section.add(Table(f"rare-{name}-crude", f"The probability of pounding per event at the gaps of experiment {crude.attrs['experiment']}: "
                          f"its contact-free runs of ensemble {crude.attrs['record']}{_cell(crude)} (crude Monte Carlo) against subset simulation",
                          _crude_frame(crude, results.runs),
                          note="Crude Monte Carlo: the fraction of the contact-free runs whose closure reaches the gap, with its 95 % "
                               "Clopper–Pearson interval; subset simulation: the curve above at the gap and its coefficient of variation. "
                               "The two use independent random numbers.",
                          formats={"runs (crude)": "{:.0f}", "runs (subset)": "{:.0f}", "subset CoV": "{:.2f}"}))
    return section


def _conditions(results: RareEventResults) -> str:
    table, motion = results.definition.table, results.definition.motion
    where = "".join(f", {key} {value}" for key, value in (("building", table.building), ("floor", table.floor), ("contact", table.contact)) if value is not None)
    what = f"the run's {table.response.replace('_', ' ')}{where}"
    if table.response == "closure":
        what = (f"the closure of contact {table.contact} of the contact-free scene (every gap infinite): by the gap identity, "
                "P(closure > g) is the probability of pounding at a gap g")
    elif table.response == "max_closure":
        what = ("the largest closure of any contact of the contact-free scene (every gap infinite): by the gap identity, "
                "P(closure > g) is the probability of pounding with the gap g at every contact")
    elif table.response == "limit_state":
        what = f"the ratio of the {table.limit_state} demand{where} to its capacity {table.capacity:g}"
    parameters = ", ".join(f"{key} = {_text(value)}" for key, value in motion.items() if key != "type")
    state = "reached" if results.target_reached else ("not reached: the run is incomplete (rerun it)" if not results.complete
                                                       else f"not reached: it stopped after max_levels = {table.max_levels}")
    chains = {"mma": "component-wise modified Metropolis", "acs": "adaptive conditional sampling, Papaioannou et al. 2015"}[table.proposal]
    described = f"{results.definition.description.rstrip('.')}. " if results.definition.description else ""
    return (f"{described}One subset simulation (Au & Beck 2001; {chains}) of {what}, under a {motion.get('type', 'kanai_tajimi')} "
            f"ground motion ({parameters}), its randomness a vector of standard normals. N = {table.samples_per_level} samples a level, "
            f"p0 = {table.p0}, seed {table.seed}: {results.levels} levels and n = {results.runs} runs in all, down to the target "
            f"probability {table.target_probability:g} per event ({state}).")


def _cell(crude: xr.Dataset) -> str:
    return f" in its cell {crude.attrs['cell']}" if crude.attrs["cell"] else ""


def _text(value: Any) -> str:
    """A motion field as its experiment file writes it: ``15``, ``true``, ``jennings``."""
    return f"{value:g}" if isinstance(value, float) else str(value).lower() if isinstance(value, bool) else str(value)


def _caption(results: RareEventResults, closure: bool, units: str, crude: xr.Dataset | None) -> str:
    what = "probability of pounding per event against the gap" if closure else "probability per event of exceeding each value"
    against = ("" if crude is None else f"; the points, crude Monte Carlo of experiment {crude.attrs['experiment']}'s contact-free runs at its gaps "
               "with their 95 % Clopper–Pearson intervals")
    return (f"The {what} ({units or 'ratio'}) by subset simulation, down to {results.definition.table.target_probability:g}, with its 95 % interval "
            f"(shaded); n = {results.runs} runs{against}.")


def _curve_figure(results: RareEventResults, closure: bool, units: str, crude: xr.Dataset | None) -> Figure:
    curve = results.curve
    figure = Figure(figsize=(6.0, 3.6), layout="constrained")
    ax = figure.add_subplot()
    ax.set_yscale("log")
    ax.fill_between(curve["threshold"].values, curve["lower"].values, curve["upper"].values, color="C0", alpha=0.25, linewidth=0, label="95 % interval")
    ax.plot(curve["threshold"].values, curve["probability"].values, color="C0", label="subset simulation")
    if crude is not None:
        ax.errorbar(crude["gap"].values, crude["crude"].values, yerr=[crude["crude"].values - crude["crude_lower"].values,
                    crude["crude_upper"].values - crude["crude"].values], fmt="o", color="C1", label=f"crude Monte Carlo ({crude.attrs['experiment']})")
    ax.set_xlabel(f"{'gap' if closure else 'threshold'} ({units or 'ratio'})")
    ax.set_ylabel("probability per event")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    return figure


def _table_caption(closure: bool, units: str) -> str:
    what = "The separation (the gap) for each probability of pounding per event" if closure else "The response exceeded with each probability per event"
    return f"{what} ({units or 'ratio'}), with its 95 % interval and the estimate's coefficient of variation"


def _crude_frame(crude: xr.Dataset, runs: int) -> pd.DataFrame:
    return pd.DataFrame({
        "gap (m)": crude["gap"].values,
        "crude Monte Carlo": crude["crude"].values,
        "95 % interval, low": crude["crude_lower"].values,
        "95 % interval, high": crude["crude_upper"].values,
        "runs (crude)": crude["realizations"].values,
        "subset simulation": crude["subset"].values,
        "subset CoV": crude["subset_cov"].values,
        "runs (subset)": [runs] * crude.sizes["gap"],
    }).set_index("gap (m)")


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
