"""Findings on the mechanisms of pounding in an ensemble: ratcheting of a sliding base, amplification by impacts, wall penetration.

Each sentence is computed by :mod:`stochpound.analysis.mechanisms` from the
store, each run against its twin (the same motion without the impact elements):

* with contact-free twins (a gap axis holding ``inf``): where pounding
  ratchets the studied building's sliding base, where it does not, and
  how much it raises its peak floor acceleration and storey drift (when
  the store keeps demands);
* with walls (a moat) and runs without them, either a gap axis over the
  walls holding ``inf`` (walls never reached) or a variant axis whose
  values add walls beside a variant without walls: how much a wall raises
  those demands over the same motions without a wall, and how deep the
  stiff wall elements were penetrated (``peak_wall_penetration``, the
  largest over the runs, and where).

A cell is stated only from at least :data:`~stochpound.analysis._intervals.MIN_RUNS`
paired runs; a finding whose data the store lacks is left out, and a
mechanism that is absent is said to be absent.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from stochpound._plurals import counted
from stochpound.analysis import CellLabels, MechanismCells
from stochpound.experiment import is_gap_axis
from stochpound.store import TomlTable, contact_free, contact_gap_dims, has_contact_free, wall_axis, with_contacts
from stochpound.report.render import Block, Paragraph
from stochpound.report.sections._ensembles import CM, MIN_RUNS, Ensemble
from stochpound.report.sections._facets import dim_text, labels_text, value_text

#: Demands compared with their twins without impacts: store variable -> (words, unit shown, factor to it).
DEMANDS = {
    "peak_floor_acceleration": ("peak floor acceleration", "m/s²", 1.0),
    "peak_interstorey_drift": ("peak storey drift", "cm", CM),
}
#: Most cells a sentence lists one by one (the others are counted).
LISTED = 12


def mechanism_findings(name: str, store: xr.Dataset, label: str) -> list[Block]:
    """Every mechanism finding that applies to ensemble ``label`` of ``store`` (the whole store: its contact-free cases included)."""
    blocks: list[Block] = []
    for impacts, twins, cause, twin in _comparisons(name, store, label):
        if cause == "pounding":
            blocks.append(Paragraph(ratcheting_text(impacts, twins, away_from_neighbour(store, impacts.studied))))
        blocks += [Paragraph(amplification_text(impacts, twins, variable, cause, twin)) for variable in DEMANDS if variable in store]
    axis = wall_axis(store)
    if "peak_wall_penetration" in store:
        blocks.append(Paragraph(penetration_text(_walled(name, store, label, axis), axis[0] if axis else None)))
    return blocks


def _without_walls(axis: str, reference: Any) -> str:
    """The runs without a wall in words: the variant without walls, or the walls never reached (clearance ∞)."""
    if is_gap_axis(axis):
        return f"the same motion with the walls never reached ({axis} = ∞)"
    return f"the same motion without a wall ({axis} {reference})"



def _comparisons(name: str, store: xr.Dataset, label: str) -> list[tuple[Ensemble, Ensemble, str, str]]:
    """(cells with impacts, their twins without, the cause in words, the twins in words) of ensemble ``label``: pounding against
    the contact-free twins, a wall against the variant without walls (those the store has)."""
    comparisons = []
    if has_twins(store):
        comparisons.append((Ensemble(name, with_contacts(store), label), Ensemble(name, contact_free(store), label), "pounding",
                            "its contact-free twin (gap = ∞)"))
    axis = wall_axis(store)
    if axis is not None:
        walls, reference = axis
        comparisons.append((_walled(name, store, label, axis), Ensemble(name, store.sel({walls: reference}, drop=True), label), "a wall",
                            _without_walls(walls, reference)))
    return comparisons


def _walled(name: str, store: xr.Dataset, label: str, axis: tuple[str, Any] | None) -> Ensemble:
    """Ensemble ``label`` of the store's cells with walls (without the wall axis's value without walls, if any)."""
    return Ensemble(name, store if axis is None else store.drop_sel({axis[0]: axis[1]}), label)


def has_twins(store: xr.Dataset) -> bool:
    """Whether ``store`` has cells with contacts and their contact-free twins (a gap axis holding ``inf`` and finite gaps)."""
    return has_contact_free(store) and all(with_contacts(store).sizes[d] for d in contact_gap_dims(store))


def mechanism_answer(name: str, store: xr.Dataset) -> str | None:
    """The summary's answer "Which mechanisms do the runs show?", per synthetic ensemble in one sentence (None when the store can show none)."""
    kinds = dict(zip(store["record"].values.tolist(), store["record_kind"].values.tolist()))
    axis = wall_axis(store)
    parts, compared = [], False
    for label in (label for label, kind in kinds.items() if kind == "synthetic"):
        found = []
        for impacts, twins, cause, _ in _comparisons(name, store, label):
            compared = True
            away = away_from_neighbour(store, impacts.studied)
            if cause == "pounding" and away is not None and impacts.sliding:
                result = impacts.ratcheting_against(twins, away)
                found.append(f"pounding ratchets {impacts.studied}'s sliding base in {result.flagged_count} of "
                             f"{counted(result.assessed_count, 'cell')}" + _pushed_summary(result) + _lowered_summary(result))
            found += [_raised(impacts.amplification_over(twins, v), cause, DEMANDS[v][0]) for v in DEMANDS if v in store]
        if "peak_wall_penetration" in store:
            deepest = _walled(name, store, label, axis).wall_penetration().largest
            found.append(f"the walls were penetrated by up to {deepest * CM:.3g} cm" if np.isfinite(deepest) else "no run with a wall")
        if found:
            parts.append(f"ensemble {label}: " + "; ".join(found))
    if not parts:
        return None
    how = (f" (each run against the same motion without impacts, cells with at least {MIN_RUNS} paired runs; details and intervals in "
           "the findings)" if compared else "")
    return f"Which mechanisms do the runs show{how}? " + "; ".join(parts) + "."


def _pushed_summary(result: MechanismCells) -> str:
    """" and pushes its residual away from the neighbour (by 0.04–0.17 cm on average), without a resolved change of its size, in 2
    more" ("" when no cell is pushed): the size of the push stated, so that a resolved but tiny effect reads as tiny."""
    pushed = result.pushed()
    if not pushed:
        return ""
    sizes = [float(result.found["away_change_mean"].sel(c)) * CM for c in pushed]
    low, high = min(sizes), max(sizes)
    by = f"{low:.2g} cm" if f"{low:.2g}" == f"{high:.2g}" else f"{low:.2g}–{high:.2g} cm"
    return (f" and pushes its residual away from the neighbour (by {by} on average), without a resolved change of its size, in "
            f"{len(pushed)} more")


def _lowered_summary(result: MechanismCells) -> str:
    """"; it leaves the base nearer its start than without contacts in 1 cell" ("" when in none)."""
    lowered = result.lowered()
    return f"; it leaves the base nearer its start than without contacts in {counted(len(lowered), 'cell')}" if lowered else ""


def _raised(found: MechanismCells, cause: str, words: str) -> str:
    """"a wall raises the peak floor acceleration in 4 of 4 cells (5.02–13.3 times per run)"."""
    text = f"{cause} raises the {words} in {found.flagged_count} of {counted(found.assessed_count, 'cell')}"
    ratios = found.ratio_range()
    if ratios is not None:
        low, high = ratios
        text += f" ({low:.3g}–{high:.3g} times per run)" if f"{low:.3g}" != f"{high:.3g}" else f" ({low:.3g} times per run)"
    return text


def away_from_neighbour(store: xr.Dataset, building: str) -> int | None:
    """−1 if ``building`` is left of every contact it has, +1 if right of every one, None otherwise (no contact, or both sides)."""
    if "contact_left" not in store.coords:
        return None
    left = set(np.asarray(store["contact_left"].values).ravel().tolist())
    right = set(np.asarray(store["contact_right"].values).ravel().tolist())
    if building in left and building not in right:
        return -1
    if building in right and building not in left:
        return 1
    return None


def _value(mean: float, lower: float, upper: float, unit: str, factor: float, digits: str = ".3g") -> str:
    """``20.4 cm [16.1, 24.9]``."""
    suffix = f" {unit}" if unit else ""
    return f"{mean * factor:{digits}}{suffix} [{lower * factor:{digits}}, {upper * factor:{digits}}]"


def _listed(parts: list[str]) -> str:
    """At most :data:`LISTED` parts joined with "; ", and how many more."""
    shown = "; ".join(parts[:LISTED])
    return shown + (f"; and {len(parts) - LISTED} more cells" if len(parts) > LISTED else "")


def ratcheting_text(pounding: Ensemble, free: Ensemble, away: int | None) -> str:
    """Where pounding ratchets the studied building's sliding base against its contact-free twins, and where it does not."""
    building, opening = pounding.studied, f"Ratcheting ({pounding.label}, {pounding.studied}): "
    if away is None:
        return opening + "not assessed: the studied building has neighbours on both sides or none, so 'away from the neighbour' is undefined."
    if not pounding.sliding:
        return opening + "none possible: the studied building's base does not slide in any cell."
    found = pounding.ratcheting_against(free, away)
    direction = "left" if away < 0 else "right"
    enough = found.assessed()
    if not enough:
        return opening + f"not assessed: no cell has {MIN_RUNS} runs paired with their contact-free twins (at most {found.most_runs})."

    def describe(cell: CellLabels) -> str:
        at = found.found.sel(cell)
        n = int(at["abs_change_count"])
        return (f"at {labels_text(cell)}, mean abs(residual sliding) {_value(float(at.abs_mean), float(at.abs_lower), float(at.abs_upper), 'cm', CM)} "
                f"against {_value(float(at.free_abs_mean), float(at.free_abs_lower), float(at.free_abs_upper), 'cm', CM)} in the twins (paired "
                f"increase {_value(float(at.abs_change_mean), float(at.abs_change_lower), float(at.abs_change_upper), 'cm', CM)}), "
                f"residual away from the neighbour {_value(float(at.away_mean), float(at.away_lower), float(at.away_upper), 'cm', CM)}, "
                f"{_value(float(at.away_change_mean), float(at.away_change_lower), float(at.away_change_upper), 'cm', CM)} more than the twins' (n = {n})")

    ratchets, lowers, pushed = found.flagged(), found.lowered(), found.pushed()
    rest = [c for c in enough if c not in ratchets and c not in lowers and c not in pushed]
    text = opening + (
        f"pounding ratchets {building}'s sliding base — the paired {pounding.confidence:.0%} bootstrap intervals of the increase of abs(residual sliding) over "
        f"the contact-free twin and of its increase away from the neighbour (to the {direction}) both lie above 0 — in {len(ratchets)} "
        f"of the {counted(len(enough), 'cell')} with contacts that have at least {MIN_RUNS} paired runs"
    )
    text += (": " + _listed([describe(c) for c in ratchets]) + "." if ratchets else "; it does not ratchet it in any of them.")
    if ratchets and len(enough) > LISTED:
        text += " " + _by_axis(found, "ratcheting")
    if pushed:
        text += (f" In {counted(len(pushed), 'cell')} the impacts push the residual away from the neighbour without a resolved change of its "
                 "size: " + _listed([describe(c) for c in pushed]) + ".")
    if lowers:
        text += (f" In {counted(len(lowers), 'cell')} pounding leaves the base nearer its start than without contacts (the paired "
                 "increase of abs(residual sliding) lies below 0): " + _listed([describe(c) for c in lowers]) + ".")
    if rest:
        text += f" No resolved ratcheting at {_listed([labels_text(c) for c in rest])}."
    short = found.short()
    if short:
        text += f" Fewer than {MIN_RUNS} paired runs, not assessed: {_listed([labels_text(c) for c in short])}."
    return text


def _by_axis(found: MechanismCells, what: str) -> str:
    """Where the effect is resolved, counted along each axis of more than one value: "Cells with ratcheting, by gap: 2 cm 3 of 4; ..."."""
    parts = [f"by {dim_text(dim)}: " + ", ".join(f"{value_text(dim, v)} {held} of {assessed}" for v, held, assessed in counts)
             for dim, counts in found.by_axis()]
    return f"Cells with {what}, " + "; ".join(parts) + "." if parts else ""


def amplification_text(impacts: Ensemble, twins: Ensemble, variable: str, cause: str, twin: str) -> str:
    """How much ``cause`` (pounding, a wall) raises the studied building's demand ``variable`` over ``twin``, cell by cell."""
    words, unit, factor = DEMANDS[variable]
    found = impacts.amplification_over(twins, variable)
    enough = found.assessed()
    opening = f"Amplification of the {words} by {cause} ({impacts.label}, {impacts.studied}): "
    if not enough:
        return opening + f"not assessed: no cell has {MIN_RUNS} runs paired with {twin} (at most {found.most_runs})."

    def describe(cell: CellLabels) -> str:
        at = found.found.sel(cell)
        return (f"{labels_text(cell)}: {_value(float(at.ratio_mean), float(at.ratio_lower), float(at.ratio_upper), '', 1.0)} times "
                f"({_value(float(at.with_mean), float(at.with_lower), float(at.with_upper), unit, factor)} against "
                f"{_value(float(at.twin_mean), float(at.twin_lower), float(at.twin_upper), unit, factor)}, n = {int(at.ratio_count)})")

    raises, lowers = found.flagged(), found.lowered()
    rest = [c for c in enough if c not in raises and c not in lowers]
    text = opening + (
        f"{cause} multiplies {impacts.studied}'s {words} over {twin} by the mean of the per-run ratios given for each cell "
        f"({impacts.confidence:.0%} bootstrap intervals in brackets; in parentheses the mean with {cause} and the twins' mean). It raises it "
        f"in {len(raises)} of the {counted(len(enough), 'cell')} with at least {MIN_RUNS} paired runs"
    )
    text += (": " + _listed([describe(c) for c in raises]) + "." if raises else ".")
    if lowers:
        text += f" It lowers it in {len(lowers)}: " + _listed([describe(c) for c in lowers]) + "."
    if raises and len(enough) > LISTED:
        text += " " + _by_axis(found, f"a resolved rise of the {words}")
    if rest:
        text += f" No resolved change at {_listed([labels_text(c) for c in rest])}."
    short = found.short()
    if short:
        text += f" Fewer than {MIN_RUNS} paired runs, not assessed: {_listed([labels_text(c) for c in short])}."
    return text


def penetration_text(ensemble: Ensemble, walls: str | None) -> str:
    """The largest penetration of the walls over the runs of ``ensemble`` (its cells with walls), and where, also per value of the
    axis ``walls`` that adds them or sets their clearance (if any): what a 'rigid' wall is here."""
    penetration = ensemble.wall_penetration(walls)
    definition = ensemble.data.pound.definition
    edits = [TomlTable(override).table_or_empty("scene") for axis in definition.variants for override in axis.overrides.values()]
    tables = [*TomlTable(definition.scene, "scene").tables("wall"), *(wall for edit in edits for wall in edit.tables("wall"))]
    stiffness = sorted({wall.number("stiffness") for wall in tables if "stiffness" in wall})
    runs = penetration.runs
    if runs == 0:
        return f"Wall penetration ({ensemble.label}): no run with a wall is in the store."
    at, largest = penetration.at, penetration.largest
    per_wall = "" if walls is None else (f"; the largest per value of {walls}: "
                                         + "; ".join(f"{value_text(walls, v)}: {deepest * CM:.3g} cm" for v, deepest in penetration.per_value))
    return (
        f"Wall penetration ({ensemble.label}, {ensemble.studied}): a 'rigid' wall is here a stiff impact element"
        + (f" (k = {', '.join(f'{k / 1e6:.4g}' for k in stiffness)} MN/m)" if stiffness else "")
        + f" that the level it faces penetrates while in contact. Over the {runs} runs with a wall the largest penetration is "
        f"{largest * CM:.3g} cm ({largest * 1000:.3g} mm), at {labels_text({k: v for k, v in at.items() if k != 'realization'})}, realization "
        f"{penetration.realization}{per_wall}. It is the located peak of the level's displacement toward each "
        "wall beyond its gap (store variable peak_wall_penetration), not a sampled value."
    )
