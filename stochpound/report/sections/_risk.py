"""The "Risk" section of a report: pounding risk at the site of a store's hazard.

For a store with intensity stripes (or IDA capacities) and a hazard curve
(its experiment's ``[hazard]`` table; docs/risk.md), the section renders
the risk chain's results (:class:`~stochpound.risk.StoreRisk` and
:class:`~stochpound.risk.StoreDemands`, computed once per store by the
report's assembler): it computes nothing itself. It gives:

* first, the risk-targeted separation g* for each target probability, per
  configuration (every combination of the grid's axes other than the gap),
  with its bootstrap interval and the number of motions;
* the pounding fragility over (gap, IM), and the curves at a few gaps with
  their stripe points (Clopper–Pearson intervals) and fitted bands;
* the pounding risk curve λ_P(g) with its band and the targets marked, and
  the table of g*;
* the code separation rules in risk terms (the gap each asks for at the
  code intensity and how often that gap pounds);
* demand hazard curves: the studied building's base displacement (with
  the moat walls' clearance as a limit state when the scene has them),
  and storey drift and floor acceleration when the store keeps demands.

:func:`summary_answer` gives the g* paragraph alone, for the summary.
"""

from __future__ import annotations

import math
from collections.abc import Collection, Hashable, Sequence
from typing import Any

import numpy as np
import pandas as pd
import xarray as xr
from matplotlib.figure import Figure
from matplotlib.ticker import LogLocator, NullFormatter

from stochpound._plurals import counted
from stochpound.analysis import CellLabels
from stochpound.report.render import Block, FigureItem, Paragraph, Section, Table, figures
from stochpound.report.sections._facets import labels_text
from stochpound.report.sections._stripe_motions import is_selected
from stochpound.risk import MODEL_DRIFT_LIMIT, CollapseRisk, Sensitivity, StoreDamage, StoreDemands, StoreRisk
from stochpound.store import VariableAttributes


def hazard_provenance(store: xr.Dataset) -> str:
    """Where a store's hazard curve comes from, in a sentence ("" without one): its source, range and provenance lines."""
    hazard = store.pound.hazard
    if hazard is None:
        return ""
    given = {"file": lambda: f"the file {hazard.file} (sha256 {hazard.file_sha256})", "bundled": lambda: f"the bundled curve {hazard.bundled}",
             "power_law": lambda: f"the power law {hazard.power_law['k0']:g} x^-{hazard.power_law['k']:g}",
             "ruptures": lambda: f"the site's ruptures {hazard.ruptures} (the NGA-West2 average summed over them)"}[hazard.source]()
    table = (f", a table of {len(hazard.im)} intensities from {hazard.im[0]:g} to {hazard.im[-1]:g} {hazard.units} "
             f"(log-log interpolation{', extrapolated beyond it as power laws' if hazard.extrapolate else '; no extrapolation'})"
             if hazard.im else "")
    provenance = " ".join(line.strip() for line in hazard.provenance.splitlines())
    return f"hazard curve ({hazard.description} in {hazard.units}) from {given}{table}, carried in the store. Provenance: {provenance}"


def configurations(data: xr.DataArray | xr.Dataset, keep: tuple[str, ...] = ()) -> list[CellLabels]:
    """The labels of every configuration: each combination of ``data``'s dimensions other than ``keep``."""
    dims = [d for d in data.dims if d not in keep]
    if not dims:
        return [{}]
    index = pd.MultiIndex.from_product([data[d].values for d in dims], names=dims)
    return [dict(zip(dims, values)) for values in index]


def _percent(confidence: float) -> str:
    return f"{int(100 * confidence)} %"


def headline_text(name: str, risk: StoreRisk) -> str:
    """The section's first paragraph: g* for each target, per configuration, with its interval and the number of motions."""
    targets = " and ".join(risk.target_text(p) for p in risk.separation["target"].values)
    per = []
    for labels, rows in risk.by_configuration(risk.to_frame()):
        values = "; ".join(f"at least {_gap_text(row.separation)} for {risk.target_text(row.target)} (beyond the stripes' runs: no interval)"
                           if row.lower_bound else
                           f"{_gap_text(row.separation)} for {risk.target_text(row.target)}"
                           + ("" if risk.no_interval else f" [{_gap_text(row.lower)}, {_gap_text(row.upper)}]")
                           for row in rows.itertuples())
        per.append(f"{labels_text(labels) or 'the scene'}: {values}")
    stripes = f"{risk.stripes} stripes of " if risk.stripes is not None else "IDA capacities in "
    partial = f" (an unfinished store, {risk.progress}: answered from the cases that ran)" if risk.progress else ""
    beyond = risk.beyond_stripes_text()
    return (
        f"Risk-targeted separation g* (the gap whose mean annual frequency of pounding is that of {targets}, Poisson) of experiment "
        f"{name}{partial}, from {_motions_text(risk)}{' per stripe' if is_selected(risk.setting) else ''} ({stripes}{risk.measure} in {risk.setting.units}) at the site of its hazard curve, "
        + (f"without intervals (not estimable: {risk.no_interval}): " if risk.no_interval else
           f"with {_percent(risk.confidence)} intervals ({_resampling(risk)}): ") + ". ".join(per) + "." + (f" {beyond}" if beyond else "")
    )


def _gap_text(value: float) -> str:
    return "wider than every gap of the grid" if math.isinf(value) else f"{value:.3f} m"


def _with_interval(risk: StoreRisk, what: str, shown: str = "") -> str:
    """``with its 95 % bootstrap <what><shown>``, or ``without a <what> (not estimable: <why>)`` where the motions cannot be
    resampled (:attr:`~stochpound.risk.StoreRisk.no_interval`)."""
    if risk.no_interval:
        return f"without {'an' if what[0] in 'aeiou' else 'a'} {what} (not estimable: {risk.no_interval})"
    return f"with its {_percent(risk.confidence)} bootstrap {what}{shown}"


def _resampling(risk: StoreRisk) -> str:
    """How the intervals resampled the motions, as the chain's results say (by motion, or by event where the store knows them)."""
    lower = risk.separation["lower"] if "lower" in risk.separation else None
    return (VariableAttributes.of(lower).method if lower is not None else None) or "BCa bootstrap over motions"


def summary_answer(name: str, risk: StoreRisk) -> list[Block]:
    """The summary's answer to "which gap meets a target risk?": the g* paragraph of a store's risk."""
    return [Paragraph(headline_text(name, risk))]


# ---------------------------------------------------------------- the section


def risk_section(name: str, risk: StoreRisk, demands: StoreDemands | None = None, damage: StoreDamage | None = None,
                 choice: pd.DataFrame | None = None, collapse: CollapseRisk | None = None, sensitivity: Sensitivity | None = None) -> Section:
    """The "Risk" section of one store, from its risk chain, its demand hazard curves (:func:`~stochpound.risk.store_demands`),
    for yielding buildings the damage its runs did (:func:`~stochpound.risk.store_damage`), which measure is the most
    efficient (:func:`~stochpound.experiment.measure_choice`) and g* with the runs beyond the model counted apart
    (:func:`~stochpound.risk.collapse_risk`, shown where some run is beyond the model), and how far g* moves under the choices it
    rests on (:func:`~stochpound.risk.separation_sensitivity`)."""
    section = Section(f"Risk: experiment {name}", key=f"risk-{name}")
    section.add(Paragraph(headline_text(name, risk)))
    collapse = collapse if collapse is not None and collapse.collapsed else None
    section.add(Paragraph(design_summary_text(risk, demands, damage, collapse, sensitivity)))
    if collapse is not None:
        section.add(Paragraph(collapse.text(risk.years)))
        section.add(Table(f"risk-collapse-{name}", f"Experiment {name}: g* both ways, every run as computed and the runs beyond the "
                          "model counted apart as collapses (FEMA P-58), with the collapse rate λ_C", collapse.both_ways(risk.separation, risk.years),
                          formats={"g* as run (m)": "{:.3f}", "g* collapses apart (m)": "{:.3f}", "λ_C (1/yr)": "{:.3g}"}))
    if sensitivity is not None:
        section.add(Paragraph(sensitivity.text()))
        section.add(Table(f"risk-sensitivity-{name}", f"Experiment {name}: g* under each choice it rests on, each alone (no bootstrap; "
                          "the selection seed, the measure and the moat wall's stiffness from other stores, where given), with its change from "
                          "g* (with three selection seeds or more, their median and largest g* and the spread of λ_P over them at that median)",
                          sensitivity.frame, formats={c: _sensitivity_format(c) for c in sensitivity.frame.columns}))
    section.add(Paragraph(_hazard_text(risk)))
    for block in _measure_choice_blocks(name, risk, choice):
        section.add(block)
    section.add(_separation_table(name, risk))
    section.add(_risk_curve_figure(name, risk))
    section.add(_surface_figure(name, risk))
    section.add(_curves_figure(name, risk))
    for block in _rules_blocks(name, risk):
        section.add(block)
    for block in _demand_blocks(name, risk, demands):
        section.add(block)
    moat = moat_text(risk, demands)
    if moat:
        section.add(Paragraph(moat))
    return section


def _sensitivity_format(column: str) -> str:
    """The format of a sensitivity table's column: Δ in % to 0.1, a ratio (×) to 0.01, a gap (m) to the mm."""
    return "{:.1f}" if column.endswith("(%)") else "{:.2f}" if column.endswith("(×)") else "{:.3f}"


def _separation_table(name: str, risk: StoreRisk) -> Table:
    """The g* table, its caption saying how the intervals resampled the motions."""
    interval = _with_interval(risk, "interval") if risk.no_interval else f"with its {_percent(risk.confidence)} interval ({_resampling(risk)})"
    return Table(f"risk-separation-{name}", f"Experiment {name}: risk-targeted separation g* per configuration and target, {interval}",
                 risk.separation_frame(),
                 note=_grid_note(risk), formats={"g* (m)": "{:.3f}", "lower (m)": "{:.3f}", "upper (m)": "{:.3f}"})


def design_summary_text(risk: StoreRisk, demands: StoreDemands | None = None, damage: StoreDamage | None = None,
                        collapse: CollapseRisk | None = None, sensitivity: Sensitivity | None = None) -> str:
    """The design summary: the governing limit state (once: each limit state is judged against its own objective, the same at
    every target), what limits the separation at each target (pounding at g*, or the moat clearance in the configurations whose
    base reaches it more often than the target allows), the gap to design to (with several selection seeds in ``sensitivity``,
    where their largest g* lies above it), which code rules meet their level, and what the answer rests on (hazard, scenario,
    structural model, suite), all from the chain's results and the store."""
    targets = risk.separation["target"].values
    limits = "; ".join(_separation_limit(risk, demands, float(t)) for t in targets)
    if risk.rules_frame().empty:
        meets = f"The code rules were not evaluated ({risk.rules_note})."
    else:
        column, met = risk.rules_meeting()
        meets = (f"Code rules meeting their own design level as a target in every configuration and level ({column.replace('meets, ', '') if 'upper' in column else 'estimate'}): "
                 f"{', '.join(met.index[met]) or 'none'}; not: {', '.join(met.index[~met]) or 'none'}.")
    rests = "; ".join(f"{key}: {value}" for key, value in {"hazard": f"{risk.hazard.describe()} ({_source(risk)})", **risk.assumptions,
                                                          **_outside_stripes_assumption(risk), **_beyond_model(damage, collapse),
                                                          **_limit_states_assumption(damage)}.items())
    if damage is not None and damage.has_objectives():
        judged = (f"Governing limit state (the largest λ/λ_target of the limit states beyond 1, each against its own objective, the same "
                  f"at every target; pounding at g* has 1; each ratio in the Damage section): {_structural_governs(damage)}. At g*, what "
                  f"limits the separation: {limits}.")
    else:
        judged = (f"Limit state judged (no structural limit state with an objective, so none is ranked against it; at g*, what limits "
                  f"the separation): {limits}.")
    seeds = "" if sensitivity is None else seeds_beside_design_text(risk, sensitivity)
    return (f"Design summary. {judged} {design_value_text(risk)}{seeds} {meets} The answer holds only for what it "
            f"rests on; a change to any of these voids it: {rests}.")


def _separation_limit(risk: StoreRisk, demands: StoreDemands | None, target: float) -> str:
    """What limits the separation at ``target``: pounding between the buildings, or, in the configurations whose base reaches a
    moat clearance more often than the target allows, that clearance (named with those configurations and the worst return period)."""
    pounding = f"pounding between the buildings for {risk.target_text(target)}"
    reached = [row for row in (demands.wall_exceedances([target], risk.years) if demands is not None else []) if row[2]]
    if not reached:
        return pounding
    parts = []
    for _, clearance, over, every, worst, _ in reached:
        parts.append(f"the base reaching the moat wall at its {clearance:.3g} m clearance more often than the target allows in "
                     f"{_where(over, every, _walled_noun(demands))}, once in {1 / worst:.3g}{_wall_interval(demands, clearance)} yr at worst")
    others = "" if all(len(row[2]) == row[3] for row in reached) and demands.walled is None else ", and pounding between the buildings in the other configurations"
    return f"for {risk.target_text(target)}, " + "; ".join(parts) + others


def _walled_noun(demands: StoreDemands) -> str:
    """The configurations a moat wall's rows count: every one, or those with the wall where some have none."""
    return "configurations" if demands.walled is None else "configurations with the wall"


def _where(over: Sequence[dict[str, Hashable]], every: int, noun: str = "configurations") -> str:
    """The configurations ``over`` of ``every``: ``every configuration``, or ``2 of 8 configurations (<labels>; <labels>)``
    (``noun``: what the ``every`` are, e.g. the configurations with a wall)."""
    if len(over) == every and noun == "configurations":
        return "every configuration"
    return f"{len(over)} of {every} {noun} (" + "; ".join(labels_text(labels) for labels in over) + ")"


def _structural_governs(damage: StoreDamage) -> str:
    """What governs among the buildings' own limit states (:meth:`~stochpound.risk.StoreDamage.governing`, the same at every target),
    with their counts of configurations, and pounding at g* where none misses its objective; a limit state whose fit the runs
    do not pin governs only on the lower bound of λ the stripes give (said so), and those the runs leave open are named. Where
    some run is beyond the model, judged both ways (as run, and with those runs counted apart as collapses), saying whether they
    agree."""
    run = damage.governing_counts()
    apart = damage.governing_counts(apart=True) if damage.judged_both_ways() else None
    if apart is None:
        if not run[0]:
            return f"{POUNDING_AT_G} in every configuration (no limit state beyond its objective){_left_open(damage, False)}"
        return f"{_listed(run, damage.governing_unpinned())}{_rest([run])}{_left_open(damage, False)}{_base_note(damage, run, None, '; ')}"
    if not run[0] and not apart[0]:
        return (f"{POUNDING_AT_G} in every configuration, as run and with the runs beyond the model counted apart as collapses alike"
                f"{_left_open(damage, False)}{_left_open(damage, True)}")
    count, configurations = damage.disagreements()
    agree = _base_note(damage, run, apart, "", "; ") + ("the two treatments agree in every configuration" if not count else
             f"the two treatments disagree in {count} of {configurations} configurations: what governs depends on whether the runs "
             "beyond the model are taken as computed or as collapses")
    return (f"as run, {_listed(run, damage.governing_unpinned()) or 'no limit state beyond its objective'}{_rest([run])}"
            f"{_left_open(damage, False)}; with the runs beyond the model counted apart as collapses, "
            f"{_listed(apart, damage.governing_unpinned(apart=True)) or 'no limit state beyond its objective'}{_rest([apart])}"
            f"{_left_open(damage, True)}; {agree}")


POUNDING_AT_G = "pounding at g*"


def _base_note(damage: StoreDamage, run: tuple[dict[str, int], int], apart: tuple[dict[str, int], int] | None, head: str = "",
               tail: str = "") -> str:
    """Where a base-displacement limit state governs somewhere and some configurations have no moat wall: ``head``, what it is
    there (the base passing the walled twin's clearance, no stop modelled), ``tail``; "" where not."""
    governing = set(run[0]) | (set(apart[0]) if apart is not None else set())
    named = [state.label for state in damage.limit_states if state.kind == "isolator_displacement" and state.label in governing]
    walled, every = damage.wall_counts()
    if not named or not every or walled == every:
        return ""
    return (f"{head}in the {counted(every - walled, 'configuration')} without the moat wall, {' and '.join(named)} is the base passing the walled "
            f"twin's clearance, with no stop modelled there{tail}")


def _listed(counted: tuple[dict[str, int], int], unpinned: Collection[str] = ()) -> str:
    """One treatment's governing limit states with their counts of configurations ("" where none governs), each of ``unpinned``
    (:meth:`~stochpound.risk.StoreDamage.governing_unpinned`) said to govern on the lower bound of λ the stripes alone give."""
    states, configurations = counted
    return ", ".join(f"{state} in {count} of {configurations} configurations"
                     + (" (on the lower bound of λ the stripes' fractions alone give: its fit does not pin λ)" if state in unpinned else "")
                     for state, count in states.items())


def _left_open(damage: StoreDamage, apart: bool) -> str:
    """``; left open by the runs …: <state> in <n> of <m> configurations`` for the limit states whose fit the runs do not pin and
    whose bounds straddle their objective (:meth:`~stochpound.risk.StoreDamage.undecided_counts`), else ""."""
    counts = damage.undecided_counts(apart)
    if not counts:
        return ""
    every = damage.governing_counts(apart)[1]
    return ("; left open by the runs, its fit not pinning λ and the bounds the stripes give either side of its objective: "
            + ", ".join(f"{state} in {n} of {every} configurations" for state, n in counts.items()))


def _rest(treatments: list[tuple[dict[str, int], int]]) -> str:
    """``, pounding at g* in the other <n>`` where the treatment's limit states leave some configurations to pounding at g*, else ""."""
    states, configurations = treatments[0]
    left = configurations - sum(states.values())
    return f", {POUNDING_AT_G} in the other {left}" if left and states else ""


def _beyond_model(damage: StoreDamage | None, collapse: CollapseRisk | None = None) -> dict[str, str]:
    """The assumption the runs beyond the model strain: {"beyond the model": "<n> of <N> runs ..."} where some run exceeds
    ``MODEL_DRIFT_LIMIT`` ({} otherwise or without ``damage``), and how the answer counts them."""
    beyond, runs = damage.beyond_model_total() if damage is not None else (0, 0)
    if not beyond:
        return {}
    apart = "; the limit states are given both ways too (the Damage section)" if damage.collapses_apart() else ""
    counted = ("g* above and the limit states keep them as computed; g* with them counted apart as collapses (FEMA P-58, by total "
               f"probability) is given beside it, 'g* both ways'{apart}" if collapse is not None else
               "they enter g* and the limit states as computed (the Damage section)" + apart)
    return {"beyond the model": f"{beyond} of {runs} runs exceed a "
                                f"{100 * MODEL_DRIFT_LIMIT:g} % storey drift, where the storeys' lack of strength loss and collapse makes their "
                                f"response not credible; {counted}"}


def _limit_states_assumption(damage: StoreDamage | None) -> dict[str, str]:
    """What the governing limit state rests on: the limit states' capacities and objectives and how their λ is judged
    ({} without limit states with objectives)."""
    if damage is None or not damage.has_objectives():
        return {}
    return {"limit states": f"{len(damage.limit_states)} capacities, each with its objective, as the Damage section lists them; each λ "
                            "from its fit where the runs pin it (a lognormal they identify), else judged on the lower bound the "
                            "stripes' fractions give (a fragility that does not fall with intensity); point estimates without an interval"}


def _source(risk: StoreRisk) -> str:
    return risk.hazard.source.splitlines()[0] if risk.hazard.source else "no provenance stated"


def _wall_interval(demands: StoreDemands | None, clearance: float) -> str:
    """`` [lower, upper]`` of the return period of reaching the wall at ``clearance`` in its worst configuration ("" without a bootstrap)."""
    interval = demands.wall_interval(clearance) if demands is not None else None
    return "" if interval is None else f" [{interval[0]:.3g}, {interval[1]:.3g}]"


def design_value_text(risk: StoreRisk) -> str:
    """The number to design to: per configuration and target, the upper bound of g* (stated as such), from :meth:`StoreRisk.design_frame`."""
    per = []
    for labels, rows in risk.by_configuration(risk.design_frame()):
        values = "; ".join(f"{_gap_text(row.design) if row.design == row.design else row.basis} for {risk.target_text(row.target)}"
                           for row in rows.itertuples())
        per.append(f"{labels_text(labels) or 'the scene'}: {values}")
    motions = f"{_motions_text(risk)}{' per stripe' if is_selected(risk.setting) else ''}"
    if "upper" not in risk.separation:
        why = "its interval is not estimable" if risk.no_interval else "no bootstrap was run"
        return (f"There is no upper bound of g* to design to ({why}): the values are g* itself, a central estimate "
                f"from {motions} that meets its target only about half the time: " + ". ".join(per) + ".")
    return (f"The gap to design to is the {risk.design_basis()}, not g* itself (g* is a central estimate from "
            f"{motions} and meets its target only about half the time): " + ". ".join(per) + ". It bounds the record-to-record "
            "sampling of the motions only (which records were drawn), none of the choices the answer rests on (the gap grid, the "
            "collapse treatment, modelling dispersion, the selection seed, the conditioning measure"
            + (", the moat wall's stiffness" if "moat walls" in risk.assumptions else "") + ": the sensitivity table).")


def seeds_beside_design_text(risk: StoreRisk, sensitivity: Sensitivity) -> str:
    """With three selection seeds or more, whether their largest g* lies above the gap to design to, where and by how much,
    as a sentence after a leading space ("" with fewer seeds or no row to compare)."""
    both = sensitivity.seeds_beside_design(risk.design_frame(), risk.years)
    if both.empty:
        return ""
    above = both[both["above"]]
    where = "; ".join(f"{labels_text(dict(zip(both.index.names[:-1], index[:-1]))) or 'the scene'}, {index[-1]}: {row.largest:.3f} m against "
                      f"{row.design:.3f} m" for index, row in above.iterrows())
    said = (f"lies above the gap to design to in {len(above)} of {counted(len(both), 'row')} ({where}): that bound does not cover which "
            "motions are chosen" if len(above) else f"stays within the gap to design to in {'all ' if len(both) > 1 else ''}{counted(len(both), 'row')}")
    return f" Over the {sensitivity.seeds} selection seeds of the sensitivity table, the largest g* {said}."


def _motions_text(risk: StoreRisk) -> str:
    """``N motions``, or ``1 motion``."""
    return counted(risk.motions, "motion")


def moat_text(risk: StoreRisk, demands: StoreDemands | None) -> str:
    """Whether the wall-free suite-mean peak base displacement (the D_M form) exceeds the moat clearance at each design level, and whether reaching the wall is more
    frequent than each target allows (the wall then governs that target); "" without a moat or a D_TM rule."""
    largest_dtm = risk.largest_dtm()
    if demands is None or demands.moat is None or not largest_dtm:
        return ""
    clearances = demands.moat["level"].values
    sentences = []
    for level, (value, varies) in largest_dtm.items():
        if not math.isfinite(value):
            continue
        exceeded = [c for c in clearances if value > c]
        verdict = (f"exceeds the moat clearance{'s' if len(exceeded) > 1 else ''} {', '.join(f'{c:.3g} m' for c in exceeded)}: "
                   "at that level the base reaches the wall, so the moat is short of even D_M (chapter 17's D_TM adds torsion)"
                   if exceeded else f"is within the moat clearance{'s' if len(clearances) > 1 else ''} "
                   f"{', '.join(f'{c:.3g} m' for c in clearances)}")
        largest = " (the largest over the configurations)" if varies else ""
        sentences.append(f"The wall-free suite-mean peak base displacement (the D_M form, no torsion) at {100 * level:g} %/{risk.years:g} yr{largest} is "
                         f"{value:.3g} m and {verdict}.")
    noun = _walled_noun(demands)
    for target, clearance, over, every, worst, rate in demands.wall_exceedances(risk.separation["target"].values, risk.years):
        allowed = 1.0 / rate
        head = (f"The base reaches the moat wall at its {clearance:.3g} m clearance once in {1 / worst:.3g}"
                f"{_wall_interval(demands, clearance)} yr in its worst configuration with the wall")
        if not over:
            verdict = (f"less often than {risk.target_text(target)} allows (once in {allowed:.3g} yr) in every configuration with "
                       "the wall: it does not limit the separation for this target")
        else:
            verdict = (f"more often than {risk.target_text(target)} allows (once in {allowed:.3g} yr) in {_where(over, every, noun)}: "
                       "there the wall, not the gap, limits the separation for this target")
        sentences.append(f"{head}; {verdict}.")
    if demands.walled is not None:
        sentences.append("In the configurations without the wall no stop is modelled at the base (the bearing has none in these runs): "
                         "the moat table's rows for them give how often their base passes the walled twin's clearance, with nothing "
                         "there to reach, which limits nothing.")
    return " ".join(sentences)


def _hazard_text(risk: StoreRisk) -> str:
    hz = risk.hazard
    levels = risk.hazard_levels((0.10, 0.02))
    units = risk.setting.units
    source = hz.source.splitlines()[0] if hz.source else ""
    fitted = ("fitted to the stripes' counts by maximum likelihood, from the contact-free runs by the gap identity" if risk.method == "stripes"
              else "of the motions' IDA capacities IM·g/D (log-moments), from one contact-free run per motion")
    degenerate = risk.degenerate_text() or "Every fit is a lognormal (no degenerate step)."
    extrapolated = " The hazard was extrapolated beyond its table (as a power law) for some integrals." if hz.extrapolated else ""
    return (
        f"Hazard curve of {risk.measure} in {units}, {hz.describe()} ({source}); its 10 %/50 yr intensity is "
        f"{levels[0.10]:.3g} and its 2 %/50 yr intensity {levels[0.02]:.3g} {units}. The fragility at each gap is a "
        f"lognormal {fitted}, where the data identify one. {degenerate} λ_P(g) = ∫ F(x; g) |dλ(x)|; the intervals resample the motions and "
        "refit the whole chain. Assumptions: Poisson "
        "occurrence, record-to-record variability only (not the hazard's or the model's uncertainty), and "
        f"{'the motions chosen and scaled for each stripe' if is_selected(risk.setting) else 'a suite scaled to each intensity'} "
        f"standing for the site's motions of that intensity.{extrapolated}{_outside_stripes_text(risk)}"
    )


def _lowest_stripe_text(risk: StoreRisk) -> str:
    """The lowest stripe's level and return period in words."""
    lowest, period = risk.lowest_stripe()
    return f"{lowest:.3g} {(risk.setting.units if risk.setting is not None else '')}, once in {period:.3g} yr"


def _outside_stripes_text(risk: StoreRisk) -> str:
    """How much of λ_P at g* comes from shaking below the lowest stripe and beyond the top one, where the fit is extrapolated
    (the worst configuration per target; "" for IDA runs or without a finite g*)."""
    worst = risk.worst_outside_stripes()
    if not worst:
        return ""
    below = " and ".join(f"{_share_text(b)} for {risk.target_text(t)}" for t, b, _ in worst if np.isfinite(b))
    above = " and ".join(f"{_share_text(a)} for {risk.target_text(t)}" for t, _, a in worst if np.isfinite(a))
    advice = (" That part of the answer rests on the fitted fragility's extrapolation: stripes at more frequent intensities would "
              "replace it by runs." if max(b for _, b, _ in worst if np.isfinite(b)) >= OUTSIDE_STRIPES_NOTABLE else "")
    return (f" Shaking weaker than the lowest stripe ({_lowest_stripe_text(risk)}), where the fitted fragility is extrapolated, carries up "
            f"to this share of λ_P at g* (the worst configuration): {below}; the fitted fragility's rise beyond the top stripe up to "
            f"{above}.{advice}")


def _outside_stripes_assumption(risk: StoreRisk) -> dict[str, str]:
    """{"shaking below the stripes": ...} where that shaking carries at least :data:`OUTSIDE_STRIPES_NOTABLE` of λ_P at g*, else {}."""
    notable = [(t, b) for t, b, _ in risk.worst_outside_stripes() if np.isfinite(b) and b >= OUTSIDE_STRIPES_NOTABLE]
    if not notable:
        return {}
    shares = " and ".join(f"{_share_text(b)} for {risk.target_text(t)}" for t, b in notable)
    return {"shaking below the stripes": f"{shares} of λ_P at g* (the worst configuration) comes from shaking weaker than the lowest "
                                         f"stripe ({_lowest_stripe_text(risk)}), where the fitted fragility is extrapolated"}


def _measure_choice_blocks(name: str, risk: StoreRisk, choice: pd.DataFrame | None) -> list[Block]:
    """Which measure: the most efficient the site's hazard has per configuration, against the store's own, with the estimate's noise."""
    if choice is None or choice.empty or not choice.attrs.get("hazard_measures"):
        return []
    if choice.attrs["unjudged"]:
        return [Paragraph(f"Which measure: {choice.attrs['unjudged']}.")]
    measures, own = choice.attrs["hazard_measures"], choice.attrs["store_measure"]
    counts = choice["most efficient"].value_counts()
    best = ", ".join(f"{label} in {count} of {len(choice)} configurations" for label, count in counts.items())
    if own not in measures:
        verdict = f"The store is conditioned on {own}, a measure the site's hazard is not given in among these."
    elif measures == [own]:
        verdict = f"The site's hazard is given in the store's own measure, {own}, only: no other measure is compared with it."
    else:
        excess, noise, runs = risk.measure_margin(choice, own)
        if excess == 0.0:
            verdict = f"The store is conditioned on {own}, the most efficient in every configuration."
        else:
            within = excess <= 2.0 * noise
            verdict = (f"The store is conditioned on {own}, whose β exceeds the most efficient one's by up to {excess:.3f}: "
                       f"{'within' if within else 'beyond'} twice the standard error of one β estimate (about β/√(2(n − 2)) ≈ {noise:.3f} "
                       f"for the {runs} contact-free runs of a configuration)" + (", so these runs do not tell the two apart." if within else "."))
    text = (f"Which measure: β, the dispersion of ln(peak closure) given each measure the site's hazard is given in, over the contact-free "
            f"runs (a smaller β needs fewer motions for the same precision; stochpound.experiment.measure_choice): the most efficient is "
            f"{best}. {verdict} Of all candidates (PSA at the structure's own periods, PGV, Sa_avg), the most efficient is named per "
            "configuration in the table: a measure the site's hazard is not given in cannot carry the risk integral.")
    columns = ["where", *measures, "most efficient", "best candidate", "best β"]
    table = Table(f"risk-measure-{name}", f"Experiment {name}: β of ln(peak closure) given each measure, per configuration",
                  choice[columns].rename(columns={"where": "configuration"}).set_index("configuration"),
                  formats={**{m: "{:.3f}" for m in measures}, "best β": "{:.3f}"})
    return [Paragraph(text), table]


def _grid_note(risk: StoreRisk) -> str:
    """What the printed g* is exactly: where the non-increasing fit of λ_P(g) on the (refined) gap grid crosses the target, and
    how far the grid as first made would have put it."""
    gaps = risk.curve["gap"].values
    made = risk.grid or "log-spaced over the contact-free closures"
    change = risk.coarse_change()
    coarse = (f" Each gap's λ_P comes from its own fit of the same runs, so λ_P(g) is a step function of g (its steps at the runs' "
              f"closures), rough between neighbouring gaps: read off the grid as first made, before its refinement, interpolating "
              f"across those steps, g* differs from the value printed by up to {100 * change:.1f} % (largest over the configurations "
              "and targets)." if change == change else "")
    return (f"g* is interpolated on a grid of {gaps.size} gaps from {gaps[0]:.3g} to {gaps[-1]:.3g} m ({made}): it is where the "
            "non-increasing fit of ln λ_P along the gaps, an isotonic regression with each gap weighted by the share of ln g it "
            f"stands for, crosses the target, linearly in ln λ against ln g between the two gaps that bracket it.{coarse}")


def _panel_grid(count: int, height: float = 2.6) -> tuple[Figure, list[Any]]:
    columns = min(count, 2)
    rows = int(math.ceil(count / columns))
    figure = Figure(figsize=(7.5, height * rows), layout="constrained")
    return figure, list(np.atleast_1d(figure.subplots(rows, columns, squeeze=False)).ravel())


def _share_text(share: float) -> str:
    """A share in words: ``37 %``, or ``under 1 %``."""
    return "under 1 %" if share < 0.005 else f"{100.0 * share:.0f} %"


OUTSIDE_STRIPES_NOTABLE = 0.10
"""A share of λ_P at g* from below the lowest stripe from which the report says the answer rests on the extrapolation."""


def _risk_curve_figure(name: str, risk: StoreRisk) -> FigureItem:
    curve = risk.curve
    gaps = curve["gap"].values
    envelope = risk.non_increasing_maf()
    figure = Figure(figsize=(7.5, 4.2), layout="constrained")
    ax = figure.subplots()
    for labels in configurations(curve["maf"], ("gap",)):
        cell = curve.sel(labels)
        maf = envelope.sel(labels).values
        (line,) = ax.loglog(gaps, np.where(maf > 0, maf, np.nan), lw=1.4, label=labels_text(labels) or None)
        if "maf_lower" in cell:
            ax.fill_between(gaps, cell["maf_lower"].values, cell["maf_upper"].values, color=line.get_color(), alpha=0.12)
        for value in risk.separation["separation"].sel(labels).values:
            if np.isfinite(value):
                ax.axvline(value, color=line.get_color(), lw=0.6, ls=":")
    for p, rate, style in zip(risk.separation["target"].values, risk.separation["target_rate"].values, ("--", "-.", ":")):
        ax.axhline(float(rate), color="k", lw=0.8, ls=style, label=f"target: {risk.target_text(p)}")
    ax.set_ylim(figures.rate_limits(envelope.values, risk.separation["target_rate"].values))
    ax.set_xlabel("gap g (m)")
    ax.set_ylabel("λ_P: pounding per year")
    ax.grid(True, which="both", lw=0.3, color="0.85")
    ax.legend(fontsize=6)
    return FigureItem(f"risk-curve-{name}", f"Experiment {name}: the pounding risk curve λ_P(g) per configuration (made non-increasing "
                      f"along g) {_with_interval(risk, 'band', ' (shaded)')}, the targets (black) and g* (dotted verticals).",
                      figure)


def _surface_figure(name: str, risk: StoreRisk) -> FigureItem:
    gaps = risk.fragility["gap"].values
    levels = risk.im_axis()
    cells = configurations(risk.fragility["theta"], ("gap",))
    figure, axes = _panel_grid(len(cells))
    surface = risk.surface()
    mesh = None
    for ax, labels in zip(axes, cells):
        values = surface.sel(labels).transpose("gap", "im").values
        mesh = ax.pcolormesh(levels, gaps, values, vmin=0.0, vmax=1.0, cmap="viridis", shading="auto")
        ax.contour(levels, gaps, values, levels=[0.1, 0.5, 0.9], colors="w", linewidths=0.6)
        ax.set_yscale("log")
        ax.set_title(labels_text(labels) or name, fontsize=7)
        ax.set_xlabel(risk.setting.measure.axis_label(risk.setting.units), fontsize=7)
        ax.set_ylabel("gap (m)", fontsize=7)
        ax.tick_params(labelsize=6)
    for ax in axes[len(cells):]:
        ax.set_visible(False)
    if mesh is not None:
        figure.colorbar(mesh, ax=axes[:len(cells)], label="P(pounding | IM, gap)", shrink=0.8)
    return FigureItem(f"risk-surface-{name}", f"Experiment {name}: the fitted pounding fragility over (IM, gap), one panel per "
                      "configuration; white lines at 10, 50 and 90 %.", figure)


def _curves_figure(name: str, risk: StoreRisk) -> FigureItem:
    fragility = risk.fragility
    levels = risk.im_axis()
    cells = configurations(fragility["theta"], ("gap",))
    figure, axes = _panel_grid(len(cells))
    curves = risk.fragility_curves()
    shown = curves["gap"].values
    for ax, labels in zip(axes, cells):
        for gap in shown:
            cell = curves.sel(gap=gap).sel(labels)
            (line,) = ax.plot(levels, cell["fit"].values, lw=1.2, label=f"g = {gap:.3g} m")
            if "lower" in cell:
                ax.fill_between(levels, cell["lower"].values, cell["upper"].values, color=line.get_color(), alpha=0.15)
            if "probability" in fragility:
                points = fragility.sel(gap=gap).sel(labels)
                x = points["intensity"].values
                p = points["probability"].values
                ax.errorbar(x, p, yerr=[p - points["probability_lower"].values, points["probability_upper"].values - p], fmt="o",
                            ms=3, color=line.get_color(), capsize=2, lw=0.8)
        ax.set_title(labels_text(labels) or name, fontsize=7)
        ax.set_xlabel(risk.setting.measure.axis_label(risk.setting.units), fontsize=7)
        ax.set_ylabel("P(pounding)", fontsize=7)
        ax.set_ylim(-0.02, 1.02)
        ax.tick_params(labelsize=6)
        ax.grid(True, lw=0.3, color="0.85")
        ax.legend(fontsize=6)
    for ax in axes[len(cells):]:
        ax.set_visible(False)
    points = " with the stripes' empirical points and their Clopper–Pearson intervals" if "probability" in fragility else ""
    return FigureItem(f"risk-fragility-{name}", f"Experiment {name}: fitted pounding fragility at {len(shown)} gaps "
                      f"{_with_interval(risk, 'band', ' (shaded)')}{points}, one panel per configuration.", figure)


_RATE_FORMATS = {"once in (yr)": "{:.3g}", "once in, lower (yr)": "{:.3g}", "once in, upper (yr)": "{:.3g}", "P lower": "{:.3f}",
                 "P upper": "{:.3f}"}


def _rules_blocks(name: str, risk: StoreRisk) -> list[Block]:
    if risk.rules is None:
        return [Paragraph(f"Code rules in risk terms: not evaluated for experiment {name}: {risk.rules_note}.")]
    rules = risk.rules
    years = risk.years
    units = f" {risk.setting.units}" if risk.setting is not None else ""
    code = ", ".join(f"{100 * p:g} %/{years:g} yr: {float(c):.3g}{units} (stripe {float(s):g}{units})" for p, c, s in
                     zip(rules["design_level"].values, rules["code_intensity"].values, rules["stripe_intensity"].values))
    frame = risk.rules_frame()
    shortest, longest = risk.return_period_range()
    text = (
        f"Code rules in risk terms (experiment {name}): each suite-mean rule's gap is computed from the suite means of the stripe "
        f"nearest the code intensity (the hazard's intensities, and the stripes used: {code}); its risk is the mean annual frequency "
        f"of pounding at that gap, fitted over every stripe: 'this rule means pounding once in N years here'. Over the suite-mean "
        f"rules, levels and configurations, the return periods range from {shortest:.3g} to {longest:.3g} years."
    )
    dtm = risk.dtm_text()
    if dtm:
        text += f" {dtm}"
    text += " " + risk.design_rules_text()
    degenerate = risk.rules_degenerate_text()
    if degenerate:
        text += " Rule rows whose fit is not a lognormal (their 'fit' column): " + degenerate.removeprefix("Degenerate fits, not lognormals: ")
    table = Table(f"risk-rules-{name}", f"Experiment {name}: the code separation rules in risk terms: the gap at each contact, the "
                  f"mean annual frequency λ_P of pounding at it, the return period and the probability in {years:g} years, each "
                  f"{_with_interval(risk, 'interval')}, and the fragility's kind (a lognormal, a degenerate step, or flat where the "
                  "counts do not rise with intensity)", frame,
                  formats={**_RATE_FORMATS, "λ_P (1/yr)": "{:.3g}", "λ_P lower": "{:.3g}", "λ_P upper": "{:.3g}", f"P in {years:g} yr": "{:.3f}",
                           **{c: "{:.3f}" for c in frame.columns if str(c).startswith("gap")}})
    return [Paragraph(text), table]


def _demands_both_ways(name: str, risk: StoreRisk, demands: StoreDemands) -> list[Block]:
    """The demands with the runs beyond the model counted apart: which runs (per stripe), how, and each demand's level at the targets both ways."""
    per_stripe = "; ".join(f"{b} of {n} at stripe {level:.4g}" for level, b, n in demands.beyond_model_per_stripe())
    text = (f"Demands with collapses counted apart (FEMA P-58): runs whose peak storey drift ratio passes {100 * MODEL_DRIFT_LIMIT:g} % "
            f"are beyond what the model represents; per stripe over every configuration, {per_stripe}. Counted apart, P(C | IM) is a "
            "lognormal fitted over the stripes to them, each level's exceedance is fitted on the credible runs only, and the rate is "
            "λ(D > x) = ∫ [P(C | im) + (1 − P(C | im)) P(D > x | im, no C)] |dλ(im)|, a collapse counted as exceeding every level "
            "(the dashed curves). The table gives the level each demand exceeds at each target's rate both ways (inf: the collapses "
            "alone are more frequent than the target allows; –: already below the target at the curve's lowest level).")
    frame = demands.levels_at(risk.separation["target"].values, risk.years)
    values = [c for c in frame.columns if c in ("as run", "collapses apart")]
    index = [c for c in frame.columns if c not in values]
    table = Table(f"risk-demands-apart-{name}", f"Experiment {name}: the level each demand exceeds at the targets' rates, as run and "
                  "with the runs beyond the model counted apart as collapses", frame.set_index(index),
                  formats={c: "{:.3g}" for c in values})
    return [Paragraph(text), table]


def _demand_blocks(name: str, risk: StoreRisk, demands: StoreDemands | None) -> list[Block]:
    """Demand hazard curves of a stripes store: base displacement (and the moat walls' clearance), drift, floor acceleration."""
    if demands is None:
        return []
    figure, axes = _panel_grid(len(demands.curves), 2.5)
    for ax, (label, curve) in zip(axes, demands.curves.items()):
        levels = curve["level"].values
        envelope = demands.non_increasing_maf(label)
        apart = demands.non_increasing_apart(label) if label in demands.apart else None
        for labels in configurations(curve["maf"], ("level",)):
            maf = envelope.sel(labels).values
            (line,) = ax.loglog(levels, np.where(maf > 0, maf, np.nan), lw=1.1, label=labels_text(labels) or None)
            if apart is not None:
                counted = apart.sel(labels).values
                ax.loglog(levels, np.where(counted > 0, counted, np.nan), lw=0.9, ls="--", color=line.get_color())
        ax.set_ylim(figures.rate_limits(envelope.values))
        ax.xaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
        ax.xaxis.set_minor_formatter(NullFormatter())  # labels on 1-2-5 only: the minor ones overlapped on short axes
        ax.set_title(label, fontsize=7)
        ax.set_xlabel(f"{label} ({demands.units[label]})", fontsize=7)
        ax.set_ylabel("exceedances per year", fontsize=7)
        ax.tick_params(labelsize=6)
        ax.grid(True, which="both", lw=0.3, color="0.85")
    for ax in axes[len(demands.curves):]:
        ax.set_visible(False)
    if axes[0].get_legend_handles_labels()[1]:
        axes[0].legend(fontsize=5)
    walled = ("; with a moat wall, the base displacement is the walled runs', capped near the wall's clearance (their only impacts "
              "are on the wall)") if demands.moat is not None else ""
    dashed = "; dashed: the runs beyond the model counted apart as collapses (below)" if demands.apart else ""
    blocks: list[Block] = [FigureItem(f"risk-demands-{name}", f"Experiment {name}: demand hazard curves (mean annual frequency of "
                                      "exceeding each level, a lognormal fragility fitted at every level over the stripes' "
                                      "contact-free runs (a step, or flat, where the runs identify no lognormal) and integrated with the "
                                      f"hazard, made non-increasing along the level), per configuration{walled}{dashed}.", figure)]
    if demands.apart:
        blocks += _demands_both_ways(name, risk, demands)
    if demands.moat is not None:
        blocks.append(Table(f"risk-moat-{name}", f"Experiment {name}: moat-wall contact as a limit state: the mean annual frequency with "
                            "which the studied building's base reaches the moat wall's clearance (peak base displacement ≥ clearance; "
                            "before the first wall impact a run with the wall equals the run without; in a configuration without the "
                            "wall, the rate its base passes that clearance, where no stop is modelled: 'what it is'), "
                            f"{_with_interval(risk, 'interval', ' (of the return period and the probability too)')}", demands.moat_frame(),
                            formats={**_RATE_FORMATS, "λ (1/yr)": "{:.3g}", "λ lower": "{:.3g}", "λ upper": "{:.3g}",
                                     f"P in {demands.years:g} yr": "{:.3f}"}))
    return blocks
