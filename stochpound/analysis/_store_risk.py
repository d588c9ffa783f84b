"""An experiment store's intensity-conditioned runs through the risk chain.

A store with intensity stripes holds, per case, ``peak_contact_closure``
over the grid's dimensions (``gap``, ``mu``, variants, ``intensity``,
``record``, ``realization``) and ``contact``; its contact-free cases are
those at ``inf`` on every gap axis. By the gap identity, their largest closure over the
contacts decides pounding at every gap, so the pounding fragility of every
gap and configuration comes from that one selection. A store of IDA runs
(homogeneous scenes: ``ida_capacity``, no ``intensity`` dimension) holds one
contact-free run per motion at scale 1, and every gap's capacity follows
from it (:func:`~stochpound.analysis.homogeneous_capacities`).

The motions are the store's ``record`` entries; a synthetic ensemble's
realizations are motions too (``record`` and ``realization`` are merged
into one ``record`` dimension when there is more than one realization).
:func:`store_risk` runs the whole chain of a store for a site's hazard.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np
import xarray as xr

from stochpound.analysis._code_rules_risk import MINIMUM_MOTIONS, code_rules_risk
from stochpound.analysis._fragility_ensemble import BOOTSTRAP, homogeneous_capacities, ida_fragility, limit_state_events, stripe_fragility
from stochpound.analysis._gap_axes import contact_free, gap_dims, has_contact_free
from stochpound.analysis._hazard import HazardCurve, rate_from_probability
from stochpound.analysis._risk import TARGETS, risk_curve, risk_targeted_separation
from stochpound.analysis._separation_rules import store_contact_demands

CLOSURE = "peak_contact_closure"
"""The store's variable of per-case, per-contact peak closures (m)."""
CAPACITY = "ida_capacity"
"""The variable of an IDA store (its presence marks one)."""
SLIDING = "peak_sliding_displacement"
"""The store's variable of per-case, per-building peak base (sliding) displacements max|s| (m)."""
RISK_GAPS = 60
"""Gaps of the default grid of :func:`risk_gaps`."""
NOT_INTENSITY = "store: has no intensity stripes or IDA capacities (run an experiment with an [intensity] table)"
"""The error of a store without intensity-conditioned runs."""


class RiskInputError(ValueError):
    """A store cannot go through the risk chain (the message says why, in one line)."""


def is_ida(store: xr.Dataset) -> bool:
    """True for a store of IDA runs (``ida_capacity``, no intensity stripes); raises for a store with neither."""
    if "intensity" in store.dims:
        return False
    if CAPACITY in store:
        return True
    raise RiskInputError(NOT_INTENSITY)


def store_motions(data: xr.DataArray, record_dim: str = "record", realization_dim: str = "realization") -> xr.DataArray:
    """``data`` with one motion dimension ``record_dim``: a single realization dropped, several merged into the records."""
    if realization_dim not in data.dims:
        return data
    if data.sizes[realization_dim] == 1:
        return data.isel({realization_dim: 0}, drop=True)
    per_record = [name for name, coord in data.coords.items() if set(coord.dims) & {record_dim, realization_dim}]
    stacked = data.drop_vars(per_record).stack(_motion=(record_dim, realization_dim))
    labels = [f"{record}/{realization}" for record, realization in zip(data[record_dim].values.repeat(data.sizes[realization_dim]),
                                                                        np.tile(data[realization_dim].values, data.sizes[record_dim]))]
    stacked = stacked.drop_vars(["_motion", record_dim, realization_dim]).rename(_motion=record_dim)
    return stacked.assign_coords({record_dim: labels})


def contact_free_closure(store: xr.Dataset, contact_dim: str = "contact") -> xr.DataArray:
    """The largest peak closure over the contacts of every contact-free case of a store (m), one motion dimension ``record``.

    The contact-free cases are those at ``inf`` on every gap axis
    (``stochpound.analysis._gap_axes.contact_free``); in an IDA store every
    case runs contact-free, and the first gap's are taken.
    """
    if CLOSURE not in store:
        raise RiskInputError(f"store: has no {CLOSURE!r}")
    closure = store[CLOSURE]
    gaps = gap_dims(closure)
    if gaps and CAPACITY in store and "intensity" not in store.dims:
        closure = closure.isel({dim: 0 for dim in gaps}, drop=True)
    elif gaps and not has_contact_free(closure):
        raise RiskInputError(f"store: no contact-free cases (inf on every gap axis: {', '.join(gaps)}): add inf to the gaps")
    else:
        closure = contact_free(closure)
    if contact_dim in closure.dims:
        closure = closure.max(contact_dim, skipna=False)
    return store_motions(closure).load().assign_attrs(units="m", long_name="largest contact-free peak closure over the contacts")


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


def pounding_fragility(store: xr.Dataset, gaps: Sequence[float] | np.ndarray, intensity_dim: str = "intensity", record_dim: str = "record",
                       confidence: float = 0.95, bootstrap: int = BOOTSTRAP, seed: int = 0) -> xr.Dataset:
    """The pounding fragility at every gap of ``gaps`` (m) and every configuration of a store, from stripes or IDA runs.

    Stripes: the contact-free closures' events at every gap
    (:func:`~stochpound.analysis.limit_state_events`), fitted by
    :func:`~stochpound.analysis.stripe_fragility`. IDA: every motion's
    capacity IM·g/D at every gap (:func:`~stochpound.analysis.homogeneous_capacities`),
    fitted by :func:`~stochpound.analysis.ida_fragility`.

    Returns
    -------
    xarray.Dataset
        The fit over ``gap`` (the given gaps) and the store's other grid dimensions.
    """
    closure = contact_free_closure(store)
    if is_ida(store):
        capacities = homogeneous_capacities(closure, _ida_intensity(store), gaps)
        return ida_fragility(capacities, record_dim, confidence=confidence, bootstrap=bootstrap, seed=seed)
    events = limit_state_events(closure, gaps, "gap")
    return stripe_fragility(events, intensity_dim, record_dim, confidence, bootstrap, seed)


def _ida_intensity(store: xr.Dataset) -> xr.DataArray:
    """Every motion's unscaled measure in an IDA store (units of its levels), one motion dimension ``record``."""
    intensity = store["motion_intensity"]
    return store_motions(intensity.isel(gap=0, drop=True) if "gap" in intensity.dims else intensity).load()


def _reach_intensity(hz: HazardCurve, targets: Sequence[float], years: float) -> float:
    """The intensity up to which a gap grid reaches: where the hazard's rate is a tenth of the smallest target's (within its table)."""
    rate = rate_from_probability(min(targets), years) / 10.0
    if not hz.extrapolate:
        rate = max(float(rate), float(hz.rate[-1]))
    return float(hz.intensity_at(rate))


@dataclasses.dataclass
class StoreRisk:
    """The risk chain of one store at one site (:func:`store_risk`).

    Attributes
    ----------
    fragility : xarray.Dataset
        The pounding fragility over ``gap`` and the configurations (:func:`pounding_fragility`).
    curve : xarray.Dataset
        λ_P(g), the pounding risk curve with its band (:func:`~stochpound.analysis.risk_curve`).
    separation : xarray.Dataset
        g* per target (:func:`~stochpound.analysis.risk_targeted_separation`).
    rules : xarray.Dataset or None
        The code rules in risk terms (:func:`~stochpound.analysis.code_rules_risk`);
        None for IDA runs (no stripe at the code intensity) or fewer motions than a code accepts.
    rules_note : str
        Why ``rules`` is None ("" otherwise).
    hazard : HazardCurve
        The site's hazard.
    motions : int
        The motions of every stripe (the bootstrap's sample size).
    method : str
        ``"stripes"`` or ``"ida"``.
    """

    fragility: xr.Dataset
    curve: xr.Dataset
    separation: xr.Dataset
    rules: xr.Dataset | None
    rules_note: str
    hazard: HazardCurve
    motions: int
    method: str


def store_risk(store: xr.Dataset, hz: HazardCurve, targets: Sequence[float] = TARGETS, years: float = 50.0,
               gaps: Sequence[float] | np.ndarray | None = None, studied: str | None = None, confidence: float = 0.95,
               bootstrap: int = BOOTSTRAP, seed: int = 0) -> StoreRisk:
    """Fragility at every gap, the pounding risk curve, g* and the code rules of a store's intensity-conditioned runs.

    Parameters
    ----------
    store : xarray.Dataset
        An experiment store with intensity stripes (contact-free cases at
        ``gap = inf``) or IDA capacities.
    hz : HazardCurve
        The site's hazard, in the store's intensity measure and units.
    targets : sequence of float
        Probabilities of pounding in ``years`` for g*.
    years : float
        Exposure time (yr).
    gaps : sequence of float, optional
        The gap grid (m); default :func:`risk_gaps` of the closures, for IDA
        runs (closures at scale 1) together with each closure scaled to the
        intensity where the hazard's rate is a tenth of the rarest target's
        (within the hazard's table), so that the grid reaches the separations
        the hazard asks for.
    studied : str, optional
        The building whose peak base displacement is ASCE 7's D_TM (the
        store's ``studied`` building); the rule is left out where it does not slide.
    confidence, bootstrap, seed
        As in :func:`~stochpound.analysis.stripe_fragility`.

    Raises
    ------
    ValueError
        (``RiskInputError``) A store without stripes or IDA capacities, or without contact-free runs.
    """
    closure = contact_free_closure(store)
    if gaps is not None:
        grid = np.asarray(gaps, dtype=float)
    elif is_ida(store):  # the unscaled closures, and each scaled to the hazard's intensities (IDA runs hold scale 1 only)
        grid = risk_gaps(xr.concat([closure, closure * (_reach_intensity(hz, targets, years) / _ida_intensity(store))], "record"))
    else:
        grid = risk_gaps(closure)
    fragility = pounding_fragility(store, grid, confidence=confidence, bootstrap=bootstrap, seed=seed)
    curve = risk_curve(fragility, hz, years, confidence)
    separation = risk_targeted_separation(curve, targets, years, confidence=confidence)
    motions = closure.sizes["record"]
    if "selection_scale_factor" in store:  # stripes of motions chosen for the site: the motions of a stripe
        motions = int(np.isfinite(store["selection_scale_factor"]).sum("record").min())
    method = "ida" if is_ida(store) else "stripes"
    rules, note = None, ""
    if method == "ida":
        note = "IDA runs hold no stripe at the code intensity to apply the rules to"
    elif motions < MINIMUM_MOTIONS:
        note = f"the codes take the mean over at least {MINIMUM_MOTIONS} motions; the store has {motions}"
    else:
        free = contact_free(store)
        demands = xr.Dataset({name: store_motions(value) for name, value in store_contact_demands(free).items()}).load()
        rules = code_rules_risk(demands, hz, years=years, isolator_displacement=base_displacement(free, studied), confidence=confidence,
                                bootstrap=bootstrap, seed=seed)
    return StoreRisk(fragility, curve, separation, rules, note, hz, motions, method)


def base_displacement(free: xr.Dataset, studied: str | None) -> xr.DataArray | None:
    """A building's peak base displacement max|s| per run of a store's selection (m, one motion dimension).

    NaN in the configurations where it never slides; None when it slides
    in none (or the store has no such building or variable).
    """
    if SLIDING not in free or studied is None or studied not in free["building"].values:
        return None
    sliding = store_motions(free[SLIDING].sel(building=studied, drop=True)).load()
    slides = (sliding > 0.0).any(["intensity", "record"])
    if not bool(slides.any()):
        return None
    return sliding.where(slides)
