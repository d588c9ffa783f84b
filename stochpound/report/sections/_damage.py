"""The damage section: what the runs did to yielding buildings, next to the separations (all from :class:`stochpound.risk.StoreDamage`)."""

from __future__ import annotations

import math

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
    head = (f"Limit states (capacities from {damage.source}; each building judged by its own demand): {states}. Each one's mean annual "
            "frequency λ comes from its fragility over the stripes (a lognormal, or a step where the runs identify none; the fit is "
            "named in the table) and the site's hazard, as for pounding (the table below), and is set against its own performance "
            "objective, λ_target = −ln(1 − p)/50 for its probability p in 50 yr.")
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


def _governs_text(damage: StoreDamage, apart: bool) -> str:
    """What governs per configuration in one treatment of the runs beyond the model (``apart``: counted apart as collapses),
    the configurations with the same answer grouped."""
    governing, misses = damage.governing(apart), damage.misses_objective(apart)
    largest, largest_state = damage.largest_ratio(apart)
    fits, unpinned = damage.fits(apart), damage.unpinned(apart)
    grouped: dict[str, list[str]] = {}
    for labels in _configurations(governing):
        worst = str(governing.sel(labels).item())
        value = float(largest.sel(labels))
        if worst == POUNDING:
            text = f"{POUNDING} (every limit state within its objective; the largest λ/λ_target is {ratio_text(value, 2)}, {largest_state.sel(labels).item()})"
        else:
            others = [str(state) for state, flag in zip(misses["limit_state"].values, misses.sel(labels).values) if flag and state != worst]
            fit = str(fits.sel(labels).sel(limit_state=worst).item()) if fits is not None else ""
            loose = unpinned is not None and bool(unpinned.sel(labels).sel(limit_state=worst).item())
            caveat = f"; its fit, {fit}, is not pinned by the runs: the ratio rests on it" if loose else ""
            text = (f"{worst} (λ/λ_target = {ratio_text(value, 2)}{caveat})"
                    + (f"; also beyond their objectives: {', '.join(others)}" if others else ""))
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
    maf, periods, fits = damage.risk["maf"], damage.return_period(), damage.fits()
    ratio, apart, bound_ratio = damage.ratio(), damage.collapses_apart(), damage.bound_ratio()
    fits_apart = damage.fits(apart=True)
    rows = []
    for labels in _configurations(maf):
        for state in maf["limit_state"].values:
            at = {**labels, "limit_state": state}
            target = float(maf["target"].sel(limit_state=state))
            bound = float(damage.bound.sel(at)) if damage.bound is not None else math.nan
            row = {"configuration": _label(labels), "limit state": str(state), "λ (1/yr)": _rate_cell(float(maf.sel(at)), bound),
                   "once in (yr)": _period_cell(float(periods.sel(at)), bound), "fit": str(fits.sel(at).item()),
                   "objective": f"{_percent(target)} in 50 yr" if target == target else "none",
                   "λ/λ_target": _ratio_cell(float(ratio.sel(at)), float(bound_ratio.sel(at)) if bound_ratio is not None else math.nan) if target == target else ""}
            if apart:
                bound_apart = float(damage.bounds(apart=True).sel(at)) if damage.bound is not None else math.nan
                row["λ collapses apart (1/yr)"] = _rate_cell(float(damage.risk["maf_collapses_apart"].sel(at)), bound_apart)
                row["fit collapses apart"] = str(fits_apart.sel(at).item())
                row["λ/λ_target collapses apart"] = (_ratio_cell(float(damage.ratio(apart=True).sel(at)), float(damage.bound_ratio(apart=True).sel(at))
                                                                 if damage.bound is not None else math.nan) if target == target else "")
            rows.append(row)
    both = (" and, with the runs beyond the model counted apart as collapses (FEMA P-58, by total probability: above), λ, the "
            "credible runs' fit behind it and its ratio that way") if apart else ""
    return Table(
        key=f"table-limit-states-{name}",
        caption=(f"Experiment {name}: the limit states' mean annual frequency λ with its fit, the return period, per configuration, "
                 f"against each one's objective (λ/λ_target above 1: the objective is missed){both}"),
        frame=pd.DataFrame(rows).set_index(["configuration", "limit state"]),
        note=("λ of a limit state no run reaches is 0. A step at the lowest stripe (every run, or every run above the lowest stripe, "
              "reached it) says nothing of the shaking below the runs: its λ is given as the lower bound the stripes' fractions give "
              "(≥, nothing counted below the lowest stripe) and its return period as an upper bound (≤). A lognormal 'not identified' "
              f"has its median beyond the top stripe or β ≥ {UNIDENTIFIED_BETA:g}: the runs do not pin it, and its λ rests on the "
              "lognormal's extrapolation."),
    )


def _rate_cell(rate: float, bound: float) -> str:
    """λ in the table: the rate, or ``≥`` its bound where the fit is a step at the lowest stripe (``bound`` not NaN)."""
    return f"≥ {bound:.3g}" if bound == bound else f"{rate:.3g}"


def _period_cell(period: float, bound: float) -> str:
    """The return period in the table: 1/λ, or ``≤`` 1/bound where λ is a bound."""
    return (f"≤ {1.0 / bound:.3g}" if bound > 0 else "inf") if bound == bound else f"{period:.3g}"


def _ratio_cell(ratio: float, bounded: float) -> str:
    """λ/λ_target in the table, ``≥`` the bound's where λ is one."""
    return f"≥ {ratio_text(bounded)}" if bounded == bounded else ratio_text(ratio)


def ratio_text(ratio: float, digits: int = 3) -> str:
    """λ/λ_target to ``digits`` significant digits, but to 0.001 within 0.5 % of 1, and with a digit more where ``digits`` would
    round it to 1: a ratio that decides whether the objective is missed never prints as a bare ``1`` (1.003 misses it, 0.998
    does not; 1.03 governs)."""
    if abs(ratio - 1.0) < 0.005:
        return f"{ratio:.3f}"
    text = f"{ratio:.{digits}g}"
    return f"{ratio:.{digits + 1}g}" if float(text) == 1.0 else text
