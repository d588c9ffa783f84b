"""The codes' own separations of a store's scene, from its ``[design]`` table, and how often they pound.

The suite-mean rules (:mod:`stochpound.risk._code_rules`) apply the codes'
combination rules to the peaks of response histories; the codes themselves
take the displacements of the design analysis (:mod:`stochpound.risk._code_gaps`):

* ``asce7_delta_mt``, ASCE 7-16 §12.12.3: each building's
  δ_M = C_d δ_max / I_e at the contact's floor (eq. 12.12-1) from the modal
  analysis of its fixed-base storeys under the design spectrum (S_DS,
  S_D1, T_L) with forces reduced by R / I_e, and the two buildings
  combined by SRSS, δ_MT (eq. 12.12-2). ASCE 7's performance objective is
  set at the MCE_R: its design level here is 2 % in 50 years.
* ``ec8_ds``, EN 1998-1 §4.4.2.7: d_s = q d_e (eq. 4.23) of each building
  from the analysis under the Type 1 design spectrum S_d(T) (a_g, ground
  type, q), SRSS of the two, times 0.7 where the contact's floors stand at
  the same height (§4.4.2.7(3)); at the design seismic action, 10 % in 50 years.
* ``asce7_isolated``, ASCE 7-16 chapter 17 for a building on a sliding
  base (a friction pendulum) beside a fixed-base neighbour: its total
  maximum displacement D_TM (eq. 17.5-3, at the larger of the lower- and
  upper-bound friction's, :func:`~stochpound.codes.chapter17_design`) plus
  the neighbour's δ_M at the contact's floor (eq. 12.12-1); at 2 % in 50
  years. §17.2.5.2 asks D_TM of the clearance to fixed obstructions; a
  neighbour that moves adds its own δ_M. A contact with a sliding building
  has no ``asce7_delta_mt`` (§12.12.3 is the rule of fixed-base
  structures), nor any row where both buildings slide. The superstructure's
  chapter 17 design (V_b, V_st, V_s = V_st/R_I and the limits of
  §17.5.4.3) is stated beside the rows (:func:`chapter17_text`).

Every gap is a number of the design, not of the runs: its risk is the mean
annual frequency of pounding at it (the runs of every stripe pound when
max_c (D_c − g_c) ≥ 0), fitted and integrated with the hazard as the
other rules are, and its interval resamples the motions only.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from collections.abc import Mapping
from typing import Any

import numpy as np
import xarray as xr

from stochpound.codes import Chapter17Design, IsolatedPlan, MceSpectrum, SlidingBase, chapter17_design
from stochpound.hazard import HazardCurve
from stochpound.model.building import Building
from stochpound.model.scene import Scene
from stochpound.risk import _inputs
from stochpound.risk._inputs import CASE_DIMS, Design, RiskInputError, RiskInputs
from stochpound.codes import EC8_REDUCTION
from stochpound.risk._code_gaps import (Asce7Design, Ec8Design, asce7_inelastic_displacement, ec8_design_displacement,
                                        modal_floor_displacements, srss_separation)
from stochpound.risk._fragility_ensemble import BOOTSTRAP, stripe_fragility
from stochpound.risk._maf import no_interval_attrs, rate_intervals, risk_curve

DESIGN_RULE_LEVELS = {"asce7_delta_mt": 0.02, "ec8_ds": 0.10, "asce7_isolated": 0.02}
"""Each design-analysis rule's design level: the probability of exceedance in 50 years its code sets its objective at."""
DESIGN_RULE_NAMES = {
    "asce7_delta_mt": "ASCE 7 §12.12.3 δ_MT of the design analysis",
    "ec8_ds": "Eurocode 8 §4.4.2.7 d_s of the design analysis",
    "asce7_isolated": "ASCE 7 ch. 17 D_TM (eq. 17.5-3) + the neighbour's δ_M (eq. 12.12-1)",
}
"""The design-analysis rules' names in the tables."""
_FORMULAS = {"asce7_delta_mt": "ASCE 7-16 §12.12.3: δ_M = C_d δ_max / I_e, SRSS of the two buildings, for contacts of fixed-base buildings",
             "ec8_ds": "Eurocode 8 §4.4.2.7: d_s = q d_e, SRSS, times 0.7 where the floors stand level",
             "asce7_isolated": "ASCE 7-16 chapter 17 for the building on a sliding base: its D_TM (eq. 17.5-3, the larger friction "
                               "bound's) plus the fixed-base neighbour's δ_M (eq. 12.12-1) at the contact; no §12.12.3 row for a sliding base"}
MAX_SLIDER_MU = 0.3
"""The largest nominal friction coefficient chapter 17 is applied to (``stochpound.codes.SlidingBase`` refuses more)."""
SQUARE_PLAN = IsolatedPlan(1.0, 1.0)
"""The plan assumed where ``[design.isolation]`` gives none: square, so that with the accidental eccentricity 0.05 d and y = d/2
eq. 17.5-3's amplification is 1 + 0.15 = 1.15 whatever d."""


def design_separations(scene: Scene, design: Design, studied: str | None = None) -> dict[str, np.ndarray]:
    """The codes' separations of a scene's contacts from its design (m): one array (one gap per contact) per rule.

    Parameters
    ----------
    scene : Scene
        The buildings and contacts (a base, if any, held fixed for the storeys' design analysis).
    design : Design
        The ``[design]`` table (``stochpound.experiment``'s ``parse_design``; ``Design.from_entry`` of its canonical entry).
    studied : str, optional
        Kept for the callers' symmetry: every building on a friction pendulum is designed by chapter 17.

    Returns
    -------
    dict of str to numpy.ndarray
        ``asce7_delta_mt`` (NaN at a contact with a sliding building), ``ec8_ds`` with an ``ec8`` design, and
        ``asce7_isolated`` where a contact joins a building on a friction pendulum to a fixed-base one (NaN elsewhere).
    """
    asce7 = Asce7Design(design.sds, design.sd1, design.tl, design.r, design.cd, design.ie)
    codes = {"asce7_delta_mt": lambda b: asce7_inelastic_displacement(modal_floor_displacements(b, design=asce7, g=scene.g), asce7)}
    if design.ec8 is not None:
        ec8 = Ec8Design(design.ec8.ag, design.ec8.ground, design.ec8.q)
        codes["ec8_ds"] = lambda b: ec8_design_displacement(modal_floor_displacements(b, design=ec8, g=scene.g), ec8)
    sliding = [_slides(building) for building in scene.buildings]
    gaps = {}
    for rule, displacements in codes.items():
        floors = [displacements(building) if building.n_floors > 0 else np.zeros(0) for building in scene.buildings]
        gaps[rule] = np.array([math.nan if rule == "asce7_delta_mt" and (sliding[c.left] or sliding[c.right]) else
                               srss_separation(floors[c.left][c.left_floor - 1], floors[c.right][c.right_floor - 1])
                               * (EC8_REDUCTION if rule == "ec8_ds" and _level_floors(scene, c) else 1.0) for c in scene.contacts])
    designs = {index: chapter17_of(building, design, scene.g)[0] for index, building in enumerate(scene.buildings) if _pendulum(building)}
    if designs:
        delta_m = [asce7_inelastic_displacement(modal_floor_displacements(b, design=asce7, g=scene.g), asce7) if not sliding[i] else None
                   for i, b in enumerate(scene.buildings)]
        gaps["asce7_isolated"] = np.array([_isolated_gap(c, designs, delta_m) for c in scene.contacts])
    return gaps


def _isolated_gap(contact: Any, designs: Mapping[int, Chapter17Design], delta_m: list[np.ndarray | None]) -> float:
    """D_TM of the contact's building on a pendulum plus its fixed-base neighbour's δ_M at the contact's floor (m); NaN otherwise."""
    for isolated, floor, other, other_floor in ((contact.left, contact.left_floor, contact.right, contact.right_floor),
                                                (contact.right, contact.right_floor, contact.left, contact.left_floor)):
        if isolated in designs and delta_m[other] is not None:
            return designs[isolated].total_displacement + float(delta_m[other][other_floor - 1])
    return math.nan


def chapter17_of(building: Building, design: Design, g: float) -> tuple[Chapter17Design, MceSpectrum, str]:
    """The chapter 17 design of a building on a friction pendulum, from the ``[design]`` (and its ``isolation`` part): the design,
    the MCE_R spectrum it read and where that spectrum comes from, in words.

    The spectrum: the ``isolation`` part's geometric-mean SA(0.2 s), SA(1 s)
    times the maximum-direction factors; else S_MS = 1.5 S_DS and S_M1 the
    ``sm1`` given (taken as maximum direction) or 1.5 S_D1.
    """
    isolation = design.isolation
    if isolation is not None and isolation.sa_short is not None:
        spectrum = MceSpectrum.from_geometric_mean(isolation.sa_short, isolation.sa_long, design.tl, s1=isolation.s1)
        source = (f"S_MS = 1.1 × SA(0.2 s) = 1.1 × {isolation.sa_short:.3g} g, S_M1 = 1.3 × SA(1 s) = 1.3 × {isolation.sa_long:.3g} g "
                  f"(the maximum direction from the geometric mean, ASCE 7-16 §21.2's factors, T_L = {design.tl:g} s; SA from "
                  f"{isolation.spectrum_source or 'the [design.isolation] table'})")
    else:
        sm1 = design.sm1 if design.sm1 is not None else 1.5 * design.sd1
        spectrum = MceSpectrum(1.5 * design.sds, sm1, design.tl, None if isolation is None else isolation.s1)
        source = ("S_MS = 1.5 S_DS of the [design]; S_M1 = " + (f"the [design]'s sm1 = {sm1:.3g} g, taken as the maximum direction"
                  if design.sm1 is not None else "1.5 S_D1 of the [design]") + " (no site SA(0.2 s), SA(1 s) given: [design.isolation])")
    factors = {} if isolation is None else {name: value for name in ("lambda_max", "lambda_min", "breakaway")
                                             if (value := getattr(isolation, name)) is not None}
    weight = g * (sum(building.mass) + building.base.mass)
    base = SlidingBase(building.base.mu, building.base.radius, weight, g * sum(building.mass), **factors)
    plan = SQUARE_PLAN if isolation is None or isolation.plan is None else IsolatedPlan(
        *isolation.plan, eccentricity=isolation.eccentricity, distance=isolation.distance)
    result = chapter17_design(base, spectrum, plan, design.r, wind_shear=None if isolation is None else isolation.wind_shear, g=g)
    if plan is SQUARE_PLAN:  # the plan's own sentences speak of a 1 m side: say what was assumed instead
        said = [a for a in result.assumptions if not a.startswith(("e = ", "y = "))]
        result = dataclasses.replace(result, assumptions=("square plan assumed (no [design.isolation] plan): accidental eccentricity "
                                                          "0.05 d at the far corner y = d/2 and P_T = 1 (isolators spread evenly), D_TM = 1.15 D_M whatever d", *said))
    return result, spectrum, source


def design_assumptions(design: Design | None, scenes: Mapping[tuple[Any, ...], Scene]) -> dict[str, str]:
    """What the codes' rows rest on, in words ({} without a ``design``): ``code design``, the [design]'s spectra and factors as
    given, and per building on a friction pendulum ``chapter 17 (<name>)``, the MCE_R spectrum it read (maximum-direction factors,
    the S_MS and S_M1 rule) and every default it took (plan and eccentricity of D_TM, property-modification factors, …)."""
    if design is None:
        return {}
    given = (f"ASCE 7-16: S_DS = {design.sds:.4g} g, S_D1 = {design.sd1:.4g} g, T_L = {design.tl:g} s, R = {design.r:g}, C_d = "
             f"{design.cd:g}, Ω0 = {design.omega0:g}, I_e = {design.ie:g}, as the [design] gives them (not derived here from the site's "
             "hazard; the design-analysis rows' δ_M rest on them)")
    if design.ec8 is not None:
        given += f"; Eurocode 8: a_g = {design.ec8.ag:g} g, ground {design.ec8.ground}, q = {design.ec8.q:g}"
    said = {"code design": given}
    for scene in scenes.values():
        for building in scene.buildings:
            if _pendulum(building):
                result, _, source = chapter17_of(building, design, scene.g)
                key = f"chapter 17 ({building.name})"
                text = f"MCE_R spectrum {source}; assumed: {'; '.join(result.assumptions)}"
                said[key] = text if key not in said or text in said[key] else f"{said[key]} | μ = {building.base.mu:g}: {text}"
    return said


def chapter17_text(building: Building, design: Design, g: float) -> str:
    """A building's chapter 17 design in words: D_M, D_TM at both friction bounds, V_b, V_s against its model's strength, what
    governs V_s, the spectrum and every assumption."""
    result, spectrum, source = chapter17_of(building, design, g)
    lower, upper = result.lower, result.upper
    weight, superstructure = g * (sum(building.mass) + building.base.mass), g * sum(building.mass)
    strength = (f"; against it, the [design]'s fixed-base shear is at most S_DS I_e / R = {design.sds * design.ie / design.r:.3g} W_s"
                + (f" and the model's first storey yields at {building.yield_force[0] / superstructure:.3g} W_s"
                   if building.yield_force is not None else " and the model's storeys are elastic"))
    return (f"{building.name} (μ = {building.base.mu:g}, R = {building.base.radius:g} m) by ASCE 7-16 §17.5 at lower/upper-bound friction "
            f"μ = {lower.mu:.3g}/{upper.mu:.3g}: T_M = {lower.period:.3g}/{upper.period:.3g} s, β_M = {100 * lower.damping:.3g}/"
            f"{100 * upper.damping:.3g} %, D_M = {lower.displacement:.3f}/{upper.displacement:.3f} m (eq. 17.5-1), D_TM = "
            f"{lower.total_displacement:.3f}/{upper.total_displacement:.3f} m (eq. 17.5-3), V_b = {lower.base_shear / weight:.3g}/"
            f"{upper.base_shear / weight:.3g} W; the superstructure's V_s = {result.design_shear / superstructure:.3g} W_s "
            f"(R_I = {result.r_i:g}; governed by {result.governs}; limits: item 1 {result.fixed_base_shear / superstructure:.3g} W_s, "
            f"item 3 {result.activation_shear / superstructure:.3g} W_s){strength}. Spectrum: {source}. Assumed: "
            f"{'; '.join(result.assumptions)}")


def design_rules_risk(store: xr.Dataset | RiskInputs, hz: HazardCurve, design: Design, studied: str | None = None, years: float = 50.0,
                      confidence: float = 0.95, bootstrap: int = BOOTSTRAP, seed: int = 0) -> xr.Dataset:
    """The codes' own gaps of every configuration of a store with stripes and the mean annual frequency of pounding at each.

    Parameters
    ----------
    store : xarray.Dataset or RiskInputs
        An experiment store with intensity stripes and contact-free cases, or
        its inputs read with a design (:func:`~stochpound.risk.read_risk_inputs`).
    hz : HazardCurve
        The site's hazard, in the store's intensity measure.
    design : Design
        The ``[design]`` entry (:func:`design_separations`).
    studied : str, optional
        Kept for the callers' symmetry (:func:`design_separations`).
    years, confidence, bootstrap, seed
        As in :func:`~stochpound.risk.code_rules_risk`.

    Returns
    -------
    xarray.Dataset
        Over ``rule`` (coordinate ``design_level``: each rule's probability
        in ``years``) and the configurations: ``gap`` (m, per contact), the
        fragility's ``theta``, ``beta``, ``status``, ``maf`` (1/yr),
        ``probability``, ``return_period`` (yr) and, with a bootstrap, their
        bounds (or the attribute ``no_interval``, as in
        :func:`~stochpound.risk.stripe_fragility`). A rule that does not
        apply to a configuration is NaN there.
    """
    if isinstance(store, RiskInputs):
        if store.demands is None or not store.scenes:
            raise RiskInputError("design_rules_risk: the inputs were read without a design (read_risk_inputs(..., design=...))")
        closure, scenes = store.demands["peak_closure"], store.scenes
    else:
        closure = _inputs.contact_free_demands(store)["peak_closure"]
        scenes = _inputs.configuration_scenes(store, closure)
    if "gap" in closure.coords and "gap" not in closure.dims:
        closure = closure.drop_vars("gap")
    gaps = _configuration_gaps(scenes, closure, design, studied)
    excess = (closure - gaps).max("contact")  # over the contacts the rule applies to (NaN where it applies to none)
    events = (excess >= 0.0).astype(float).where(excess.notnull())
    fragility = stripe_fragility(events, "intensity", "record", confidence, bootstrap, seed)
    curve = risk_curve(fragility, hz, years, confidence)
    result = xr.Dataset({"gap": gaps.assign_attrs(units="m", long_name="gap of the code's design analysis"),
                         **{name: fragility[name] for name in ("theta", "beta", "status")},
                         **{name: curve[name] for name in ("maf", "maf_lower", "maf_upper", "probability", "return_period") if name in curve}})
    if "maf_lower" in result:
        result = rate_intervals(result, years)
    levels = [DESIGN_RULE_LEVELS[rule] for rule in result["rule"].values]
    chapter17 = dict.fromkeys(chapter17_text(building, design, scene.g) for scene in scenes.values() for building in scene.buildings
                              if _pendulum(building))
    return result.assign_coords(design_level=("rule", levels, {"units": "1", "long_name": f"the rule's design level in {years:g} years"}))\
        .assign_attrs(years=years, chapter17=" ".join(f"{text}." for text in chapter17), **no_interval_attrs(fragility))


def design_rules_text(design_rules: xr.Dataset | None, note: str) -> str:
    """The rules table's design-analysis rows in words: what they are and how often each pounds, the chapter 17 design of a
    building on a sliding base, or why there are none (``note``)."""
    if design_rules is None:
        return f"The codes' own gaps from the design analysis are not evaluated: {note}."
    periods = []
    for rule in design_rules["rule"].values:
        applies = design_rules["gap"].sel(rule=rule).notnull().any("contact")
        period = design_rules["return_period"].sel(rule=rule).where(applies)
        if bool(period.notnull().any()):
            low, high = float(period.min()), float(period.max())
            periods.append(f"{DESIGN_RULE_NAMES[str(rule)]}, pounding once in {low:.3g}" + (f" to {high:.3g}" if high != low else "") + " years")
    given = "; ".join(_FORMULAS[str(rule)] for rule in design_rules["rule"].values if bool(design_rules["gap"].sel(rule=rule).notnull().any()))
    chapter17 = str(design_rules.attrs["chapter17"]) if "chapter17" in design_rules.attrs else ""
    return ("The rows '(design analysis)' are the codes' own gaps, from the design analysis under the spectra of the store's [design] "
            f"({given}), not from the runs; each with the mean annual frequency of pounding at that gap: here: "
            f"{'; '.join(periods) or 'none applies to these contacts (sliding bases beyond a slider friction of 0.3)'}."
            + (f" Chapter 17 design: {chapter17}" if chapter17 else "") + _without_ec8_text(design_rules))


def _without_ec8_text(design_rules: xr.Dataset) -> str:
    """Why the design-analysis rows have no Eurocode 8 row, when they have none ("" otherwise)."""
    if "ec8_ds" in design_rules["rule"].values:
        return ""
    return (" There is no Eurocode 8 §4.4.2.7 row: the store's [design] has no ec8 entry (a_g, ground type, q). Eurocode 8 is "
            "the design code of a European site, not of this one unless a user designs to it; give [design] an ec8 = { ag, ground, q } (or "
            "stochpound risk --design) to add its row.")


def _configuration_gaps(scenes: Mapping[tuple[Any, ...], Scene], closure: xr.DataArray, design: Design,
                        studied: str | None) -> xr.DataArray:
    """The rules' gaps (m) over ``rule``, the configurations of ``closure`` and ``contact``, from each configuration's scene
    (``scenes``, keyed by its labels: :func:`~stochpound.risk._inputs.configuration_scenes`)."""
    configs = [dim for dim in closure.dims if dim not in CASE_DIMS]
    per_config = {labels: design_separations(scene, design, studied) for labels, scene in scenes.items()}
    rules = list(dict.fromkeys(rule for gaps in per_config.values() for rule in gaps))
    contacts = closure.sizes["contact"]
    values = np.full((len(rules), *(closure.sizes[dim] for dim in configs), contacts), np.nan)
    for index, labels in enumerate(itertools.product(*(range(closure.sizes[dim]) for dim in configs))):
        for r, rule in enumerate(rules):
            gaps = list(per_config.values())[index].get(rule)
            if gaps is not None:
                values[(r, *labels)] = gaps
    coords = {dim: closure[dim] for dim in configs}
    return xr.DataArray(values, dims=("rule", *configs, "contact"), coords={**coords, "rule": rules, "contact": closure["contact"]})


def _level_floors(scene: Scene, contact: Any) -> bool:
    """Whether a contact's two floors stand at the same height (EN 1998-1 §4.4.2.7(3)); unknown heights: same floor numbers."""
    left, right = scene.buildings[contact.left], scene.buildings[contact.right]
    if left.storey_height is None or right.storey_height is None:
        return contact.left_floor == contact.right_floor
    return math.isclose(sum(left.storey_height[:contact.left_floor]), sum(right.storey_height[:contact.right_floor]))


def _slides(building: Building) -> bool:
    """Whether a building stands on a sliding base (a base whose μ is finite; μ = ∞ is a fixed base)."""
    return building.base is not None and building.base.mu < math.inf


def _pendulum(building: Building) -> bool:
    """Whether a building slides on a friction pendulum chapter 17 designs (a radius, 0 < μ <= ``MAX_SLIDER_MU``; a higher μ is
    no slider's: such a contact gets neither row)."""
    base = building.base
    return base is not None and base.radius is not None and 0.0 < base.mu <= MAX_SLIDER_MU
