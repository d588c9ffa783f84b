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
* ``asce7_dtm``, ASCE 7-16 §17.2.5.2 and eq. 17.5-1: the total maximum
  displacement D_TM = D_M (a planar model has no torsion) of the studied
  building's friction pendulum, from S_M1 and the case's μ and radius
  (:func:`~stochpound.risk.asce7_isolator_displacement`), as the gap at
  every contact, like the suite-mean D_TM rule; at 2 % in 50 years.

Every gap is a number of the design, not of the runs: its risk is the mean
annual frequency of pounding at it (the runs of every stripe pound when
max_c (D_c − g_c) ≥ 0), fitted and integrated with the hazard as the
other rules are, and its interval resamples the motions only.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping
from typing import Any

import numpy as np
import xarray as xr

from stochpound.hazard import HazardCurve
from stochpound.model.building import Building
from stochpound.model.scene import Scene
from stochpound.risk import _inputs
from stochpound.risk._inputs import CASE_DIMS, Design, RiskInputError, RiskInputs
from stochpound.codes import EC8_REDUCTION
from stochpound.risk._code_gaps import (Asce7Design, Ec8Design, asce7_inelastic_displacement, asce7_isolator_displacement,
                                        ec8_design_displacement, modal_floor_displacements, srss_separation)
from stochpound.risk._fragility_ensemble import BOOTSTRAP, stripe_fragility
from stochpound.risk._maf import no_interval_attrs, rate_intervals, risk_curve

DESIGN_RULE_LEVELS = {"asce7_delta_mt": 0.02, "ec8_ds": 0.10, "asce7_dtm": 0.02}
"""Each design-analysis rule's design level: the probability of exceedance in 50 years its code sets its objective at."""


def design_separations(scene: Scene, design: Design, studied: str | None = None) -> dict[str, np.ndarray]:
    """The codes' separations of a scene's contacts from its design (m): one array (one gap per contact) per rule.

    Parameters
    ----------
    scene : Scene
        The buildings and contacts (a base, if any, held fixed for the storeys' design analysis).
    design : Design
        The ``[design]`` table (``stochpound.experiment``'s ``parse_design``; ``Design.from_entry`` of its canonical entry).
    studied : str, optional
        The building whose friction pendulum gives ``asce7_dtm`` (with ``sm1``
        in the design and a finite μ and radius in the scene).

    Returns
    -------
    dict of str to numpy.ndarray
        ``asce7_delta_mt``, and ``ec8_ds`` with an ``ec8`` design, ``asce7_dtm`` where it applies.
    """
    asce7 = Asce7Design(design.sds, design.sd1, design.tl, design.r, design.cd, design.ie)
    codes = {"asce7_delta_mt": lambda b: asce7_inelastic_displacement(modal_floor_displacements(b, design=asce7, g=scene.g), asce7)}
    if design.ec8 is not None:
        ec8 = Ec8Design(design.ec8.ag, design.ec8.ground, design.ec8.q)
        codes["ec8_ds"] = lambda b: ec8_design_displacement(modal_floor_displacements(b, design=ec8, g=scene.g), ec8)
    gaps = {}
    for rule, displacements in codes.items():
        floors = [displacements(building) for building in scene.buildings]
        gaps[rule] = np.array([srss_separation(floors[c.left][c.left_floor - 1], floors[c.right][c.right_floor - 1])
                               * (EC8_REDUCTION if rule == "ec8_ds" and _level_floors(scene, c) else 1.0) for c in scene.contacts])
    isolated = next((b for b in scene.buildings if b.name == studied), None)
    if design.sm1 is not None and isolated is not None and _pendulum(isolated):
        weight = scene.g * (sum(isolated.mass) + isolated.base.mass)
        dtm, _, _ = asce7_isolator_displacement(weight, isolated.base.mu, isolated.base.radius, design.sm1, scene.g)
        gaps["asce7_dtm"] = np.full(len(scene.contacts), dtm)
    return gaps


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
        The building of ``asce7_dtm``.
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
    excess = (closure - gaps).max("contact", skipna=False)
    events = (excess >= 0.0).astype(float).where(excess.notnull())
    fragility = stripe_fragility(events, "intensity", "record", confidence, bootstrap, seed)
    curve = risk_curve(fragility, hz, years, confidence)
    result = xr.Dataset({"gap": gaps.assign_attrs(units="m", long_name="gap of the code's design analysis"),
                         **{name: fragility[name] for name in ("theta", "beta", "status")},
                         **{name: curve[name] for name in ("maf", "maf_lower", "maf_upper", "probability", "return_period") if name in curve}})
    if "maf_lower" in result:
        result = rate_intervals(result, years)
    levels = [DESIGN_RULE_LEVELS[rule] for rule in result["rule"].values]
    return result.assign_coords(design_level=("rule", levels, {"units": "1", "long_name": f"the rule's design level in {years:g} years"}))\
        .assign_attrs(years=years, **no_interval_attrs(fragility))


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


def _pendulum(building: Building) -> bool:
    """Whether a building slides on a friction pendulum eq. 17.5-1 applies to (finite μ > 0, a radius)."""
    base = building.base
    return base is not None and base.radius is not None and 0.0 < base.mu < math.inf
