"""Report sections for any experiment store: its records' cases and its ensembles' distributions.

Used for stores that no study claims (:mod:`stochpound.studies`), e.g. a
user's grid or a stochastic study. The motions
of a store are of two kinds:

* records (one realization each): a table of every case's summaries and
  the summaries against the numeric grid axes, every case drawn;
* synthetic ensembles: per grid cell, the ensemble statistics, their
  findings and the distributions (:mod:`stochpound.report.sections._ensembles`,
  :mod:`stochpound.report.sections._ensemble_findings`).
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import xarray as xr

from stochpound.report.render import figures
from stochpound.report.render import Block, FigureItem, Paragraph, Section, Table
from stochpound.report.sections._ensemble_findings import compare_ensembles, ensemble_findings, isolation_across
from stochpound.report.sections._ensembles import PHASES, Ensemble
from stochpound.report.sections._mechanism_findings import mechanism_findings
from stochpound.experiment import is_gap_axis
from stochpound.store import wall_gap_dims, walls_only
from stochpound.report.sections._facets import dim_text, labels_text, layouts, line_colours, plain, value_text, cell_gid

CM = 100.0
#: Summaries of a record's case: store variable -> (label, factor to the shown unit).
COLUMNS = {
    "response_std": ("std (cm)", CM),
    "response_skewness": ("skewness", 1.0),
    "response_excess": ("excess", 1.0),
    "impacts": ("impacts", 1.0),
    "impacts_in_phase": ("in-phase", 1.0),
    "impacts_out_of_phase": ("out-of-phase", 1.0),
    "peak_impact_force": ("peak impact force (kN)", 1e-3),
    "peak_total_displacement": ("peak total displacement (cm)", CM),
    "fixed_base_correlation": ("correlation with fixed base", 1.0),
}
#: Summaries drawn against a grid axis: store variable -> (axis label, factor).
AGAINST = {
    "impacts": ("impacts", 1.0),
    "peak_impact_force": ("peak impact force (kN)", 1e-3),
    "peak_total_displacement": ("peak total displacement (cm)", CM),
    "response_std": ("std of the response (cm)", CM),
}


def store_section(name: str, store: xr.Dataset, contact_free: bool = False, whole: xr.Dataset | None = None) -> Section:
    """A section for one store: description, its records' cases, its ensembles.

    ``contact_free``: ``store`` is a store's cases with contacts (or walls
    reached), its contact-free (wall-free) ``inf`` gap values left for the
    Separation section; the dimensions then count them, and say so.
    ``whole``: the whole store (its contact-free and wall-free cases included), whose mechanism findings compare the cases
    with their twins without impacts (:mod:`stochpound.report.sections._mechanism_findings`);
    ``store`` itself if not given.
    """
    section = Section(f"Experiment {name}", key=f"experiment-{name}")
    walls = wall_gap_dims(store)
    dims = [f"{d} ({store.sizes[d] + 1}: {store.sizes[d]} {'clearances' if d in walls else 'gaps'} here and the "
            f"{'wall-free one of the Moat clearance' if d in walls else 'contact-free one of the Separation'} section)" if contact_free and is_gap_axis(d)
            else f"{d} ({store.sizes[d]})" for d in store["case_status"].dims]
    written = store.pound.provenance
    section.add(Paragraph(
        f"{written.experiment_description} Studied building: {written.studied_building}; its "
        f"top-floor total displacement is the response, and its peaks are those shown. Dimensions: "
        f"{', '.join(dims)}; {written.cases_done} of "
        f"{written.cases_total} runs done (Methods describes every building, contact and motion)."
    ))
    kinds = dict(zip(store["record"].values.tolist(), store["record_kind"].values.tolist()))
    records = [label for label, kind in kinds.items() if kind != "synthetic"]
    if records:
        for block in record_blocks(name, store.sel(record=records).isel(realization=[0])):
            section.add(block)
    ensembles = [Ensemble(name, store, label) for label, kind in kinds.items() if kind == "synthetic"]
    for ensemble in ensembles[1:]:
        section.add(compare_ensembles(ensembles[0], ensemble))
    across = isolation_across(ensembles)
    if across is not None:
        section.add(across)
    for ensemble in ensembles:
        mechanisms = mechanism_findings(name, store if whole is None else whole, ensemble.label)
        for block in [*ensemble_findings(ensemble), *mechanisms, *ensemble.blocks()]:
            section.add(block)
    return section


def record_blocks(name: str, store: xr.Dataset) -> list[Block]:
    """The records' cases: a table of every case and, per numeric grid axis, the summaries against it."""
    data = store.squeeze("realization", drop=True)
    blocks: list[Block] = [summary_table(name, data)]
    grid = {d: [plain(v) for v in data[d].values] for d in data["case_status"].dims}
    for axis in (d for d in grid if (is_gap_axis(d) or d == "mu") and len(grid[d]) > 1):
        blocks += against_axis(name, data, grid, axis)
    return blocks


def _studied(data: xr.Dataset, store: xr.Dataset) -> xr.Dataset:
    """``data`` (variables of ``store``) of the store's studied building."""
    building = store.pound.provenance.studied_building
    return data.sel(building=building, drop=True) if "building" in data.dims else data


def summary_table(name: str, data: xr.Dataset) -> Table:
    """Every case of the records: its summaries, one row per case."""
    walls = walls_only(data)
    present = [v for v in COLUMNS if v in data and not (walls and v in PHASES)]  # a wall hit has no phase
    values = _studied(data[present], data).load()
    dims = list(data["case_status"].dims)
    frame = pd.DataFrame({COLUMNS[v][0]: (values[v] * COLUMNS[v][1]).transpose(*dims).to_series() for v in present})
    rows = [label if isinstance(label, tuple) else (label,) for label in frame.index]
    frame.index = pd.MultiIndex.from_tuples([tuple(value_text(d, v) for d, v in zip(dims, row)) for row in rows], names=[dim_text(d) for d in dims])
    return Table(
        key=f"table-{name}-records",
        caption=f"Experiment {name}: the summaries of every case under a record.",
        frame=frame,
        note="std, skewness and excess (kurtosis − 3) of the studied building's top-floor total displacement over time; peak "
        "impact force 0 where a case has no impact; μ fixed: a fixed base."
        + (" Every impact is a wall hit, which has no phase (a wall moves with the ground)." if walls else ""),
        formats={"impacts": "{:.0f}", "in-phase": "{:.0f}", "out-of-phase": "{:.0f}"},
        per_cell=True,
    )


def against_axis(name: str, data: xr.Dataset, grid: dict[str, list], axis: str) -> list[FigureItem]:
    """Summaries against ``axis`` (a gap axis or μ), one line per value of one other axis, one panel per combination of the rest."""
    values = _studied(data[[v for v in AGAINST if v in data]], data).load()
    x_values = grid[axis]
    others = [d for d in grid if d != axis]
    line_dim = next((d for d in ("mu", *others) if d in others and len(grid[d]) > 1), None)
    if is_gap_axis(axis):
        positions, ticks = np.asarray(x_values, dtype=float) * CM, None
    else:
        positions = np.arange(len(x_values), dtype=float)
        ticks = {float(p): value_text(axis, v) for p, v in zip(positions, x_values)}
    items = []
    for variable, (label, factor) in AGAINST.items():
        if variable not in values:
            continue
        panel_dims = {d: grid[d] for d in others if d != line_dim}
        plans = layouts(panel_dims)
        for number, layout in enumerate(plans, start=1):
            panels = {}
            for panel in layout.panels:
                where = {**layout.shared, **panel}
                curves = []
                for value, colour in zip(grid[line_dim] if line_dim else [None], line_colours(line_dim, grid[line_dim]) if line_dim else ["C0"]):
                    cell = {**where, **({line_dim: value} if line_dim else {})}
                    series = values[variable].sel(cell).sel({axis: x_values}).values * factor
                    if variable == "peak_impact_force":
                        series = np.where(values["impacts"].sel(cell).sel({axis: x_values}).values > 0, series, np.nan)
                    curves.append(figures.Curve(
                        value_text(line_dim, value) if line_dim else label, positions, series, color=colour, marker="o",
                        gid="|".join(cell_gid({**cell, axis: x}) for x in x_values),
                    ))
                panels[labels_text(panel) or "all cases"] = curves
            part = f" ({layout.title})" if layout.title else ""
            suffix = f"-{number}" if len(plans) > 1 else ""
            x_label = dim_text(axis) + (" (cm)" if is_gap_axis(axis) else "")
            figure = figures.panel_grid(panels, f"{name}{part}: {label}", x_label, label, x_ticks=ticks, legend_title=dim_text(line_dim) if line_dim else "")
            note = " (not drawn where a case has no impact)" if variable == "peak_impact_force" else ""
            caption = f"Experiment {name}{part}, the records' cases: {label}{note} against {dim_text(axis)}, every case drawn."
            items.append(FigureItem(f"figure-{name}-{variable}-{axis}{suffix}", caption, figure))
    return items
