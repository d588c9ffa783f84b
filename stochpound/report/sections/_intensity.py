"""The "Intensity" section of a report: a store whose motions were scaled to intensity levels.

For a store made with an ``[intensity]`` table (docs/intensity.md) it gives:

* what ran (stripes or IDA, and why) and the measure;
* the response spectra (5 % damping) of the experiment's motions as
  recorded, and, for stripes, the motions' median and 16/84 % spectra
  scaled to each level;
* a table of every stripe: its level, the range of the scale factors and,
  per gap, the runs, those that pounded (at least one impact) and the
  probability of pounding with its 95 % Clopper–Pearson interval;
* per gap, that probability against intensity (for the contact-free runs,
  which never pound, at gaps near g*, from their closures); for IDA, the fraction of
  motions whose capacity is at most x, against x, with the same interval;
* for stripes whose hazard is a bundled site's curve, the site's hazard at
  its other measures recomputed from the stripes' motions against its own
  curves, and their ratio at the 10 % and 2 % in 50 years intensities
  (:func:`stochpound.risk.site_consistency`).

Other structural axes (μ, variants) give one line per combination.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import pandas as pd
import xarray as xr
from matplotlib.figure import Figure

from stochpound._plurals import counted
from stochpound.stats.kernels import clopper_pearson
from stochpound.report.render import FigureItem, Paragraph, Section, Table
from stochpound.report.sections._stripe_motions import stripe_motions_text
from stochpound.experiment import is_gap_axis
from stochpound.motions import DEFAULT_G, TARGET_TOLERANCE, TRUNCATION_EPSILON
from stochpound.risk import (
    TARGETS,
    consistency_at_targets,
    contact_free_closure,
    limit_state_events,
    rate_from_probability,
    selection_misses,
    site_consistency,
    stripes_beyond_truncation,
)
from stochpound.store import Intensity, has_contact_free, scenario_kind, stripe_holdings, with_contacts

CONFIDENCE = 0.95
SHOWN_GAPS = 3
"""Most gaps at which the contact-free runs' probability of pounding is drawn against intensity."""
CLOSURE = "peak_contact_closure"


def intensity_section(name: str, store: xr.Dataset, gaps: Sequence[float] = ()) -> Section:
    """The "Intensity" section of one store (call when ``store.pound.intensity`` is not None).

    ``gaps`` (m), the store's risk-targeted separations g* when it has a
    hazard, are where its contact-free runs' probability of pounding is drawn
    against intensity (without them: the quartiles of their closures).
    """
    setting = store.pound.intensity
    section = Section(f"Intensity: experiment {name}", key=f"intensity-{name}")
    section.add(Paragraph(method_text(store, setting)))
    section.add(_spectra(name, store, setting))
    if "intensity" in store.dims:
        section.add(_stripe_table(name, store, setting))
        section.add(_stripe_figure(name, store, setting, gaps))
        consistency = site_consistency(store)
        if "target_median" in store:
            section.add(Paragraph(_selection_text(store, setting) + _fitted_text(store, bool(consistency))))
            section.add(_selection_figure(name, store, setting))
        if consistency:
            section.add(Paragraph(_consistency_text(consistency, setting)))
            section.add(_consistency_figure(name, consistency, setting))
    elif "ida_capacity" in store:
        section.add(_ida_figure(name, store, setting))
    return section


def method_text(store: xr.Dataset, setting: Intensity) -> str:
    """What ran (stripes or IDA, and why), the measure and the levels: one paragraph of the section and of the methods."""
    levels = ", ".join(f"{level:g}" for level in setting.levels)
    text = (
        f"Intensity measure {setting.description}, in {setting.units}. Method requested: {setting.method}; ran: "
        f"{setting.ran} ({setting.note})."
    )
    if setting.ran == "stripes":
        return text + f" Levels {levels} {setting.units}: {stripe_motions_text(store)} (a scale factor is the level over the motion's own measure)."
    text += f" {counted(store.sizes['record'], 'motion')}"
    return text + ": each run once without contacts; a motion whose contacts close by D at scale 1 first pounds at gap g at the intensity IM·g/D."


def _cells(data: xr.DataArray, keep: tuple[str, ...]) -> list[tuple[str, xr.DataArray]]:
    """(label, data) per combination of the structural dimensions other than ``keep`` (and record, realization)."""
    others = [d for d in data.dims if d not in (*keep, "record", "realization")]
    if not others:
        return [("", data)]
    stacked = data.stack(cell=others)
    cells = []
    for i in range(stacked.sizes["cell"]):
        labels = stacked["cell"].values[i]
        labels = labels if isinstance(labels, tuple) else (labels,)
        cells.append((", ".join(f"{d}={v}" for d, v in zip(others, labels)), stacked.isel(cell=i, drop=True)))
    return cells


def _first_cell(data: xr.DataArray) -> xr.DataArray:
    """The values at the first index of every structural dimension (the motion's measures repeat along them)."""
    return data.isel({d: 0 for d in data.dims if d not in ("record", "realization", "spectrum_period", "intensity")})


def _spectra(name: str, store: xr.Dataset, setting: Intensity) -> FigureItem:
    periods = store["spectrum_period"].values
    psa = _first_cell(store["motion_psa"])
    done = _first_cell(store["case_status"]) == 1
    figure = Figure(figsize=(7.5, 4.0), layout="constrained")
    ax = figure.subplots()
    unscaled = psa.isel(intensity=0) if "intensity" in psa.dims else psa
    rows = unscaled.stack(motion=("record", "realization")).transpose("motion", ...).values / DEFAULT_G
    mask = (done.any("intensity") if "intensity" in done.dims else done).stack(motion=("record", "realization")).values  # a selection runs each motion at some stripes
    for row in rows[mask]:
        ax.loglog(periods, row, lw=0.4, color="0.8")
    if "intensity" in store.dims:
        scale = _first_cell(store["scale_factor"])
        for j, level in enumerate(store["intensity"].values):
            scaled = (psa.isel(intensity=j) * scale.isel(intensity=j)).stack(motion=("record", "realization")).transpose("motion", ...).values[mask] / DEFAULT_G
            low, median, high = np.nanpercentile(scaled, [16, 50, 84], axis=0)
            (line,) = ax.loglog(periods, median, lw=1.6, label=f"{level:g} {setting.units}: median, 16/84 %")
            ax.fill_between(periods, low, high, color=line.get_color(), alpha=0.15)
    ax.set_xlabel("period T (s)")
    ax.set_ylabel("PSA (g), 5 % damping")
    ax.grid(True, which="both", lw=0.3, color="0.85")
    if "intensity" in store.dims:
        ax.legend(fontsize=7)
    chosen = " chosen for some stripe" if "selection_scale_factor" in store else ""
    caption = f"Experiment {name}: response spectra (5 % damping) of the {counted(int(mask.sum()), 'motion')}{chosen}, as recorded (grey)"
    if "intensity" in store.dims:
        caption += "; at each level, the median and the 16-84 % band of the motions scaled to it"
    return FigureItem(f"intensity-spectra-{name}", caption + ".", figure)


def _pounding_counts(store: xr.Dataset) -> tuple[xr.DataArray, xr.DataArray]:
    """Runs done and runs with at least one impact, per structural cell (summed over record and realization)."""
    done = store["case_status"] == 1
    pounded = (store["impacts"].fillna(0) > 0) & done
    return done.sum(("record", "realization")), pounded.sum(("record", "realization"))


def _proportion(k: np.ndarray, n: np.ndarray) -> np.ndarray:
    """k / n, NaN where n = 0."""
    return np.where(n > 0, k / np.maximum(n, 1), np.nan)


def _probability_axes(ax: Any, setting: Intensity, label: str, legend: bool) -> None:
    """Axes of a probability against the intensity measure."""
    ax.set_xlabel(f"{setting.description} ({setting.units})")
    ax.set_ylabel(label)
    ax.set_ylim(-0.02, 1.02)
    ax.grid(True, lw=0.3, color="0.85")
    if legend:
        ax.legend(fontsize=7)


def _stripe_table(name: str, store: xr.Dataset, setting: Intensity) -> Table:
    runs, pounded = _pounding_counts(store)
    lower, upper = clopper_pearson(pounded.values, runs.values, CONFIDENCE)
    probability = xr.DataArray(_proportion(pounded.values, runs.values), runs.coords, runs.dims)
    # a run's impacts count its hits on a moat wall too: where a wall was hit, they are impacts, not pounding on the neighbour
    walls = "peak_wall_penetration" in store and bool((store["peak_wall_penetration"] > 0).any())
    event, probability_name = ("impacted", "P(impact)") if walls else ("pounded", "P(pounding)")
    counts = {event: pounded, probability_name: probability}
    if walls:
        counts["wall hit"] = ((store["peak_wall_penetration"] > 0) & (store["case_status"] == 1)).sum(("record", "realization"))
    frame = xr.Dataset({"runs": runs, **counts, "lower": (runs.dims, lower), "upper": (runs.dims, upper)}).to_dataframe()
    scale = _first_cell(store["scale_factor"]).where(_first_cell(store["case_status"]) == 1)
    factors = pd.DataFrame(
        {
            "scale min": scale.min(("record", "realization")).to_series(),
            "scale median": scale.median(("record", "realization")).to_series(),
            "scale max": scale.max(("record", "realization")).to_series(),
        }
    )
    holdings = stripe_holdings(store)
    frame = frame.reset_index().merge(factors.reset_index(), on="intensity").merge(holdings.reset_index(), on="intensity").set_index(list(runs.dims))
    what = ("runs with an impact (on the neighbour or on a moat wall: at gap = ∞ the contacts never close, so every impact there "
            "is a wall hit), the runs that hit a wall, and the probability of an impact" if walls else
            "runs that pounded and the probability of pounding")
    return Table(
        f"intensity-stripes-{name}",
        f"Experiment {name}: every stripe ({setting.description} in {setting.units}): scale factors, runs, {what} with its "
        f"{int(100 * CONFIDENCE)} % Clopper–Pearson interval, and the motions that ran there: their earthquakes (one name across "
        "suites: 'Northridge 1994' and 'Northridge-01 1994' are one), the largest share of one earthquake, the pulse records and "
        "the motions shared with the stripe below",
        frame,
        formats={"motions": "{:.0f}", "earthquakes": "{:.0f}", "shared with the stripe below": "{:.0f}",
                 "runs": "{:.0f}", event: "{:.0f}", "wall hit": "{:.0f}", probability_name: "{:.3f}", "lower": "{:.3f}", "upper": "{:.3f}"},
    )


def _stripe_figure(name: str, store: xr.Dataset, setting: Intensity, gaps: Sequence[float] = ()) -> FigureItem:
    """P(pounding) against intensity: per finite gap from the runs' impacts; for the contact-free runs (gap = ∞, which never
    pound) at gaps that mean something, from their closures (the gap identity): ``gaps`` (g*), else the closures' quartiles."""
    contact_free = has_contact_free(store) and CLOSURE in store
    finite = with_contacts(store) if contact_free else store
    figure = Figure(figsize=(7.5, 3.4), layout="constrained")
    ax = figure.subplots()
    levels = store["intensity"].values
    cells: list[tuple[str, xr.DataArray]] = []
    if all(finite.sizes[d] for d in finite["case_status"].dims):
        runs, pounded = _pounding_counts(finite)
        cells += _cells(xr.Dataset({"runs": runs, "pounded": pounded}).to_array("what"), ("intensity", "what"))
    shown = np.array([])
    if contact_free:
        closure = contact_free_closure(store)
        shown = _closure_gaps(closure, gaps)
        events = limit_state_events(closure, shown, "gap")
        counts = xr.Dataset({"runs": events.notnull().sum("record"), "pounded": events.sum("record")}).to_array("what")
        for gap in shown:
            for label, cell in _cells(counts.sel(gap=gap, drop=True), ("intensity", "what")):
                cells.append((", ".join(filter(None, [f"g = {gap:.3g} m (contact-free closures)", label])), cell))
    for label, cell in cells:
        n, k = cell.sel(what="runs").values, cell.sel(what="pounded").values
        lower, upper = clopper_pearson(k, n, CONFIDENCE)
        (line,) = ax.plot(levels, _proportion(k, n), "o-", label=label or None)
        ax.fill_between(levels, lower, upper, color=line.get_color(), alpha=0.15)
    _probability_axes(ax, setting, "P(pounding)", any(label for label, _ in cells))
    gap_dims = [d for d in finite["case_status"].dims if is_gap_axis(d) and finite.sizes[d]]
    per = " per " + ", ".join(gap_dims) if gap_dims else ""
    caption = f"Experiment {name}: probability of pounding against intensity{per}, with the stripes' {int(100 * CONFIDENCE)} % Clopper–Pearson intervals (shaded)"
    if shown.size:
        which = "the risk-targeted separations g*" if any(np.isfinite(g) and g > 0 for g in gaps) else "the quartiles of the contact-free closures"
        caption += (f"; at {_listed([f'{g:.3g} m' for g in shown])} ({which}), the contact-free runs' fraction whose contacts close by "
                    "that gap (they pound there, the gap identity)")
    return FigureItem(f"intensity-pounding-{name}", caption + ".", figure)


def _closure_gaps(closure: xr.DataArray, gaps: Sequence[float]) -> np.ndarray:
    """At most :data:`SHOWN_GAPS` gaps: the finite positive ``gaps`` (spread by their quantiles), else the closures' quartiles (m)."""
    values = np.asarray([g for g in gaps if np.isfinite(g) and g > 0], dtype=float)
    if values.size == 0:
        values = closure.values[np.isfinite(closure.values) & (closure.values > 0)]
        if values.size == 0:
            return np.array([])
        values = np.quantile(values, [0.25, 0.5, 0.75])
    elif np.unique(values).size > SHOWN_GAPS:
        values = np.quantile(values, np.linspace(0.0, 1.0, SHOWN_GAPS), method="nearest")
    return np.unique(values)


def _listed(items: list[str]) -> str:
    return items[0] if len(items) == 1 else ", ".join(items[:-1]) + " and " + items[-1]


def _selection_text(store: xr.Dataset, setting: Intensity) -> str:
    """The selection for the site: the scenario of every stripe and the stripes whose selection misses its target."""
    mixture = scenario_kind(store) == "ruptures"  # the exact conditional spectrum: the means of its mixture over the site's ruptures
    scenarios = "; ".join(
        f"{level:g} {setting.units}: " + (f"the ruptures' mean M {m:.3g} at {r:.3g} km (mean ε {e:.2f})" if mixture else f"M {m:g} at {r:g} km (ε {e:.2f})")
        for level, m, r, e in zip(store["intensity"].values, store["site_magnitude"].values, store["site_distance_km"].values, store["target_epsilon"].values)
    )
    missed = selection_misses(store)
    beyond = stripes_beyond_truncation(store)
    truncation = (
        ""
        if not beyond
        else f" At {'the stripe' if len(beyond) == 1 else 'the stripes'} {', '.join(f'{level:g}' for level in beyond)} {setting.units} the scenario's "
        f"ε is beyond {TRUNCATION_EPSILON:g}, where hazard models truncate the ground motion (the USGS models of the bundled curves do): "
        f"there no earthquake of that magnitude and distance causes the level, and {'the stripe stands' if len(beyond) == 1 else 'those stripes stand'} "
        "for larger or nearer ones than the scenario."
    )
    verdict = (
        f"Every stripe's selection matches its target within {TARGET_TOLERANCE:g} in the mean and the standard deviation of ln Sa at every period."
        if not missed
        else f"The selection misses its target (mean or standard deviation of ln Sa off by more than {TARGET_TOLERANCE:g} at a period) at the "
        f"stripes {', '.join(f'{level:g}' for level in missed)} {setting.units}: their motions do not represent the site's at that intensity."
    )
    return (f"The motions of every stripe were chosen for the site: the conditional spectrum of the stripe's scenario (Vs30 "
            f"{float(store['site_vs30'].values[0]):g} m/s, {store['site_mechanism'].values[0]} faulting): {scenarios}.{truncation} {verdict}"
            f"{_holdings(store, setting)}")


def _fitted_text(store: xr.Dataset, consistency: bool) -> str:
    """For stripes of a scenario fitted to the site's curves: what it stands for, and that this store cannot say what it costs in g*
    ("" for any other scenario); ``consistency``: the section shows the hazard consistency across the stripes."""
    if scenario_kind(store) != "fitted":
        return ""
    measured = " (how closely: the hazard consistency below)" if consistency else ""
    return (" The scenario was fitted to the site's hazard curves ([site] scenario = \"fitted\"): a calibration standing in for a "
            "disaggregation of the site's hazard, which the experiment does not give. One scenario serves every stripe, the one whose "
            f"conditional spectra give back the site's other curves best{measured}; it is not the earthquakes that cause each level, "
            "and every g* of this store is conditioned on it. What it costs in g* is not measured by this store: that takes the site's "
            "earthquakes, a site of ruptures, where the answer without an intensity measure checks the chain (docs/measure-free.md).")


def _holdings(store: xr.Dataset, setting: Intensity) -> str:
    """What every stripe holds: its recorded and simulated motions and its earthquakes ("" for a store that does not say)."""
    if "selection_recorded" not in store:
        return ""
    earthquakes = stripe_holdings(store)["earthquakes"]  # one name across suites (the stored count predates it in older stores)
    stripes = "; ".join(
        f"{level:g} {setting.units}: {int(recorded)} recorded and {int(simulated)} simulated from {int(earthquakes.loc[level])} earthquakes"
        for level, recorded, simulated in zip(store["intensity"].values, store["selection_recorded"].values, store["selection_simulated"].values)
    )
    return f" The stripes hold (each simulated motion its own earthquake) {stripes}."


def _selection_figure(name: str, store: xr.Dataset, setting: Intensity) -> FigureItem:
    """Per stripe: the target's median and 16/84 % spectra against the chosen set's (exp of mean ± std of ln Sa)."""
    periods = store["selection_period"].values
    levels = store["intensity"].values
    columns = min(levels.size, 4)
    rows = -(-levels.size // columns)
    figure = Figure(figsize=(7.5, 2.2 * rows + 0.4), layout="constrained")
    axes = np.atleast_1d(figure.subplots(rows, columns, sharex=True, sharey=True, squeeze=False)).ravel()
    for j, level in enumerate(levels):
        ax = axes[j]
        median, sigma = store["target_median"].values[j], store["target_sigma_ln"].values[j]
        mean_ln, std_ln = store["selection_mean_ln"].values[j], store["selection_std_ln"].values[j]
        ax.loglog(periods, median, color="k", lw=1.4, label="target")
        ax.loglog(periods, median * np.exp(-sigma), "k--", lw=0.8)
        ax.loglog(periods, median * np.exp(sigma), "k--", lw=0.8)
        ax.loglog(periods, np.exp(mean_ln), color="C3", lw=1.2, label="chosen")
        ax.fill_between(periods, np.exp(mean_ln - std_ln), np.exp(mean_ln + std_ln), color="C3", alpha=0.2)
        factors = store["selection_scale_factor"].values[j]
        factors = factors[np.isfinite(factors)]
        ax.set_title(f"{level:g} {setting.units}: scale {factors.min():.2g}-{factors.max():.2g}", fontsize=8)
        ax.grid(True, which="both", lw=0.3, color="0.85")
    for ax in axes[levels.size :]:
        ax.set_visible(False)
    axes[0].legend(fontsize=7)
    figure.supxlabel("period T (s)", fontsize=9)
    figure.supylabel("PSA (g), 5 % damping", fontsize=9)
    return FigureItem(
        f"intensity-selection-{name}",
        f"Experiment {name}: per stripe, the conditional spectrum's median and 16/84 % spectra (black, dashed) against the chosen, "
        "scaled motions' (red: the exponential of the mean and of the mean ± the standard deviation of ln Sa), and the range of their scale factors.",
        figure,
    )


def _consistency_text(consistency: dict[str, xr.Dataset], setting: Intensity) -> str:
    """How far the site's hazard at its other periods, recomputed from the stripes' motions, lies from its own curves."""
    targets = _targets_text()
    parts = []
    for label, result in consistency.items():
        ratios = consistency_at_targets(result)
        shown = "/".join("beyond the curve" if np.isnan(r) else f"{r:.2f}" for r in ratios)
        parts.append(f"{label} {shown}")
    return (f"Hazard consistency across the stripes: the site's hazard at its other measures recomputed from the stripes' motions as "
            f"they ran, λ(Sa(T') > y) ≈ Σ_j P(Sa(T') > y | {setting.description} = x_j) Δλ(x_j), with P the fraction of stripe j's "
            f"scaled motions above y and Δλ the site's rate of the stripe's bin, is {'; '.join(parts)} times the site's own curve at its "
            f"intensities of {targets} in 50 years. A ratio near 1 says the stripes represent the site at that period; "
            "well above 1, the motions carry too much of that period's shaking for the site, below 1 too little.")


def _targets_text() -> str:
    return " and ".join(f"{100 * p:g} %" for p in TARGETS)


def _consistency_figure(name: str, consistency: dict[str, xr.Dataset], setting: Intensity) -> FigureItem:
    """Per other measure of the site: its own hazard curve against the one recomputed from the stripes."""
    columns = len(consistency)
    figure = Figure(figsize=(7.5, 2.8), layout="constrained")
    axes = np.atleast_1d(figure.subplots(1, columns, sharey=True, squeeze=False)).ravel()
    for ax, (label, result) in zip(axes, consistency.items()):
        y = result["im"].values
        ax.loglog(y, result["site"].values, color="k", lw=1.4, label="site")
        recomputed = np.where(result["recomputed"].values > 0, result["recomputed"].values, np.nan)
        ax.loglog(y, recomputed, "o-", color="C3", ms=3, lw=1.0, label="from the stripes")
        for rate in rate_from_probability(np.asarray(TARGETS)):
            ax.axhline(rate, color="0.5", lw=0.6, ls=":")
        ax.set_title(label, fontsize=8)
        ax.set_xlabel(f"{label} (g)", fontsize=8)
        ax.grid(True, which="both", lw=0.3, color="0.85")
    axes[0].set_ylabel("annual rate of exceedance (1/yr)")
    axes[0].legend(fontsize=7)
    return FigureItem(
        f"intensity-consistency-{name}",
        f"Experiment {name}: the site's hazard curves at its other measures (black) against the ones recomputed from the stripes of "
        f"{setting.description}, in red: the fraction of every stripe's scaled motions above the intensity, weighted by the site's "
        f"rate of the stripe's bin; dotted: the rates of {_targets_text()} in 50 years.",
        figure,
    )


def _ida_figure(name: str, store: xr.Dataset, setting: Intensity) -> FigureItem:
    capacity = store["ida_capacity"].where(store["case_status"] == 1)
    figure = Figure(figsize=(7.5, 3.4), layout="constrained")
    ax = figure.subplots()
    finite = capacity.values[np.isfinite(capacity.values)]
    top = float(np.max(finite)) * 1.1 if finite.size else 1.0
    grid = np.linspace(0.0, top, 200)
    cells = _cells(capacity, ())
    for label, cell in cells:
        values = cell.values.ravel()
        values = values[~np.isnan(values)]
        k = np.array([(values <= x).sum() for x in grid])
        lower, upper = clopper_pearson(k, np.full(grid.shape, values.size), CONFIDENCE)
        (line,) = ax.step(grid, k / max(values.size, 1), where="post", label=label or None)
        ax.fill_between(grid, lower, upper, step="post", color=line.get_color(), alpha=0.15)
    _probability_axes(ax, setting, "P(pounding) (fraction of motions)", any(label for label, _ in cells))
    return FigureItem(
        f"intensity-ida-{name}",
        f"Experiment {name}: fraction of motions whose IDA capacity is at most x (they pound when scaled to x), per gap, with "
        f"{int(100 * CONFIDENCE)} % Clopper–Pearson intervals (shaded).",
        figure,
    )
