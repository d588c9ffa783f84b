"""An experiment store's intensity-conditioned runs through the risk chain.

A store with intensity stripes holds, per case, ``peak_contact_closure``
over the grid's dimensions (``gap``, ``mu``, variants, ``intensity``,
``record``, ``realization``) and ``contact``; its contact-free cases are
those at ``inf`` on every gap axis. By the gap identity, their largest closure over the
contacts decides pounding at every gap, so the pounding fragility of every
gap and configuration comes from that one selection. A store of IDA runs
(homogeneous scenes: ``ida_capacity``, no ``intensity`` dimension) holds one
contact-free run per motion at scale 1, and every gap's capacity follows
from it (:func:`~stochpound.risk.homogeneous_capacities`).

The motions are the store's ``record`` entries; a synthetic ensemble's
realizations are motions too (``record`` and ``realization`` are merged
into one ``record`` dimension when there is more than one realization).
:func:`store_risk` runs the whole chain of a store for a site's hazard and
returns a :class:`StoreRisk`, which owns the chain's tables
(:meth:`StoreRisk.to_frame`, :meth:`StoreRisk.separation_frame`,
:meth:`StoreRisk.rules_frame`): the report renders them and
``stochpound risk`` prints them. The store is read once, in
``stochpound.risk._inputs`` (:func:`~stochpound.risk.read_risk_inputs`),
and the chain runs on those inputs (:class:`~stochpound.risk.RiskInputs`).
"""

from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import pandas as pd
import xarray as xr

from stochpound._memory import check_memory
from stochpound.hazard import HazardCurve, rate_from_probability
from stochpound.risk import _inputs
from stochpound.risk._inputs import Design, Intensity, RiskInputError, RiskInputs, read_risk_inputs
from stochpound.risk._code_rules import MINIMUM_MOTIONS, code_rules_risk
from stochpound.risk._design_rules import DESIGN_RULE_NAMES, design_assumptions, design_rules_risk, design_rules_text
from stochpound.risk._fragility_ensemble import BOOTSTRAP, fragility_band, fragility_surface, homogeneous_capacities, ida_fragility, limit_state_events, stripe_fragility
from stochpound.risk._fragility import DECREASING, EMPTY, FIT, STATUS
from stochpound.risk._gap_grid import GRID_TOLERANCE, MAX_REFINEMENTS, grid_note, refinement_gaps
from stochpound.risk._maf import TARGETS, degenerate_text, non_increasing, risk_curve, risk_targeted_separation, separation_envelope, target_text
from stochpound.risk._stripe_coverage import at_lowest_stripe, maf_outside_stripes, top_capped_maf

YEARS = 50.0
"""The default exposure time of the targets (yr)."""
CONFIDENCE = 0.95
"""The default confidence of the intervals."""
RISK_GAPS = 60
"""Gaps of the default grid of :func:`risk_gaps`."""
RULE_NAMES = {
    "abs": "ABS",
    "srss": "SRSS of suite-mean peaks (ASCE 7 δ_MT form)",
    "srss_reduced": "0.7 SRSS of suite-mean peaks (Eurocode 8 form)",
    "ddc": "DDC",
    "ddc_cqc": "DDC (CQC ρ)",
    "dtm": "suite-mean peak base displacement (ASCE 7 D_M form: no torsion)",
    **DESIGN_RULE_NAMES,
}
"""The code rules' names in the tables: each applied to the suite-mean peaks of the stripe at the design level
(the codes apply them to the design analysis: named as suite-mean so they are not read as the codes' own gaps), and the codes'
own gaps from the design analysis of the store's ``[design]`` (:func:`~stochpound.risk.design_rules_risk`)."""
CURVE_GAPS = 3
"""Fragility curves drawn per configuration (at gaps spread over the risk curve's range)."""
IM_POINTS = 120
"""Intensities of :meth:`StoreRisk.im_axis`."""
_SEPARATION = {"separation": "g* (m)", "lower": "lower (m)", "upper": "upper (m)"}
_RULE_VALUES = ("maf", "maf_lower", "maf_upper", "return_period", "return_period_lower", "return_period_upper", "probability",
                "probability_lower", "probability_upper")
_RULE_COLUMNS = ("λ_P (1/yr)", "λ_P lower", "λ_P upper", "once in (yr)", "once in, lower (yr)", "once in, upper (yr)", "P in {years:g} yr",
                 "P lower", "P upper")


def risk_gaps(closure: xr.DataArray, count: int = RISK_GAPS) -> np.ndarray:
    """A log-spaced grid of ``count`` gaps (m) spanning the contact-free closures, from half the smallest to 1.5 × the largest.

    Below the grid every run pounds, above it none does, so the risk curve
    over it reaches both ends of the data.
    """
    values = np.asarray(closure.values, dtype=float)
    positive = values[np.isfinite(values) & (values > 0.0)]
    if positive.size == 0:
        raise RiskInputError("store: no contact-free run closes any contact (every peak closure <= 0): no gap can pound")
    return np.geomspace(0.5 * positive.min(), 1.5 * positive.max(), count)


def pounding_fragility(store: xr.Dataset | RiskInputs, gaps: Sequence[float] | np.ndarray, intensity_dim: str = "intensity",
                       record_dim: str = "record", confidence: float = CONFIDENCE, bootstrap: int = BOOTSTRAP, seed: int = 0) -> xr.Dataset:
    """The pounding fragility at every gap of ``gaps`` (m) and every configuration of a store, from stripes or IDA runs.

    Stripes: the contact-free closures' events at every gap
    (:func:`~stochpound.risk.limit_state_events`), fitted by
    :func:`~stochpound.risk.stripe_fragility`. IDA: every motion's
    capacity IM·g/D at every gap (:func:`~stochpound.risk.homogeneous_capacities`),
    fitted by :func:`~stochpound.risk.ida_fragility`.

    Parameters
    ----------
    store : xarray.Dataset or RiskInputs
        The store, or its inputs already read (:func:`~stochpound.risk.read_risk_inputs`).

    Returns
    -------
    xarray.Dataset
        The fit over ``gap`` (the given gaps) and the store's other grid dimensions.
    """
    closure, intensity = ((store.closure, store.motion_intensity) if isinstance(store, RiskInputs)
                          else (_inputs.contact_free_closure(store), _inputs.motion_intensity(store) if _inputs.is_ida(store) else None))
    if intensity is not None:
        capacities = homogeneous_capacities(closure, intensity, gaps)
        return ida_fragility(capacities, record_dim, confidence=confidence, bootstrap=bootstrap, seed=seed)
    events = limit_state_events(closure, gaps, "gap")
    return stripe_fragility(events, intensity_dim, record_dim, confidence, bootstrap, seed)


@dataclasses.dataclass
class StoreRisk:
    """The risk chain of one store at one site (:func:`store_risk`), with its tables.

    Its tables, those ``stochpound risk`` prints and the report shows:
    ``to_frame()`` (g* per configuration and target, one row each, with
    its interval and the number of motions), ``separation_frame()`` (the
    g* table, the targets side by side) and ``rules_frame()`` (the code
    rules in risk terms: per configuration, design level and rule, the gap
    at each contact and λ_P there). For figures: ``non_increasing_maf()``
    (λ_P(g) as g* reads it), ``surface()`` and ``fragility_curves()``
    (the fitted fragility over ``im_axis()``), ``hazard_levels()``.

    Attributes
    ----------
    fragility : xarray.Dataset
        The pounding fragility over ``gap`` and the configurations (:func:`pounding_fragility`).
    curve : xarray.Dataset
        λ_P(g), the pounding risk curve with its band (:func:`~stochpound.risk.risk_curve`).
    separation : xarray.Dataset
        g* per target (:func:`~stochpound.risk.risk_targeted_separation`).
    rules : xarray.Dataset or None
        The code rules in risk terms (:func:`~stochpound.risk.code_rules_risk`);
        None for IDA runs (no stripe at the code intensity) or fewer motions than a code accepts.
    rules_note : str
        Why ``rules`` is None ("" otherwise).
    hazard : HazardCurve
        The site's hazard.
    motions : int
        The motions of every stripe (the bootstrap's sample size): the fewest that ran in a stripe and configuration.
    method : str
        ``"stripes"`` or ``"ida"``.
    setting : Intensity or None
        The store's ``[intensity]`` setting (its measure, units and levels; :class:`stochpound.store.Intensity`).
    stripes : int or None
        The store's intensity stripes that ran (None for IDA runs).
    progress : str
        The store's cases done, ``288/704 cases done`` ("" for a store whose every case ran).
    experiment : str or None
        The store's experiment name.
    years : float
        The exposure time of the targets (yr).
    confidence : float
        The confidence of the intervals.
    dtm_note : str
        Why the rules hold no suite-mean peak base displacement row ("" where they do, or where the studied building does not slide).
    design_rules : xarray.Dataset or None
        The codes' own gaps from the design analysis and their risk
        (:func:`~stochpound.risk.design_rules_risk`); None without a ``[design]`` or without stripes.
    design_note : str
        Why ``design_rules`` is None ("" otherwise).
    grid : str
        How the gap grid was made, in words (``60 log-spaced gaps, refined 3 times near each g* to 84 gaps, …``;
        ``stochpound.risk._gap_grid``; also the separation's ``grid`` attribute).
    assumptions : dict[str, str]
        What the answer rests on besides the hazard, in words from the
        store's definition: ``structural model``, ``suite`` (and its
        selection), ``scenario``.
    """

    fragility: xr.Dataset
    curve: xr.Dataset
    separation: xr.Dataset
    rules: xr.Dataset | None
    rules_note: str
    hazard: HazardCurve
    motions: int
    method: str
    setting: Intensity | None = None
    stripes: int | None = None
    progress: str = ""
    experiment: str | None = None
    years: float = YEARS
    confidence: float = CONFIDENCE
    assumptions: dict[str, str] = dataclasses.field(default_factory=dict)
    dtm_note: str = ""
    design_rules: xr.Dataset | None = None
    design_note: str = ""
    grid: str = ""

    @property
    def no_interval(self) -> str:
        """Why g* has no interval though a bootstrap was asked: the motions cannot be resampled (one motion, or every motion
        from one earthquake: ``stochpound.stats.resampling_obstacle``); "" where it has one, or where none was asked."""
        return str(self.separation.attrs.get("no_interval", ""))

    @property
    def measure(self) -> str:
        """The intensity measure in words, e.g. ``PSA(2 s, 5 %)`` ("" without a setting)."""
        return self.setting.description if self.setting is not None else ""

    def to_frame(self) -> pd.DataFrame:
        """The g* numbers: one row per configuration and target.

        Returns
        -------
        pandas.DataFrame
            Columns: the configuration's dimensions, ``target`` (probability in
            ``years``), ``separation``, ``lower``, ``upper`` (m; ``inf``: wider
            than every gap of the grid), ``lower_bound`` (True where
            ``separation`` is only a lower bound of g*, the target beyond
            the stripes' runs: ``stochpound.risk._chain.bound_beyond_stripes``; its interval is
            then NaN), ``confidence``, ``motions``.
        """
        separation = self.separation
        for bound in ("lower", "upper"):  # absent without a bootstrap
            if bound not in separation:
                separation = separation.assign({bound: xr.full_like(separation["separation"], np.nan)})
        if "lower_bound" not in separation:  # IDA runs: homogeneity carries every gap
            separation = separation.assign(lower_bound=xr.zeros_like(separation["separation"], dtype=bool))
        frame = _grid_only(separation[[*_SEPARATION, "lower_bound"]]).to_dataframe().reset_index()
        frame = frame.drop(columns=[c for c in ("target_rate",) if c in frame])
        return frame.assign(confidence=self.confidence, motions=self.motions)

    def configuration_dims(self) -> list[str]:
        """The dimensions of :meth:`to_frame` that name a configuration (every grid axis but the gap)."""
        return [c for c in self.to_frame().columns if c not in ("target", *_SEPARATION, "lower_bound", "confidence", "motions")]

    def by_configuration(self, frame: pd.DataFrame) -> list[tuple[dict[str, str | float | int], pd.DataFrame]]:
        """The rows of ``frame`` (:meth:`to_frame`, :meth:`design_frame`) per configuration, in their order: its labels
        (dimension -> value of :meth:`configuration_dims`; empty for the one configuration of a scene without axes) and its rows."""
        config = self.configuration_dims()
        groups = frame.groupby(config, sort=False) if config else [((), frame)]
        return [(dict(zip(config, labels if isinstance(labels, tuple) else (labels,))), rows) for labels, rows in groups]

    def separation_frame(self) -> pd.DataFrame:
        """The g* table: per configuration, g* and its interval (m) for each target (columns grouped by target); a g* that
        is only a lower bound (``stochpound.risk._chain.bound_beyond_stripes``) is the text ``≥ 0.640``, its interval empty."""
        frame = self.to_frame()
        years = _stated_years(self.separation, self.years)
        config = self.configuration_dims()
        frame["target"] = [target_text(p, years) for p in frame["target"]]
        frame["separation"] = [f"≥ {value:.3f}" if bound else value for value, bound in zip(frame["separation"], frame["lower_bound"])]
        table = frame.set_index([*config, "target"])[list(_SEPARATION)].rename(columns=_SEPARATION)
        if config:
            table = table.unstack("target")
            table.columns = table.columns.swaplevel(0, 1)
            order = [target_text(p, years) for p in self.separation["target"].values]
            table = table.reindex(columns=pd.MultiIndex.from_product([order, list(_SEPARATION.values())]))
        return table

    def rules_frame(self) -> pd.DataFrame:
        """The code rules in risk terms: per configuration, design level and rule, its gap per contact (m) and the MAF of pounding there.

        With the return period and the probability, each with its interval,
        the fit's kind (``fit``: ``lognormal`` or the step), and whether the
        rule meets its own design level as a target (``meets its level``:
        λ_P ≤ −ln(1 − p)/t for the level's probability p; ``meets, upper
        bound``: the same for the upper bound of λ_P). The suite-mean rules'
        rows first, then the codes' own gaps from the design analysis
        (design level ``… (design analysis)``, where the store has a
        ``[design]``). A rule's rows are left out where it does not apply
        (D_TM where the studied building's base never slides:
        :meth:`dtm_text`). Empty when no rule was evaluated (``rules_note`` and
        ``design_note`` say why).
        """
        frames = []
        if self.rules is not None:
            rules = _grid_only(self.rules, keep=("code_intensity", "stripe_intensity"))
            stripes = [design_text(p, float(i), _stated_years(rules, self.years))
                       for p, i in zip(rules["design_level"].values, rules["stripe_intensity"].values)]
            rows = self._rules_rows(rules.drop_vars(["code_intensity", "stripe_intensity"]), dict(zip(rules["design_level"].values, stripes)))
            frames.append(rows[rows[[c for c in rows.columns if c.startswith("gap, ")]].notna().any(axis=1)])  # D_TM: not where the base never slides
        if self.design_rules is not None:
            rules = _grid_only(self.design_rules, keep=("design_level",))
            years = _stated_years(rules, self.years)
            rows = self._rules_rows(rules, {p: f"{100 * p:g} %/{years:g} yr (design analysis)" for p in rules["design_level"].values})
            rows = rows[rows[[c for c in rows.columns if c.startswith("gap, ")]].notna().any(axis=1)]  # not where a rule does not apply
            frames.append(rows.reorder_levels(frames[0].index.names) if frames else rows)
        return pd.concat(frames) if frames else pd.DataFrame()

    def _rules_rows(self, rules: xr.Dataset, level_names: Mapping[float, str]) -> pd.DataFrame:
        """The rows of :meth:`rules_frame` of one rules dataset (``design_level`` a dimension or a coordinate along ``rule``)."""
        years = _stated_years(rules, self.years)
        gaps = rules["gap"].to_dataframe()[["gap"]]["gap"].unstack("contact")
        gaps.columns = [f"gap, contact {c} (m)" for c in gaps.columns]
        if {"status", "theta"} <= set(rules.data_vars) and self.stripes is not None:  # a step at the lowest stripe: a bound, not a rate
            rules = rules.assign(bound=at_lowest_stripe(rules, float(np.min(self.fragility["intensity"].values))))
        values = rules[[name for name in (*_RULE_VALUES, "status", "bound") if name in rules]].to_dataframe()
        frame = gaps.join(values[[c for c in values.columns if c in (*_RULE_VALUES, "status", "bound")]])
        if "design_level" not in frame.index.names:
            frame = frame.set_index(pd.Index([rules["design_level"].sel(rule=r).item() for r in frame.index.get_level_values("rule")],
                                             name="design_level"), append=True)
        if "status" in frame:
            bound = frame.pop("bound") if "bound" in frame else pd.Series(False, index=frame.index)
            frame["status"] = [(LOWEST_STRIPE_STEP if b else fit_name(int(s))) if np.isfinite(s) else "" for s, b in zip(frame["status"], bound)]
        allowed = rate_from_probability(frame.index.get_level_values("design_level").to_numpy(dtype=float), years)
        frame["meets its level"] = frame["maf"] <= allowed  # λ_P at the rule's gap within the rate of its own design level
        if "maf_upper" in frame:
            frame["meets, upper bound"] = frame["maf_upper"] <= allowed
        names = {**dict(zip(_RULE_VALUES, (column.format(years=years) for column in _RULE_COLUMNS))), "status": "fit"}
        frame = frame.rename(columns=names).reset_index()
        frame["design_level"] = [level_names[p] for p in frame["design_level"]]
        frame["rule"] = [RULE_NAMES.get(r, r) for r in frame["rule"]]
        index = [c for c in frame.columns if not c.startswith(("gap, ", "meets")) and c not in names.values()]
        return frame.set_index(index).dropna(how="all")

    def dtm_text(self) -> str:
        """Where the suite-mean peak base displacement rule (the D_M form) applies, in words: why it is absent, or the configurations it is left out of ("" where it
        applies in every one)."""
        if self.rules is None:
            return ""
        if "dtm" not in self.rules["rule"].values:
            never = ("the studied building's base slides in no run of this store (a fixed base, or friction the motions never overcame): "
                     "there is no isolator displacement to size")
            return f"The row '{RULE_NAMES['dtm']}' is not given: {self.dtm_note or never}."
        missing = self.rules["gap"].sel(rule="dtm").isnull().all("contact")
        missing = missing.any("design_level") if "design_level" in missing.dims else missing
        if not bool(missing.any()):
            return ""
        where = [", ".join(f"{d} {_label(v)}" for d, v in zip(missing.dims, index)) for index in zip(*(
            missing[d].values[i] for d, i in zip(missing.dims, np.nonzero(missing.values))))] if missing.dims else ["the scene"]
        return ("The suite-mean peak base displacement (ASCE 7's D_M form: no torsion, not D_TM) sizes the clearance of a base that "
                "slides; its rows are left out where the studied building's "
                f"base never slid in any run ({'; '.join(where)}): a fixed base (μ = ∞), or friction the motions never overcame, has no "
                "isolator displacement to size (it stays 0), and its separation is the storeys' rules'.")

    def design_rules_text(self) -> str:
        """The rules table's design-analysis rows in words: what they are, or why there are none (``stochpound.risk._design_rules``)."""
        return design_rules_text(self.design_rules, self.design_note)

    def design_frame(self) -> pd.DataFrame:
        """The gap to design to: per configuration and target, the upper bound of g*'s interval (m; g* itself without one).

        g* is the central estimate from a finite suite; its upper bound is
        the gap that meets the target with the intervals' confidence
        (one-sided: (1 + confidence)/2), the number to design to.

        Returns
        -------
        pandas.DataFrame
            Columns: the configuration's dimensions, ``target``, ``design``
            (m; NaN, withheld, where g* is only a lower bound: the target lies
            beyond the stripes' runs, ``stochpound.risk._chain.bound_beyond_stripes``), ``basis``
            (what ``design`` is, in words).
        """
        frame = self.to_frame()
        bounded = frame["upper"].notna()
        one_sided = f"{100 * (1 + self.confidence) / 2:g} % one-sided upper bound of g*"
        frame["design"] = frame["upper"].where(bounded, frame["separation"]).where(~frame["lower_bound"])
        frame["basis"] = np.where(bounded, one_sided, "g* (no bound: the interval is not estimable)" if self.no_interval else "g* (no bootstrap: no bound)")
        frame.loc[frame["lower_bound"], "basis"] = [f"withheld: g* ≥ {value:.3f} m, beyond the stripes' runs"
                                                    for value in frame.loc[frame["lower_bound"], "separation"]]
        return frame[[*self.configuration_dims(), "target", "design", "basis"]]

    def beyond_stripes_text(self) -> str:
        """Which targets' g* lie beyond the stripes' runs (given as lower bounds) and what to add, in words ("" when none does)."""
        if "lower_bound" not in self.separation or not bool(self.separation["lower_bound"].any()):
            return ""
        top = float(self.separation.attrs["top_stripe"])
        units = self.setting.units if self.setting is not None else self.hazard.units
        sentences = []
        for target in self.separation["target"].values:
            at = self.separation.sel(target=target)
            flagged = at["lower_bound"]
            if not bool(flagged.any()):
                continue
            rate = float(at["target_rate"])
            where = "in every configuration" if bool(flagged.all()) else f"in {int(flagged.sum())} of {flagged.size} configurations"
            reach = float(at["reach"].where(flagged).max())
            at_top = float(self.hazard(min(top, self.hazard.support[1])))
            why = (f"its rate, {rate:.3g} /yr, is below the hazard's rate at the top stripe ({top:g} {units}, {at_top:.3g} /yr)"
                   if rate < at_top else f"the top stripe's runs close no gap wider than {reach:.3f} m, where λ_P is still above it")
            level = _reach_intensity(self.hazard, [float(target)], self.years)
            add = (f"add stripes above {top:g} {units}" + (f", up to about {level:.3g} {units} (where the hazard's rate is a tenth of the "
                                                           f"target's)" if level > top else ""))
            sentences.append(f"g* for {self.target_text(float(target))} lies beyond the stripes' runs {where}: {why}. It is given as a lower "
                             f"bound (≥, the gap where pounding is as frequent as the target with the fragility held at its top-stripe "
                             f"value beyond it, at most {reach:.3f} m); its interval and the gap to design to are withheld: {add}.")
        return " ".join(sentences)

    def degenerate_text(self) -> str:
        """The degenerate fragility fits among the gaps (steps, not lognormals) and what each does to λ_P ("" when there are none)."""
        if "status" not in self.fragility:
            return ""
        what = "fits (gaps × configurations)" if self.configuration_dims() else "gaps"
        return degenerate_text(self.fragility["status"].values, self.hazard, what)

    @functools.cached_property
    def outside_stripes(self) -> xr.Dataset | None:
        """The shares of λ_P at g* from shaking below the lowest stripe and beyond the top one, with the fit there
        (:func:`~stochpound.risk.maf_outside_stripes`, computed once); None for IDA runs or a fit without its stripes' levels."""
        if self.method != "stripes" or "intensity" not in self.fragility.coords or "separation" not in self.separation:
            return None
        return maf_outside_stripes(self.fragility, self.separation["separation"], self.hazard)

    def worst_outside_stripes(self) -> list[tuple[float, float, float]]:
        """Per target: (target, below, above), the worst configuration's shares of λ_P at g* from below the lowest stripe and
        beyond the top one (``outside_stripes``; [] for IDA runs or without a finite g*)."""
        shares = self.outside_stripes
        if shares is None or not np.isfinite(shares["below"].values).any():
            return []
        return [(float(t), float(shares["below"].sel(target=t).max()), float(shares["above"].sel(target=t).max())) for t in shares["target"].values]

    def lowest_stripe(self) -> tuple[float, float]:
        """The lowest stripe's level (IM units) and the hazard's return period there (yr)."""
        lowest = float(np.min(self.fragility["intensity"].values))
        return lowest, float(1.0 / self.hazard(lowest))

    def rules_meeting(self) -> tuple[str, pd.Series]:
        """Which code rules meet their own design level as a target in every configuration and level: the column of
        :meth:`rules_frame` read (``meets, upper bound`` with a bootstrap, else ``meets its level``) and, per rule, whether it does."""
        rules = self.rules_frame()
        column = "meets, upper bound" if "meets, upper bound" in rules else "meets its level"
        return column, rules[column].groupby(level="rule", sort=False).all()

    def largest_dtm(self) -> dict[float, tuple[float, bool]]:
        """Per design level of the suite-mean D_TM rule: its largest gap over the configurations (m) and whether the configurations'
        finite gaps differ; {} without the rule."""
        if self.rules is None or "dtm" not in self.rules["rule"].values:
            return {}
        dtm = self.rules["gap"].sel(rule="dtm")
        largest = {}
        for level in dtm["design_level"].values:
            values = dtm.sel(design_level=level).values
            largest[float(level)] = (float(dtm.sel(design_level=level).max(skipna=True)), np.unique(values[np.isfinite(values)]).size > 1)
        return largest

    def rules_degenerate_text(self) -> str:
        """The degenerate fits among the rules' rows, suite-mean and design-analysis (where a rule applies: a gap at every
        contact), and what each does to λ_P (:func:`~stochpound.risk.degenerate_text`; "" when there are none)."""
        statuses = [self.rules["status"].values.ravel()] if self.rules is not None else []
        if self.design_rules is not None:
            applies = self.design_rules["gap"].notnull().all("contact")
            statuses.append(self.design_rules["status"].values[applies.broadcast_like(self.design_rules["status"]).values])
        return degenerate_text(np.concatenate(statuses), self.hazard, "rule rows") if statuses else ""

    def coarse_change(self) -> float:
        """The largest ``|g*_coarse / g* − 1|`` over the configurations and targets, g*_coarse read off the gap grid as first made
        (before its refinement near each g*): how far interpolating across the coarse grid's brackets moves g*, λ_P(g) being a
        step function of g (NaN where the grid was given, not refined)."""
        return float(self.separation.attrs["coarse_change"]) if "coarse_change" in self.separation.attrs else math.nan

    def non_increasing_maf(self) -> xr.DataArray:
        """λ_P(g) made non-increasing along the gaps as g* reads it (the isotonic fit of ln λ with the gaps' weights,
        ``stochpound.risk._maf.separation_envelope``; NaN along a configuration without a rate; 1/yr)."""
        return separation_envelope(self.curve["maf"])

    def hazard_levels(self, probabilities: Sequence[float] = (0.10, 0.02)) -> dict[float, float]:
        """The hazard's intensity (IM units) at each probability of exceedance in ``years``."""
        return {p: float(self.hazard.intensity_at(rate_from_probability(p, self.years))) for p in probabilities}

    def im_axis(self, count: int = IM_POINTS) -> np.ndarray:
        """Intensities (IM units) to draw the fragility over: up to 1.1 × the highest stripe (IDA: the 2 % intensity in ``years``)."""
        top = (float(self.fragility["intensity"].values.max()) if "intensity" in self.fragility.coords
               else self.hazard_levels((0.02,))[0.02])
        return np.linspace(top / 200.0, 1.1 * top, count)

    def surface(self) -> xr.DataArray:
        """The fitted fragility P(pounding | IM, gap) over :meth:`im_axis` (dimension ``im``) and the gaps."""
        return fragility_surface(self.fragility, self.im_axis())

    def curve_gaps(self, count: int = CURVE_GAPS) -> np.ndarray:
        """Grid gaps (m) to draw fragility curves at: nearest to the quantiles (in ln g) of the finite g* values, else spread over the grid."""
        gaps = self.fragility["gap"].values
        found = self.separation["separation"].values
        found = found[np.isfinite(found) & (found > gaps[0])]
        if found.size:
            wanted = np.exp(np.quantile(np.log(found), np.linspace(0.0, 1.0, count)))
        else:
            wanted = np.geomspace(gaps[0], gaps[-1], count + 2)[1:-1]
        return np.unique(gaps[[int(np.argmin(np.abs(np.log(gaps) - np.log(w)))) for w in wanted]])

    def fragility_curves(self) -> xr.Dataset:
        """The fitted fragility at :meth:`curve_gaps` over :meth:`im_axis`: ``fit`` and, with a bootstrap, ``lower`` and ``upper``."""
        shown = self.fragility.sel(gap=self.curve_gaps())
        levels = self.im_axis()
        curves = xr.Dataset({"fit": fragility_surface(shown, levels)})
        if "theta_bootstrap" in shown:
            band = fragility_band(shown, levels, self.confidence)
            curves = curves.assign(lower=band["lower"], upper=band["upper"])
        return curves

    def design_basis(self) -> str:
        """What the gap to design to is (:meth:`design_frame`'s ``basis`` of its first row with a value): by default the upper
        bound of g*'s interval."""
        frame = self.design_frame()
        given = frame["design"].notna()
        return str(frame.loc[given, "basis"].iloc[0]) if given.any() else "upper bound of g*'s interval"

    def measure_margin(self, choice: pd.DataFrame, own: str) -> tuple[float, float, int]:
        """How far the store's own measure ``own`` is from the most efficient one of ``choice`` (the measure choice's table:
        β per measure and configuration, ``most efficient`` naming the smallest): the largest excess of its β over the
        smallest, the standard error of one β estimate (about β/√(2(n − 2)), its largest β), and n, the contact-free runs
        of a configuration (motions × stripes)."""
        runs = self.motions * (self.stripes or 1)
        excess = max(float(row[own] - row[row["most efficient"]]) for _, row in choice.iterrows())
        noise = float(choice[own].max()) / math.sqrt(2.0 * max(runs - 2, 1))
        return excess, noise, runs

    def return_period_range(self) -> tuple[float, float]:
        """The smallest and largest finite return period (yr) over the rules, levels and configurations (NaN without rules)."""
        if self.rules is None:
            return math.nan, math.nan
        finite = self.rules["return_period"].where(np.isfinite(self.rules["return_period"]))
        return float(finite.min()), float(finite.max())

    def target_text(self, probability: float) -> str:
        """A target in words: ``10 % in 50 yr``."""
        return target_text(probability, self.years)


def _stated_years(result: xr.Dataset, years: float) -> float:
    """The investigation time (yr) a result of the chain states in its ``years`` attribute, else ``years``."""
    return float(result.attrs.get("years", years))


def non_increasing_along(maf: xr.DataArray, dim: str) -> xr.DataArray:
    """A rate made non-increasing along its thresholds ``dim``: the least-squares non-increasing fit of ln λ (pool-adjacent-violators,
    ``stochpound.risk._maf.non_increasing``), NaN left out of the fit."""
    return xr.apply_ufunc(non_increasing, maf, input_core_dims=[[dim]], output_core_dims=[[dim]]).transpose(*maf.dims)


def _reach_intensity(hz: HazardCurve, targets: Sequence[float], years: float) -> float:
    """The intensity up to which a gap grid reaches: where the hazard's rate is a tenth of the smallest target's (within its table)."""
    rate = rate_from_probability(min(targets), years) / 10.0
    if not hz.extrapolate:
        rate = max(float(rate), float(hz.rate[-1]))
    return float(hz.intensity_at(rate))


def bootstrap_bytes(resamples: int, fits: int, stripes: int, motions: int) -> int:
    """Upper estimate of the memory (bytes) the resamples of the risk chain hold at once: ``resamples`` refits of ``fits`` fits
    (gaps × configurations) over ``stripes`` stripes (1 for IDA runs) of ``motions`` motions.

    Counted in doubles per resample: the stripes' weighted counts and the
    maximum-likelihood fit's work arrays (16 per fit and stripe), each
    fit's θ, β, flat fraction, λ and g* with their sorted copies for the
    intervals (24 per fit), the resample's weights (2 per motion); and
    64 MiB whatever their number, the quadrature of the MAF (chunks of 4096
    fits at 192 nodes). The tests check it against the measured peak of the chain.
    """
    return 8 * resamples * (16 * fits * stripes + 24 * fits + 2 * motions) + 64 * 2**20


def check_bootstrap(resamples: int, fits: int, stripes: int, motions: int) -> None:
    """Refuse a bootstrap whose resamples would hold more memory than the limit (``MemoryLimitError``, naming ``bootstrap``)."""
    check_memory(bootstrap_bytes(resamples, fits, stripes, motions),
                 f"bootstrap (--bootstrap): {resamples} resamples of {motions} motions, each refitting {fits} fits (gaps × configurations) "
                 f"over {stripes} stripe{'s' if stripes != 1 else ''}; the risk chain")


def bound_beyond_stripes(separation: xr.Dataset, fragility: xr.Dataset, hz: HazardCurve, years: float = YEARS) -> xr.Dataset:
    """g* of a stripes fit, given as a lower bound where it lies beyond what the stripes' runs observe.

    A target's g* is beyond the runs where (a) it is wider than ``reach``,
    the widest grid gap the top stripe's runs still close (wider gaps fit
    ``never``: λ_P drops to 0 there, and g* would stop at the largest closure
    seen, however rare the target), or (b) the target's rate is below the
    hazard's rate at the top stripe (the pounding it allows comes from
    shaking no stripe ran). There ``separation`` becomes a lower bound that
    rests on the runs alone: the gap where λ⁻ (``stochpound.risk._stripe_coverage.top_capped_maf``,
    the fragility held beyond the top stripe at its value there) meets the
    target, and no wider than ``reach``; its interval is withheld (NaN).

    Parameters
    ----------
    separation : xarray.Dataset
        From :func:`~stochpound.risk.risk_targeted_separation` of the fit's risk curve.
    fragility : xarray.Dataset
        The stripes fit over ``gap`` (with ``exceeded`` per stripe and the ``intensity`` coordinate).
    hz : HazardCurve
        The site's hazard.
    years : float
        The targets' exposure time (yr).

    Returns
    -------
    xarray.Dataset
        ``separation`` with ``lower_bound`` (True where ``separation`` is a
        lower bound), ``reach`` (m, per configuration) and the attribute
        ``top_stripe`` (the top stripe's level, IM units).
    """
    top = float(np.max(fragility["intensity"].values))
    gap = fragility["gap"]
    reach = gap.where(fragility["exceeded"].sel(intensity=top, drop=True) > 0.0).max("gap")
    capped = risk_targeted_separation(xr.Dataset({"maf": top_capped_maf(fragility, hz)}), separation["target"].values, years)["separation"]
    value = separation["separation"]
    rarer = separation["target_rate"] < float(hz(min(top, hz.support[1])))
    beyond = value.notnull() & (rarer | ~(value <= reach))
    bound = np.fmin(np.fmin(capped, reach), value)
    result = separation.assign(separation=value.where(~beyond, bound).assign_attrs(value.attrs))
    for name in ("lower", "upper"):
        if name in result:
            result[name] = result[name].where(~beyond).assign_attrs(result[name].attrs)
    flag = {"long_name": "separation is only a lower bound of g* (the target lies beyond the stripes' runs)"}
    return result.assign(lower_bound=beyond.assign_attrs(flag),
                         reach=reach.assign_attrs(units="m", long_name="widest gap of the grid the top stripe's runs close")
                         ).assign_attrs(top_stripe=top)


def store_risk(store: xr.Dataset | RiskInputs, hz: HazardCurve | None = None, targets: Sequence[float] = TARGETS, years: float = YEARS,
               gaps: Sequence[float] | np.ndarray | None = None, studied: str | None = None, confidence: float = CONFIDENCE,
               bootstrap: int = BOOTSTRAP, seed: int = 0, design: Design | None = None, partial: bool = False,
               grid_tolerance: float | None = GRID_TOLERANCE) -> StoreRisk:
    """Fragility at every gap, the pounding risk curve, g* and the code rules of a store's intensity-conditioned runs.

    Parameters
    ----------
    store : xarray.Dataset or RiskInputs
        An experiment store with intensity stripes (contact-free cases at
        ``gap = inf``) or IDA capacities, read here once
        (:func:`~stochpound.risk.read_risk_inputs`), or its inputs already read.
    hz : HazardCurve, optional
        The site's hazard, in the store's intensity measure and units;
        default: the hazard the store carries (its experiment's ``[hazard]``).
    targets : sequence of float
        Probabilities of pounding in ``years`` for g*.
    years : float
        Exposure time (yr).
    gaps : sequence of float, optional
        The gap grid (m); default :func:`risk_gaps` of the closures, for IDA
        runs (closures at scale 1) together with each closure scaled to the
        intensity where the hazard's rate is a tenth of the rarest target's
        (within the hazard's table), so that the grid reaches the separations
        the hazard asks for. Either grid is refined near each g* (``grid_tolerance``).
    studied : str, optional
        The building whose suite-mean peak base displacement (wall-free: a
        moat wall caps the displacement it sizes) is the D_M-form rule; default
        the store's ``studied`` building. The rule is left out where it does not slide.
    confidence, bootstrap, seed
        As in :func:`~stochpound.risk.stripe_fragility`.
    design : Design, optional
        The buildings' code design (an experiment file's ``[design]`` table, docs/experiments.md, parsed)
        whose design analysis gives the codes' own gaps; default the store's.
    partial : bool
        Answer from the cases that ran of a store with missing cases (its
        counts of motions and stripes are those that ran); without it such a
        store is refused. With inputs already read, ``studied``, ``design``
        and ``partial`` are theirs (giving them again is refused).
    grid_tolerance : float or None
        λ_P of stripes is a step function of the gap (its steps at the runs' closures), so g* interpolated between two grid
        gaps is off by up to their spacing: the grid is refined near each g* (``stochpound.risk._gap_grid``) until each lies
        between two gaps at most this far apart (relative), and any finer grid moves it by less. None: the grid as given.
        The separation's ``grid`` attribute says how the grid was made.

    Raises
    ------
    ValueError
        (``RiskInputError``) A store without stripes or IDA capacities, or
        without contact-free runs, or without a hazard when none is given;
        (``UnfinishedStoreError``) a store with missing cases without ``partial``;
        (``MemoryLimitError``) a ``bootstrap`` beyond the memory limit (``stochpound.risk._chain.check_bootstrap``).
    """
    if isinstance(store, RiskInputs) and (studied is not None or design is not None or partial):
        raise RiskInputError("store_risk: studied, design and partial are read with the inputs (read_risk_inputs): give them there")
    inputs = store if isinstance(store, RiskInputs) else read_risk_inputs(store, hz, studied=studied, design=design, partial=partial)
    hz = inputs.hazard if hz is None else hz
    closure = inputs.closure
    if gaps is not None:
        grid = np.asarray(gaps, dtype=float)
    elif inputs.motion_intensity is not None:  # the unscaled closures, and each scaled to the hazard's intensities (IDA runs hold scale 1 only)
        grid = risk_gaps(xr.concat([closure, closure * (_reach_intensity(hz, targets, years) / inputs.motion_intensity)], "record"))
    else:
        grid = risk_gaps(closure)
    fragility, curve, separation = _refined_chain(inputs, hz, grid, targets, years, confidence, bootstrap, seed, grid_tolerance)
    made = str(separation.attrs["grid"])
    rules, note = None, ""
    if inputs.method == "ida":
        note = "IDA runs hold no stripe at the code intensity to apply the rules to"
    elif inputs.motions < MINIMUM_MOTIONS:
        note = f"the codes take the mean over at least {MINIMUM_MOTIONS} motions; the store has {inputs.motions}"
    elif inputs.demands is None:
        note = "the inputs hold no peak demands of the contact-free runs to apply the rules to"
    else:
        rules = code_rules_risk(inputs.demands, hz, years=years, isolator_displacement=inputs.isolator,
                                confidence=confidence, bootstrap=bootstrap, seed=seed)
    design_rules, design_note = None, ""
    if inputs.design is None:
        design_note = "the store's experiment has no [design] table (the buildings' code design)"
    elif inputs.method == "ida":
        design_note = "IDA runs: the codes' gaps are fitted over stripes"
    else:
        design_rules = design_rules_risk(inputs, hz, inputs.design, inputs.studied, years, confidence, bootstrap, seed)
    return StoreRisk(fragility, curve, separation, rules, note, hz, inputs.motions, inputs.method, setting=inputs.setting,
                     stripes=inputs.stripes, progress=inputs.progress, experiment=inputs.experiment, years=years, confidence=confidence,
                     assumptions={**inputs.assumptions, **design_assumptions(inputs.design, inputs.scenes)}, dtm_note=inputs.dtm_note, design_rules=design_rules, design_note=design_note,
                     grid=made)


def _separation(curve: xr.Dataset, fragility: xr.Dataset, hz: HazardCurve, targets: Sequence[float], years: float, confidence: float,
                method: str) -> xr.Dataset:
    """g* of a risk curve (:func:`~stochpound.risk.risk_targeted_separation`), for stripes given as a lower bound beyond the
    stripes' runs (:func:`bound_beyond_stripes`)."""
    separation = risk_targeted_separation(curve, targets, years, confidence=confidence)
    return bound_beyond_stripes(separation, fragility, hz, years) if method == "stripes" else separation


def _with_gaps(data: xr.Dataset, added: xr.Dataset) -> xr.Dataset:
    """Two results over ``gap`` of the same runs (fits or risk curves) as one, its gaps sorted."""
    joined = xr.concat([data, added], "gap", data_vars="minimal", coords="minimal", compat="override", combine_attrs="override")
    if "hazard_extrapolated" in data.attrs:
        joined.attrs["hazard_extrapolated"] = max(int(data.attrs["hazard_extrapolated"]), int(added.attrs["hazard_extrapolated"]))
    return joined.sortby("gap")


def _refined_chain(inputs: RiskInputs, hz: HazardCurve, grid: np.ndarray, targets: Sequence[float], years: float, confidence: float,
                   bootstrap: int, seed: int, tolerance: float | None) -> tuple[xr.Dataset, xr.Dataset, xr.Dataset]:
    """The fit, risk curve and g* on ``grid`` refined near each g* (``stochpound.risk._gap_grid``) until each lies between gaps
    at most ``tolerance`` apart (None: on ``grid`` as given), each refinement fitted at its new gaps only (the same resamples
    of the motions: they do not depend on the gaps); the separation's ``grid`` attribute says how the grid was made."""
    closure = inputs.closure
    configurations = math.prod(size for dim, size in closure.sizes.items() if dim not in ("record", "intensity"))
    stripes, motions = closure.sizes.get("intensity", 1), closure.sizes["record"]

    def fitted(gaps: np.ndarray, held: int) -> tuple[xr.Dataset, xr.Dataset]:
        check_bootstrap(bootstrap, (held + gaps.size) * configurations, stripes, motions)
        fit = pounding_fragility(inputs, gaps, confidence=confidence, bootstrap=bootstrap, seed=seed)
        return fit, risk_curve(fit, hz, years, confidence)

    fragility, curve = fitted(grid, 0)
    coarse = None
    for refinements in range(MAX_REFINEMENTS + 1 if tolerance is not None else 0):  # the last pass only checks convergence
        estimate = _separation(curve[["maf"]], fragility, hz, targets, years, confidence, inputs.method)  # g* alone: no resamples
        coarse = estimate["separation"] if coarse is None else coarse
        added = refinement_gaps(fragility["gap"].values, estimate, tolerance)
        converged = not added.size
        if converged or refinements == MAX_REFINEMENTS:
            break
        fit, more = fitted(added, fragility.sizes["gap"])
        fragility, curve = _with_gaps(fragility, fit), _with_gaps(curve, more)
    separation = _separation(curve, fragility, hz, targets, years, confidence, inputs.method)
    note = (f"{grid.size} gaps as given, not refined" if tolerance is None else
            grid_note(fragility.sizes["gap"], grid.size, refinements, tolerance, converged))
    return fragility, curve, separation.assign_attrs(grid=note, coarse_change=_coarse_change(separation["separation"], coarse))


def _coarse_change(refined: xr.DataArray, coarse: xr.DataArray | None) -> float:
    """The largest relative difference |g*_coarse / g* − 1| between g* read off the grid as first made and g* on the refined grid,
    over the finite values of both (NaN where the grid was not refined or no g* is finite)."""
    if coarse is None:
        return math.nan
    with np.errstate(divide="ignore", invalid="ignore"):
        change = np.abs(np.asarray(coarse.values, dtype=float) / np.asarray(refined.values, dtype=float) - 1.0)
    change = change[np.isfinite(change)]
    return float(change.max()) if change.size else math.nan


def design_text(probability: float, stripe: float, years: float = YEARS) -> str:
    """A code's design level in words, with the stripe its rules use: ``2 %/50 yr (stripe 0.508)``."""
    return f"{100 * probability:g} %/{years:g} yr (stripe {stripe:g})"


LOWEST_STRIPE_STEP = "step at the lowest stripe: λ_P a bound, not a rate (nothing is known below the runs)"
"""A rule row's fit where it is a step at or below the lowest stripe (:func:`~stochpound.risk.at_lowest_stripe`)."""


def fit_name(status: int) -> str:
    """A fit's kind in words: ``lognormal`` for a fit, ``flat: decreasing`` (:func:`~stochpound.risk.flat_fit_maf`), ``no runs``,
    else the step it is (``step: always`` …)."""
    return {FIT: "lognormal", DECREASING: "flat: decreasing (F ≡ fraction of runs that pounded)", EMPTY: "no runs"}.get(status, f"step: {STATUS[status]}")


def _label(value: Any) -> str:
    """A grid label in words: ``∞`` for inf, else as it prints."""
    return "∞" if isinstance(value, float | np.floating) and math.isinf(value) else f"{value:g}" if isinstance(value, float | np.floating) else str(value)


def gap_text(value: float) -> str:
    """A gap in words (m), ``inf`` as "wider than every gap of the grid"."""
    return "wider than every gap of the grid" if math.isinf(value) else f"{value:.3f} m"


def _grid_only(data: xr.Dataset, keep: tuple[str, ...] = ()) -> xr.Dataset:
    """``data`` without its coordinates that are not dimensions (what each grid point ran: friction and law parameters), but ``keep``."""
    return data.drop_vars([name for name in data.coords if name not in data.dims and name not in keep])
