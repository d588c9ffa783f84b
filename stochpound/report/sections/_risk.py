"""The "Risk" section of a report: pounding risk at the site of a store's hazard.

For a store with intensity stripes (or IDA capacities) and a hazard curve
(its experiment's ``[hazard]`` table; docs/risk.md), the section gives:

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

:func:`store_headline` returns the g* numbers alone (one row per configuration
and target, with the interval and the number of motions), for a summary.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pandas as pd
import xarray as xr
from matplotlib.figure import Figure

from stochpound.analysis import HazardCurve, demand_hazard_curve, fragility_band, fragility_surface, rate_from_probability
from stochpound.analysis._fragility_ensemble import BOOTSTRAP
from stochpound.analysis._risk import TARGETS
from stochpound.analysis._gap_axes import contact_free, wall_free
from stochpound.analysis._store_risk import StoreRisk, base_displacement, store_motions, store_risk
from stochpound.experiment._definition import read_definition
from stochpound.experiment._hazard import stored_hazard, stored_hazard_entry
from stochpound.experiment._intensity import describe_measure
from stochpound.report.render import Block, FigureItem, Paragraph, Section, Table
from stochpound.report.sections._facets import labels_text
from stochpound.report.sections._intensity import intensity_setting
from stochpound.report.sections._summary import RISK_ANSWERS

CONFIDENCE = 0.95
YEARS = 50.0
CURVE_GAPS = 3
"""Fragility curves drawn per configuration (at gaps spread over the risk curve's range)."""
DEMAND_LEVELS = 40
"""Levels of each demand hazard curve."""
RULE_NAMES = {
    "abs": "ABS",
    "srss": "SRSS (ASCE 7 δ_MT)",
    "srss_reduced": "0.7 SRSS (Eurocode 8)",
    "ddc": "DDC",
    "ddc_cqc": "DDC (CQC ρ)",
    "dtm": "D_TM (ASCE 7 §17.2.5.2)",
}
DEMANDS = {
    "peak_interstorey_drift": ("peak storey drift", "m", 1.0),
    "peak_floor_acceleration": ("peak floor acceleration", "g", 1.0 / 9.81),
}
"""Demands of a store with ``[output] demands = true`` drawn as hazard curves: (name, display units, factor from SI)."""
_CACHE: dict[tuple[str, str, int], StoreRisk] = {}


def has_risk(store: xr.Dataset) -> bool:
    """Whether a store gets a Risk section: intensity levels (stripes or IDA) and a stored hazard."""
    return intensity_setting(store) is not None and stored_hazard(store) is not None and ("intensity" in store.dims or "ida_capacity" in store)


def hazard_provenance(store: xr.Dataset) -> str:
    """Where a store's hazard curve comes from, in a sentence ("" without one): its source, range and provenance lines."""
    entry = stored_hazard_entry(store)
    if entry is None:
        return ""
    given = {"file": lambda: f"the file {entry['file']} (sha256 {entry['file_sha256']})", "bundled": lambda: f"the bundled curve {entry['bundled']}",
             "power_law": lambda: f"the power law {entry['power_law']['k0']:g} x^-{entry['power_law']['k']:g}"}[entry["source"]]()
    table = (f", a table of {len(entry['im'])} intensities from {entry['im'][0]:g} to {entry['im'][-1]:g} {entry['units']} "
             f"(log-log interpolation{', extrapolated beyond it as power laws' if entry['extrapolate'] else '; no extrapolation'})"
             if "im" in entry else "")
    provenance = " ".join(line.strip() for line in entry["provenance"].splitlines())
    return f"hazard curve ({describe_measure(entry)} in {entry['units']}) from {given}{table}, carried in the store. Provenance: {provenance}"


def risk_of(store: xr.Dataset, hz: HazardCurve | None = None, bootstrap: int = BOOTSTRAP, seed: int = 0) -> StoreRisk:
    """:func:`~stochpound.analysis.store_risk.store_risk` of a store at its own hazard (or ``hz``), once per store and hazard."""
    hazard = stored_hazard(store) if hz is None else hz
    if hazard is None:
        raise ValueError("store: has no [hazard]; give a hazard curve")
    key = (str(store.attrs.get("definition_sha256", "")) + str(store.attrs.get("updated", "")), repr(hazard) + hazard.source, bootstrap)
    if key not in _CACHE:
        _CACHE[key] = store_risk(store, hazard, TARGETS, YEARS, studied=store.attrs.get("studied_building"), confidence=CONFIDENCE,
                                 bootstrap=bootstrap, seed=seed)
    return _CACHE[key]


# ---------------------------------------------------------------- numbers and tables


def configurations(data: xr.DataArray | xr.Dataset, keep: tuple[str, ...] = ()) -> list[dict[str, Any]]:
    """The labels of every configuration: each combination of ``data``'s dimensions other than ``keep``."""
    dims = [d for d in data.dims if d not in keep]
    if not dims:
        return [{}]
    index = pd.MultiIndex.from_product([data[d].values for d in dims], names=dims)
    return [dict(zip(dims, values)) for values in index]


def risk_headline(risk: StoreRisk) -> pd.DataFrame:
    """The g* numbers: one row per configuration and target.

    Returns
    -------
    pandas.DataFrame
        Columns: the configuration's dimensions, ``target`` (probability in
        50 years), ``separation``, ``lower``, ``upper`` (m; ``inf``: wider
        than every gap of the grid), ``confidence``, ``motions``.
    """
    separation = risk.separation
    for bound in ("lower", "upper"):  # absent without a bootstrap
        if bound not in separation:
            separation = separation.assign({bound: xr.full_like(separation["separation"], np.nan)})
    frame = _grid_only(separation[["separation", "lower", "upper"]]).to_dataframe().reset_index()
    frame = frame.drop(columns=[c for c in ("target_rate",) if c in frame])
    return frame.assign(confidence=CONFIDENCE, motions=risk.motions)


def store_headline(store: xr.Dataset) -> pd.DataFrame | None:
    """:func:`risk_headline` of a store at its own hazard (None when it gets no Risk section); computed once per build."""
    return risk_headline(risk_of(store)) if has_risk(store) else None


def separation_frame(risk: StoreRisk) -> pd.DataFrame:
    """The g* table: per configuration, g* and its interval for each target (columns grouped by target)."""
    frame = risk_headline(risk)
    years = float(risk.separation.attrs.get("years", YEARS))
    config = [c for c in frame.columns if c not in ("target", "separation", "lower", "upper", "confidence", "motions")]
    frame["target"] = [_target_text(p, years) for p in frame["target"]]
    table = frame.set_index([*config, "target"])[["separation", "lower", "upper"]].rename(columns={"separation": "g* (m)", "lower": "lower (m)", "upper": "upper (m)"})
    if config:
        table = table.unstack("target")
        table.columns = table.columns.swaplevel(0, 1)
        order = [_target_text(p, years) for p in risk.separation["target"].values]
        table = table.reindex(columns=pd.MultiIndex.from_product([order, ["g* (m)", "lower (m)", "upper (m)"]]))
    return table


def rules_frame(risk: StoreRisk) -> pd.DataFrame:
    """The code rules in risk terms: per configuration, design level and rule, its gap per contact and the MAF of pounding there."""
    rules = risk.rules
    if rules is None:
        return pd.DataFrame()
    rules = _grid_only(rules, keep=("code_intensity", "stripe_intensity"))
    years = float(rules.attrs.get("years", YEARS))
    gaps = rules["gap"].to_dataframe()["gap"].unstack("contact")
    gaps.columns = [f"gap, contact {c} (m)" for c in gaps.columns]
    values = rules[[name for name in ("maf", "maf_lower", "maf_upper", "return_period", "probability") if name in rules]].to_dataframe()
    frame = gaps.join(values)
    frame = frame.rename(columns={"maf": "λ_P (1/yr)", "maf_lower": "λ_P lower", "maf_upper": "λ_P upper", "return_period": "once in (yr)",
                                  "probability": f"P in {years:g} yr"})
    frame = frame.reset_index()
    frame["design_level"] = [_design_text(p, float(i), years) for p, i in zip(frame["design_level"], frame["stripe_intensity"])]
    frame["rule"] = [RULE_NAMES.get(r, r) for r in frame["rule"]]
    frame = frame.drop(columns=[c for c in ("code_intensity", "stripe_intensity") if c in frame])
    index = [c for c in frame.columns if not c.startswith("gap, ") and c not in ("λ_P (1/yr)", "λ_P lower", "λ_P upper", "once in (yr)", f"P in {years:g} yr")]
    return frame.set_index(index).dropna(how="all")


def _grid_only(data: xr.Dataset, keep: tuple[str, ...] = ()) -> xr.Dataset:
    """``data`` without its coordinates that are not dimensions (what each grid point ran: friction and law parameters), but ``keep``."""
    return data.drop_vars([name for name in data.coords if name not in data.dims and name not in keep])


def _target_text(probability: float, years: float = YEARS) -> str:
    return f"{100 * probability:g} % in {years:g} yr"


def _design_text(probability: float, stripe: float, years: float = YEARS) -> str:
    return f"{100 * probability:g} %/{years:g} yr (stripe {stripe:g})"


def _gap_text(value: float) -> str:
    return "wider than every gap of the grid" if math.isinf(value) else f"{value:.3f} m"


def headline_text(name: str, store: xr.Dataset, risk: StoreRisk) -> str:
    """The section's first paragraph: g* for each target, per configuration, with its interval and the number of motions."""
    setting = intensity_setting(store)
    frame = risk_headline(risk)
    config = [c for c in frame.columns if c not in ("target", "separation", "lower", "upper", "confidence", "motions")]
    targets = " and ".join(_target_text(p) for p in risk.separation["target"].values)
    per = []
    for labels, rows in (frame.groupby(config, sort=False) if config else [((), frame)]):
        labels = labels if isinstance(labels, tuple) else (labels,)
        values = "; ".join(f"{_gap_text(row.separation)} for {_target_text(row.target)} [{_gap_text(row.lower)}, {_gap_text(row.upper)}]"
                           for row in rows.itertuples())
        per.append(f"{labels_text(dict(zip(config, labels))) or 'the scene'}: {values}")
    stripes = f"{store.sizes['intensity']} stripes of " if "intensity" in store.dims else "IDA capacities in "
    return (
        f"Risk-targeted separation g* (the gap whose mean annual frequency of pounding is that of {targets}, Poisson) of experiment "
        f"{name}, from {risk.motions} motions ({stripes}{describe_measure(setting)} in {setting['units']}) at the site of its hazard curve, "
        f"with {int(100 * CONFIDENCE)} % BCa bootstrap intervals over the motions: " + ". ".join(per) + "."
    )


def summary_answer(name: str, store: xr.Dataset) -> list[Block]:
    """The summary's answer to "which gap meets a target risk?" (a builder of :data:`stochpound.report.sections._summary.RISK_ANSWERS`)."""
    return [Paragraph(headline_text(name, store, risk_of(store)))] if has_risk(store) else []


RISK_ANSWERS.append(summary_answer)


# ---------------------------------------------------------------- the section


def risk_section(name: str, store: xr.Dataset) -> Section:
    """The "Risk" section of one store (call when :func:`has_risk` is true)."""
    risk = risk_of(store)
    setting = intensity_setting(store)
    section = Section(f"Risk: experiment {name}", key=f"risk-{name}")
    section.add(Paragraph(headline_text(name, store, risk)))
    section.add(Paragraph(_hazard_text(risk.hazard, setting, risk.method)))
    section.add(Table(f"risk-separation-{name}", f"Experiment {name}: risk-targeted separation g* per configuration and target, with its "
                      f"{int(100 * CONFIDENCE)} % BCa bootstrap interval over the {risk.motions} motions", separation_frame(risk),
                      note=_grid_note(risk), formats={"g* (m)": "{:.3f}", "lower (m)": "{:.3f}", "upper (m)": "{:.3f}"}))
    section.add(_risk_curve_figure(name, risk, setting))
    section.add(_surface_figure(name, risk, setting))
    section.add(_curves_figure(name, risk, setting))
    for block in _rules_blocks(name, risk):
        section.add(block)
    for block in _demand_blocks(name, store, risk, setting):
        section.add(block)
    return section


def _hazard_text(hz: HazardCurve, setting: dict[str, Any], method: str) -> str:
    levels = {p: float(hz.intensity_at(rate_from_probability(p, YEARS))) for p in (0.10, 0.02)}
    source = hz.source.splitlines()[0] if hz.source else ""
    fitted = ("fitted to the stripes' counts by maximum likelihood, from the contact-free runs by the gap identity" if method == "stripes"
              else "of the motions' IDA capacities IM·g/D (log-moments), from one contact-free run per motion")
    extrapolated = " The hazard was extrapolated beyond its table (as a power law) for some integrals." if hz.extrapolated else ""
    return (
        f"Hazard curve {repr(hz)} of {describe_measure(setting)} in {setting['units']} ({source}); its 10 %/50 yr intensity is "
        f"{levels[0.10]:.3g} and its 2 %/50 yr intensity {levels[0.02]:.3g} {setting['units']}. The fragility of every gap is the "
        f"lognormal {fitted}; λ_P(g) = ∫ F(x; g) |dλ(x)|; the intervals resample the motions and refit the whole chain. Assumptions: Poisson "
        "occurrence, record-to-record variability only (not the hazard's or the model's uncertainty), and a suite scaled to each "
        f"intensity standing for the site's motions of that intensity.{extrapolated}"
    )


def _grid_note(risk: StoreRisk) -> str:
    gaps = risk.curve["gap"].values
    return (f"g* is interpolated on a grid of {gaps.size} gaps from {gaps[0]:.3g} to {gaps[-1]:.3g} m (log-spaced over the contact-free "
            "closures); λ_P(g) is made non-increasing along it.")


def _panel_grid(count: int, height: float = 2.6) -> tuple[Figure, list[Any]]:
    columns = min(count, 2)
    rows = int(math.ceil(count / columns))
    figure = Figure(figsize=(7.5, height * rows), layout="constrained")
    return figure, list(np.atleast_1d(figure.subplots(rows, columns, squeeze=False)).ravel())


def _risk_curve_figure(name: str, risk: StoreRisk, setting: dict[str, Any]) -> FigureItem:
    curve = risk.curve
    gaps = curve["gap"].values
    figure = Figure(figsize=(7.5, 4.2), layout="constrained")
    ax = figure.subplots()
    for labels in configurations(curve["maf"], ("gap",)):
        cell = curve.sel(labels)
        maf = _non_increasing(cell["maf"].values)
        (line,) = ax.loglog(gaps, np.where(maf > 0, maf, np.nan), lw=1.4, label=labels_text(labels) or None)
        if "maf_lower" in cell:
            ax.fill_between(gaps, cell["maf_lower"].values, cell["maf_upper"].values, color=line.get_color(), alpha=0.12)
        for value in risk.separation["separation"].sel(labels).values:
            if np.isfinite(value):
                ax.axvline(value, color=line.get_color(), lw=0.6, ls=":")
    for p, style in zip(risk.separation["target"].values, ("--", "-.", ":")):
        ax.axhline(float(rate_from_probability(p, YEARS)), color="k", lw=0.8, ls=style, label=f"target: {_target_text(p)}")
    ax.set_xlabel("gap g (m)")
    ax.set_ylabel("λ_P: pounding per year")
    ax.grid(True, which="both", lw=0.3, color="0.85")
    ax.legend(fontsize=6)
    return FigureItem(f"risk-curve-{name}", f"Experiment {name}: the pounding risk curve λ_P(g) per configuration (made non-increasing "
                      f"along g) with its {int(100 * CONFIDENCE)} % bootstrap band (shaded), the targets (black) and g* (dotted verticals).",
                      figure)


def _non_increasing(maf: np.ndarray) -> np.ndarray:
    """The running minimum of a rate along its thresholds (a higher threshold cannot be exceeded more often; a rise is fitting noise)."""
    return np.fmin.accumulate(np.where(np.isnan(maf), np.inf, maf))


def _surface_figure(name: str, risk: StoreRisk, setting: dict[str, Any]) -> FigureItem:
    fragility = risk.fragility
    gaps = fragility["gap"].values
    levels = _im_axis(fragility, risk.hazard)
    cells = configurations(fragility["theta"], ("gap",))
    figure, axes = _panel_grid(len(cells))
    surface = fragility_surface(fragility, levels)
    mesh = None
    for ax, labels in zip(axes, cells):
        values = surface.sel(labels).transpose("gap", "im").values
        mesh = ax.pcolormesh(levels, gaps, values, vmin=0.0, vmax=1.0, cmap="viridis", shading="auto")
        ax.contour(levels, gaps, values, levels=[0.1, 0.5, 0.9], colors="w", linewidths=0.6)
        ax.set_yscale("log")
        ax.set_title(labels_text(labels) or name, fontsize=7)
        ax.set_xlabel(f"{_measure_label(setting)}", fontsize=7)
        ax.set_ylabel("gap (m)", fontsize=7)
        ax.tick_params(labelsize=6)
    for ax in axes[len(cells):]:
        ax.set_visible(False)
    if mesh is not None:
        figure.colorbar(mesh, ax=axes[:len(cells)], label="P(pounding | IM, gap)", shrink=0.8)
    return FigureItem(f"risk-surface-{name}", f"Experiment {name}: the fitted pounding fragility over (IM, gap), one panel per "
                      "configuration; white lines at 10, 50 and 90 %.", figure)


def _curves_figure(name: str, risk: StoreRisk, setting: dict[str, Any]) -> FigureItem:
    fragility = risk.fragility
    levels = _im_axis(fragility, risk.hazard)
    cells = configurations(fragility["theta"], ("gap",))
    figure, axes = _panel_grid(len(cells))
    shown = _curve_gaps(risk)
    band = fragility_band(fragility.sel(gap=shown), levels, CONFIDENCE) if "theta_bootstrap" in fragility else None
    for ax, labels in zip(axes, cells):
        for gap in shown:
            fit = fragility_surface(fragility.sel(gap=gap).sel(labels), levels).values
            (line,) = ax.plot(levels, fit, lw=1.2, label=f"g = {gap:.3g} m")
            if band is not None:
                cell = band.sel(gap=gap).sel(labels)
                ax.fill_between(levels, cell["lower"].values, cell["upper"].values, color=line.get_color(), alpha=0.15)
            if "probability" in fragility:
                points = fragility.sel(gap=gap).sel(labels)
                x = points["intensity"].values
                p = points["probability"].values
                ax.errorbar(x, p, yerr=[p - points["probability_lower"].values, points["probability_upper"].values - p], fmt="o",
                            ms=3, color=line.get_color(), capsize=2, lw=0.8)
        ax.set_title(labels_text(labels) or name, fontsize=7)
        ax.set_xlabel(_measure_label(setting), fontsize=7)
        ax.set_ylabel("P(pounding)", fontsize=7)
        ax.set_ylim(-0.02, 1.02)
        ax.tick_params(labelsize=6)
        ax.grid(True, lw=0.3, color="0.85")
        ax.legend(fontsize=6)
    for ax in axes[len(cells):]:
        ax.set_visible(False)
    points = " with the stripes' empirical points and their Clopper–Pearson intervals" if "probability" in fragility else ""
    return FigureItem(f"risk-fragility-{name}", f"Experiment {name}: fitted pounding fragility at {len(shown)} gaps with its "
                      f"{int(100 * CONFIDENCE)} % bootstrap band (shaded){points}, one panel per configuration.", figure)


def _curve_gaps(risk: StoreRisk) -> np.ndarray:
    """Grid gaps at which curves are drawn: nearest to the quartiles (in ln g) of the finite g* values, else spread over the grid."""
    gaps = risk.fragility["gap"].values
    found = risk.separation["separation"].values
    found = found[np.isfinite(found) & (found > gaps[0])]
    if found.size:
        wanted = np.exp(np.quantile(np.log(found), np.linspace(0.0, 1.0, CURVE_GAPS)))
    else:
        wanted = np.geomspace(gaps[0], gaps[-1], CURVE_GAPS + 2)[1:-1]
    return np.unique(gaps[[int(np.argmin(np.abs(np.log(gaps) - np.log(w)))) for w in wanted]])


def _im_axis(fragility: xr.Dataset, hz: HazardCurve) -> np.ndarray:
    top = float(fragility["intensity"].values.max()) if "intensity" in fragility.coords else float(hz.intensity_at(rate_from_probability(0.02, YEARS)))
    return np.linspace(top / 200.0, 1.1 * top, 120)


def _measure_label(setting: dict[str, Any]) -> str:
    return f"{describe_measure(setting)} ({setting['units']})"


def _rules_blocks(name: str, risk: StoreRisk) -> list[Block]:
    if risk.rules is None:
        return [Paragraph(f"Code rules in risk terms: not evaluated for experiment {name}: {risk.rules_note}.")]
    rules = risk.rules
    code = ", ".join(f"{100 * p:g} %/{YEARS:g} yr: {float(c):.3g} (stripe {float(s):g})" for p, c, s in
                     zip(rules["design_level"].values, rules["code_intensity"].values, rules["stripe_intensity"].values))
    frame = rules_frame(risk)
    worst = rules["return_period"].where(np.isfinite(rules["return_period"]))
    text = (
        f"Code rules in risk terms (experiment {name}): each rule's gap is computed from the suite means of the stripe nearest the "
        f"code intensity (the hazard's intensities, and the stripes used: {code}); its risk is the mean annual frequency of pounding "
        f"at that gap, fitted over every stripe: 'this rule means pounding once in N years here'. Over the rules, levels and "
        f"configurations, the return periods range from {float(worst.min()):.3g} to {float(worst.max()):.3g} years."
    )
    if "dtm" not in rules["rule"].values:
        text += " D_TM is not applied: the studied building has no sliding base in this store."
    table = Table(f"risk-rules-{name}", f"Experiment {name}: the code separation rules in risk terms: the gap at each contact, the "
                  f"mean annual frequency λ_P of pounding at it with its {int(100 * CONFIDENCE)} % bootstrap interval, the return period "
                  f"and the probability in {YEARS:g} years", frame,
                  formats={"λ_P (1/yr)": "{:.3g}", "λ_P lower": "{:.3g}", "λ_P upper": "{:.3g}", "once in (yr)": "{:.3g}",
                           f"P in {YEARS:g} yr": "{:.3f}", **{c: "{:.3f}" for c in frame.columns if str(c).startswith("gap")}})
    return [Paragraph(text), table]


def _demand_blocks(name: str, store: xr.Dataset, risk: StoreRisk, setting: dict[str, Any]) -> list[Block]:
    """Demand hazard curves of a stripes store: base displacement (and the moat walls' clearance), drift, floor acceleration."""
    if "intensity" not in store.dims:
        return []
    free = wall_free(contact_free(store))  # the runs without impacts: contacts open, walls never reached
    studied = store.attrs.get("studied_building")
    demands: dict[str, tuple[xr.DataArray, str]] = {}
    sliding = base_displacement(free, studied)
    if sliding is not None:
        demands[f"peak base displacement of {studied}"] = (sliding, "m")
    for variable, (label, units, factor) in DEMANDS.items():
        if variable in free:
            for building in free["building"].values:
                demands[f"{label} of {building}"] = (store_motions(free[variable].sel(building=building, drop=True)) * factor, units)
    if not demands:
        return []
    figure, axes = _panel_grid(len(demands), 2.5)
    curves = {}
    for ax, (label, (demand, units)) in zip(axes, demands.items()):
        values = demand.values[np.isfinite(demand.values) & (demand.values > 0)]
        levels = np.geomspace(np.quantile(values, 0.01), values.max(), DEMAND_LEVELS)
        curve = demand_hazard_curve(demand, levels, risk.hazard, confidence=CONFIDENCE, bootstrap=0)
        curves[label] = curve
        for labels in configurations(curve["maf"], ("level",)):
            maf = _non_increasing(curve["maf"].sel(labels).values)
            ax.loglog(levels, np.where(maf > 0, maf, np.nan), lw=1.1, label=labels_text(labels) or None)
        ax.set_title(label, fontsize=7)
        ax.set_xlabel(f"{label} ({units})", fontsize=7)
        ax.set_ylabel("exceedances per year", fontsize=7)
        ax.tick_params(labelsize=6)
        ax.grid(True, which="both", lw=0.3, color="0.85")
    for ax in axes[len(demands):]:
        ax.set_visible(False)
    if axes[0].get_legend_handles_labels()[1]:
        axes[0].legend(fontsize=5)
    blocks: list[Block] = [FigureItem(f"risk-demands-{name}", f"Experiment {name}: demand hazard curves (mean annual frequency of "
                                      "exceeding each level, the lognormal fragility of every level fitted over the stripes' "
                                      "contact-free runs and integrated with the hazard, made non-increasing along the level), per "
                                      "configuration.", figure)]
    base = next((label for label in demands if label.startswith("peak base displacement")), None)
    moats = _moat_clearances(store, studied)
    if base is not None and moats:
        blocks.append(_moat_table(name, demands[base][0], moats, risk.hazard))
    return blocks


def _moat_clearances(store: xr.Dataset, studied: str | None) -> list[float]:
    """The distinct gaps of the walls at the studied building's base in the definition (its scene, with the values of a gap axis
    that sets a wall instead of its own gap, and its variants), finite ones only."""
    definition = read_definition(store)
    walls = [(w, axis.values if axis is not None else (w["gap"],)) for w, axis in
             ((w, definition.wall_gap_axis(index)) for index, w in enumerate(definition.scene.get("wall", [])))]
    for variant in definition.variants:
        for override in variant.overrides.values():
            walls += [(w, (w["gap"],)) for w in override.get("scene", {}).get("wall", []) or []]
    return sorted({float(gap) for w, gaps in walls for gap in gaps
                   if w.get("building") == studied and w.get("level", 0) == 0 and math.isfinite(float(gap))})


def _moat_table(name: str, sliding: xr.DataArray, clearances: list[float], hz: HazardCurve) -> Table:
    curve = demand_hazard_curve(sliding, clearances, hz, confidence=CONFIDENCE, bootstrap=BOOTSTRAP)
    frame = curve[["maf", "maf_lower", "maf_upper", "return_period", "probability"]].reset_coords(drop=True).to_dataframe()
    frame = frame.rename(columns={"maf": "λ (1/yr)", "maf_lower": "λ lower", "maf_upper": "λ upper", "return_period": "once in (yr)",
                                  "probability": f"P in {YEARS:g} yr"})
    frame.index = frame.index.set_names({"level": "moat clearance (m)"})
    return Table(f"risk-moat-{name}", f"Experiment {name}: moat-wall contact as a limit state: the mean annual frequency with which the "
                 "studied building's base reaches the moat wall's clearance (peak base displacement ≥ clearance; before the first "
                 f"wall impact a run with the wall equals the run without), with its {int(100 * CONFIDENCE)} % bootstrap interval",
                 frame, formats={"λ (1/yr)": "{:.3g}", "λ lower": "{:.3g}", "λ upper": "{:.3g}", "once in (yr)": "{:.3g}",
                                 f"P in {YEARS:g} yr": "{:.3f}"})
