"""Collapse as performance-based earthquake engineering treats it: runs beyond what the model represents counted apart.

The storeys are bilinear without strength loss, so a run whose peak storey
drift ratio passes ``MODEL_DRIFT_LIMIT`` (5 %, the collapse-prevention drift
of steel moment frames) is beyond what the model represents: its closure is
not credible. FEMA P-58 (2018, vol. 1) keeps such runs out of
the demands and counts them as collapses: per stripe, the fraction of runs
that collapse gives P(C | IM), fitted by a lognormal fragility over the
stripes (:func:`~stochpound.risk.stripe_fragility`), and the demands come
from the credible runs only. By total probability, with a collapse counted
as reaching the gap (the separation is not met by a building that has lost
its storeys),

    P(P | IM, g) = P(C | IM) + (1 − P(C | IM)) P(P | IM, g, no C),

P(P | IM, g, no C) the lognormal fit of the credible runs' pounding at gap g.
Its mean annual frequency integrates it with the hazard as
:func:`~stochpound.risk.mean_annual_frequency` integrates a lognormal:
λ = P(lo) λ(lo) + ∫ λ(x) dP(x) over the hazard's range (trapezoids on
``GRID_POINTS`` points in ln x; a hazard without ends from ``BEYOND`` e-folds
below the lowest stripe to as many above the highest). g* is read off it as
off the chain's curve (:func:`~stochpound.risk.risk_targeted_separation`).

:func:`collapse_risk` gives it beside the chain's answer (every run taken as
computed): the two answers, the collapse rate λ_C and the runs counted apart,
so a report shows the answer both ways.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np
import pandas as pd
import xarray as xr

from stochpound.hazard import HazardCurve
from stochpound.risk import _inputs
from stochpound.risk._fragility import DECREASING, lognormal_cdf
from stochpound.risk._fragility_ensemble import limit_state_events, stripe_fragility
from stochpound.risk._maf import mean_annual_frequency, risk_targeted_separation, target_text
from stochpound.risk._stripe_coverage import identified, stripes_only_maf, stripes_upper_maf

MODEL_DRIFT_LIMIT = 0.05
"""Peak storey drift ratio beyond which a run is beyond what the model represents: a collapse (no strength loss or collapse is modelled)."""
COLLAPSE_BOUNDS = "λ_C, stripes' bounds where P(C | IM) is not identified (1/yr)"
"""The g* both ways table's column of what the stripes' fractions alone bound λ_C to, where they do not identify P(C | IM)."""
GRID_POINTS = 2000
"""Points in ln x of the integration over the hazard's range."""
BEYOND = 8.0
"""For a hazard without ends: e-folds of x integrated below the lowest stripe and above the highest."""


@dataclasses.dataclass(frozen=True)
class CollapseRisk:
    """The risk-targeted separation with collapses counted apart (:func:`collapse_risk`).

    Attributes
    ----------
    collapse : xarray.Dataset
        The collapse fragility P(C | IM) per configuration (``theta``, ``beta``, ``status``, per stripe
        ``exceeded``, ``runs``) and ``maf``, λ_C (1/yr).
    separation : xarray.Dataset
        g* per target and configuration by total probability (:func:`~stochpound.risk.risk_targeted_separation`).
    maf : xarray.DataArray
        λ_P(g) by total probability over ``gap`` and the configurations (1/yr).
    collapsed, runs : int
        The runs beyond the model and the runs, over every stripe and configuration.
    """

    collapse: xr.Dataset
    separation: xr.Dataset
    maf: xr.DataArray
    collapsed: int
    runs: int

    def both_ways(self, as_run: xr.Dataset, years: float = 50.0) -> pd.DataFrame:
        """g* both ways per configuration and target (m): ``as run`` (the chain's ``StoreRisk.separation``, every run as computed) and
        ``collapses apart`` (this), beside each configuration's λ_C (1/yr), the bounds the stripes give it where they do not identify
        P(C | IM) (``COLLAPSE_BOUNDS``), and its runs beyond the model."""
        rows = xr.Dataset({"g* as run (m)": _dims_only(as_run["separation"]),
                           "g* collapses apart (m)": _dims_only(self.separation["separation"])}).to_dataframe().reset_index()
        rows["target"] = [target_text(p, years) for p in rows["target"]]
        config = [name for name in rows.columns if name not in ("target", "g* as run (m)", "g* collapses apart (m)")]
        counts = xr.Dataset({"λ_C (1/yr)": _dims_only(self.collapse["maf"]), "collapsed": _dims_only(self.collapse["exceeded"].sum("intensity")),
                             "runs": _dims_only(self.collapse["runs"].sum("intensity"))})
        extra = counts.to_dataframe().reset_index() if config else pd.DataFrame({name: [float(counts[name])] for name in counts.data_vars})
        extra["runs beyond the model"] = [f"{int(k)} of {int(n)}" for k, n in zip(extra["collapsed"], extra["runs"])]
        extra = extra.drop(columns=["collapsed", "runs"])
        if "maf_lower" in self.collapse:  # where the stripes do not identify P(C | IM), λ_C is its extrapolation: what they bound it to
            loose = _dims_only(~identified(self.collapse))
            bounds = xr.Dataset({"loose": loose, "lower": _dims_only(self.collapse["maf_lower"]), "upper": _dims_only(self.collapse["maf_upper"])})
            table = bounds.to_dataframe().reset_index() if config else pd.DataFrame({name: [bounds[name].item()] for name in bounds.data_vars})
            table[COLLAPSE_BOUNDS] = [f"[{low:.3g}, {high:.3g}]" if flag else "identified" for flag, low, high in
                                      zip(table["loose"], table["lower"], table["upper"])]
            extra = extra.merge(table[[*config, COLLAPSE_BOUNDS]], on=config) if config else extra.assign(**{COLLAPSE_BOUNDS: table[COLLAPSE_BOUNDS]})
        merged = rows.merge(extra, on=config) if config else rows.assign(**{name: extra[name].iloc[0] for name in extra.columns})
        return merged.set_index([*config, "target"])

    def text(self, years: float = 50.0) -> str:
        """What the runs beyond the model are and how the answer counts them, in words."""
        theta, beta = self.collapse["theta"], self.collapse["beta"]
        fits = (f"θ = {float(theta.min()):.3g}" + (f"–{float(theta.max()):.3g}" if float(theta.max()) != float(theta.min()) else "")
                + f", β = {float(beta.min()):.2g}" + (f"–{float(beta.max()):.2g}" if float(beta.max()) != float(beta.min()) else ""))
        beyond = [target_text(float(p), years) for p in self.separation["target"].values
                  if bool(np.isinf(self.separation["separation"].sel(target=p)).any())]
        return (f"Collapse as FEMA P-58 treats it: {self.collapsed} of {self.runs} contact-free runs pass a {100 * MODEL_DRIFT_LIMIT:g} % "
                "storey drift, beyond what the model represents (no strength loss or collapse is modelled); they are counted apart as "
                f"collapses. P(C | IM) is a lognormal fitted over the stripes ({fits}; a step where the runs identify none), "
                f"λ_C = {float(self.collapse['maf'].min()):.3g}" + (f"–{float(self.collapse['maf'].max()):.3g}"
                if float(self.collapse["maf"].max()) != float(self.collapse["maf"].min()) else "") + f" /yr{self._unpinned_text()}; pounding is fitted on the "
                "credible runs only and combined with it by total probability, P(P | IM) = P(C | IM) + (1 − P(C | IM)) P(P | IM, no C), a "
                "collapse counted as reaching the gap. g* both ways: 'as run' keeps every run as computed; 'collapses apart' is the PBEE "
                "answer" + (f"; it is inf (no gap meets the target) where collapse alone is more frequent than the target allows "
                            f"({', '.join(beyond)}): there the structure, not the gap, governs" if beyond else "") + ".")


    def _unpinned_text(self) -> str:
        """Where the stripes do not identify P(C | IM) (its median beyond the top stripe, β ≥ 0.8, or a step), that λ_C rests on
        the fit's extrapolation and the bounds the stripes' fractions alone give it; "" where they identify it everywhere."""
        loose = ~identified(self.collapse)
        if not bool(loose.any()) or "maf_lower" not in self.collapse:
            return ""
        low, high = self.collapse["maf_lower"].where(loose), self.collapse["maf_upper"].where(loose)
        return (f" (the stripes do not identify P(C | IM) in {int(loose.sum())} of {int(loose.size)} configurations: a step, or a "
                "lognormal with its median beyond the top stripe or β ≥ 0.8, so λ_C there rests on the fit's extrapolation; the stripes' "
                f"fractions alone bound it to {float(low.min()):.3g}–{float(high.max()):.3g} /yr)")


def collapsed_runs(store: xr.Dataset, limit: float = MODEL_DRIFT_LIMIT) -> xr.DataArray | None:
    """1 where a contact-free run's peak storey drift ratio (any building) exceeds ``limit``, 0 where not, NaN where it
    did not run; None for a store without storey drift ratios."""
    summaries, _ = _inputs.run_summaries(store, ["peak_drift_ratio"])
    return beyond_model(summaries["peak_drift_ratio"], limit) if "peak_drift_ratio" in summaries else None


def beyond_model(drift: xr.DataArray, limit: float = MODEL_DRIFT_LIMIT) -> xr.DataArray:
    """1 where a run's peak storey drift ratio (the largest over a ``building`` dimension) exceeds ``limit``, 0 where not, NaN
    where it did not run: the runs beyond what the model represents, counted apart as collapses."""
    drift = drift.max("building") if "building" in drift.dims else drift
    return (drift > limit).astype(float).where(drift.notnull())


def rate_collapses_apart(demand: xr.DataArray, collapsed: xr.DataArray, thresholds: Sequence[float] | np.ndarray, dim: str,
                         hz: HazardCurve, collapse: xr.Dataset | None = None) -> tuple[xr.DataArray, xr.Dataset, xr.Dataset]:
    """λ (1/yr) of a demand reaching each threshold with the collapses counted apart (module docstring), the collapse fit and the
    credible runs' fit.

    A collapse counts as reaching every threshold (a building that has lost its storeys has met every limit state, FEMA P-58);
    the credible runs' fit of demand ≥ threshold and P(C | IM) are combined by total probability, ``combined_rate``.

    Parameters
    ----------
    demand : xarray.DataArray
        One value per run (dims ``intensity``, ``record`` and the configurations), in the thresholds' units.
    collapsed : xarray.DataArray
        :func:`beyond_model` of the same runs (1 collapse, 0 credible, NaN not run).
    thresholds : sequence of float
        The thresholds (a gap m, a capacity), along the new dimension ``dim``.
    dim : str
        The name of the thresholds' dimension.
    hz : HazardCurve
        The site's hazard.
    collapse : xarray.Dataset, optional
        ``collapse_fit`` of ``collapsed`` already made (several demands of the same runs share it); default fitted here.

    Returns
    -------
    tuple of xarray.DataArray, xarray.Dataset and xarray.Dataset
        λ over ``dim`` and the configurations; P(C | IM)'s stripe fit (:func:`~stochpound.risk.stripe_fragility`) with its
        ``maf``, λ_C; and the credible runs' stripe fit of demand ≥ each threshold, whose kind (a lognormal the runs identify
        or not, a step) says what λ rests on.
    """
    demand, collapsed = xr.align(demand, _dims_only(collapsed), join="inner")
    collapse = collapse_fit(collapsed, hz) if collapse is None else collapse
    credible = stripe_fragility(limit_state_events(demand.where(collapsed == 0.0), thresholds, dim), bootstrap=0)
    return combined_rate(collapse, credible, hz), collapse, credible


def collapse_fit(collapsed: xr.DataArray, hz: HazardCurve) -> xr.Dataset:
    """P(C | IM): the stripe fit (:func:`~stochpound.risk.stripe_fragility`, no bootstrap) of the runs beyond the model
    (:func:`beyond_model`: 1 collapse, 0 credible, NaN not run), with its ``maf``, λ_C (1/yr), and ``maf_lower``, ``maf_upper``,
    the bounds of λ_C the stripes' fractions alone give (:func:`~stochpound.risk.stripes_only_maf`,
    :func:`~stochpound.risk.stripes_upper_maf`)."""
    collapse = stripe_fragility(_dims_only(collapsed), bootstrap=0)
    collapse["maf"] = mean_annual_frequency(collapse, hz)
    collapse["maf_lower"], collapse["maf_upper"] = stripes_only_maf(collapse, hz), stripes_upper_maf(collapse, hz)
    return collapse


def collapse_risk(store: xr.Dataset, hz: HazardCurve, gaps: Sequence[float] | np.ndarray, targets: Sequence[float],
                  years: float = 50.0, limit: float = MODEL_DRIFT_LIMIT) -> CollapseRisk | None:
    """g* of a stripes store with the runs beyond the model counted as collapses (module docstring); None without storey drifts.

    Parameters
    ----------
    store : xarray.Dataset
        An experiment store with intensity stripes and contact-free runs.
    hz : HazardCurve
        The site's hazard.
    gaps : sequence of float
        The gap grid (m), ascending (the chain's: ``StoreRisk.fragility["gap"]``).
    targets : sequence of float
        Probabilities of pounding in ``years``.
    years : float
        Their exposure time.
    limit : float
        The peak storey drift ratio beyond which a run counts as a collapse.
    """
    collapsed = collapsed_runs(store, limit)
    if collapsed is None:
        return None
    closure, collapsed = xr.align(_inputs.contact_free_closure(store), _dims_only(collapsed), join="inner")
    maf, collapse, _ = rate_collapses_apart(closure, collapsed, gaps, "gap", hz)
    separation = risk_targeted_separation(xr.Dataset({"maf": maf}), targets, years)
    return CollapseRisk(collapse, separation, maf, int(collapsed.sum()), int(collapsed.notnull().sum()))


def combined_rate(collapse: xr.Dataset, pounding: xr.Dataset, hz: HazardCurve) -> xr.DataArray:
    """λ (1/yr) of P(C | x) + (1 − P(C | x)) P(P | x, no C), the two stripe fits integrated with the hazard (module docstring)."""
    levels = np.asarray(pounding["intensity"].values, dtype=float)
    lo, hi = hz.support
    start = np.log(lo) if lo > 0.0 else np.log(levels.min()) - BEYOND
    stop = np.log(hi) if np.isfinite(hi) else np.log(levels.max()) + BEYOND
    x = xr.DataArray(np.exp(np.linspace(start, stop, GRID_POINTS)), dims="im")
    probability = _fitted(collapse, x) + (1.0 - _fitted(collapse, x)) * _fitted(pounding, x)
    rate = xr.DataArray(np.exp(hz.log_rate(np.log(x.values))), dims="im")
    middle = xr.DataArray(0.5 * (rate.values[1:] + rate.values[:-1]), dims="im")
    steps = probability.diff("im", label="lower").drop_vars("im", errors="ignore") * middle
    total = probability.isel(im=0, drop=True) * rate[0].item() + steps.sum("im")
    return total.assign_attrs(units="1/yr", long_name="mean annual frequency of pounding, collapses counted apart")


def _fitted(fit: xr.Dataset, x: xr.DataArray) -> xr.DataArray:
    """F(x) of stripe fits: the lognormal (or step), and the pooled fraction Σk/Σn where the fit is ``decreasing`` (flat)."""
    curve = xr.apply_ufunc(lognormal_cdf, x, fit["theta"], fit["beta"])
    flat = fit["exceeded"].sum("intensity") / fit["runs"].sum("intensity")
    return curve.where(fit["status"] != DECREASING, flat)


def _dims_only(data: xr.DataArray) -> xr.DataArray:
    """``data`` without its coordinates that are not dimensions."""
    return data.drop_vars([name for name in data.coords if name not in data.dims])
