"""Which intensity measure predicts the response best: efficiency and sufficiency from a store's contact-free runs.

For every configuration (each combination of the store's grid axes other
than the gaps and the intensity) and every candidate measure IM, the
contact-free runs give pairs (IM, D), D the largest peak closure over the
contacts or the studied building's peak base displacement, IM the measure
of the motion as it ran (its unscaled measure times the run's scale
factor). A straight line ln D = a + b ln IM is fitted by least squares over
every run (every stripe and motion; for an IDA store, the one run per
motion, whose response is homogeneous in the input); its residual standard
deviation β (n − 2 degrees of freedom) is the measure's **efficiency**: the
dispersion a fragility in that measure carries, and so how many motions an
answer needs (about (β/ε)² for a relative precision ε of the median).
**Sufficiency**: the residuals' linear trend (slope and its two-sided
p-value) with ln(scale factor), the motions' magnitude and distance; a
sufficient measure leaves none.

The candidates: PGA, PGV, PSA at given periods (each building's first-mode
period, the isolated period, the hazard's periods) and Sa_avg over 10
log-spaced periods from 0.2 times the shortest to 3 times the longest
structural period (within the stored spectrum's periods). PSA at a period comes from the spectrum every store keeps
for every motion (5 % damping, at ``spectrum_period``), interpolated
linearly in ln PSA against ln T (periods outside the stored range clipped
to it; the store's own conditioning period is exact, its
``motion_intensity``). The interpolation moves a motion's PSA by a few per
cent between the stored periods, and β by about as much.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import xarray as xr

from stochpound.motions import Measure
from stochpound.risk._inputs import efficiency_runs

#: Periods of Sa_avg, log-spaced over 0.2 T_min – 3 T_max of the structure.
SA_AVG_PERIODS = 10


def measure_efficiency(store: xr.Dataset, periods: Mapping[str, float], structure: Mapping[str, float] | None = None,
                       studied: str | None = None, sa_avg_periods: Sequence[float] | None = None) -> xr.Dataset:
    """Efficiency (β) and sufficiency (residual trends) of candidate measures, per configuration (module docstring).

    Parameters
    ----------
    store : xarray.Dataset
        An experiment store with intensity stripes (contact-free cases) or IDA runs.
    periods : mapping of str to float
        Candidate PSA periods (s), by name (e.g. ``{"B1 first mode": 0.30, "hazard": 1.0}``).
    structure : mapping of str to float, optional
        The structure's periods (s) over which Sa_avg is taken; default ``periods``.
    studied : str, optional
        The building whose peak base displacement is the second response (where it slides).
    sa_avg_periods : sequence of float, optional
        The periods (s) of the Sa_avg candidate (e.g. a store's own Sa_avg band); default 10 log-spaced over 0.2 T_min – 3 T_max
        of ``structure``, within the stored spectrum's periods.

    Returns
    -------
    xarray.Dataset
        Over ``response`` (``closure``, and ``base_displacement`` for a
        sliding studied building), ``measure`` and the configurations:
        ``beta``, ``slope`` (b), ``runs``, and for each of scale_factor,
        magnitude and distance the residuals' ``trend_<x>`` (per unit of x)
        and ``p_<x>``. ``measure`` carries ``measure_period`` (s; NaN for PGA, PGV, Sa_avg).
    """
    runs = efficiency_runs(store, studied)
    scale, spectrum_periods, psa = runs.scale_factor, runs.spectrum_periods, runs.psa
    average = _average_periods(structure or periods, spectrum_periods) if sa_avg_periods is None else np.asarray(sa_avg_periods, dtype=float)
    if average.ndim != 1 or average.size < 2 or not np.all(average > 0):
        raise ValueError(f"sa_avg_periods: must be two or more periods > 0 s, got {sa_avg_periods!r}")
    candidates = {Measure("pga").label: runs.pga, Measure("pgv").label: runs.pgv}
    measure_periods = [np.nan, np.nan]
    for name, period in periods.items():
        label = candidate_name(period, name)
        if period == runs.conditioning:  # the store's own measure, exact
            candidates[label] = runs.intensity
        else:
            candidates[label] = _interpolated(psa, spectrum_periods, [period]).isel(period=0, drop=True)
        measure_periods.append(float(period))
    candidates[Measure("sa_avg", periods=tuple(average)).named(".3g")] = np.exp(np.log(_interpolated(psa, spectrum_periods, average)).mean("period"))
    measure_periods.append(np.nan)
    covariates = {"scale_factor": np.log(scale)}
    for key, coordinate in (("magnitude", "record_magnitude"), ("distance", "record_distance")):
        if coordinate in runs.covariates:
            covariates[key] = runs.covariates[coordinate].broadcast_like(scale)
    fits = {response: xr.concat([_fit(value, im * scale, covariates) for im in candidates.values()], "measure")
            for response, value in runs.responses.items()}
    result = xr.concat(list(fits.values()), "response").assign_coords(response=list(fits), measure=list(candidates))
    return result.assign_coords(measure_period=("measure", np.array(measure_periods)))


def _average_periods(structure: Mapping[str, float], spectrum_periods: np.ndarray) -> np.ndarray:
    """The default periods (s) of Sa_avg: ``SA_AVG_PERIODS`` log-spaced over 0.2 T_min – 3 T_max, within the stored spectrum's periods."""
    structural = np.array(list(structure.values()), dtype=float)
    low, high = max(0.2 * structural.min(), spectrum_periods[0]), min(3.0 * structural.max(), spectrum_periods[-1])
    return np.geomspace(low, high, SA_AVG_PERIODS)


def candidate_name(period: float | None, name: str) -> str:
    """The name of a candidate measure: PSA at ``period`` (s; None: PGA) with the ``name`` of that period, e.g. ``PSA(0.305 s, B1 first mode)``."""
    return Measure("pga").label if period is None else Measure("psa", float(period)).named(".3g", name)


def most_efficient(efficiency: xr.Dataset, measures: list[str], response: str = "closure") -> xr.DataArray:
    """The name of the measure of least β among ``measures`` (names of ``efficiency.measure``), per configuration."""
    beta = efficiency["beta"].sel(response=response, measure=measures).transpose(..., "measure")
    index = np.argmin(np.nan_to_num(beta.values, nan=np.inf), axis=-1)
    return xr.DataArray(np.asarray(measures, dtype=object)[index], dims=beta.dims[:-1], coords={d: beta[d] for d in beta.dims[:-1]})


def _interpolated(psa: xr.DataArray, spectrum_periods: np.ndarray, periods: np.ndarray | list[float]) -> xr.DataArray:
    """PSA at ``periods`` (s), linear in ln PSA against ln T between the stored periods (clipped to their range)."""
    log_t = np.log(np.clip(np.asarray(periods, dtype=float), spectrum_periods[0], spectrum_periods[-1]))
    log_psa = np.log(psa.transpose(..., "spectrum_period"))
    values = np.apply_along_axis(lambda row: np.interp(log_t, np.log(spectrum_periods), row), -1, log_psa.values)
    dims = log_psa.dims[:-1] + ("period",)
    return xr.DataArray(np.exp(values), dims=dims, coords={k: v for k, v in log_psa.coords.items() if "spectrum_period" not in v.dims})


def _fit(response: xr.DataArray, im: xr.DataArray, covariates: Mapping[str, xr.DataArray]) -> xr.Dataset:
    """Least-squares ln D = a + b ln IM per configuration over the runs (the stripes and motions), with the residuals' trends."""
    from scipy.stats import linregress

    runs = [d for d in ("intensity", "record") if d in response.dims]
    configurations = [d for d in response.dims if d not in runs]
    shape = [response.sizes[d] for d in configurations]
    flat = {name: _by_configuration(value, response, configurations + runs, shape) for name, value in {"d": response, "im": im, **covariates}.items()}
    names = ["beta", "slope", "runs"] + [f"{kind}_{key}" for key in covariates for kind in ("trend", "p")]
    out = {name: np.full(shape, np.nan) for name in names}
    for index in np.ndindex(*shape):
        d, x = flat["d"][index], flat["im"][index]
        ok = np.isfinite(d) & (d > 0) & np.isfinite(x) & (x > 0)
        out["runs"][index] = ok.sum()
        if ok.sum() < 3:
            continue
        fit = linregress(np.log(x[ok]), np.log(d[ok]))
        residual = np.log(d[ok]) - (fit.intercept + fit.slope * np.log(x[ok]))
        out["beta"][index] = np.sqrt(np.sum(residual**2) / (ok.sum() - 2))
        out["slope"][index] = fit.slope
        for key in covariates:
            c = flat[key][index][ok]
            if np.all(np.isfinite(c)) and np.ptp(c) > 1e-12 * max(1.0, np.max(np.abs(c))):
                trend = linregress(c, residual)
                out[f"trend_{key}"][index], out[f"p_{key}"][index] = trend.slope, trend.pvalue
    coords = {d: response[d] for d in configurations}
    return xr.Dataset({name: (configurations, value) for name, value in out.items()}, coords=coords)


def _by_configuration(value: xr.DataArray, response: xr.DataArray, order: list[str], shape: list[int]) -> np.ndarray:
    """``value`` on ``response``'s dimensions as floats of shape ``shape`` + (runs,): the runs (stripes, then motions) in C order.

    ``value`` has the same labels as ``response`` on the dimensions they share (both are read from one store: checked).
    """
    for dim in value.dims:
        index = response.indexes.get(dim)
        if dim in value.indexes and (index is None or not value.indexes[dim].equals(index)):
            raise ValueError(f"{value.name or 'value'}: its {dim!r} labels are not the response's")
    expanded = value.variable.set_dims({dim: response.sizes[dim] for dim in order})
    return expanded.transpose(*order).values.astype(float).reshape(*shape, -1)
