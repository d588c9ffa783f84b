"""The "Separation" section of a report: how wide the gap must be, from a store's contact-free (or wall-free) cases.

A store has contact-free cases when every gap axis of its grid that sets
contacts holds ``inf`` (docs/separation.md). Before its first impact a run
with gap g is the contact-free run, so a case pounds at gap g exactly when
its contact-free twin's peak closure D reaches g. The same holds for a gap
axis that sets walls only (a moat's clearance c, :data:`WALLS`): its
wall-free (``inf``) runs give P(wall hit | c) = P(D ≥ c), D the largest
closure toward a wall (``largest_wall_closure``). For each synthetic
ensemble of the store the section draws, per grid cell (μ, neighbour, …):

* the pounding curve P(D ≥ g) against g with its Clopper–Pearson band, and
  the probability of pounding of the same store's runs at its finite gaps
  (the identity checked on the data, in a sentence);
* the separation needed for target probabilities of pounding, with
  order-statistic intervals, as a table and against the probability;
* between buildings, each separation rule's gap (ABS, SRSS, 0.7·SRSS, DDC)
  evaluated per realization and the probability that it is reached.

For records (one realization each), a table gives D (and every rule's gap)
per cell. Every sentence is computed from the store.
"""

from __future__ import annotations

import math

import numpy as np
import xarray as xr

from stochpound._plurals import counted
from stochpound.analysis import CONTACTS, RARE, CellLabels, Closure, Needed, StoreSeparation, ValueRange
from stochpound.report.render import figures
from stochpound.report.render import Block, FigureItem, Paragraph, Section, Table
from stochpound.report.sections._ensembles import Ensemble, line_label, lines, table_frame
from stochpound.store import contact_gap_dims, isolated_mus, wall_gap_dims
from stochpound.report.sections._facets import dim_text, labels_text, value_text

CM = 100.0
RULE_TEXT = {
    "abs": "ABS (u1 + u2)",
    "srss": "SRSS (√(u1² + u2²), ASCE 7's δ_MT)",
    "srss_reduced": "0.7·SRSS (Eurocode 8, floor levels coinciding)",
    "ddc": "DDC (√(u1² + u2² − 2ρ u1 u2), ρ from the histories)",
}
#: Target probabilities of a wall hit whose clearance the findings state (among the table's).
WALL_TARGETS = (0.05, 0.01)


def separation_section(name: str, store: xr.Dataset, closure: Closure = CONTACTS) -> Section:
    """The "Separation" section of one store (call when :func:`stochpound.store.has_contact_free`, or with
    :data:`WALLS` when :func:`~stochpound.store.has_wall_free`)."""
    free = closure.free_cases(store)
    title, key = (f"Moat clearance: experiment {name}", f"clearance-{name}") if closure.walls else (f"Separation: experiment {name}", f"separation-{name}")
    section = Section(title, key=key)
    section.add(_wall_method_paragraph(store) if closure.walls else _method_paragraph(store))
    kinds = dict(zip(store["record"].values.tolist(), store["record_kind"].values.tolist()))
    records = [label for label, kind in kinds.items() if kind != "synthetic"]
    if records:
        section.add(_record_table(name, free.sel(record=records).isel(realization=0, drop=True), closure))
    for label in (label for label, kind in kinds.items() if kind == "synthetic"):
        for block in SeparationEnsemble(name, store, label, closure=closure).blocks():
            section.add(block)
    return section


def _wall_method_paragraph(store: xr.Dataset) -> Paragraph:
    axes = ", ".join(wall_gap_dims(store))
    return Paragraph(
        f"The moat's clearance c, the grid's gap axis over the walls ({axes}), holds ∞: those runs ran wall-free, their walls never "
        "reached, but the closure toward each wall (the studied level's displacement toward it) is located on the solution. "
        "Before its first wall impact a run at clearance c is the wall-free run, so it hits a wall at clearance c exactly when the "
        "wall-free run's peak closure D (the largest over the run and over the walls, store variable largest_wall_closure) "
        "reaches c. One wall-free ensemble thus gives P(wall hit | c) = P(D ≥ c) at every clearance at once, and the clearance "
        "needed for a target probability p, the 1 − p quantile of D."
    )


def _method_paragraph(store: xr.Dataset) -> Paragraph:
    contacts = store.sizes.get("contact", 0)
    axes = ", ".join(contact_gap_dims(store))
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
            " The store has sliding bases. ASCE 7 (§17.2.5.2) asks for a separation of at least the total maximum displacement "
            "D_TM between an isolated structure and the retaining walls or other fixed obstructions around it; it gives no "
            "combination rule for a neighbour that moves too, and taking D_TM there is a bound on the isolated side alone; "
            "SRSS and DDC combine the peaks of linear, fixed-base buildings, whose derivation does not hold for a sliding base. "
            "For the isolated cases they are applied here as a designer would, to the total displacements (sliding included), "
            "and judged by the probability of pounding they leave."
        )
    return Paragraph(text)


def _record_table(name: str, free: xr.Dataset, closure: Closure) -> Table:
    """Per record cell: D and every rule's gap (cm; between buildings only)."""
    dims = [d for d in free["case_status"].dims]
    columns = {(f"D, {'clearance' if closure.walls else 'separation'} needed", "cm"): closure.demand(free) * CM}
    if closure.walls:
        return Table(
            key=f"table-{name}-clearance-records",
            caption=f"Experiment {name}, records: the clearance each record needed (D of its wall-free run).",
            frame=table_frame(columns, dims),
            note="A record hits a wall at any clearance up to D.",
            per_cell=True,
        )
    rules = StoreSeparation.rule_gaps_of(free)
    for rule in rules["rule"].values:
        columns[(RULE_TEXT[str(rule)], "cm")] = rules.sel(rule=rule, drop=True) * CM
    return Table(
        key=f"table-{name}-separation-records",
        caption=f"Experiment {name}, records: the separation each record needed (D of its contact-free run) and the gap each rule asks for.",
        frame=table_frame(columns, dims),
        note="A record pounds at any gap up to D; a rule's gap below D would have let it pound.",
        per_cell=True,
    )


class SeparationEnsemble(StoreSeparation):
    """The separation (clearance) one synthetic ensemble calls for (:class:`stochpound.analysis.StoreSeparation`), as the report shows it."""

    def __init__(self, name: str, store: xr.Dataset, label: str, confidence: float = 0.95, closure: Closure = CONTACTS) -> None:
        super().__init__(name, store, label, confidence, closure)
        self.ensemble = Ensemble(name, closure.free_cases(store), label, confidence)

    def blocks(self) -> list[Block]:
        """Findings, tables and figures, in reading order."""
        needed = self.needed()
        if self.closure.walls:
            return [*self._identity_check(), self._wall_findings(needed), self._separation_table(needed), *self._curve_figures(), *self._separation_figures()]
        rules = self.rule_gaps()
        exceedance = self.exceedance(rules)
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
        """Runs at the store's finite gaps against the contact-free (wall-free) closures of the same realizations."""
        check = self.identity_check()
        if check is None:
            return []
        c, axis = self.closure, self.gap_axis
        compared, disagree, gaps = check.compared, check.disagree, check.gaps
        text = (
            f"Checked on this store: at its {gaps.size} finite {c.gap}(s) ({', '.join(value_text(axis, g) for g in gaps)}), "
            f"{compared} runs with {'walls' if c.walls else 'contacts'} were compared with the {c.free} run of the same cell and realization; "
        )
        closes = "hits a wall" if c.walls else "pounds"
        text += (f"every one {closes} exactly when D ≥ {c.symbol}." if disagree == 0
                 else f"{disagree} of them disagree with D ≥ {c.symbol} (see docs/separation.md for the assumption).")
        if check.ties:
            text += f" {counted(check.ties, 'run')} with D within 1e-9 m of {c.symbol} {'is' if check.ties == 1 else 'are'} not counted."
        return [Paragraph(text)]

    def _findings(self, needed: Needed, exceedance: xr.Dataset) -> Paragraph:
        p = 0.05 if 0.05 in needed["probability"].values else float(needed["probability"].values[0])
        separation = needed["separation"].sel(probability=p)
        low, high = needed.extreme_cells(p)
        n = needed.fewest_runs
        text = (
            f"With {n}{'' if n == needed.most_runs else '–' + str(needed.most_runs)} contact-free realizations per cell, "
            f"a {p:.0%} probability of pounding needs a gap of {_cm(separation.sel(low))} ({labels_text(low) or 'the one cell'})"
        )
        if high != low:
            text += f" up to {_cm(separation.sel(high))} ({labels_text(high)})"
        text += ". "
        text += self._grid_answer(needed, p)
        sentences = []
        for reach in self.rule_reach(exceedance, p):
            rule, lo, hi, share = reach.rule, reach.lowest, reach.highest, reach.share_within
            if rule == "abs" and hi == 0.0:
                sentences.append("ABS is never reached (it bounds D by construction)")
                continue
            sentences.append(
                f"{RULE_TEXT[rule].split(' (')[0]} is reached with probability {lo:.3f}" + (f" to {hi:.3f}" if hi > lo else "")
                + (f" (upper bound ≤ {p:.0%} in {share:.0%} of the cells)" if needed.cells > 1
                   else f" (its upper bound {'at or below' if share else 'above'} {p:.0%})")
            )
        text += "Separated by a rule's gap, the buildings pound: " + "; ".join(sentences) + "."
        return Paragraph(text)

    def _wall_findings(self, needed: Needed) -> Paragraph:
        """P(wall hit) at the grid's clearances from the wall-free runs against the runs there, and the clearance for each target."""
        text = f"With {needed.fewest_runs} wall-free realizations per cell: "
        if self.gap_axis is not None:
            clearances = self.impacts[self.gap_axis].values
            curve = self.curve_at_grid()
            inside, cells = self.curve_agreement()
            text += (
                f"P(wall hit | c) = P(D ≥ c) is {'; '.join(f'{value_text(self.gap_axis, c)}: {span(curve.probability.sel({self.gap_axis: c}))}' for c in clearances)} "
                f"over the cells; the runs at those clearances hit a wall in a fraction within its {self.confidence:.0%} Clopper–Pearson "
                f"interval in {inside} of {counted(cells, 'cell')}. "
            )
        for p in WALL_TARGETS:
            separation = needed["separation"].sel(probability=p)
            low, high = needed.extreme_cells(p)
            text += f"P(wall hit) = {p:.0%} needs a clearance of {_cm(separation.sel(low))} ({labels_text(low) or 'the one cell'})"
            if high != low:
                text += f" up to {_cm(separation.sel(high))} ({labels_text(high)})"
            text += f", upper {self.confidence:.0%} bound {span_cm(needed['upper'].sel(probability=p))}. "
        return Paragraph(text.strip())

    def _grid_answer(self, needed: Needed, p: float) -> str:
        """How the answer from the grid's own gaps (the experiment section's "rare" gap) relates to the contact-free quantile at ``p``."""
        rare = self.grid_rare(needed, p)
        if rare is None:
            return ""
        grid, above, above_bound, cells = rare.gap, rare.above_estimate, rare.above_bound, rare.cells
        estimate, bound = needed["separation"].sel(probability=p), needed["upper"].sel(probability=p)
        if not rare.known:
            return (
                f"On the grid's own gaps (the experiment's section) the same question has no answer: no gap of the grid brings "
                f"the upper {self.confidence:.0%} bound of P(pounding) below {RARE:.0%}. "
            )
        return (
            f"The experiment's section answers the same question on the grid's own gaps: the smallest gap of the grid from which "
            f"on the upper {self.confidence:.0%} bound of P(pounding) is below {RARE:.0%}, {span_cm(grid)} in {rare.known} of "
            f"{counted(cells, 'cell')}. That answer can only name a gap of the grid, and asks the bound, not the estimate, to be below "
            f"{RARE:.0%}: it is at or above the estimate here in {above} of those cells and at or above its upper bound in "
            f"{above_bound}; the quantile of D gives the gap between the grid's gaps (estimate {span_cm(estimate)}, upper "
            f"bound {span_cm(bound)}). "
        )

    # ------------------------------------------------------------ tables

    def _separation_table(self, needed: Needed) -> Table:
        columns: dict[tuple[str, str], xr.DataArray] = {("realizations", "n"): needed["realizations"]}
        for p in needed["probability"].values:
            head = f"{self.closure.gap} for P({self.closure.event}) = {p:g} (cm)"
            for part, variable in (("estimate", "separation"), ("lower", "lower"), ("upper", "upper")):
                columns[(head, part)] = needed[variable].sel(probability=p, drop=True) * CM
        return Table(
            key=f"table-{self.name}-{self.label}-{'clearance' if self.closure.walls else 'separation'}",
            caption=(f"Experiment {self.name}, ensemble {self.label}: the {self.closure.gap} needed for each target probability of "
                     f"{'a wall hit' if self.closure.walls else 'pounding'} (the 1 − p quantile of D)."),
            frame=table_frame(columns, list(self.ensemble.grid)),
            note=(
                f"Distribution-free {self.confidence:.0%} intervals from order statistics; a bound is empty when the sample "
                f"of n runs is too small to give it: the upper bound needs (1 − p)ⁿ ≤ {(1 - self.confidence) / 2:g}, the lower "
                f"bound pⁿ ≤ {(1 - self.confidence) / 2:g}."
            ),
            per_cell=True,
        )

    def _rule_table(self, rules: xr.DataArray, exceedance: xr.Dataset) -> Table:
        columns: dict[tuple[str, str], xr.DataArray] = {("realizations", "n"): exceedance["realizations"].isel(rule=0, drop=True)}
        for rule in rules["rule"].values:
            head = RULE_TEXT[str(rule)].split(" (")[0]
            columns[(head, "mean gap (cm)")] = self.mean_rule_gaps(rules).sel(rule=rule, drop=True) * CM
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
        gaps = self.curve_gaps()
        curve = self.curve(gaps)
        axis = self.gap_axis
        direct = self.hit_probability()["probability"] if axis else None
        c = self.closure
        line_dim = ensemble.line_dim()

        def curves(panel: CellLabels) -> list[figures.Curve]:
            result = []
            for value, colour in lines(ensemble.grid, line_dim):
                where = {**panel, **({line_dim: value} if line_dim else {})}
                cell = curve.sel(where)
                result.append(figures.Curve(line_label(line_dim, value), gaps * CM, cell["probability"].values, cell["lower"].values, cell["upper"].values, colour, gid=ensemble.gid(where)))
                if direct is not None:
                    runs = direct.sel(where)
                    result.append(figures.Curve(
                        f"runs at the grid's {c.gap}s (squares)",
                        runs[axis].values * CM, runs.values, color=colour, style="none", marker="s", gid=ensemble.gid(where),
                    ))
            return result

        what = (
            f"the {'wall-hit' if c.walls else 'pounding'} curve P(D ≥ {c.symbol}) from the {c.free} runs, with its {self.confidence:.0%} "
            "Clopper–Pearson band, up to the 99.5 % quantile of D over all cells"
            + (f"; squares: the fraction of the store's runs at its finite {c.gap}s that {'hit a wall' if c.walls else 'pounded'} (same realizations)"
               if direct is not None else "")
        )
        return ensemble.facet_figures(f"{'clearance' if c.walls else 'separation'}-curve", [line_dim], curves, f"{c.gap} {c.symbol} (cm)", f"P({c.event})", what,
                                      title=f"{'wall-hit' if c.walls else 'pounding'} curve", y_limits=(-0.03, 1.03), legend_title=dim_text(line_dim) if line_dim else "")

    def _separation_figures(self) -> list[FigureItem]:
        """The separation needed against the target probability (log axis), with its interval."""
        ensemble = self.ensemble
        usable = self.curve_probabilities()
        needed = self.needed(usable).data
        line_dim = ensemble.line_dim()

        def curves(panel: CellLabels) -> list[figures.Curve]:
            result = []
            for value, colour in lines(ensemble.grid, line_dim):
                where = {**panel, **({line_dim: value} if line_dim else {})}
                cell = needed.sel(where)
                result.append(figures.Curve(line_label(line_dim, value), np.asarray(usable), cell["separation"].values * CM,
                                            cell["lower"].values * CM, cell["upper"].values * CM, colour, gid=ensemble.gid(where)))
            return result

        c = self.closure
        event = "a wall hit" if c.walls else "pounding"
        what = (f"the {c.gap} needed for a target probability of {event} p (the 1 − p quantile of D), with its {self.confidence:.0%} "
                "order-statistic band (empty where the sample is too small)")
        return ensemble.facet_figures(f"{'clearance' if c.walls else 'separation'}-needed", [line_dim], curves, f"probability of {event} p", f"{c.gap} needed (cm)", what,
                                      title=f"{c.gap} needed" if c.walls else "separation needed", log_x=True, legend_title=dim_text(line_dim) if line_dim else "")


def span(values: xr.DataArray) -> str:
    """The range of the probabilities ``values`` over their cells, NaN ignored ("—" if none)."""
    extent = ValueRange.of(values)
    if extent is None:
        return "—"
    low, high = f"{extent.low:.3f}", f"{extent.high:.3f}"
    return low if low == high else f"{low}–{high}"


def span_cm(values: xr.DataArray) -> str:
    """The range of ``values`` (m) in cm, NaN ignored ("—" if none)."""
    extent = ValueRange.of(values)
    if extent is None:
        return "—"
    low, high = extent.low * CM, extent.high * CM
    return f"{low:.1f} cm" if f"{low:.1f}" == f"{high:.1f}" else f"{low:.1f}–{high:.1f} cm"


def _cm(value: xr.DataArray) -> str:
    number = float(value)
    return "—" if math.isnan(number) else f"{number * CM:.1f} cm"
