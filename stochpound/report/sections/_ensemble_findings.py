"""Findings written from an ensemble's statistics: what its realizations show that one record cannot.

Every sentence is computed from :attr:`stochpound.report.sections._ensembles.Ensemble.statistics`:
how wide the intervals are, how the probability of pounding falls with each
gap axis (and the gap it takes to make pounding unlikely with 95 %
confidence), where a sliding base helps or hurts against the fixed base,
and how far the peaks spread. A finding whose axis the store lacks is left
out.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pandas as pd
import xarray as xr

from stochpound.stats import kernels
from stochpound.analysis import RARE
from stochpound.report.render import Block, Paragraph, Table
from stochpound.report.sections._ensembles import CM, MIN_RUNS, Ensemble
from stochpound.experiment import FIXED_BASE, is_fixed_base, is_gap_axis
from stochpound.store import fixed_base, has_fixed_base_twins, isolated_mus
from stochpound.report.sections._facets import dim_text, labels_text, value_text

#: Estimates compared between a sliding and a fixed base: statistic -> label.
COMPARED = {
    "pounding_probability": "P(pounding)",
    "peak_relative_displacement": "peak relative displacement",
    "peak_total_displacement": "peak total displacement",
}


def ensemble_findings(ensemble: Ensemble) -> list[Block]:
    """Every finding that applies to the ensemble's grid."""
    blocks: list[Block] = [precision(ensemble), spread(ensemble)]
    for dim in ensemble.grid:
        if is_gap_axis(dim) and len(ensemble.grid[dim]) > 1:
            blocks += gap_effect(ensemble, dim)
    mus = ensemble.grid.get("mu", [])
    if has_fixed_base_twins(mus):
        blocks += isolation_effect(ensemble)
    return blocks


def _half_widths(stats: xr.Dataset, name: str) -> np.ndarray:
    return ((stats[f"{name}_upper"] - stats[f"{name}_lower"]) / 2.0).values.ravel()


def precision(ensemble: Ensemble) -> Paragraph:
    """How wide the 95 % intervals of P(pounding) and of the mean peak displacement are."""
    stats = ensemble.statistics
    p = _half_widths(stats, "pounding_probability")
    peak = stats["peak_total_displacement_mean"].values.ravel()
    relative = _half_widths(stats, "peak_total_displacement") / peak
    cells = int(stats["pounding_probability"].size)
    return Paragraph(
        f"Ensemble {ensemble.label}: {ensemble.size} realizations in each of {cells} cells. The {ensemble.confidence:.0%} "
        f"interval of the probability of {ensemble.event} is at most ±{np.nanmax(p):.3f} wide (median ±{np.nanmedian(p):.3f}; widest "
        f"where P is near 0.5, narrowest where it is 0 or 1), and the mean peak total displacement of {ensemble.studied} is "
        f"known to ±{np.nanmedian(relative) * 100:.1f} % (median over cells; at most ±{np.nanmax(relative) * 100:.1f} %). "
        + (f"The convergence figures show these estimates from the first {MIN_RUNS} realizations to all {ensemble.size}."
           if ensemble.size >= MIN_RUNS else f"With fewer than {MIN_RUNS} realizations per cell no convergence figure is drawn.")
    )


def spread(ensemble: Ensemble) -> Paragraph:
    """How far the peaks spread between realizations of the same cell, which one record cannot show (only from cells with :data:`MIN_RUNS` runs)."""
    stats = ensemble.statistics
    quantile = stats["peak_total_displacement_quantile"]
    top = float(quantile["quantile"].max())
    between = ((stats["pounding_probability_lower"] > 0) & (stats["pounding_probability_upper"] < 1)).values
    if ensemble.size >= MIN_RUNS:
        ratio = (quantile.sel(quantile=top) / quantile.sel(quantile=0.5)).values.ravel()
        sentence = (
            f"Within one cell the realizations differ widely: the {top * 100:g} % quantile of {ensemble.studied}'s peak total "
            f"displacement is {np.nanmin(ratio):.2f} to {np.nanmax(ratio):.2f} times its median (n = {ensemble.size} per cell). "
        )
    else:
        sentence = (
            f"With {ensemble.size} realizations per cell (fewer than {MIN_RUNS}) the spread of the peaks within a cell is not "
            "estimated. "
        )
    sentence += (
        f"In {int(between.sum())} of {between.size} cells the probability of {ensemble.event} lies strictly between 0 and 1 with "
        f"{ensemble.confidence:.0%} confidence: there a single record answers yes or no where the ensemble gives a probability."
    )
    if "peak_impact_force_quantile" in stats:
        sentence += " " + _force_spread(stats, top, "pounding realizations" if ensemble.event == "pounding" else "realizations that hit a wall")
    return Paragraph(sentence)


def _force_spread(stats: xr.Dataset, top: float, impacting: str) -> str:
    """The spread of the peak impact force over the realizations with impacts (``impacting``, in words), from the cells with at least :data:`MIN_RUNS` of them."""
    force, count = stats["peak_impact_force_quantile"], stats["peak_impact_force_count"]
    enough = (count >= MIN_RUNS).values.ravel()
    if not enough.any():
        return (
            f"No cell has {MIN_RUNS} {impacting} (at most {int(count.max())}): the spread of the peak impact force is "
            "not estimated."
        )
    ratio = (force.sel(quantile=top) / force.sel(quantile=0.5)).values.ravel()[enough]
    counts = count.values.ravel()[enough]
    text = (
        f"In the {int(enough.sum())} cells with at least {MIN_RUNS} {impacting} (n = {int(counts.min())}–{int(counts.max())}), "
        f"the {top * 100:g} % quantile of the peak impact force is {np.nanmin(ratio):.2f} to {np.nanmax(ratio):.2f} times its median"
    )
    rest = int((~enough).sum())
    return text + (f"; the other {rest} cells have fewer {impacting} and give no ratio." if rest else ".")


def gap_effect(ensemble: Ensemble, dim: str) -> list[Block]:
    """How P(pounding) falls with gap axis ``dim``, and the gap beyond which pounding is rare (a table)."""
    stats = ensemble.statistics
    p = stats["pounding_probability"]
    first, last = p.isel({dim: 0}), p.isel({dim: -1})
    lines = int(first.size)
    lower_at_end = int((last < first).sum())
    needed = ensemble.rare_gap(dim)
    event, gap = ensemble.event, ("clearance" if ensemble.event != "pounding" else "gap")
    reached = needed.notnull()
    others = [d for d in ensemble.grid if d != dim]
    text = (
        f"The probability of {event} falls as {dim_text(dim)} widens: over the {lines} combinations of "
        f"{', '.join(dim_text(d) for d in others) or 'the grid'} it is lower at {value_text(dim, ensemble.grid[dim][-1])} than at "
        f"{value_text(dim, ensemble.grid[dim][0])} in {lower_at_end} (P from {_range(first)} to {_range(last)}). {event.capitalize()} becomes rare (upper {ensemble.confidence:.0%} bound below "
        f"{RARE:.0%} at that {gap} and every larger one of the grid) within the grid in {int(reached.sum())} of them"
    )
    if bool(reached.any()):
        text += f", at {needed.min().item() * CM:g} to {needed.max().item() * CM:g} cm"
    missing = [labels_text(cell) for cell in _cells(needed, others) if not bool(reached.sel(cell))]
    if missing:
        text += f"; it does not within {value_text(dim, ensemble.grid[dim][-1])} for " + "; ".join(missing)
    blocks: list[Block] = [Paragraph(text + ".")]
    if others:
        blocks.append(_needed_table(ensemble, dim, needed, others))
    return blocks


def _most(stats: xr.Dataset, fixed: xr.Dataset, candidates: list[tuple[float, xr.DataArray]], verb: str) -> str:
    """"It hurts (helps) most at ...": the cell with the largest clear change of P(pounding), "" if none."""
    found = [(float(change.max()), mu, change) for mu, change in candidates if bool(change.notnull().any())]
    if not found:
        return ""
    _, mu, change = max(found, key=lambda item: item[0])
    where = change.where(change == change.max(), drop=True)
    labels = {d: where[d].values[0].item() for d in where.dims}
    cell = {**labels, "mu": mu}

    def estimate(data: xr.Dataset, at: dict) -> str:
        return f"{float(data['pounding_probability'].sel(at)):.2f} [{float(data['pounding_probability_lower'].sel(at)):.2f}, {float(data['pounding_probability_upper'].sel(at)):.2f}]"

    return f"It {verb} most at {labels_text(cell)}: P(pounding) {estimate(stats, cell)} against {estimate(fixed, labels)} on a fixed base."


def _range(values: xr.DataArray) -> str:
    low, high = float(values.min()), float(values.max())
    return f"{low:.2f}" if f"{low:.2f}" == f"{high:.2f}" else f"{low:.2f}–{high:.2f}"


def _cells(data: xr.DataArray, dims: list[str]) -> list[dict[str, Any]]:
    stacked = data.transpose(*dims).to_series() if dims else pd.Series([data.item()])
    return [dict(zip(dims, label if isinstance(label, tuple) else (label,))) for label in stacked.index] if dims else [{}]


def _needed_table(ensemble: Ensemble, dim: str, needed: xr.DataArray, others: list[str]) -> Table:
    columns = "mu" if "mu" in others else others[-1]
    rows = [d for d in others if d != columns]
    series = (needed * CM).transpose(*others).to_series()
    frame = series.unstack(columns) if rows else series.to_frame().T
    frame.columns = [value_text(columns, c) for c in frame.columns]
    frame.columns.name = dim_text(columns)
    if rows:
        labels = [label if isinstance(label, tuple) else (label,) for label in frame.index]
        frame.index = pd.MultiIndex.from_tuples([tuple(value_text(d, v) for d, v in zip(rows, label)) for label in labels], names=[dim_text(d) for d in rows])
    else:
        frame.index = pd.Index(["all"], name="cell")
    return Table(
        key=f"table-{ensemble.name}-{ensemble.label}-rare-{dim}",
        caption=(
            f"Experiment {ensemble.name}, ensemble {ensemble.label}: the smallest {dim_text(dim)} (cm) of the grid from which on "
            f"{ensemble.event} is rare, i.e. the upper {ensemble.confidence:.0%} Clopper–Pearson bound of its probability is below {RARE:.0%} "
            f"there and at every larger {'gap' if ensemble.event == 'pounding' else 'clearance'} of the grid."
        ),
        frame=frame,
        note=(
            f"– : not reached within the grid (largest {dim_text(dim)} {value_text(dim, ensemble.grid[dim][-1])}). With "
            f"{ensemble.size} realizations and none {'pounding' if ensemble.event == 'pounding' else 'hitting a wall'} the upper bound is "
            f"{float(kernels.clopper_pearson(0, ensemble.size, ensemble.confidence)[1]):.4f}: "
            "a smaller threshold needs more realizations."
        ),
        formats={},
    )


def isolation_effect(ensemble: Ensemble) -> list[Block]:
    """Where a sliding base lowers or raises P(pounding) and the peak displacement, against the fixed base, cell by cell."""
    stats = ensemble.statistics
    mus = ensemble.grid["mu"]
    fixed = fixed_base(stats)
    rows = {}
    extremes: dict[str, list[tuple[float, xr.DataArray]]] = {"hurts": [], "helps": []}
    for mu in isolated_mus(mus):
        isolated = stats.sel(mu=mu)
        row = []
        for name in COMPARED:
            lower, higher = _clearly(isolated, fixed, name)
            row += [int(lower.sum()), int(higher.sum()), int((~lower & ~higher).sum())]
        rows[value_text("mu", mu)] = row
        difference = isolated["pounding_probability"] - fixed["pounding_probability"]
        extremes["hurts"].append((mu, difference.where(isolated["pounding_probability_lower"] > fixed["pounding_probability_upper"])))
        extremes["helps"].append((mu, -difference.where(isolated["pounding_probability_upper"] < fixed["pounding_probability_lower"])))
    columns = pd.MultiIndex.from_product([[f"mean {label}" if name != "pounding_probability" else label for name, label in COMPARED.items()], ["lower", "higher", "no clear difference"]])
    frame = pd.DataFrame.from_dict(rows, orient="index", columns=columns)
    frame.index.name = "μ"
    cells = int(fixed["pounding_probability"].size)
    sentences = [
        f"A sliding base against the fixed base, cell by cell over the {cells} combinations of the other axes (the table "
        f"below counts the cells where the isolated estimate is lower or higher with non-overlapping {ensemble.confidence:.0%} "
        "intervals, a conservative test)."
    ]
    counts = [(frame.iloc[:, 3 * i].sum(), frame.iloc[:, 3 * i + 1].sum()) for i in range(len(COMPARED))]
    sentences.append(
        f"Of {cells * len(rows)} isolated cells, isolation lowers the probability of pounding in {counts[0][0]} and raises it in "
        f"{counts[0][1]}; it lowers {ensemble.studied}'s mean peak relative displacement (its deformation) in {counts[1][0]} and "
        f"raises it in {counts[1][1]}; it lowers its mean peak total displacement (deformation plus sliding) in {counts[2][0]} and "
        f"raises it in {counts[2][1]}."
    )
    flip = _where_sign_flips(ensemble)
    if flip:
        sentences.append(flip)
    for verb, candidates in extremes.items():
        sentence = _most(stats, fixed, candidates, verb)
        if sentence:
            sentences.append(sentence)
    return [
        Paragraph(" ".join(sentences)),
        Table(
            key=f"table-{ensemble.name}-{ensemble.label}-isolation",
            caption=f"Experiment {ensemble.name}, ensemble {ensemble.label}: cells where a sliding base of friction μ gives a lower or higher estimate "
            "than the fixed base (μ = ∞) at the same other labels.",
            frame=frame,
            note=f"lower / higher: the {ensemble.confidence:.0%} intervals do not overlap; no clear difference: they do.",
            formats={},
        ),
    ]


def _clearly(isolated: xr.Dataset, fixed: xr.Dataset, name: str) -> tuple[xr.DataArray, xr.DataArray]:
    """Cells where the isolated estimate of ``name`` is lower, and where it is higher, than the fixed base's with non-overlapping intervals."""
    return isolated[f"{name}_upper"] < fixed[f"{name}_lower"], isolated[f"{name}_lower"] > fixed[f"{name}_upper"]


def isolation_changes(ensemble: Ensemble) -> tuple[xr.DataArray, xr.DataArray]:
    """Per isolated cell (μ finite, every other label): where isolation clearly lowers and where it clearly raises P(pounding) against the fixed base."""
    stats = ensemble.statistics
    finite = [m for m in ensemble.grid["mu"] if not is_fixed_base(m)]
    return _clearly(stats.sel(mu=finite), stats.sel(mu=FIXED_BASE, drop=True), "pounding_probability")


def _where_sign_flips(ensemble: Ensemble) -> str:
    """Where isolation lowers and where it raises P(pounding), by the axis that separates the two best ("" when the sign does not flip)."""
    lower, higher = isolation_changes(ensemble)
    if not (bool(lower.any()) and bool(higher.any())):
        return ""
    best, purity = None, -1.0
    for dim in (d for d in lower.dims if lower.sizes[d] > 1):
        lowered, raised = lower.sum([d for d in lower.dims if d != dim]), higher.sum([d for d in higher.dims if d != dim])
        score = float(np.maximum(lowered, raised).sum() / (lowered + raised).sum())
        if score > purity:
            best, purity = (dim, lowered, raised), score
    if best is None:
        return ""
    dim, lowered, raised = best
    parts = [f"{value_text(dim, v)}: {int(lo)} lower, {int(hi)} higher" for v, lo, hi in zip(lowered[dim].values, lowered.values, raised.values) if lo + hi]
    return (
        f"The sign of the change of P(pounding) flips with {dim_text(dim)} (cells with a clear difference, by {dim_text(dim)}: "
        + "; ".join(parts) + ")."
    )


def isolation_across(ensembles: list[Ensemble]) -> Paragraph | None:
    """Whether isolation's effect on P(pounding) has the same sign in every ensemble (e.g. soils), or where it flips; None without a fixed and a sliding base."""
    counts = {}
    for ensemble in ensembles:
        mus = ensemble.grid.get("mu", [])
        if any(is_fixed_base(m) for m in mus) and any(not is_fixed_base(m) for m in mus):
            lower, higher = isolation_changes(ensemble)
            counts[ensemble.label] = (int(lower.sum()), int(higher.sum()), int(lower.size))
    if len(counts) < 2:
        return None
    described = "; ".join(f"ensemble {label}: lower in {lo}, higher in {hi} of {n} isolated cells" for label, (lo, hi, n) in counts.items())
    return Paragraph(f"{isolation_verdict(counts)} ({described}; non-overlapping {ensembles[0].confidence:.0%} intervals).")


def isolation_verdict(counts: dict[str, tuple[int, int, int]]) -> str:
    """How isolation's effect on P(pounding) compares across ensembles, from (cells lowered, cells raised, cells) per ensemble.

    An ensemble where isolation lowers and raises it in as many cells is a
    tie, not a sign: the effect "changes sign" only where it lowers it in
    more cells in one ensemble and raises it in more in another.
    """
    signs = {label: int(np.sign(raised - lowered)) for label, (lowered, raised, _) in counts.items()}
    lowers = [label for label, sign in signs.items() if sign < 0]
    raises = [label for label, sign in signs.items() if sign > 0]
    ties = [label for label, sign in signs.items() if sign == 0]
    if len(set(signs.values())) == 1:
        return ("Isolation lowers and raises the probability of pounding in as many cells in every ensemble" if ties else
                "Isolation changes the probability of pounding the same way in every ensemble")
    parts = [f"it lowers it in more cells than it raises it in {', '.join(lowers)}" if lowers else "",
             f"raises it in more cells than it lowers it in {', '.join(raises)}" if raises else "",
             f"lowers and raises it in as many cells in {', '.join(ties)}" if ties else ""]
    opening = ("The effect of isolation on the probability of pounding changes sign between the ensembles: " if lowers and raises else
               "The effect of isolation on the probability of pounding differs between the ensembles: ")
    return opening + "; ".join(p for p in parts if p)


def compare_ensembles(first: Ensemble, second: Ensemble) -> Paragraph:
    """Cell by cell, where the second ensemble's P(pounding) and peak displacements are higher or lower than the first's."""
    a, b = first.statistics, second.statistics
    parts = []
    for name, label in COMPARED.items():
        lower = int((b[f"{name}_upper"] < a[f"{name}_lower"]).sum())
        higher = int((b[f"{name}_lower"] > a[f"{name}_upper"]).sum())
        parts.append(f"{label if name == 'pounding_probability' else 'the mean ' + label} higher in {higher} and lower in {lower}")
    cells = int(a["pounding_probability"].size)
    return Paragraph(
        f"Ensemble {second.label} against ensemble {first.label}, cell by cell over the {cells} cells of the grid (non-overlapping "
        f"{first.confidence:.0%} intervals): " + "; ".join(parts) + "."
    )
