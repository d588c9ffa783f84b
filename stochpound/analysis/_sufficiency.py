"""Is a stripe's measure sufficient? The demand's residual trend with M, R and ε within the stripes (issue 44, item 5; docs/measure-free.md).

Within a stripe every motion is scaled to the same level of the measure, so
a measure that is *sufficient* for the demand (Luco & Cornell 2007) leaves
nothing of the motion's earthquake in it: the demand's distribution at the
level does not depend on the magnitude M, the distance R or the ε of the
motion. The test is a regression of ln D on the covariates within the
stripes, pooled over the stripes with one intercept per stripe (stripe
fixed effects):

    ln D_ij = α_i + Σ_k b_k x_kij + e_ij,    i the stripe, j its motion,

fitted by least squares (equivalently: y and every x less its stripe's
mean, one line through the origin). Each slope b_k comes with its standard
error, its interval and the two-sided p-value of b_k = 0 (Student's t); the
measure is called *insufficient with respect to x_k* where that p-value is
below the stated level (the regression test of Luco & Cornell 2007 and
Tothong & Luco 2007; Jalayer et al. 2012's information-theoretic measure
is another, not computed here). Each covariate is tested at the level on its own: with three
of them and no trend at all, one or more is flagged with a chance up to
1 − (1 − level)³ (14 % at 5 %).

**Errors clustered by earthquake.** A stripe store runs the same records
at several stripes, and the two components of a record (and the records of
one earthquake) share M and most of their ε, so the runs are not
independent draws: least squares' textbook errors would count one record at
five stripes as five pieces of evidence and call trends that are not there.
By default the errors are clustered by earthquake (Cameron & Miller 2015:
the sandwich Σ_g X_gᵀ e_g e_gᵀ X_g over the clusters g, the small-sample
factor G/(G − 1) · (n − 1)/(n − S − K), and Student's t with G − 1 degrees
of freedom); ``cluster=None`` gives the textbook errors (n − S − K degrees
of freedom), right only where every run is a motion of its own.

In a store (:func:`store_sufficiency`) the covariates are each motion's
magnitude, ln of its rupture distance (km) and its ε: the standard normal
deviate of its own (unscaled) measure in its own earthquake, (ln IM − ln
median) / σ, the median and σ of the NGA-West2 average the conditional
spectrum uses (:func:`stochpound.motions.scenario_distribution`) at the
motion's M, R_rup and Vs30 (Baker & Cornell 2005's record ε). The store
keeps no record's mechanism nor its R_JB: a record's ε takes the stripe's
scenario mechanism and the scenario estimates of the conditional spectrum
(R_JB = R_rup, no hanging wall); it is therefore a record ε up to those
terms. A simulated motion of a site's rupture (``[site] simulated_motions``
with ``[site] ruptures``) carries its rupture in its table: its ε is in
that rupture, its mechanism and geometry included.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd
import xarray as xr
from numpy.typing import ArrayLike

from stochpound.motions import Measure

SUFFICIENCY_LEVEL = 0.05
"""The level of the test by default: a slope whose two-sided p-value is below it is a measured trend."""
COVARIATES = {"M": "magnitude", "ln R": "ln of the rupture distance (km)", "ε": "the motion's ε in its own earthquake"}
"""The covariates of a store's test, with what each is."""
RUN_DIMS = ("intensity", "record")
"""The dimensions of a store's contact-free closure that are its runs (the stripe and the motion)."""


@dataclass(frozen=True)
class Sufficiency:
    """The demand's trend with each covariate within the stripes (:func:`stripe_regression`).

    Attributes
    ----------
    covariates : tuple of str
        The covariates' names, in the order of the other fields.
    slope, standard_error, lower, upper, p_value : tuple of float
        Each covariate's slope b_k (ln D per unit of it), its standard error, its interval at ``confidence`` and the two-sided
        p-value of b_k = 0.
    runs, stripes, clusters : int
        The runs fitted (n), the stripes (S) and the clusters (G; ``runs`` when the errors are not clustered).
    degrees_of_freedom : int
        Of Student's t: G − 1 clustered, n − S − K otherwise.
    residual_sigma : float
        The residuals' standard deviation about the fit (n − S − K degrees of freedom).
    level, confidence : float
        The level of the test and the interval's confidence.
    clustered : bool
        Whether the errors are clustered (module docstring).
    """

    covariates: tuple[str, ...]
    slope: tuple[float, ...]
    standard_error: tuple[float, ...]
    lower: tuple[float, ...]
    upper: tuple[float, ...]
    p_value: tuple[float, ...]
    runs: int
    stripes: int
    clusters: int
    degrees_of_freedom: int
    residual_sigma: float
    level: float
    confidence: float
    clustered: bool

    @property
    def insufficient(self) -> tuple[str, ...]:
        """The covariates whose slope is significant at ``level`` (none: no measured trend)."""
        return tuple(name for name, p in zip(self.covariates, self.p_value) if p < self.level)

    def frame(self) -> pd.DataFrame:
        """One row per covariate: slope, standard error, lower, upper, p-value and whether it is significant."""
        return pd.DataFrame({"slope": self.slope, "standard error": self.standard_error, "lower": self.lower, "upper": self.upper,
                             "p-value": self.p_value, "significant": [p < self.level for p in self.p_value]},
                            index=pd.Index(self.covariates, name="covariate"))

    def conditions(self) -> str:
        """The fit's n and conditions in words."""
        errors = f"errors clustered by earthquake ({self.clusters} clusters)" if self.clustered else "textbook least-squares errors"
        return (f"n {self.runs} runs in {self.stripes} stripes, one intercept a stripe, {errors}, "
                f"{_percent(self.confidence)} intervals, two-sided test at the {_percent(self.level)} level")

    def reason(self) -> str:
        """The measured reason in one sentence: the significant trends, or that there is none."""
        if not self.insufficient:
            return (f"no residual trend with {', '.join(self.covariates)} within the stripes at the {_percent(self.level)} level "
                    f"(n {self.runs}): not insufficient by this test")
        trends = []
        for k, name in enumerate(self.covariates):
            if name in self.insufficient:
                trends.append(f"ln D {'rises' if self.slope[k] > 0 else 'falls'} by {abs(self.slope[k]):.3g} a unit of {name} "
                              f"({_percent(self.confidence)}: {self.lower[k]:.3g} to {self.upper[k]:.3g}, p {self.p_value[k]:.2g})")
        return f"insufficient with respect to {', '.join(self.insufficient)}: {'; '.join(trends)} within the stripes (n {self.runs})"


def _percent(fraction: float) -> str:
    """A fraction as a percentage in the project's style, e.g. ``5 %``."""
    return f"{100 * fraction:g} %"


def stripe_regression(log_demand: ArrayLike, stripe: ArrayLike, covariates: Mapping[str, ArrayLike], *, cluster: ArrayLike | None = None,
                      level: float = SUFFICIENCY_LEVEL, confidence: float = 0.95) -> Sufficiency:
    """Regress ln D on the covariates within the stripes, one intercept a stripe (module docstring).

    Parameters
    ----------
    log_demand : array_like
        ln D of every run (one value a run); runs with a non-finite value anywhere are left out.
    stripe : array_like
        Each run's stripe (any labels).
    covariates : mapping of str to array_like
        Each covariate's value at every run, by name.
    cluster : array_like, optional
        Each run's cluster (e.g. its earthquake): clustered errors; none: textbook least-squares errors.
    level : float
        The test's level, in (0, 1).
    confidence : float
        The intervals' confidence, in (0, 1).

    Returns
    -------
    Sufficiency

    Raises
    ------
    ValueError
        One line naming the argument: lengths that differ, no covariate, a level or confidence outside (0, 1), too few runs
        (or clusters) for the fit, a covariate without variation within the stripes.
    """
    from scipy import stats

    for name, value in (("level", level), ("confidence", confidence)):
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0.0 < value < 1.0:
            raise ValueError(f"{name}: must be in (0, 1), got {value!r}")
    if not covariates:
        raise ValueError("covariates: must name one or more")
    y = np.asarray(log_demand, dtype=float).ravel()
    x = np.column_stack([np.asarray(v, dtype=float).ravel() for v in covariates.values()]) if covariates else np.empty((y.size, 0))
    labels = {"stripe": np.asarray(stripe).ravel(), **({} if cluster is None else {"cluster": np.asarray(cluster).ravel()})}
    for name, value in (("covariates", x), *labels.items()):
        if len(value) != y.size:
            raise ValueError(f"{name}: must have one value a run ({y.size}), got {len(value)}")
    keep = np.isfinite(y) & np.all(np.isfinite(x), axis=1)
    y, x, labels = y[keep], x[keep], {k: v[keep] for k, v in labels.items()}
    groups = pd.factorize(labels["stripe"])[0]
    n, k, s = y.size, x.shape[1], groups.max(initial=-1) + 1
    if n - s - k < 1:
        raise ValueError(f"log_demand: {n} runs with finite values in {s} stripes are too few for {k} slopes (need more than {s + k})")
    xd, yd = _within(x, groups, s), _within(y[:, None], groups, s)[:, 0]
    gram = xd.T @ xd
    flat = [name for j, name in enumerate(covariates) if gram[j, j] <= 1e-12 * max(1.0, float(np.sum(x[:, j] ** 2)))]
    if flat:
        raise ValueError(f"covariates[{flat[0]!r}]: does not vary within the stripes, no trend can be measured")
    inverse = np.linalg.inv(gram)
    slope = inverse @ xd.T @ yd
    residual = yd - xd @ slope
    sigma2 = float(residual @ residual) / (n - s - k)
    if cluster is None:
        covariance, clusters, dof = sigma2 * inverse, n, n - s - k
    else:
        covariance, clusters = _clustered(xd, residual, inverse, pd.factorize(labels["cluster"])[0], s)
        dof = clusters - 1
        if clusters <= k:
            raise ValueError(f"cluster: the runs fall in {clusters} cluster{'s' if clusters > 1 else ''}, clustered errors of {k} "
                             f"slope{'s' if k > 1 else ''} need more than {k}")
    error = np.sqrt(np.diag(covariance))
    p = 2.0 * stats.t.sf(np.abs(slope) / error, dof)
    half = stats.t.ppf(0.5 + confidence / 2.0, dof) * error
    return Sufficiency(tuple(covariates), *(tuple(float(v) for v in a) for a in (slope, error, slope - half, slope + half, p)),
                       runs=n, stripes=int(s), clusters=int(clusters), degrees_of_freedom=int(dof), residual_sigma=math.sqrt(sigma2),
                       level=float(level), confidence=float(confidence), clustered=cluster is not None)


def _within(values: np.ndarray, groups: np.ndarray, count: int) -> np.ndarray:
    """Each column less its mean over the rows of the same group (the stripe fixed effects taken out)."""
    sums = np.zeros((count, values.shape[1]))
    np.add.at(sums, groups, values)
    return values - (sums / np.bincount(groups, minlength=count)[:, None])[groups]


def _clustered(xd: np.ndarray, residual: np.ndarray, inverse: np.ndarray, clusters: np.ndarray, stripes: int) -> tuple[np.ndarray, int]:
    """The cluster-robust covariance of the slopes (CR1) and the number of clusters."""
    g = clusters.max() + 1
    scores = np.zeros((g, xd.shape[1]))
    np.add.at(scores, clusters, xd * residual[:, None])
    n, k = xd.shape
    factor = g / max(g - 1, 1) * (n - 1) / (n - stripes - k)
    return factor * inverse @ (scores.T @ scores) @ inverse, int(g)


@dataclass(frozen=True)
class StoreSufficiency:
    """The sufficiency test of a stripe store's measure for each configuration (:func:`store_sufficiency`).

    Attributes
    ----------
    measure : str
        The store's measure (its label).
    demand : str
        The demand tested (``closure``: the largest contact-free peak closure over the contacts).
    configurations : tuple of tuple
        Each configuration's labels, as (dimension, label) pairs (empty: a store of one configuration).
    results : tuple of Sufficiency
        The test of each configuration.
    """

    measure: str
    demand: str
    configurations: tuple[tuple[tuple[str, Any], ...], ...]
    results: tuple[Sufficiency, ...]

    def result(self, labels: tuple[tuple[str, Any], ...]) -> Sufficiency:
        """The test of one configuration (its (dimension, label) pairs), or a one-line error naming what the store lacks."""
        wanted = dict(labels)
        for mine, result in zip(self.configurations, self.results):
            if all(wanted.get(dim) == value for dim, value in mine):
                return result
        raise ValueError(f"labels: no configuration {labels!r} in the sufficiency test of {self.measure}")

    def verdict(self) -> str:
        """Each configuration's :meth:`Sufficiency.reason`, after its labels where it has any (``"mu 0.05: ...; mu 0.08: ..."``)."""
        from stochpound.analysis._measure_free_store import configuration_label

        return "; ".join(f"{configuration_label(labels)}: {result.reason()}" if labels else result.reason()
                         for labels, result in zip(self.configurations, self.results))

    def frame(self) -> pd.DataFrame:
        """One row per configuration and covariate: slope, its error, interval and p-value, whether significant, and n."""
        from stochpound.analysis._measure_free_store import configuration_label

        parts = [result.frame().assign(runs=result.runs).set_index(pd.Index([configuration_label(labels)] * len(result.covariates),
                                                                            name="configuration"), append=True)
                 for labels, result in zip(self.configurations, self.results)]
        return pd.concat(parts).reorder_levels(["configuration", "covariate"])

    def display_frame(self) -> pd.DataFrame:
        """:meth:`frame` for reading: slopes, errors and intervals to 4 decimals, p-values to 2 significant digits."""
        frame = self.frame()
        numbers = ["slope", "standard error", "lower", "upper"]
        return frame.assign(**{name: frame[name].round(4) for name in numbers}, **{"p-value": frame["p-value"].map(lambda p: f"{p:.2g}")})


def store_sufficiency(store: xr.Dataset, *, cluster: bool = True, level: float = SUFFICIENCY_LEVEL, confidence: float = 0.95) -> StoreSufficiency:
    """The sufficiency test of a stripe store's measure for the contact-free closure, per configuration (module docstring).

    Parameters
    ----------
    store : xarray.Dataset
        An experiment store of intensity stripes with contact-free cases and each motion's ``record_magnitude`` and
        ``record_distance`` (motions from suites or simulated ones); ε needs a measure in g (PGA, PSA, Sa_avg).
    cluster : bool
        Errors clustered by earthquake (``record_event``; a motion without one is its own), or textbook errors.
    level, confidence : float
        As :func:`stripe_regression`.

    Returns
    -------
    StoreSufficiency

    Raises
    ------
    ValueError
        One line naming what the store lacks, or as :func:`stripe_regression`.
    """
    from stochpound.risk import contact_free_closure

    setting = store.pound.intensity
    if setting is None or "intensity" not in store.dims:
        raise ValueError("store: has no intensity stripes (an [intensity] table with method = \"stripes\")")
    missing = [name for name in ("record_magnitude", "record_distance") if name not in store.coords]
    if missing:
        raise ValueError(f"store: has no {missing[0]!r} (the motions' earthquakes: motions from suites or simulated ones)")
    closure = contact_free_closure(store)
    if "record" not in closure.coords or closure["record"].size != store["record"].size:
        raise ValueError("store: its motions have several realizations; the test takes one run a motion and stripe")
    covariates = _store_covariates(store, setting.measure, setting.units)
    events = store["record_event"].values.astype(str) if "record_event" in store.coords else np.full(store.sizes["record"], "")
    earthquake = np.where(events == "", store["record"].values.astype(str), events)
    others = [d for d in closure.dims if d not in RUN_DIMS]
    configurations, results = [], []
    for index in np.ndindex(*[closure.sizes[d] for d in others]):
        labels = tuple((d, closure[d].values[i].item()) for d, i in zip(others, index))
        demand = closure.isel(dict(zip(others, index))).transpose(*RUN_DIMS)
        stripe, record = np.meshgrid(np.arange(demand.sizes["intensity"]), np.arange(demand.sizes["record"]), indexing="ij")
        with np.errstate(divide="ignore", invalid="ignore"):
            log_demand = np.log(demand.values)
        results.append(stripe_regression(log_demand, stripe, {name: value[record] for name, value in covariates.items()},
                                         cluster=earthquake[record] if cluster else None, level=level, confidence=confidence))
        configurations.append(labels)
    return StoreSufficiency(setting.measure.label, "closure", tuple(configurations), tuple(results))


def _simulated_ruptures(store: xr.Dataset) -> list[tuple[str | None, Mapping[str, float]]]:
    """Per motion, the mechanism and geometry of the rupture a simulated motion's table names (``[site] simulated_motions`` at a site
    of ruptures); (None, {}) for a record, whose ε takes the stripe's scenario mechanism."""
    from stochpound.motions import GEOMETRY_FIELDS

    tables = [json.loads(str(text)) for text in store["record_motion"].values] if "record_motion" in store.coords else []
    found: list[tuple[str | None, Mapping[str, float]]] = [(None, {})] * store.sizes["record"]
    for j, table in enumerate(tables):
        if isinstance(table, dict) and "rupture" in table and "mechanism" in table:
            found[j] = (str(table["mechanism"]), {key: float(table[key]) for key in GEOMETRY_FIELDS if key in table})
    return found


def _store_covariates(store: xr.Dataset, measure: Measure, units: str) -> dict[str, np.ndarray]:
    """Each motion's M, ln R and (for a measure in g) ε in its own earthquake, the stripe's scenario mechanism (module docstring)."""
    magnitude, distance = (store[name].values.astype(float) for name in ("record_magnitude", "record_distance"))
    values = {"M": magnitude, "ln R": np.log(distance)}
    if units != "g" or measure.kind not in ("pga", "psa", "sa_avg") or "motion_intensity" not in store:
        return values
    from stochpound._errors import SiteError
    from stochpound.motions import scenario_distribution

    own = store["motion_intensity"]
    own = own.max([d for d in own.dims if d != "record"], skipna=True).values.astype(float)  # the same unscaled value at every case
    vs30 = store["record_vs30"].values.astype(float) if "record_vs30" in store.coords else np.full(magnitude.size, float(store["site_vs30"].values[0]))
    mechanism = str(store["site_mechanism"].values[0]) if "site_mechanism" in store.coords else "strike_slip"
    own_ruptures = _simulated_ruptures(store)
    period = measure.period if measure.kind == "psa" else (list(measure.periods) if measure.kind == "sa_avg" else None)
    epsilon = np.full(magnitude.size, np.nan)  # NaN: a motion without its earthquake, or outside the models' range (left out)
    for j in range(magnitude.size):
        if all(np.isfinite(v) for v in (magnitude[j], distance[j], vs30[j], own[j])) and own[j] > 0:
            try:
                median, sigma = scenario_distribution(measure.kind, period, magnitude=magnitude[j], distance_km=distance[j], vs30=vs30[j],
                                                      mechanism=own_ruptures[j][0] or mechanism, geometry=own_ruptures[j][1])
            except SiteError:
                continue
            epsilon[j] = (math.log(own[j]) - math.log(median)) / sigma
    values["ε"] = epsilon
    return values
