"""The damage section: what the runs did to yielding buildings, next to the separations (all from :class:`stochpound.risk.StoreDamage`)."""

from __future__ import annotations

from collections.abc import Hashable

import pandas as pd

from stochpound.report.render import Paragraph, Section, Table
from stochpound.report.sections._description import number
from stochpound.risk import DAMAGE_DEMANDS, MODEL_DRIFT_LIMIT, POUNDING_AT_G_STAR as POUNDING, UNIDENTIFIED_BETA, StoreDamage


def damage_section(name: str, damage: StoreDamage) -> Section:
    """The ductility and residual drift demands at the 10 % and 2 % in 50 yr stripes, runs beyond the model, and the governing limit state."""
    section = Section(f"Damage: experiment {name}", key=f"damage-{name}")
    runs = "contact-free runs (those the separations come from)" if damage.contact_free else "runs"
    stripes = "; ".join(f"{_percent(p)} in 50 yr: stripe {number(level)}" for p, level in damage.design_stripes.items())
    measured = [DAMAGE_DEMANDS[name] + (" (drift over yield drift)" if name == "peak_ductility" else "") for name in DAMAGE_DEMANDS if name in damage.demands]
    section.add(Paragraph(
        f"What the earthquakes do to the buildings of experiment {name}, from its {runs}: the median and 84 % fractile over "
        f"each stripe's motions of every building's largest {', '.join(measured)}, at the stripes nearest (in ln IM) the hazard's "
        f"intensities of the design levels ({stripes}).{_elastic_text(damage)}"
    ))
    section.add(_demands_table(name, damage))
    section.add(Paragraph(_beyond_model_text(damage)))
    if damage.risk is not None:
        section.add(Paragraph(_governing_text(damage)))
        section.add(_limit_states_table(name, damage))
    return section


def _elastic_text(damage: StoreDamage) -> str:
    """Which buildings are elastic (their storeys never yield: no ductility), in a sentence ("" when every building yields)."""
    if not damage.elastic:
        return ""
    if "peak_ductility" not in damage.demands:
        return " The buildings are elastic (no storey yields in any run): they have no ductility, and the table gives their drifts only."
    return (f" {', '.join(damage.elastic)} {'is' if len(damage.elastic) == 1 else 'are'} elastic (no storey yields in any run): no ductility "
            "('elastic' in its column).")


def _configurations(data) -> list[dict]:
    """Every combination of ``data``'s grid labels other than intensity, quantile, building and limit state."""
    dims = [d for d in data.dims if d not in ("intensity", "quantile", "building", "limit_state")]
    index = pd.MultiIndex.from_product([data[d].values for d in dims], names=dims) if dims else [()]
    return [dict(zip(dims, labels if isinstance(labels, tuple) else (labels,))) for labels in index]


def _percent(probability: float) -> str:
    return f"{100.0 * probability:g} %"


def _label(labels: dict) -> str:
    return ", ".join(f"{k} {'fixed' if k == 'mu' and v == float('inf') else (number(v) if isinstance(v, float) else v)}" for k, v in labels.items()) or "–"


def _demands_table(name: str, damage: StoreDamage) -> Table:
    rows = []
    demands = damage.demands
    for labels in _configurations(demands[next(iter(demands.data_vars))]):
        for probability, level in damage.design_stripes.items():
            at = demands.sel(labels).sel(intensity=level)
            for building in at["building"].values:
                row = {"configuration": _label(labels), "stripe": f"{number(level)} ({_percent(probability)}/50 yr)", "building": str(building)}
                for variable, scale, unit in (("peak_ductility", 1.0, ""), ("residual_drift", 1000.0, " (mm)"), ("peak_drift_ratio", 100.0, " (%)")):
                    if variable in at:
                        for q, word in ((0.5, "median"), (0.84, "84 %")):
                            value = float(at[variable].sel(building=building, quantile=q)) * scale
                            elastic = variable == "peak_ductility" and str(building) in damage.elastic
                            row[f"{DAMAGE_DEMANDS[variable]}{unit}, {word}"] = "elastic" if elastic else f"{value:.3g}"
                row["runs > model"] = f"{int(damage.beyond_model.sel(labels).sel(intensity=level))} of {int(damage.runs.sel(labels).sel(intensity=level))}"
                rows.append(row)
    frame = pd.DataFrame(rows).set_index(["configuration", "stripe", "building"])
    return Table(
        key=f"table-damage-{name}",
        caption=(f"Experiment {name}: each building's largest {', '.join(DAMAGE_DEMANDS[v] for v in DAMAGE_DEMANDS if v in demands)}, "
                 "median and 84 % fractile over the stripe's motions, at the stripes of 10 % and 2 % in 50 yr"),
        frame=frame,
        note=(f"runs > model: the stripe's runs whose peak storey drift ratio (any building) exceeds {_percent(MODEL_DRIFT_LIMIT)}, beyond what "
              "the model represents (below). Empirical fractiles (linear interpolation between the ordered runs)."),
    )


def _beyond_model_text(damage: StoreDamage) -> str:
    per_stripe = damage.beyond_model_per_stripe()
    flagged = [f"{b} of {n} at stripe {number(level)}" for level, b, n in per_stripe if b]
    head = (f"The storeys are bilinear without strength loss, degradation or collapse, so a drift beyond {_percent(MODEL_DRIFT_LIMIT)} of the "
            "storey height (the collapse-prevention drift of steel moment frames) is beyond what the model represents: ")
    if not flagged:
        return head + f"none of the {damage.beyond_model_total()[1]} runs reaches it."
    both = (" The limit states' table gives each λ both ways: as run (these runs as computed), and with these runs counted apart as "
            "collapses, as FEMA P-58 does: P(C | IM) a lognormal fitted over the stripes to them, each limit state fitted on the "
            "credible runs only, and λ = ∫ [P(C | x) + (1 − P(C | x)) P(LS | x, no C)] |dλ(x)|, a collapse counted as reaching every "
            "limit state (of either building: past 5 % in one, the pair's response is not credible). What governs (below) is judged "
            "both ways." if damage.collapses_apart() else "")
    return (head + "runs reaching it, per stripe over every configuration: " + "; ".join(flagged) + ". Their drifts, ductilities and "
            "residual drifts are not credible (a real frame would have lost strength or collapsed), and the fractiles above include them."
            + both)


def _governing_text(damage: StoreDamage) -> str:
    states = "; ".join(state.label + (f" (objective: {_percent(state.target)} in 50 yr)" if state.target is not None else " (no objective)")
                       for state in damage.limit_states)
    head = (f"Limit states (capacities from {damage.source}; each building judged by its own demand): {states}.{_base_text(damage)} Each one's mean annual "
            "frequency λ comes from its fragility over the stripes (the fit is named in the table) and the site's hazard, as for "
            "pounding, and is set against its own performance objective, λ_target = −ln(1 − p)/50 for its probability p in 50 yr. "
            "Where the fit is not a lognormal the runs identify (a step, a flat fraction, a lognormal with its median beyond the top "
            "stripe or β ≥ 0.8), the runs do not pin λ: the table gives the bounds the stripes' fractions alone give it, and such a "
            "limit state misses its objective only where the lower bound does.")
    if not damage.has_objectives():
        return (head + " No limit state has an objective, so none is said to govern: give [limit_states] targets (docs/risk.md). "
                "A [limit_states] table in the experiment file replaces these capacities.")
    governs = _governs_text(damage, apart=False)
    if damage.judged_both_ways():
        governs = (f"as run, {governs}; with the runs beyond the model counted apart as collapses, "
                   f"{_governs_text(damage, apart=True)}. {_agreement_text(damage)}")
    else:
        governs += "."
    return (head + " What governs is the largest ratio λ/λ_target: pounding at the risk-targeted separation g* has ratio 1 at every "
            "target (g* is where pounding is as frequent as the target allows), so a structural limit state governs where it misses its "
            f"own objective (ratio above 1), at every target alike. Governing: {governs} A [limit_states] table in the experiment file "
            "replaces these capacities and objectives (targets; docs/risk.md).")


def _base_text(damage: StoreDamage) -> str:
    """What a limit state on the base displacement is in these runs: the base passing a displacement, with no stop modelled at
    the bearing, and where it is a moat wall's clearance, reaching the wall only in the configurations that have it ("" without one)."""
    states = [state for state in damage.limit_states if state.kind == "isolator_displacement"]
    if not states:
        return ""
    walled, every = damage.wall_counts()
    parts = []
    for state in states:
        text = f" {state.label} counts the runs whose base passes {state.capacity:g} m: no stop is modelled at the bearing in these runs"
        if any(abs(state.capacity - wall) <= 1e-9 * wall for wall in damage.walls):
            text += (f"; {state.capacity:g} m is the moat wall's clearance, so in the {walled} of {every} configurations with the wall "
                     f"passing it is reaching the wall, and in the {every - walled} without it the base passes the walled twin's "
                     "clearance with nothing there")
        parts.append(text + ".")
    return "".join(parts)


def _governs_text(damage: StoreDamage, apart: bool) -> str:
    """What governs per configuration in one treatment of the runs beyond the model (``apart``: counted apart as collapses),
    the configurations with the same answer grouped; a limit state whose fit the runs do not pin is judged on the lower bound of
    λ the stripes give (said so), and those whose bounds straddle their objective are named as left open."""
    governing, misses = damage.governing(apart), damage.misses_objective(apart)
    largest, largest_state = damage.largest_ratio(apart)
    fits, pinned, open_ = damage.fits(apart), damage.pinned(apart), damage.undecided(apart)
    bounds = damage.bound_ratios(apart)
    grouped: dict[str, list[str]] = {}
    for labels in _configurations(governing):
        worst = str(governing.sel(labels).item())
        value = float(largest.sel(labels))
        if worst == POUNDING:
            state = str(largest_state.sel(labels).item())
            lower = "" if bounds is None or bool(pinned.sel(labels).sel(limit_state=state).item()) else " (its lower bound: its fit does not pin λ)"
            text = (f"{POUNDING} (no limit state the runs put beyond its objective; the largest λ/λ_target is "
                    f"{ratio_text(value, 2)}{lower}, {state})")
        else:
            others = [str(state) for state, flag in zip(misses["limit_state"].values, misses.sel(labels).values) if flag and state != worst]
            if bounds is None or bool(pinned.sel(labels).sel(limit_state=worst).item()):
                text = f"{worst} (λ/λ_target = {ratio_text(value, 2)})"
            else:
                fit = str(fits.sel(labels).sel(limit_state=worst).item()) if fits is not None else "not a lognormal the runs identify"
                high = float(bounds[1].sel(labels).sel(limit_state=worst))
                text = (f"{worst} (λ/λ_target ≥ {ratio_text(value, 2)}, the lower bound the stripes' fractions alone give: its fit, "
                        f"{fit}, does not pin λ, which the runs bound to {ratio_text(value, 2)}–{ratio_text(high, 2)} times λ_target)")
            text += f"; also beyond their objectives: {', '.join(others)}" if others else ""
        left = [str(state) for state, flag in zip(open_["limit_state"].values, open_.sel(labels).values) if flag]
        if left and bounds is not None:
            text += "; left open by the runs (a fit they do not pin, its bounds either side of the objective): " + ", ".join(
                f"{state} ({ratio_text(float(bounds[0].sel(labels).sel(limit_state=state)), 2)}–"
                f"{ratio_text(float(bounds[1].sel(labels).sel(limit_state=state)), 2)} times λ_target)" for state in left)
        grouped.setdefault(text, []).append(_label(labels))
    every = len(_configurations(governing))
    return "; ".join((f"{' and '.join(names)}: " if len(names) < every else "") + text for text, names in grouped.items())


def _agreement_text(damage: StoreDamage) -> str:
    """Whether the two treatments name the same governing limit state, plainly, with the configurations where they do not."""
    differ = damage.disagreement()
    configurations = _configurations(differ)
    where = [labels for labels in configurations if bool(differ.sel(labels))]
    if not where:
        return "The two treatments agree on what governs in every configuration."
    run, apart = damage.governing(False), damage.governing(True)
    listed = "; ".join((f"{_label(labels)}: " if labels else "") + f"{run.sel(labels).item()} as run, {apart.sel(labels).item()} with "
                       "collapses apart" for labels in where)
    return (f"The two treatments disagree on what governs in {len(where)} of {len(configurations)} configurations ({listed}): which "
            "limit state governs depends on whether the runs beyond the model are taken as computed or as collapses.")


def _limit_states_table(name: str, damage: StoreDamage) -> Table:
    apart = damage.collapses_apart()
    rows = []
    maf = damage.risk["maf"]
    for labels in _configurations(maf):
        for state in maf["limit_state"].values:
            at = {**labels, "limit_state": state}
            target = float(maf["target"].sel(limit_state=state))
            row = {"configuration": _label(labels), "limit state": str(state),
                   "objective": f"{_percent(target)} in 50 yr" if target == target else "none"}
            for way in ([False, True] if apart else [False]):
                cells = _rate_cells(damage, at, way, target == target)
                row.update({(_APART_COLUMNS[column] if way else column): cell for column, cell in cells.items()})
            rows.append(row)
    both = (" and, with the runs beyond the model counted apart as collapses (FEMA P-58, by total probability: above), the same "
            "with the credible runs' fit behind it") if apart else ""
    return Table(
        key=f"table-limit-states-{name}",
        caption=(f"Experiment {name}: the limit states' mean annual frequency λ with its fit, the return period, per configuration, "
                 f"against each one's objective (λ/λ_target above 1: the objective is missed){both}"),
        frame=pd.DataFrame(rows).set_index(["configuration", "limit state"]),
        note=("λ is the fitted rate only where the fit is a lognormal the runs identify (its median within the stripes, β < "
              f"{UNIDENTIFIED_BETA:g}). Any other fit does not pin λ: a step (no run reaches it, every run does, or the runs separate "
              "at one stripe), a flat fraction (the counts do not rise with intensity), a lognormal not identified (its median beyond "
              "the top stripe or β ≥ 0.8, so λ rests on the lognormal's extrapolation). For those the table gives instead, in "
              "brackets, the bounds the stripes' fractions alone give λ, [λ⁻, λ⁺], for a fragility that does not fall with intensity "
              "(λ⁻: each stripe's fraction held up to the next stripe, nothing below the lowest; λ⁺: each stripe's fraction held down "
              "to the stripe below, the lowest's down to the hazard's lowest intensity, and every run reaching it beyond the top "
              "stripe; the fractions' own sampling aside), and the return period and λ/λ_target that follow; such a limit state "
              "misses its objective only where λ⁻ does. Every λ here is a point estimate from the runs, without an interval (no "
              "resampling of the motions): a ratio within a few per cent of 1 does not decide its objective."),
    )


_APART_COLUMNS = {"λ (1/yr)": "λ collapses apart (1/yr)", "once in (yr)": "once in, collapses apart (yr)", "fit": "fit collapses apart",
                  "λ/λ_target": "λ/λ_target collapses apart"}
"""The limit states table's columns of λ with the runs beyond the model counted apart, by the column as run."""


def _rate_cells(damage: StoreDamage, at: dict[str, Hashable], apart: bool, objective: bool) -> dict[str, str]:
    """One treatment's cells of a limit state in one configuration: λ, the return period, the fit and λ/λ_target, each the
    fit's where the runs pin it, else the bounds the stripes give (``[λ⁻, λ⁺]``)."""
    rate = float((damage.risk["maf_collapses_apart"] if apart else damage.risk["maf"]).sel(at))
    fit = str(damage.fits(apart).sel(at).item())
    pinned, bounds = bool(damage.pinned(apart).sel(at).item()), damage.rate_bounds(apart)
    if pinned or bounds is None:
        ratio = float(damage.ratio(apart).sel(at))
        return {"λ (1/yr)": f"{rate:.3g}", "once in (yr)": _period(rate), "fit": fit, "λ/λ_target": ratio_text(ratio) if objective else ""}
    low, high = (float(bound.sel(at)) for bound in bounds)
    ratios = damage.bound_ratios(apart)
    span = f"[{ratio_text(float(ratios[0].sel(at)))}, {ratio_text(float(ratios[1].sel(at)))}]" if objective else ""
    return {"λ (1/yr)": f"[{low:.3g}, {high:.3g}]", "once in (yr)": f"[{_period(high)}, {_period(low)}]", "fit": fit, "λ/λ_target": span}


def _period(rate: float) -> str:
    """A return period 1/λ (yr), ``inf`` for a rate of 0."""
    return f"{1.0 / rate:.3g}" if rate > 0 else "inf"


def ratio_text(ratio: float, digits: int = 3) -> str:
    """λ/λ_target to ``digits`` significant digits, but to 0.001 within 0.5 % of 1, and with a digit more where ``digits`` would
    round it to 1: a ratio that decides whether the objective is missed never prints as a bare ``1`` (1.003 misses it, 0.998
    does not; 1.03 governs)."""
    if abs(ratio - 1.0) < 0.005:
        return f"{ratio:.3f}"
    text = f"{ratio:.{digits}g}"
    return f"{ratio:.{digits + 1}g}" if float(text) == 1.0 else text
