"""The report of a synthetic ensemble: its statistics per grid cell as tables, and its distributions as figures.

For one ensemble of a store (one label of its ``record`` dimension) every
grid cell's realizations are summarised by
:func:`stochpound.analysis.ensemble_statistics` (means with 95 % intervals,
quantiles of the peaks, the probability of pounding with its exact
interval) and drawn: the probability of pounding against each gap axis and
against μ, the empirical distributions of the peaks and of the correlation
with the fixed-base twin, and the running estimates against the number of
realizations. Every cell is in every figure family (:mod:`stochpound.report.sections._facets`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd
import xarray as xr

from stochpound.analysis import MIN_RUNS, CellLabels, StoreEnsemble
from stochpound.report.render import Block, FigureItem, Table, figures
from stochpound.experiment import is_gap_axis
from stochpound.report.sections._facets import cell_gid, dim_text, labels_text, layouts, line_colours, value_text

CM = 100.0
KN = 1e-3


@dataclass(frozen=True)
class Quantity:
    """A per-case summary as the report shows it."""

    variable: str
    label: str
    unit: str
    factor: float


PEAK_DISPLACEMENT = Quantity("peak_total_displacement", "peak total displacement", "cm", CM)
QUANTITIES = {
    "pounding": (
        Quantity("impacts_in_phase", "in-phase impacts", "", 1.0),
        Quantity("impacts_out_of_phase", "out-of-phase impacts", "", 1.0),
        Quantity("peak_impact_force", "peak impact force, given pounding", "kN", KN),
    ),
    "displacements": (
        PEAK_DISPLACEMENT,
        Quantity("peak_relative_displacement", "peak relative displacement", "cm", CM),
        Quantity("peak_sliding_displacement", "peak sliding", "cm", CM),
        Quantity("residual_sliding", "residual sliding", "cm", CM),
        Quantity("peak_wall_penetration", "peak wall penetration", "cm", CM),
    ),
    "demands": (
        Quantity("peak_floor_acceleration", "peak floor acceleration", "m/s²", 1.0),
        Quantity("peak_interstorey_drift", "peak storey drift", "cm", CM),
        Quantity("peak_base_shear", "peak base shear", "kN", KN),
    ),
    "response": (
        Quantity("response_std", "std of the response", "cm", CM),
        Quantity("response_skewness", "skewness", "", 1.0),
        Quantity("response_excess", "excess", "", 1.0),
        Quantity("fixed_base_correlation", "correlation with the fixed-base twin", "", 1.0),
    ),
}
TABLE_CAPTIONS = {
    "pounding": "the probability of pounding with its Clopper–Pearson interval, the mean numbers of impacts in and out of phase, and the peak impact force over the realizations that pound",
    "displacements": "the studied building's peak displacements and residual sliding",
    "demands": "the studied building's demands: the largest peak total floor acceleration and storey drift over its floors, and its peak base shear",
    "response": "moments of the studied building's top-floor total displacement over time, and its correlation with the same building alone on a fixed base",
}


INTERVAL_NOTE = (
    "a percentile bootstrap of the mean for quantities that cannot be negative — counts, forces, peaks, standard "
    "deviations — whose bounds stay within the realizations' range, a Student t interval for those of either sign"
)
"""How the report's intervals of means are taken (:func:`stochpound.analysis._ensemble_statistics.interval_method`)."""


def _with_unit(quantity: Quantity) -> str:
    return f"{quantity.label} ({quantity.unit})" if quantity.unit else quantity.label


class Ensemble(StoreEnsemble):
    """One synthetic ensemble of a store (:class:`stochpound.analysis.StoreEnsemble`) as the report shows it: its tables and figures."""

    @property
    def event(self) -> str:
        """What an impact is in this ensemble's words: "pounding", or "a wall hit" in a store whose only impact elements are walls."""
        return "a wall hit" if self.walls_only else "pounding"

    @property
    def probability_label(self) -> str:
        """Its probability as a label: "P(pounding)" or "P(wall hit)"."""
        return f"P({self.event.removeprefix('a ')})"

    def gid(self, labels: CellLabels) -> str:
        """The ``gid`` of a cell of this ensemble."""
        return cell_gid({**labels, "record": self.label})

    # ------------------------------------------------------------ tables

    def tables(self) -> list[Table]:
        """The pounding, displacement and response tables of every cell."""
        return [self._table(kind) for kind in QUANTITIES if kind == "pounding" or any(f"{q.variable}_mean" in self.statistics for q in QUANTITIES[kind])]

    def _caption(self, kind: str) -> str:
        """What table ``kind`` holds, naming the wall penetration only when the store has it, and wall hits as such."""
        if kind == "pounding" and self.event == "a wall hit":
            return "the probability of a wall hit with its Clopper–Pearson interval and the peak wall force over the realizations that hit a wall"
        if kind == "displacements" and "peak_wall_penetration_mean" in self.statistics:
            return f"{TABLE_CAPTIONS[kind]} and the largest penetration of a wall per run"
        return TABLE_CAPTIONS[kind]

    def _table(self, kind: str) -> Table:
        stats = self.statistics
        columns: dict[tuple[str, str], xr.DataArray] = {}
        walls = self.event == "a wall hit"
        if kind == "pounding":
            columns[("realizations", "n")] = stats["realizations"]
            for part, suffix in (("P", ""), ("lower", "_lower"), ("upper", "_upper")):
                columns[(self.probability_label, part)] = stats[f"pounding_probability{suffix}"]
        for quantity in QUANTITIES[kind]:
            if walls and quantity.variable in PHASES:
                continue  # a wall moves with the ground: its hits have no phase
            if walls and quantity.variable == "peak_impact_force":
                quantity = Quantity(quantity.variable, "peak wall force, given a wall hit", quantity.unit, quantity.factor)
            columns.update(self._columns(quantity))
        return Table(
            key=f"table-{self.name}-{self.label}-{kind}",
            caption=f"Experiment {self.name}, ensemble {self.label} ({self.size} realizations per cell): {self._caption(kind)}.",
            frame=table_frame(columns, list(self.grid)),
            note=(
                f"mean: the ensemble mean over the realizations, with the lower and upper bounds of its {self.confidence:.0%} "
                f"confidence interval ({INTERVAL_NOTE}); {self.probability_label}: fraction of realizations with at least one impact, with its "
                f"{self.confidence:.0%} Clopper–Pearson (exact binomial) interval; n: realizations used; percentages: sample "
                f"quantiles. Peaks are the studied building's ({self.studied}); μ fixed: a fixed base."
            ),
            formats={"n": "{:.0f}"},
            per_cell=True,
        )

    def _columns(self, quantity: Quantity) -> dict[tuple[str, str], xr.DataArray]:
        """Mean, bounds, count and quantiles of one quantity, in its unit (none if the store lacks it)."""
        stats, head, columns = self.statistics, _with_unit(quantity), {}
        if f"{quantity.variable}_mean" not in stats:
            return columns
        for part in ("mean", "lower", "upper"):
            columns[(head, part)] = stats[f"{quantity.variable}_{part}"] * quantity.factor
        if f"{quantity.variable}_count" in stats:
            columns[(head, "n")] = stats[f"{quantity.variable}_count"]
        if f"{quantity.variable}_quantile" in stats:
            for q in stats["quantile"].values:
                columns[(head, f"{q * 100:g} %")] = stats[f"{quantity.variable}_quantile"].sel(quantile=q, drop=True) * quantity.factor
        return columns

    def reference_table(self) -> Table | None:
        """The fixed-base twin's statistics (the studied building alone on a fixed base under the same realizations)."""
        columns: dict[tuple[str, str], xr.DataArray] = {}
        for quantity in (Quantity("reference_peak_total_displacement", "peak total displacement", "cm", CM), Quantity("reference_response_std", "std of the response", "cm", CM)):
            columns.update(self._columns(quantity))
        if not columns:
            return None
        dims = [d for d in self.grid if d in next(iter(columns.values())).dims]
        return Table(
            key=f"table-{self.name}-{self.label}-fixed-base",
            caption=f"Experiment {self.name}, ensemble {self.label}: the fixed-base twin, {self.studied} alone on a fixed base under the same {self.size} realizations.",
            frame=table_frame(columns, dims),
            note=f"Means with their {self.confidence:.0%} percentile-bootstrap intervals, and sample quantiles.",
            per_cell=True,
        )

    # ------------------------------------------------------------ figures

    def line_dim(self, exclude: Sequence[str] = ()) -> str | None:
        """The dimension drawn as lines: μ, else a gap axis, else the first other axis."""
        candidates = [d for d in self.grid if d not in exclude and len(self.grid[d]) > 1]
        for wanted in ("mu", *[d for d in candidates if is_gap_axis(d)], *candidates):
            if wanted in candidates:
                return wanted
        return None

    def pounding_against(self, x_dim: str) -> list[FigureItem]:
        """P(pounding) with its interval band against ``x_dim`` (a gap axis or μ), every cell drawn."""
        line_dim = self.line_dim(exclude=[x_dim])
        stats = self.statistics
        x_values = self.grid[x_dim]
        positions, ticks = _axis_positions(x_dim, x_values)

        def curves(panel: CellLabels) -> list[figures.Curve]:
            result = []
            for value, colour in lines(self.grid, line_dim):
                where = {**panel, **({line_dim: value} if line_dim else {})}
                cell = stats.sel({d: v for d, v in where.items()})
                p = cell["pounding_probability"].sel({x_dim: x_values})
                result.append(figures.Curve(
                    line_label(line_dim, value), positions, p.values,
                    cell["pounding_probability_lower"].sel({x_dim: x_values}).values, cell["pounding_probability_upper"].sel({x_dim: x_values}).values,
                    colour, marker="o", gid="|".join(self.gid({**where, x_dim: x}) for x in x_values),
                ))
            return result

        x_label = f"{dim_text(x_dim)}" + (" (cm)" if is_gap_axis(x_dim) else "")
        event = self.event
        return self.facet_figures(
            f"pounding-{x_dim}", [x_dim, line_dim], curves, x_label, self.probability_label,
            f"the probability of {event} against {dim_text(x_dim)}, with its {self.confidence:.0%} Clopper–Pearson band",
            x_ticks=ticks, y_limits=(-0.03, 1.03), legend_title=dim_text(line_dim) if line_dim else "",
        )

    def distributions(self, quantity: Quantity, twin: str | None = None, log_x: bool = False) -> list[FigureItem]:
        """Empirical CDFs of a summary over the realizations of every cell (and of the fixed-base twin's)."""
        line_dim = self.line_dim()
        sample = self.sample(quantity.variable)
        reference = self.twin_sample(twin) if twin else None

        def curves(panel: CellLabels) -> list[figures.Curve]:
            result = []
            for value, colour in lines(self.grid, line_dim):
                where = {**panel, **({line_dim: value} if line_dim else {})}
                result.append(figures.Curve(line_label(line_dim, value), sample.sel(where).values * quantity.factor, color=colour, gid=self.gid(where)))
            if reference is not None:
                twin_sample = reference.sel({d: v for d, v in panel.items() if d in reference.dims})
                result.append(figures.Curve(f"{self.studied} alone, fixed base", twin_sample.values * quantity.factor, color="grey", style="--", gid="fixed-base twin"))
            return result

        what = f"the empirical distribution (ECDF) of the {quantity.label} over the realizations of each cell"
        if quantity.variable == "peak_impact_force":
            what += f"; its jump at zero is the probability of {'not pounding' if self.event == 'pounding' else 'no wall hit'}"
        if reference is not None:
            what += f", with the fixed-base twin's ({self.studied} alone on a fixed base under the same realizations, dashed)"
        return self.facet_figures(
            f"ecdf-{quantity.variable}", [line_dim], curves, _with_unit(quantity), "fraction of realizations", what,
            title=f"ECDF of the {quantity.label}", y_limits=(-0.02, 1.02), log_x=log_x, legend_title=dim_text(line_dim) if line_dim else "",
        )

    def convergence(self) -> list[FigureItem]:
        """P(pounding) and the mean peak displacement over the first n realizations, n from :data:`MIN_RUNS` to all, with bands (none below :data:`MIN_RUNS` realizations)."""
        if self.size < MIN_RUNS:
            return []
        line_dim = self.line_dim()
        counts = self.convergence_counts
        panels = self.slowest_panels(line_dim)
        cut = {d: v for d, v in panels.items() if len(v) < len(self.grid[d])}
        hit = self.probability_label
        which = (f"; only the panels whose {hit} is nearest 0.5, the slowest to settle: "
                 + "; ".join(f"{dim_text(d)} {', '.join(value_text(d, x) for x in v)}" for d, v in cut.items())) if cut else ""
        items = []
        running = {
            "pounding": (self.running_pounding(), "probability", 1.0, hit, "Clopper–Pearson"),
            "peak": (self.running_mean(PEAK_DISPLACEMENT.variable), "mean", CM, "mean peak total displacement (cm)", "percentile-bootstrap"),
        }
        for key, (estimate, field, factor, y_label, method) in running.items():
            def curves(panel: CellLabels, estimate: xr.Dataset = estimate, field: str = field, factor: float = factor) -> list[figures.Curve]:
                result = []
                for value, colour in lines(self.grid, line_dim):
                    where = {**panel, **({line_dim: value} if line_dim else {})}
                    cell = estimate.sel(where)
                    result.append(figures.Curve(
                        line_label(line_dim, value), counts, cell[field].values * factor, cell["lower"].values * factor, cell["upper"].values * factor,
                        colour, marker="o", gid=self.gid(where),
                    ))
                return result

            what = y_label.split(" (")[0]
            items += self.facet_figures(
                f"convergence-{key}", [line_dim], curves, "realizations", y_label,
                f"convergence: the {what} estimated from the first n realizations (n = {', '.join(map(str, counts))}), with its "
                f"{self.confidence:.0%} {method} band{which}",
                title=f"{what} against the number of realizations", log_x=True, legend_title=dim_text(line_dim) if line_dim else "",
                panel_grid=panels,
            )
        return items

    def facet_figures(
        self, kind: str, drawn: Sequence[str | None], curves: Callable[[CellLabels], list[figures.Curve]], x_label: str, y_label: str, what: str, title: str = "",
        panel_grid: dict[str, list[Any]] | None = None, **options: Any
    ) -> list[FigureItem]:
        """One figure per layout of the dimensions not ``drawn`` (each combination a panel; ``panel_grid``: only those values of them)."""
        panel_grid = panel_grid if panel_grid is not None else {d: v for d, v in self.grid.items() if d not in drawn}
        plans = layouts(panel_grid)
        items = []
        for number, layout in enumerate(plans, start=1):
            panels = {labels_text(panel) or "all cells": curves({**layout.shared, **panel}) for panel in layout.panels}
            part = f" ({layout.title})" if layout.title else ""
            figure = figures.panel_grid(panels, f"{self.name}, {self.label}{part}: {title or y_label}", x_label, y_label, **options)
            suffix = f"-{number}" if len(plans) > 1 else ""
            caption = f"Experiment {self.name}, ensemble {self.label}{part}, {self.size} realizations per cell: {what}."
            items.append(FigureItem(f"figure-{self.name}-{self.label}-{kind}{suffix}", caption, figure))
        return items

    def figures(self) -> list[FigureItem]:
        """Every figure of the ensemble."""
        items: list[FigureItem] = []
        for dim in self.grid:
            if (is_gap_axis(dim) or dim == "mu") and len(self.grid[dim]) > 1:
                items += self.pounding_against(dim)
        items += self.distributions(PEAK_DISPLACEMENT, twin="reference_peak_total_displacement", log_x=True)
        if self.sliding:
            items += self.distributions(Quantity("peak_sliding_displacement", "peak sliding", "cm", CM))
        items += self.distributions(Quantity("peak_impact_force", "peak impact force", "kN", KN))
        items += self.distributions(Quantity("fixed_base_correlation", "correlation with the fixed-base twin", "", 1.0))
        if "peak_floor_acceleration" in self.data:
            items += self.distributions(QUANTITIES["demands"][0])
        items += self.convergence()
        return items

    def blocks(self) -> list[Block]:
        """The ensemble's tables and figures, in reading order."""
        blocks: list[Block] = [*self.tables()]
        reference = self.reference_table()
        if reference is not None:
            blocks.append(reference)
        return blocks + self.figures()


PHASES = ("impacts_in_phase", "impacts_out_of_phase")
"""The summaries that split the impacts by phase (between buildings only)."""


def table_frame(columns: dict[tuple[str, str], xr.DataArray], dims: list[str]) -> pd.DataFrame:
    """A table with one row per combination of ``dims`` (labelled as in the figures) and (quantity, estimate) columns."""
    if not dims:
        frame = pd.DataFrame({key: [float(value)] for key, value in columns.items()}, index=pd.Index(["all"], name="cell"))
    else:
        frame = pd.DataFrame({key: value.transpose(*dims).to_series() for key, value in columns.items()})
        rows = [label if isinstance(label, tuple) else (label,) for label in frame.index]
        frame.index = pd.MultiIndex.from_tuples([tuple(value_text(d, v) for d, v in zip(dims, row)) for row in rows], names=[dim_text(d) for d in dims])
    frame.columns = pd.MultiIndex.from_tuples(list(columns), names=["quantity", "estimate"])
    return frame


def lines(grid: dict[str, list[Any]], line_dim: str | None) -> list[tuple[Any, Any]]:
    if line_dim is None:
        return [(None, "C0")]
    return list(zip(grid[line_dim], line_colours(line_dim, grid[line_dim])))


def line_label(line_dim: str | None, value: Any) -> str:
    return value_text(line_dim, value) if line_dim else "all realizations"


def _axis_positions(dim: str, values: Sequence[Any]) -> tuple[np.ndarray, dict[float, str] | None]:
    """x positions of an axis's values: gaps in cm; μ by rank, labelled, so that a fixed base (∞) has a place."""
    if is_gap_axis(dim):
        return np.asarray(values, dtype=float) * CM, None
    positions = np.arange(len(values), dtype=float)
    return positions, {float(p): value_text(dim, v) for p, v in zip(positions, values)}
