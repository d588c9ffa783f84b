"""Findings written from an ensemble's statistics: what its realizations show that one record cannot.

Every sentence is computed from :attr:`stochpound.report.sections._ensembles.Ensemble.statistics`:
how wide the intervals are, how the probability of pounding falls with each
gap axis (and the gap it takes to make pounding unlikely with 95 %
confidence), where a sliding base helps or hurts against the fixed base,
and how far the peaks spread. A finding whose axis the store lacks is left
out.
"""

from __future__ import annotations


import numpy as np
import pandas as pd
import xarray as xr

from stochpound._plurals import counted
from stochpound.analysis import RARE, CellLabels, CellStatistics, ForceSpread, Largest
from stochpound.report.render import Block, Paragraph, Table
from stochpound.report.sections._ensembles import CM, MIN_RUNS, Ensemble
from stochpound.experiment import is_fixed_base, is_gap_axis
from stochpound.store import fixed_base, has_fixed_base_twins
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
    mus = ensemble.mus
    if has_fixed_base_twins(mus):
        blocks += isolation_effect(ensemble)
    return blocks


def precision(ensemble: Ensemble) -> Paragraph:
    """How wide the 95 % intervals of P(pounding) and of the mean peak displacement are."""
    found = CellStatistics(ensemble.statistics).precision()
    return Paragraph(
        f"Ensemble {ensemble.label}: {ensemble.size} realizations in {'each of ' + str(found.cells) + ' cells' if found.cells > 1 else 'its one cell'}. The {ensemble.confidence:.0%} "
        f"interval of the probability of {ensemble.event} is at most ±{found.probability_widest:.3f} wide (median ±{found.probability_median:.3f}; widest "
        f"where P is near 0.5, narrowest where it is 0 or 1), and the mean peak total displacement of {ensemble.studied} is "
        f"known to ±{found.peak_median * 100:.1f} % (median over cells; at most ±{found.peak_widest * 100:.1f} %). "
        + (f"The convergence figures show these estimates from the first {MIN_RUNS} realizations to all {ensemble.size}."
           if ensemble.size >= MIN_RUNS else f"With fewer than {MIN_RUNS} realizations per cell no convergence figure is drawn.")
    )


def spread(ensemble: Ensemble) -> Paragraph:
    """How far the peaks spread between realizations of the same cell, which one record cannot show (only from cells with :data:`MIN_RUNS` runs)."""
    found = CellStatistics(ensemble.statistics).spread(ensemble.size)
    top = found.top
    if ensemble.size >= MIN_RUNS:
        sentence = (
            f"Within one cell the realizations differ widely: the {top * 100:g} % quantile of {ensemble.studied}'s peak total "
            f"displacement is {found.lowest:.2f} to {found.highest:.2f} times its median (n = {ensemble.size} per cell). "
        )
    else:
        sentence = (
            f"With {ensemble.size} realizations per cell (fewer than {MIN_RUNS}) the spread of the peaks within a cell is not "
            "estimated. "
        )
    sentence += (
        f"In {found.between} of {counted(found.cells, 'cell')} the probability of {ensemble.event} lies strictly between 0 and 1 with "
        f"{ensemble.confidence:.0%} confidence: there a single record answers yes or no where the ensemble gives a probability."
    )
    if found.force is not None:
        sentence += " " + _force_spread(found.force, top, "pounding realizations" if ensemble.event == "pounding" else "realizations that hit a wall")
    return Paragraph(sentence)


def _force_spread(force: ForceSpread, top: float, impacting: str) -> str:
    """The spread of the peak impact force over the realizations with impacts (``impacting``, in words), from the cells with at least :data:`MIN_RUNS` of them."""
    if not force.cells:
        return (
            f"No cell has {MIN_RUNS} {impacting} (at most {force.most_anywhere}): the spread of the peak impact force is "
            "not estimated."
        )
    text = (
        f"In the {counted(force.cells, 'cell')} with at least {MIN_RUNS} {impacting} (n = {force.fewest}–{force.most}), "
        f"the {top * 100:g} % quantile of the peak impact force is {force.lowest:.2f} to {force.highest:.2f} times its median"
    )
    rest = force.rest
    return text + (f"; the other {counted(rest, 'cell')} {'has' if rest == 1 else 'have'} fewer {impacting} and give no ratio." if rest else ".")


def gap_effect(ensemble: Ensemble, dim: str) -> list[Block]:
    """How P(pounding) falls with gap axis ``dim``, and the gap beyond which pounding is rare (a table)."""
    others = [d for d in ensemble.grid if d != dim]
    found = CellStatistics(ensemble.statistics).gap_effect(dim, others)
    needed = found.rare
    event, gap = ensemble.event, ("clearance" if ensemble.event != "pounding" else "gap")
    widest, narrowest = value_text(dim, ensemble.grid[dim][-1]), value_text(dim, ensemble.grid[dim][0])
    rare = (f"{event.capitalize()} becomes rare (upper {ensemble.confidence:.0%} bound below {RARE:.0%} at that {gap} and every larger one "
            "of the grid)")
    if found.lines == 1:  # one line of the grid: its own numbers, not counts over combinations
        trend = "falls" if found.lower_at_end else "does not fall"
        text = (f"The probability of {event} {trend} as {dim_text(dim)} widens: from {found.first[0]:.3f} at {narrowest} to "
                f"{found.last[0]:.3f} at {widest}. ")
        text += (f"{rare} from {found.rare_low * CM:g} cm on" if found.reached else
                 f"{rare} nowhere within {widest}")
    else:
        text = (
            f"The probability of {event} falls as {dim_text(dim)} widens: over the {found.lines} combinations of "
            f"{', '.join(dim_text(d) for d in others)} it is lower at {widest} than at {narrowest} in {found.lower_at_end} "
            f"(P from {_range(found.first)} to {_range(found.last)}). {rare} within the grid in {found.reached} of them"
        )
        if found.reached:
            text += (f", at {found.rare_low * CM:g} cm" if found.rare_low == found.rare_high
                     else f", at {found.rare_low * CM:g} to {found.rare_high * CM:g} cm")
        missing = [labels_text(cell) for cell in found.missing]
        if missing:
            text += f"; it does not within {widest} for " + "; ".join(missing)
    blocks: list[Block] = [Paragraph(text + ".")]
    if others:
        blocks.append(_needed_table(ensemble, dim, needed, others))
    return blocks


def _most(stats: xr.Dataset, fixed: xr.Dataset, largest: Largest | None, verb: str) -> str:
    """"It hurts (helps) most at ...": the cell with the largest clear change of P(pounding), "" if none."""
    if largest is None:
        return ""

    def estimate(data: xr.Dataset, at: CellLabels) -> str:
        return f"{float(data['pounding_probability'].sel(at)):.2f} [{float(data['pounding_probability_lower'].sel(at)):.2f}, {float(data['pounding_probability_upper'].sel(at)):.2f}]"

    return f"It {verb} most at {labels_text(largest.cell)}: P(pounding) {estimate(stats, largest.cell)} against {estimate(fixed, largest.fixed)} on a fixed base."


def _range(extent: tuple[float, float]) -> str:
    """P over cells, to 3 decimals as the tables give it (0.995 is not 0.99)."""
    low, high = extent
    return f"{low:.3f}" if f"{low:.3f}" == f"{high:.3f}" else f"{low:.3f}–{high:.3f}"


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
            f"{ensemble.none_upper_bound:.4f}: "
            "a smaller threshold needs more realizations."
        ),
        formats={},
    )


def isolation_effect(ensemble: Ensemble) -> list[Block]:
    """Where a sliding base lowers or raises P(pounding) and the peak displacement, against the fixed base, cell by cell."""
    stats = ensemble.statistics
    fixed = fixed_base(stats)
    found = CellStatistics(stats).isolation(ensemble.grid["mu"])
    rows = {value_text("mu", mu): row for mu, row in found.rows}
    columns = pd.MultiIndex.from_product([[f"mean {label}" if name != "pounding_probability" else label for name, label in COMPARED.items()], ["lower", "higher", "no clear difference"]])
    frame = pd.DataFrame.from_dict(rows, orient="index", columns=columns)
    frame.index.name = "μ"
    cells = found.cells
    sentences = [
        f"A sliding base against the fixed base, cell by cell over the {cells} combinations of the other axes (the table "
        f"below counts the cells where the isolated estimate is lower or higher with non-overlapping {ensemble.confidence:.0%} "
        "intervals, a conservative test)."
    ]
    counts = found.totals()
    sentences.append(
        f"Of {cells * len(rows)} isolated cells, isolation lowers the probability of pounding in {counts[0][0]} and raises it in "
        f"{counts[0][1]}; it lowers {ensemble.studied}'s mean peak relative displacement (its deformation) in {counts[1][0]} and "
        f"raises it in {counts[1][1]}; it lowers its mean peak total displacement (deformation plus sliding) in {counts[2][0]} and "
        f"raises it in {counts[2][1]}."
    )
    flip = _where_sign_flips(ensemble)
    if flip:
        sentences.append(flip)
    for verb, largest in (("hurts", found.hurts), ("helps", found.helps)):
        sentence = _most(stats, fixed, largest, verb)
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


def _where_sign_flips(ensemble: Ensemble) -> str:
    """Where isolation lowers and where it raises P(pounding), by the axis that separates the two best ("" when the sign does not flip)."""
    flip = CellStatistics(ensemble.statistics).sign_flip(ensemble.grid["mu"])
    if flip is None:
        return ""
    dim = flip.dim
    parts = [f"{value_text(dim, v)}: {lo} lower, {hi} higher" for v, lo, hi in flip.counts]
    return (
        f"The sign of the change of P(pounding) flips with {dim_text(dim)} (cells with a clear difference, by {dim_text(dim)}: "
        + "; ".join(parts) + ")."
    )


def isolation_across(ensembles: list[Ensemble]) -> Paragraph | None:
    """Whether isolation's effect on P(pounding) has the same sign in every ensemble (e.g. soils), or where it flips; None without a fixed and a sliding base."""
    counts = {}
    for ensemble in ensembles:
        mus = ensemble.mus
        if any(is_fixed_base(m) for m in mus) and any(not is_fixed_base(m) for m in mus):
            counts[ensemble.label] = CellStatistics(ensemble.statistics).isolation_totals(mus)
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
    ours = CellStatistics(first.statistics)
    parts = []
    for name, higher, lower in ours.against(CellStatistics(second.statistics)):
        label = COMPARED[name]
        parts.append(f"{label if name == 'pounding_probability' else 'the mean ' + label} higher in {higher} and lower in {lower}")
    cells = ours.cells
    return Paragraph(
        f"Ensemble {second.label} against ensemble {first.label}, cell by cell over the {cells} cells of the grid (non-overlapping "
        f"{first.confidence:.0%} intervals): " + "; ".join(parts) + "."
    )
