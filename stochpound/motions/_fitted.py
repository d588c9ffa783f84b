"""Scenarios fitted to the site's own hazard curves, standing in for a disaggregation.

A conditional spectrum needs, per level x_j of the conditioning measure IM*,
the scenario (magnitude M, rupture distance R) that causes it: the hazard's
disaggregation. Where none is at hand but the site's hazard curves are known
at other periods T' (the bundled site: PGA and PSA at 0.03–5 s), the
scenario can be calibrated so that the stripes reproduce those curves, the
hazard-consistency check of Lin, Haselton & Baker (2013) used as the fit:

    λ(Sa(T') > y) ≈ Σ_j P(Sa(T') > y | IM* = x_j) Δλ(x_j),

with P from the conditional spectrum of the level's scenario (ln Sa(T')
normal, its conditional mean and σ; :mod:`stochpound.motions._conditional`)
and Δλ(x_j) the rate of IM* in the bin of x_j
(:func:`stochpound.risk.stripe_rate_weights`). The fit integrates on a
fine grid of :data:`FINE_LEVELS` levels (:func:`fit_levels`) from
:data:`SPAN` times below the lowest stripe (or the start of the hazard's table) to :data:`SPAN` times above the
highest or the end of the hazard's table (weaker and stronger shaking add
to the rates compared; the last takes the whole tail), so that the scenario
is fitted to the site's curves and not to the coarseness of a few stripes.

The fit: every scenario of a grid (:data:`MAGNITUDES` × :data:`DISTANCES`,
within the models' range, Vs30 and mechanism given) is a candidate for
every level. The misfit is the sum over the other curves and their
tabulated intensities y whose site rate lies within the stripes' rates
(from λ_IM*(x_top) to λ_IM*(x_1)) of (ln recomputed − ln site)². The
fitted scenario is the candidate of least misfit, the same for every level
(a scenario per level and one varying smoothly with the level were tried
and dropped: docs/intensity.md). Deterministic: no random numbers, ties go
to the first candidate (smaller M, then smaller R).

It is a calibration, not a disaggregation: M and R trade off (a larger M
farther away can give the same spectral shape), so the fitted scenario is
one that makes the site's curves consistent, not the one that dominates its
hazard. What matters downstream, the conditional spectrum's mean and σ at
the structure's periods, is what the fit pins down where the site's curves
are known.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace
from functools import lru_cache

import numpy as np

from stochpound._errors import SiteError
from stochpound.motions._conditional import (
    CONDITIONING_MEASURES,
    _average_model,
    _conditioned,
    _conditioning_nodes,
    conditioning_measure,
    _joint_nodes,
    _node_correlation,
)
from stochpound.motions._scenario import Scenario
from stochpound.motions._measure import Measure

#: Candidate magnitudes of the fit.
MAGNITUDES = tuple(np.round(np.arange(5.5, 8.01, 0.1), 2))
#: Candidate rupture distances of the fit, km.
DISTANCES = (1.0, 2.0, 4.0, 7.0, 10.0, 15.0, 20.0, 30.0, 50.0, 80.0, 120.0)
#: Levels of the fine grid over the stripes' range on which the fit integrates (each takes its nearest stripe's scenario).
FINE_LEVELS = 60
#: The fine grid spans from this factor below the lowest stripe to this factor above the highest (or the hazard table's end).
SPAN = 5.0
#: The fine grid starts at least this factor above the start of the hazard's table (its first bin reaches half a step below it).
LOW_MARGIN = 1.2


def fit_levels(levels: Sequence[float], highest: float = np.inf, lowest: float = 0.0) -> np.ndarray:
    """The fine grid (g) on which :func:`fit_scenarios` integrates: 60 log-spaced levels.

    From 5 times below the lowest of ``levels`` (g), or ``LOW_MARGIN`` (1.2)
    times ``lowest`` (g, e.g. the start of the hazard's table) if higher, so
    that the first level's bin (:func:`stochpound.risk.stripe_rate_weights`,
    half a step below it) stays within the table; to 5 times above the
    highest, or ``highest`` (g, e.g. the end of the table) if lower.
    """
    x = np.sort(np.asarray(levels, dtype=float))
    return np.geomspace(min(max(x[0] / SPAN, lowest * LOW_MARGIN), x[0]), max(min(x[-1] * SPAN, highest), x[-1]), FINE_LEVELS)


def fit_scenarios(
    measure: str,
    period: float | Sequence[float] | None,
    levels: Sequence[float],
    fine_levels: Sequence[float],
    fine_rates: Sequence[float],
    others: Sequence[tuple[float | None, Sequence[float], Sequence[float]]],
    vs30: float,
    mechanism: str,
) -> list[dict[str, float | str]]:
    """The scenario that makes the stripes reproduce the site's other hazard curves (module docstring).

    Parameters
    ----------
    measure : {"pga", "psa", "sa_avg"}
        The conditioning measure IM*; ``period`` its T* (psa) or averaging periods (sa_avg), s.
    levels : list of float
        The stripes' levels of IM*, g, increasing.
    fine_levels, fine_rates : list of float
        The site's hazard of IM* on the fine grid of :func:`fit_levels`:
        its levels (g) and the rate of each one's bin (1/yr, e.g.
        :func:`stochpound.risk.stripe_rate_weights`).
    others : list of (period or None, im, rate)
        The site's hazard curves at other periods: the period in s (None for
        PGA), the tabulated intensities (g) and their annual rates (1/yr).
    vs30 : float
        m/s.
    mechanism : {"strike_slip", "reverse", "normal"}

    Returns
    -------
    list of dict
        Per level, in order: ``magnitude``, ``distance_km``, ``vs30``,
        ``mechanism`` (the same scenario for every level: module docstring).

    Raises
    ------
    SiteError
        Naming the field: an unknown measure, levels not increasing, no
        other curve, no tabulated intensity within the stripes' rates.
    """
    if measure not in CONDITIONING_MEASURES:
        raise SiteError(f"measure: must be one of {', '.join(CONDITIONING_MEASURES)}, got {measure!r}")
    x = np.asarray(levels, dtype=float)
    if x.ndim != 1 or x.size < 2 or not np.all(np.diff(x) > 0) or not np.all(x > 0):
        raise SiteError(f"levels: the fit needs at least 2 increasing levels > 0 g, got {x.tolist()}")
    if not others:
        raise SiteError("others: the fit needs the site's hazard curve at one or more other periods")
    Scenario.of(MAGNITUDES[0], DISTANCES[0], vs30, mechanism)  # vs30 and mechanism checked, naming them
    fine, fine_weights = np.asarray(fine_levels, dtype=float), np.asarray(fine_rates, dtype=float)
    if fine.ndim != 1 or fine.shape != fine_weights.shape or fine.size < x.size or not np.all(np.diff(fine) > 0):
        raise SiteError("fine_levels: increasing levels, one rate of fine_rates each (fit_levels)")
    if fine[0] > x[0] or fine[-1] < x[-1]:
        raise SiteError(f"fine_levels: must span the levels {x[0]:g}-{x[-1]:g} g, got {fine[0]:g}-{fine[-1]:g} g")
    high_rate = float(fine_weights[fine >= x[0]].sum())  # the rates of the stripes' range: λ(x_1) to λ(x_top)
    low_rate = float(fine_weights[fine >= x[-1]].sum())
    targets = []  # per other curve: the intensities y and ln site rate within the stripes' rates
    for node, im, rate in others:
        im, rate = np.asarray(im, dtype=float), np.asarray(rate, dtype=float)
        keep = (rate >= low_rate) & (rate <= high_rate)
        if not keep.any():
            other = Measure("pga") if node is None else Measure("psa", float(node))
            raise SiteError(f"others: the site's {other.label} curve has no intensity whose rate is within the stripes' {low_rate:.3g}-{high_rate:.3g}/yr")
        targets.append((None if node is None else float(node), tuple(im[keep].tolist()), tuple(np.log(rate[keep]).tolist())))
    period = period if period is None or np.ndim(period) == 0 else tuple(period)
    magnitude, distance = _least_misfit(measure, period, tuple(fine.tolist()), tuple(fine_weights.tolist()), tuple(targets), float(vs30), mechanism)
    return [{"magnitude": float(magnitude), "distance_km": float(distance), "vs30": float(vs30), "mechanism": mechanism} for _ in x]


@lru_cache(maxsize=32)
def _least_misfit(measure: str, period: float | tuple[float, ...] | None, fine: tuple[float, ...], fine_weights: tuple[float, ...],
                  targets: tuple[tuple[float | None, tuple[float, ...], tuple[float, ...]], ...], vs30: float, mechanism: str) -> tuple[float, float]:
    """The candidate (magnitude, distance in km) of least misfit (module docstring), for :func:`fit_scenarios`'s checked inputs.

    ``targets``: per other curve, its node (period in s, None for PGA), the
    intensities y within the stripes' rates (g) and the site's ln rates
    there. Kept per process for its inputs (exact floats): experiments at
    the same site and stripes (a run, its report, another configuration)
    fit once; a pure function of its arguments, so the answer is the one a
    fit would give again.
    """
    first = Scenario.of(MAGNITUDES[0], DISTANCES[0], vs30, mechanism)
    weights = np.asarray(fine_weights, dtype=float)
    model = _SiteModel(measure, period, np.asarray(fine, dtype=float), [(node, y, ln_site) for node, y, ln_site in targets])
    intensities = [np.asarray(y, dtype=float) for _, y, _ in targets]
    ln_sites = [np.asarray(ln_site, dtype=float) for _, _, ln_site in targets]
    candidates = [(m, r) for m in MAGNITUDES for r in DISTANCES]
    scores = []
    for magnitude, distance in candidates:
        probabilities = model.exceedance(replace(first, magnitude=magnitude, distance_km=distance), intensities)
        score = 0.0
        for k, ln_site in enumerate(ln_sites):
            recomputed = sum(weights[i] * probabilities[i][k] for i in range(len(fine)))
            score += float(np.sum((np.log(np.maximum(recomputed, 1e-300)) - ln_site) ** 2))
        scores.append(score)
    return candidates[int(np.argmin(scores))]


class _SiteModel:
    """The average NGA-West2 model at the other curves' periods and the conditioning one, for the stripes' levels.

    The nodes and their correlation are those of the conditional spectrum
    (:mod:`stochpound.motions._conditional`), computed once for every scenario the fit tries.
    """

    def __init__(self, measure: str, period: float | Sequence[float] | None, levels: np.ndarray,
                 others: Sequence[tuple[float | None, Sequence[float], Sequence[float]]]) -> None:
        other_nodes = [None if node is None else float(node) for node, _, _ in others]
        self.nodes, self.weights = _joint_nodes(_conditioning_nodes(conditioning_measure(measure, period)), other_nodes)
        self.correlation = _node_correlation(self.nodes)
        self.levels, self.count = levels, len(other_nodes)

    def exceedance(self, scenario: Scenario, intensities: Sequence[np.ndarray]) -> list[list[np.ndarray]]:
        """P(Sa(T'_k) > y | IM* = x_j) of the scenario, [level j][other curve k] over that curve's ``intensities`` (g)."""
        from scipy.special import ndtr

        mean, sigma = _average_model(self.nodes, scenario)
        cond_mean, cond_cov, _ = _conditioned(mean, self.correlation * np.outer(sigma, sigma), self.weights, np.log(self.levels))
        cond_sd = np.sqrt(np.clip(np.diag(cond_cov), 1e-12, None))
        return [[ndtr((cond_mean[j, k] - np.log(y)) / cond_sd[k]) for k, y in enumerate(intensities)] for j in range(self.levels.size)]


def recomputed_hazard(
    measure: str,
    period: float | Sequence[float] | None,
    levels: Sequence[float],
    rate_weights: Sequence[float],
    scenarios: Sequence[dict[str, float | str]],
    others: Sequence[tuple[float | None, Sequence[float], Sequence[float]]],
) -> list[np.ndarray]:
    """The rates λ(Sa(T') > y) (1/yr) the stripes' conditional spectra imply, at every other curve's tabulated intensities (module docstring).

    ``scenarios`` one per level (:func:`fit_scenarios`'s output, or the
    ``[site]`` table's), sharing Vs30 and mechanism; the other arguments as
    for :func:`fit_scenarios`. Returns one array per curve of ``others``.
    """
    x = np.asarray(levels, dtype=float)
    weights = np.asarray(rate_weights, dtype=float)
    model = _SiteModel(measure, period, x, others)
    vs30, mechanism = float(scenarios[0]["vs30"]), str(scenarios[0]["mechanism"])
    intensities = [np.asarray(im, dtype=float) for _, im, _ in others]
    total = [np.zeros(y.size) for y in intensities]
    for j, scenario in enumerate(scenarios):
        probabilities = model.exceedance(Scenario(float(scenario["magnitude"]), float(scenario["distance_km"]), vs30, mechanism), intensities)[j]
        for k in range(len(total)):
            total[k] += weights[j] * probabilities[k]
    return total
