"""The code separation rules in risk terms: the gap each rule gives at the code's intensity, and how often that gap pounds.

A rule gives a gap at the code's design intensity: ASCE 7 at the MCE_R
(2 % in 50 years; its δ_MT is the SRSS rule, and an isolated building asks
for its total maximum displacement D_TM), Eurocode 8 at the design
earthquake (10 % in 50 years; SRSS, or 0.7 of it where floor levels
coincide). Here the intensity is read off the site's hazard curve, the
stripe nearest to it (in ln IM) is taken, and each rule is applied to the
*suite means* of that stripe's displacements (as a code's response-history
analysis does: the mean over at least 7 motions), using
:func:`~stochpound.analysis.separation_rules`:

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
bootstrap resamples the motions and recomputes the whole chain: the suite
means, hence the rule's gap, and the fragility at that gap.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import xarray as xr

from stochpound.stats import bootstrap_method, bootstrap_weights, interval, jackknife_weights, record_clusters, resampling_obstacle
from stochpound.risk._fragility import STATUS, stripe_mle
from stochpound.risk._fragility_ensemble import BOOTSTRAP
from stochpound.hazard import HazardCurve, probability_from_rate, rate_from_probability, return_period
from stochpound.risk._maf import fit_maf, rate_intervals
from stochpound.codes import EC8_REDUCTION, separation_rules

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
        :func:`~stochpound.analysis.store_contact_demands`
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
        As in :func:`~stochpound.analysis.separation_rules`.
    confidence, bootstrap, seed
        As in :func:`~stochpound.risk.stripe_fragility`.

    Returns
    -------
    xarray.Dataset
        Over ``design_level`` (the probabilities) and ``rule``:
        ``code_intensity`` and ``stripe_intensity`` (IM units), ``gap`` (m,
        per contact), the fragility's ``theta``, ``beta``, ``status``, and
        ``maf`` (1/yr), ``probability`` in ``years`` and ``return_period``
        (yr); with a bootstrap, ``maf_lower``/``maf_upper`` and
        ``gap_lower``/``gap_upper`` (none where the motions cannot be
        resampled, e.g. all from one earthquake: the attribute
        ``no_interval`` says why). ``.to_dataframe()`` gives a table.
    """
    for name in ("peak_displacement_left", "peak_displacement_right", "correlation", "peak_closure"):
        if name not in demands:
            raise ValueError(f"demands: missing {name!r} (see stochpound.analysis.contact_demands)")
    for dim in (intensity_dim, record_dim, contact_dim):
        if dim not in demands["peak_closure"].dims:
            raise ValueError(f"demands: peak_closure has no dimension {dim!r}")
    motions = demands.sizes[record_dim]
    ran = demands["peak_closure"].notnull().any([dim for dim in demands["peak_closure"].dims if dim not in (intensity_dim, record_dim)])
    fewest = int(ran.sum(record_dim).min())  # a conditional-spectrum stripe runs only its chosen motions of the pool
    if fewest < MINIMUM_MOTIONS:
        raise ValueError(f"{record_dim}: the codes take the mean over at least {MINIMUM_MOTIONS} motions, got {fewest}")
    if "gap" in demands.coords and "gap" not in demands.dims:  # a store's contact-free selection
        demands = demands.drop_vars("gap")
    levels = np.asarray(demands[intensity_dim].values, dtype=float)
    chain = _RuleChain(demands, hz, isolator_displacement, cqc, reduction, intensity_dim, record_dim, contact_dim)
    motions_all = xr.DataArray(np.ones((1, motions)), dims=("sample", record_dim))
    clusters = record_clusters(demands, record_dim)
    obstacle = resampling_obstacle(motions, clusters) if bootstrap else ""
    per_level = []
    for probability in np.atleast_1d(np.asarray(design_levels, dtype=float)):
        code_intensity = float(hz.intensity_at(rate_from_probability(probability, years)))
        stripe = int(np.argmin(np.abs(np.log(levels) - np.log(code_intensity))))
        estimate = chain(stripe, motions_all).isel(sample=0, drop=True)
        level = estimate.assign(
            probability=xr.apply_ufunc(probability_from_rate, estimate["maf"], kwargs={"years": years}).assign_attrs(
                units="1", long_name=f"probability of pounding in {years:g} years (Poisson)"),
            return_period=xr.apply_ufunc(return_period, estimate["maf"]).assign_attrs(units="yr", long_name="mean return period of pounding"),
        )
        if bootstrap and not obstacle:
            sampled = chain(stripe, xr.DataArray(bootstrap_weights(motions, bootstrap, seed, clusters), dims=("sample", record_dim)))
            left_out = chain(stripe, xr.DataArray(jackknife_weights(motions, clusters), dims=("sample", record_dim))).rename(sample="jackknife")
            attrs = {"confidence": confidence, "method": f"{bootstrap_method(clusters, ran.transpose(intensity_dim, record_dim).values)} (rule gap and fragility refitted)", "seed": seed}
            for name, units in (("maf", "1/yr"), ("gap", "m")):
                lower, upper = xr.apply_ufunc(lambda b, e, j: interval(b, e, j, confidence), sampled[name], estimate[name], left_out[name],
                                              input_core_dims=[["sample"], [], ["jackknife"]], output_core_dims=[[], []])
                level[f"{name}_lower"] = lower.assign_attrs(units=units, long_name=f"lower bound of {name}", **attrs)
                level[f"{name}_upper"] = upper.assign_attrs(units=units, long_name=f"upper bound of {name}", **attrs)
            level = rate_intervals(level, years)
        per_level.append(level.assign_coords(code_intensity=code_intensity, stripe_intensity=levels[stripe]))
    result = xr.concat(per_level, dim="design_level", coords="all")
    result = result.assign_coords(design_level=("design_level", np.atleast_1d(np.asarray(design_levels, dtype=float)),
                                                {"units": "1", "long_name": f"probability of exceedance in {years:g} years of the code intensity"}))
    result["code_intensity"].attrs.update(long_name="intensity with the design level's rate on the hazard curve")
    result["stripe_intensity"].attrs.update(long_name="level of the stripe the rules are applied at (nearest in ln IM)")
    return result.assign_attrs(years=years, hazard=repr(hz), **({"no_interval": obstacle} if obstacle else {}))


class _RuleChain:
    """The rules' gaps at a stripe and the MAF of pounding at them, for motion weights (dims ``sample``, record)."""

    _BLOCK = 100

    def __init__(self, demands: xr.Dataset, hz: HazardCurve, isolator: xr.DataArray | None, cqc: xr.DataArray | None,
                 reduction: float, intensity_dim: str, record_dim: str, contact_dim: str) -> None:
        self.demands, self.hz, self.isolator, self.cqc, self.reduction = demands, hz, isolator, cqc, reduction
        self.intensity_dim, self.record_dim, self.contact_dim = intensity_dim, record_dim, contact_dim
        self.levels = np.asarray(demands[intensity_dim].values, dtype=float)

    def __call__(self, stripe: int, weights: xr.DataArray) -> xr.Dataset:
        blocks = [self._block(stripe, weights.isel(sample=slice(start, start + self._BLOCK)))
                  for start in range(0, weights.sizes["sample"], self._BLOCK)]
        return xr.concat(blocks, dim="sample") if len(blocks) > 1 else blocks[0]

    def _block(self, stripe: int, weights: xr.DataArray) -> xr.Dataset:
        record, intensity = self.record_dim, self.intensity_dim
        at_stripe = self.demands.isel({intensity: stripe}, drop=True)
        means = _suite_mean(at_stripe, weights, record)
        gaps = separation_rules(means, self.cqc, self.reduction)
        if self.isolator is not None:
            isolator = self.isolator.isel({intensity: stripe}, drop=True)
            isolator = isolator.drop_vars([name for name in isolator.coords if name == "gap"])
            dtm = _suite_mean(isolator, weights, record)
            gaps = xr.concat([gaps, dtm.broadcast_like(gaps.isel(rule=0, drop=True)).expand_dims(rule=["dtm"])], dim="rule")
        excess = (self.demands["peak_closure"] - gaps).max(self.contact_dim, skipna=False)
        valid = excess.notnull()
        exceeded = ((excess >= 0.0) * weights).sum(record).transpose(..., intensity)
        runs = (valid * weights).sum(record).transpose(..., intensity)
        theta, beta, status = stripe_mle(self.levels, exceeded.values, runs.values)
        dims, coords = exceeded.dims[:-1], {name: coord for name, coord in exceeded.coords.items() if intensity not in coord.dims}
        return xr.Dataset(
            {
                "gap": gaps.assign_attrs(units="m", long_name="gap the rule asks for at the code intensity"),
                "theta": (dims, theta, {"long_name": "median of the lognormal fragility at the rule's gap (IM units)"}),
                "beta": (dims, beta, {"units": "1", "long_name": "log-standard deviation of that fragility"}),
                "status": (dims, status.astype(np.int8), {"long_name": "fit status", "flag_meanings": " ".join(STATUS)}),
                "maf": (dims, fit_maf(theta, beta, status, exceeded.values, runs.values, self.hz), {"units": "1/yr", "long_name": "mean annual frequency of pounding at the rule's gap"}),
            },
            coords=coords,
        )


def _suite_mean(values: xr.Dataset | xr.DataArray, weights: xr.DataArray, record: str) -> xr.Dataset | xr.DataArray:
    """Weighted mean over the motions that ran (a conditional-spectrum stripe leaves the pool's other motions NaN)."""
    return (values * weights).sum(record) / (values.notnull() * weights).sum(record)
