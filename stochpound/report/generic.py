"""Report sections for any experiment store: its cases' summaries as a table and against its grid axes.

Used for stores that are not the study's (``experiments/study/``), e.g. the
quick-start experiment or a user's grid. Over synthetic realizations the
table gives the ensemble mean of each summary and the probability of
pounding (fraction of realizations with at least one impact).
"""

from __future__ import annotations

import itertools

import numpy as np
import xarray as xr

from stochpound.report import figures
from stochpound.report.document import FigureItem, Paragraph, Section, Table

CM = 100.0
#: Summaries shown, with their label and factor to the shown unit.
COLUMNS = {
    "response_std": ("std (cm)", CM),
    "response_skewness": ("skewness", 1.0),
    "response_excess": ("excess", 1.0),
    "impacts": ("impacts", 1.0),
    "impacts_in_phase": ("in-phase", 1.0),
    "impacts_out_of_phase": ("out-of-phase", 1.0),
    "peak_impact_force": ("peak impact force (kN)", 1e-3),
    "fixed_base_correlation": ("correlation with fixed base", 1.0),
}
#: Most lines drawn in one panel of a figure against a grid axis.
MAX_LINES = 8


def store_section(name: str, store: xr.Dataset) -> Section:
    """A section for one store: description, summary table, summaries against its numeric axes."""
    section = Section(f"Experiment {name}", key=f"experiment-{name}")
    dims = {dim: store.sizes[dim] for dim in _grid_dims(store)}
    section.add(Paragraph(
        f"{store.attrs.get('experiment_description', '')} Studied building: {store.attrs.get('studied_building', '')}; its "
        f"top-floor total displacement is the response. Dimensions: {', '.join(f'{d} ({n})' for d, n in dims.items())}; "
        f"{int(store.attrs.get('cases_done', 0))} of {int(store.attrs.get('cases_total', 0))} cases done."
    ))
    section.add(summary_table(name, store))
    for axis in ("gap", "mu"):
        if axis in store.dims and store.sizes[axis] > 1:
            section.add(against_axis(name, store, axis))
    return section


def _grid_dims(store: xr.Dataset) -> list[str]:
    return list(store["case_status"].dims)


def summary_table(name: str, store: xr.Dataset) -> Table:
    """Every case's summaries (ensemble means over realizations, with the probability of pounding)."""
    present = [v for v in COLUMNS if v in store]
    data = store[present].load()
    for variable in present:
        data[variable] = data[variable] * COLUMNS[variable][1]
    if "realization" in data.dims:
        pounding = (data["impacts"] > 0).where(np.isfinite(data["impacts"])).mean("realization")
        data = data.mean("realization")
        data["pounding_probability"] = pounding
    frame = data.to_dataframe()[[*present, *(["pounding_probability"] if "pounding_probability" in data else [])]]
    frame = frame.rename(columns={v: COLUMNS[v][0] for v in present} | {"pounding_probability": "P(pounding)"})
    return Table(
        key=f"table-{name}",
        caption=f"Experiment {name}: summaries of every case (ensemble means over realizations).",
        frame=frame,
        note="std, skewness and excess (kurtosis − 3) of the studied building's top-floor total displacement over time; "
        "P(pounding): fraction of realizations with at least one impact.",
        formats={"impacts": "{:.1f}", "in-phase": "{:.1f}", "out-of-phase": "{:.1f}"},
    )


def against_axis(name: str, store: xr.Dataset, axis: str) -> FigureItem:
    """Impacts, peak impact force and response std against ``gap`` or ``mu``, one line per other combination."""
    data = store[[v for v in ("impacts", "peak_impact_force", "response_std") if v in store]].load()
    if "realization" in data.dims:
        data = data.mean("realization")
    data = data.isel({axis: np.flatnonzero(np.isfinite(data[axis].values))})  # μ = ∞ (fixed base) has no place on the axis
    others = [d for d in data["impacts"].dims if d != axis]
    x = data[axis].values * (CM if axis == "gap" else 1.0)
    combos = list(itertools.product(*(data[d].values for d in others)))[:MAX_LINES]
    panels = {}
    for variable, label, factor in (("impacts", "impacts", 1.0), ("peak_impact_force", "peak impact force (kN)", 1e-3), ("response_std", "std (cm)", CM)):
        if variable in data:
            panels[label] = {_combo_label(others, combo): data[variable].sel(dict(zip(others, combo))).values * factor for combo in combos}
    x_label = "gap (cm)" if axis == "gap" else "friction coefficient μ"
    title = f"Experiment {name}: against {axis}"
    caption = f"Experiment {name}: impacts, peak impact force and std of the response against {axis} (ensemble means; at most {MAX_LINES} combinations of the other axes)."
    return FigureItem(f"figure-{name}-{axis}", caption, figures.against(x, panels, title, x_label))


def _combo_label(dims: list[str], combo: tuple) -> str:
    return ", ".join(f"{d} = {v:g}" if isinstance(v, (float, np.floating)) else f"{d} = {v}" for d, v in zip(dims, combo)) or "all"

