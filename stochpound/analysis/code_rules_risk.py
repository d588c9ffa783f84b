"""The code separation rules in risk terms: the gap each rule gives at the code's intensity, and how often that gap pounds.

A rule gives a gap at the code's design intensity: ASCE 7 at the MCE_R
(2 % in 50 years; its δ_MT is the SRSS rule, and an isolated building asks
for its total maximum displacement D_TM), Eurocode 8 at the design
earthquake (10 % in 50 years; SRSS, or 0.7 of it where floor levels
coincide). Here the intensity is read off the site's hazard curve, the
stripe nearest to it (in ln IM) is taken, and each rule is applied to the
*suite means* of that stripe's displacements (as a code's response-history
analysis does: the mean over at least 7 motions), using
:func:`stochpound.analysis.separation_rules.separation_rules`:

* u1, u2: the mean over the motions of the peak displacements of the two
  floors at each contact; ρ (for DDC): the mean of their correlations;
* ``dtm`` (isolated buildings, when ``isolator_displacement`` is given):
  the mean over the motions of the isolated building's peak base (sliding)
  displacement max|s|. ASCE 7 amplifies D_M for torsion to get D_TM; a
  planar model has no torsion, so D_TM = D_M here.

The rule's risk is the mean annual frequency of pounding at that gap: at
every stripe, a run pounds when max_c (D_c − g_c) ≥ 0 (D_c its
contact-free peak closure at contact c, g_c the rule's gap there); the
lognormal fragility of those counts is integrated with the hazard. The
bootstrap resamples the motions of the fragility; the rule's gap is kept
at the whole suite's value.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import xarray as xr

from stochpound.analysis.fragility_ensemble import BOOTSTRAP, stripe_fragility
from stochpound.analysis.hazard import HazardCurve, rate_from_probability
from stochpound.analysis.risk import risk_curve
from stochpound.analysis.separation_rules import EC8_REDUCTION, separation_rules

DESIGN_LEVELS = (0.02, 0.10)
"""Default design levels: probabilities of exceedance in 50 years (ASCE 7's MCE_R; Eurocode 8's design earthquake)."""
MINIMUM_MOTIONS = 7
"""The fewest motions whose mean a code accepts for a response-history analysis (ASCE 7)."""


def code_rules_risk(demands: xr.Dataset, hz: HazardCurve, design_levels: Sequence[float] = DESIGN_LEVELS, years: float = 50.0,
                    isolator_displacement: xr.DataArray | None = None, cqc: xr.DataArray | None = None,
                    reduction: float = EC8_REDUCTION, intensity_dim: str = "intensity", record_dim: str = "record",
                    contact_dim: str = "contact", confidence: float = 0.95, bootstrap: int = BOOTSTRAP, seed: int = 0) -> xr.Dataset:
    """Each separation rule's gap at the code intensities and the mean annual frequency of pounding at that gap.

    Parameters
    ----------
    demands : xarray.Dataset
        Contact-free runs' ``peak_displacement_left``, ``peak_displacement_right``,
        ``correlation`` and ``peak_closure`` (m;
        :func:`~stochpound.analysis.separation_rules.store_contact_demands`
        of a store's ``gap = inf`` cases), with dims ``intensity_dim``
        (coordinate: the stripe levels, in the hazard's IM units),
        ``record_dim`` and ``contact_dim``; other dims are carried along.
    hz : HazardCurve
        The site's hazard.
    design_levels : sequence of float
        Probabilities of exceedance in ``years`` at which rules are applied.
    years : float
        Their exposure time (and that of ``probability``).
    isolator_displacement : xarray.DataArray, optional
        Peak base displacement max|s| (m) of the isolated building per run
        (dims ``intensity_dim``, ``record_dim``): adds the rule ``dtm``.
    cqc, reduction
        As in :func:`~stochpound.analysis.separation_rules.separation_rules`.
    confidence, bootstrap, seed
        As in :func:`~stochpound.analysis.fragility_ensemble.stripe_fragility`.

    Returns
    -------
    xarray.Dataset
        Over ``design_level`` (the probabilities) and ``rule``:
        ``code_intensity`` and ``stripe_intensity`` (IM units), ``gap`` (m,
        per contact), the fragility's ``theta``, ``beta``, ``status``, and
        ``maf`` (1/yr) with ``maf_lower``/``maf_upper``, ``probability`` in
        ``years`` and ``return_period`` (yr). ``.to_dataframe()`` gives a table.
    """
    for name in ("peak_displacement_left", "peak_displacement_right", "correlation", "peak_closure"):
        if name not in demands:
            raise ValueError(f"demands: missing {name!r} (see stochpound.analysis.separation_rules.contact_demands)")
    for dim in (intensity_dim, record_dim, contact_dim):
        if dim not in demands["peak_closure"].dims:
            raise ValueError(f"demands: peak_closure has no dimension {dim!r}")
    motions = demands.sizes[record_dim]
    if motions < MINIMUM_MOTIONS:
        raise ValueError(f"{record_dim}: the codes take the mean over at least {MINIMUM_MOTIONS} motions, got {motions}")
    if "gap" in demands.coords and "gap" not in demands.dims:  # a store's contact-free selection
        demands = demands.drop_vars("gap")
    levels = np.asarray(demands[intensity_dim].values, dtype=float)
    per_level = []
    for probability in np.atleast_1d(np.asarray(design_levels, dtype=float)):
        code_intensity = float(hz.intensity_at(rate_from_probability(probability, years)))
        stripe = int(np.argmin(np.abs(np.log(levels) - np.log(code_intensity))))
        at_stripe = demands.isel({intensity_dim: stripe})
        gaps = separation_rules(at_stripe.mean(record_dim), cqc, reduction)
        if isolator_displacement is not None:
            dtm = isolator_displacement.isel({intensity_dim: stripe}).mean(record_dim)
            dtm = dtm.drop_vars([name for name in dtm.coords if name in (intensity_dim, "gap")], errors="ignore")
            gaps = xr.concat([gaps, dtm.broadcast_like(gaps.isel(rule=0, drop=True)).expand_dims(rule=["dtm"])], dim="rule")
        gaps = gaps.drop_vars(intensity_dim, errors="ignore")
        excess = (demands["peak_closure"] - gaps).max(contact_dim, skipna=False)
        events = (excess >= 0.0).astype(float).where(excess.notnull())
        fragility = stripe_fragility(events, intensity_dim, record_dim, confidence, bootstrap, seed)
        risk = risk_curve(fragility, hz, years, confidence)
        keep = [name for name in ("maf", "maf_lower", "maf_upper", "probability", "return_period") if name in risk]
        per_level.append(xr.Dataset(
            {
                "gap": gaps.assign_attrs(units="m", long_name="gap the rule asks for at the code intensity"),
                "theta": fragility["theta"], "beta": fragility["beta"], "status": fragility["status"],
                **{name: risk[name] for name in keep},
            },
            coords={"code_intensity": code_intensity, "stripe_intensity": levels[stripe]},
        ))
    result = xr.concat(per_level, dim="design_level", coords="all")
    result = result.assign_coords(design_level=("design_level", np.atleast_1d(np.asarray(design_levels, dtype=float)),
                                                {"units": "1", "long_name": f"probability of exceedance in {years:g} years of the code intensity"}))
    result["code_intensity"].attrs.update(long_name="intensity with the design level's rate on the hazard curve")
    result["stripe_intensity"].attrs.update(long_name="level of the stripe the rules are applied at (nearest in ln IM)")
    return result.assign_attrs(years=years, hazard=repr(hz))
