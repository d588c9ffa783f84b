"""The "Separation" section of a report: how wide the gap must be, from a store's contact-free cases.

A store has contact-free cases when every gap axis of its grid holds ``inf``
(docs/separation.md). Before its first impact a run with gap g is the
contact-free run, so a case pounds at gap g exactly when its contact-free
twin's peak closure D reaches g. For each synthetic ensemble of the store the
section draws, per grid cell (μ, neighbour, …):

* the pounding curve P(D ≥ g) against g with its Clopper–Pearson band, and
  the probability of pounding of the same store's runs at its finite gaps
  (the identity checked on the data, in a sentence);
* the separation needed for target probabilities of pounding, with
  order-statistic intervals, as a table and against the probability;
* each separation rule's gap (ABS, SRSS, 0.7·SRSS, DDC) evaluated per
  realization and the probability that it is reached.

For records (one realization each), a table gives D and every rule's gap per
cell. Every sentence is computed from the store.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import xarray as xr

from stochpound.analysis import pounding_curve, pounding_probability, required_separation, rule_exceedance, separation_rules, store_contact_demands
from stochpound.report.render import _figures as figures
from stochpound.report.render._document import Block, FigureItem, Paragraph, Section, Table
from stochpound.report.sections._ensemble_findings import RARE, rare_gap
from stochpound.report.sections._ensembles import Ensemble, line_label, lines, table_frame
from stochpound.experiment._selections import contact_free, gap_dims, isolated_mus, with_contacts
from stochpound.report.sections._facets import dim_text, labels_text, value_text

CM = 100.0
RULE_TEXT = {
    "abs": "ABS (u1 + u2)",
    "srss": "SRSS (√(u1² + u2²), ASCE 7's δ_MT)",
    "srss_reduced": "0.7·SRSS (Eurocode 8, floor levels coinciding)",
    "ddc": "DDC (√(u1² + u2² − 2ρ u1 u2), ρ from the histories)",
}
#: Target probabilities of the separation-against-probability figure.
CURVE_PROBABILITIES = tuple(np.round(np.geomspace(0.005, 0.9, 31), 5))


def separation_section(name: str, store: xr.Dataset) -> Section:
    """The "Separation" section of one store (call when :func:`stochpound.experiment._selections.has_contact_free`)."""
    free = contact_free(store)
    section = Section(f"Separation: experiment {name}", key=f"separation-{name}")
    section.add(_method_paragraph(store))
    kinds = dict(zip(store["record"].values.tolist(), store["record_kind"].values.tolist()))
    records = [label for label, kind in kinds.items() if kind != "synthetic"]
    if records:
        section.add(_record_table(name, free.sel(record=records).isel(realization=0, drop=True)))
    for label in (label for label, kind in kinds.items() if kind == "synthetic"):
        for block in SeparationEnsemble(name, store, label).blocks():
            section.add(block)
    return section


def _method_paragraph(store: xr.Dataset) -> Paragraph:
    contacts = store.sizes.get("contact", 0)
    axes = ", ".join(gap_dims(store))
    sliding = "mu" in store.dims and bool(isolated_mus(store["mu"].values))
    text = (
        f"The grid's gap axis ({axes}) holds ∞: those cases ran contact-free, every contact open throughout. Before its first "
        f"impact a run with gap g is the contact-free run, so it pounds at gap g exactly when the contact-free run's peak "
        f"closure D (the largest y_left − y_right over the run, located on the solution"
        f"{', and over the ' + str(contacts) + ' contacts' if contacts > 1 else ''}) reaches g. One contact-free ensemble thus "
        f"gives P(pounding | g) = P(D ≥ g) at every gap at once. The separation rules are applied per realization to the "
        f"same runs: u1 and u2 are the peak displacements relative to the ground of the two floors a contact joins, located "
        f"on the solution like D (so ABS = u1 + u2 ≥ D in every run), ρ the correlation of their histories."
    )
    if sliding:
        text += (
            " The store has sliding bases. For an isolated building, ASCE 7 (§17.2.5.2) asks for a separation from adjacent "
            "structures of at least its total maximum displacement D_TM, a bound like ABS rather than a combination of peaks; "
            "SRSS and DDC combine the peaks of linear, fixed-base buildings, whose derivation does not hold for a sliding base. "
            "For the isolated cases they are applied here as a designer would, to the total displacements (sliding included), "
            "and judged by the probability of pounding they leave."
        )
    return Paragraph(text)


def _rule_gaps(free: xr.Dataset) -> xr.DataArray:
    """Each rule's gap per case, the largest over contacts (m)."""
    return separation_rules(store_contact_demands(free)).max("contact")


def _record_table(name: str, free: xr.Dataset) -> Table:
    """Per record cell: D and every rule's gap (cm)."""
    dims = [d for d in free["case_status"].dims]
    columns = {("D, separation needed", "cm"): free["peak_contact_closure"].max("contact") * CM}
    rules = _rule_gaps(free)
    for rule in rules["rule"].values:
        columns[(RULE_TEXT[str(rule)], "cm")] = rules.sel(rule=rule, drop=True) * CM
    return Table(
        key=f"table-{name}-separation-records",
        caption=f"Experiment {name}, records: the separation each record needed (D of its contact-free run) and the gap each rule asks for.",
        frame=table_frame(columns, dims),
        note="A record pounds at any gap up to D; a rule's gap below D would have let it pound.",
        per_cell=True,
    )


class SeparationEnsemble:
    """The contact-free cells of one synthetic ensemble and the separation they call for."""

    def __init__(self, name: str, store: xr.Dataset, label: str, confidence: float = 0.95) -> None:
        self.ensemble = Ensemble(name, contact_free(store), label, confidence)
        self.name, self.label, self.confidence = name, label, confidence
        self.demand = self.ensemble.data["peak_contact_closure"].load().max("contact", skipna=False)
        # the runs at the grid's finite gaps, compared with D when one gap axis sets every gap
        axes = gap_dims(store)
        finite = store[axes[0]].values[np.isfinite(store[axes[0]].values)] if len(axes) == 1 else []
        self.gap_axis = axes[0] if len(finite) else None
        self.impacts = Ensemble(name, with_contacts(store), label, confidence).data["impacts"].load() if self.gap_axis else None

    def blocks(self) -> list[Block]:
        """Findings, tables and figures, in reading order."""
        rules = _rule_gaps(self.ensemble.data).load()
        exceedance = rule_exceedance(self.demand, rules, confidence=self.confidence, contact_dim=None).compute()
        needed = required_separation(self.demand, confidence=self.confidence, contact_dim=None).compute()
        return [
            *self._identity_check(),
            self._findings(needed, exceedance),
            self._separation_table(needed),
            self._rule_table(rules, exceedance),
            *self._curve_figures(),
            *self._separation_figures(),
        ]

    # ------------------------------------------------------------ text

    def _identity_check(self) -> list[Block]:
        """Runs at the store's finite gaps against the contact-free closures of the same realizations."""
        if self.gap_axis is None:
            return []
        axis, impacts = self.gap_axis, self.impacts
        pounded = (impacts > 0).where(impacts.notnull())
        gaps = xr.DataArray(impacts[axis].values, dims=axis)
        reached = (self.demand >= gaps).where(self.demand.notnull())
        both = pounded.notnull() & reached.notnull()
        ties = both & (abs(self.demand - gaps) <= 1e-9)
        compared = int((both & ~ties).sum())
        disagree = int(((pounded != reached) & both & ~ties).sum())
        text = (
            f"Checked on this store: at its {gaps.size} finite gap(s) ({', '.join(value_text(axis, g) for g in gaps.values)}), "
            f"{compared} runs with contacts were compared with the contact-free run of the same cell and realization; "
        )
        text += "every one pounds exactly when D ≥ g." if disagree == 0 else f"{disagree} of them disagree with D ≥ g (see docs/separation.md for the assumption)."
        if int(ties.sum()):
            text += f" {int(ties.sum())} runs with D within 1e-9 m of g are not counted."
        return [Paragraph(text)]

    def _findings(self, needed: xr.Dataset, exceedance: xr.Dataset) -> Paragraph:
        p = 0.05 if 0.05 in needed["probability"].values else float(needed["probability"].values[0])
        separation = needed["separation"].sel(probability=p)
        low, high = _extreme_cells(separation)
        n = int(needed["realizations"].min())
        text = (
            f"With {n}{'' if n == int(needed['realizations'].max()) else '–' + str(int(needed['realizations'].max()))} contact-free realizations per cell, "
            f"a {p:.0%} probability of pounding needs a gap of {_cm(separation.sel(low))} ({labels_text(low) or 'the one cell'})"
        )
        if high != low:
            text += f" up to {_cm(separation.sel(high))} ({labels_text(high)})"
        text += ". "
        text += self._grid_answer(needed, p)
        sentences = []
        for rule in exceedance["rule"].values:
            probability = exceedance["probability"].sel(rule=rule)
            lo, hi = float(probability.min()), float(probability.max())
            share = float((exceedance["upper"].sel(rule=rule) <= p).mean())
            if rule == "abs" and hi == 0.0:
                sentences.append("ABS is never reached (it bounds D by construction)")
                continue
            sentences.append(
                f"{RULE_TEXT[str(rule)].split(' (')[0]} is reached with probability {lo:.3f}" + (f" to {hi:.3f}" if hi > lo else "")
                + f" (upper bound ≤ {p:.0%} in {share:.0%} of the cells)"
            )
        text += "Separated by a rule's gap, the buildings pound: " + "; ".join(sentences) + "."
        return Paragraph(text)

    def _grid_answer(self, needed: xr.Dataset, p: float) -> str:
        """How the answer from the grid's own gaps (the experiment section's "rare" gap) relates to the contact-free quantile at ``p``."""
        if self.gap_axis is None or p != RARE:
            return ""
        upper = pounding_probability(self.impacts, confidence=self.confidence)["upper"].compute()
        grid = rare_gap(upper, self.gap_axis)
        estimate, bound = needed["separation"].sel(probability=p), needed["upper"].sel(probability=p)
        known = grid.notnull()
        cells = int(known.size)
        if not bool(known.any()):
            return (
                f"On the grid's own gaps (the experiment's section) the same question has no answer: no gap of the grid brings "
                f"the upper {self.confidence:.0%} bound of P(pounding) below {RARE:.0%}. "
            )
        above = int((known & (grid >= estimate)).sum())
        above_bound = int((known & (grid >= bound)).sum())
        return (
            f"The experiment's section answers the same question on the grid's own gaps: the smallest gap of the grid from which "
            f"on the upper {self.confidence:.0%} bound of P(pounding) is below {RARE:.0%}, {span_cm(grid)} in {int(known.sum())} of "
            f"{cells} cells. That answer can only name a gap of the grid, and asks the bound, not the estimate, to be below "
            f"{RARE:.0%}: it is at or above the estimate here in {above} of those cells and at or above its upper bound in "
            f"{above_bound}; the quantile of D gives the gap between the grid's gaps (estimate {span_cm(estimate)}, upper "
            f"bound {span_cm(bound)}). "
        )

    # ------------------------------------------------------------ tables

    def _separation_table(self, needed: xr.Dataset) -> Table:
        columns: dict[tuple[str, str], xr.DataArray] = {("realizations", "n"): needed["realizations"]}
        for p in needed["probability"].values:
            head = f"gap for P(pounding) = {p:g} (cm)"
            for part, variable in (("estimate", "separation"), ("lower", "lower"), ("upper", "upper")):
                columns[(head, part)] = needed[variable].sel(probability=p, drop=True) * CM
        return Table(
            key=f"table-{self.name}-{self.label}-separation",
            caption=f"Experiment {self.name}, ensemble {self.label}: the gap needed for each target probability of pounding (the 1 − p quantile of D).",
            frame=table_frame(columns, list(self.ensemble.grid)),
            note=(
                f"Distribution-free {self.confidence:.0%} intervals from order statistics; a bound is empty when the sample "
                f"is too small to give it (the lower bound of p needs pⁿ < {(1 - self.confidence) / 2:g})."
            ),
            per_cell=True,
        )

    def _rule_table(self, rules: xr.DataArray, exceedance: xr.Dataset) -> Table:
        columns: dict[tuple[str, str], xr.DataArray] = {("realizations", "n"): exceedance["realizations"].isel(rule=0, drop=True)}
        for rule in rules["rule"].values:
            head = RULE_TEXT[str(rule)].split(" (")[0]
            columns[(head, "mean gap (cm)")] = rules.sel(rule=rule, drop=True).mean("realization") * CM
            for part in ("probability", "lower", "upper"):
                columns[(head, "P" if part == "probability" else part)] = exceedance[part].sel(rule=rule, drop=True)
        return Table(
            key=f"table-{self.name}-{self.label}-separation-rules",
            caption=(
                f"Experiment {self.name}, ensemble {self.label}: each separation rule's gap, evaluated per realization, and the "
                f"probability that buildings separated by it pound (P(D ≥ the rule's gap), {self.confidence:.0%} Clopper–Pearson interval)."
            ),
            frame=table_frame(columns, list(self.ensemble.grid)),
            note="; ".join(f"{k}: {v}" for k, v in RULE_TEXT.items() if k in rules["rule"].values) + ". A rule's gap is the largest over the contacts.",
            per_cell=True,
        )

    # ------------------------------------------------------------ figures

    def _curve_figures(self) -> list[FigureItem]:
        """P(D ≥ g) against g, and the store's runs at its finite gaps as markers."""
        ensemble = self.ensemble
        finite = self.demand.values[np.isfinite(self.demand.values)]
        top = float(np.quantile(finite, 0.995)) if finite.size else 0.1  # the far tail of one cell would squeeze the others
        gaps = np.linspace(0.0, 1.05 * top, 211)
        curve = pounding_curve(self.demand, gaps, confidence=self.confidence, contact_dim=None).compute()
        axis = self.gap_axis
        direct = pounding_probability(self.impacts, confidence=self.confidence)["probability"].compute() if axis else None
        line_dim = ensemble.line_dim()

        def curves(panel: dict[str, Any]) -> list[figures.Curve]:
            result = []
            for value, colour in lines(ensemble.grid, line_dim):
                where = {**panel, **({line_dim: value} if line_dim else {})}
                cell = curve.sel(where)
                result.append(figures.Curve(line_label(line_dim, value), gaps * CM, cell["probability"].values, cell["lower"].values, cell["upper"].values, colour, gid=ensemble.gid(where)))
                if direct is not None:
                    runs = direct.sel(where)
                    result.append(figures.Curve(
                        "runs at the grid's gaps (squares)",
                        runs[axis].values * CM, runs.values, color=colour, style="none", marker="s", gid=ensemble.gid(where),
                    ))
            return result

        what = (
            f"the pounding curve P(D ≥ g) from the contact-free runs, with its {self.confidence:.0%} Clopper–Pearson band, up to the 99.5 % quantile of D over all cells"
            + ("; squares: the fraction of the store's runs at its finite gaps that pounded (same realizations)" if direct is not None else "")
        )
        return ensemble.facet_figures("separation-curve", [line_dim], curves, "gap g (cm)", "P(pounding)", what, title="pounding curve", y_limits=(-0.03, 1.03), legend_title=dim_text(line_dim) if line_dim else "")

    def _separation_figures(self) -> list[FigureItem]:
        """The separation needed against the target probability (log axis), with its interval."""
        ensemble = self.ensemble
        usable = [p for p in CURVE_PROBABILITIES if p >= 1.0 / max(ensemble.size, 1)]
        needed = required_separation(self.demand, usable, confidence=self.confidence, contact_dim=None).compute()
        line_dim = ensemble.line_dim()

        def curves(panel: dict[str, Any]) -> list[figures.Curve]:
            result = []
            for value, colour in lines(ensemble.grid, line_dim):
                where = {**panel, **({line_dim: value} if line_dim else {})}
                cell = needed.sel(where)
                result.append(figures.Curve(line_label(line_dim, value), np.asarray(usable), cell["separation"].values * CM, cell["lower"].values * CM, cell["upper"].values * CM, colour, gid=ensemble.gid(where)))
            return result

        what = f"the gap needed for a target probability of pounding p (the 1 − p quantile of D), with its {self.confidence:.0%} order-statistic band (empty where the sample is too small)"
        return ensemble.facet_figures("separation-needed", [line_dim], curves, "probability of pounding p", "gap needed (cm)", what, title="separation needed", log_x=True, legend_title=dim_text(line_dim) if line_dim else "")


def _extreme_cells(values: xr.DataArray) -> tuple[dict[str, Any], dict[str, Any]]:
    """Labels of the cells with the smallest and largest value (NaN ignored)."""
    flat = values.stack(cell=values.dims) if values.dims else values.expand_dims(cell=[0])
    order = np.argsort(np.where(np.isnan(flat.values), np.inf, flat.values))
    finite = [i for i in order if np.isfinite(flat.values[i])] or [int(order[0])]

    def labels(i: int) -> dict[str, Any]:
        return {d: flat[d].values[i].item() for d in values.dims}

    return labels(finite[0]), labels(finite[-1])


def span_cm(values: xr.DataArray) -> str:
    """The range of ``values`` (m) in cm, NaN ignored ("—" if none)."""
    finite = values.values[np.isfinite(values.values)]
    if not finite.size:
        return "—"
    low, high = finite.min() * CM, finite.max() * CM
    return f"{low:.1f} cm" if f"{low:.1f}" == f"{high:.1f}" else f"{low:.1f}–{high:.1f} cm"


def _cm(value: xr.DataArray) -> str:
    number = float(value)
    return "—" if math.isnan(number) else f"{number * CM:.1f} cm"
