"""The conditional spectrum of a site scenario (Baker 2011), from the NGA-West2 models in pygmm.

Given a scenario (magnitude M, rupture distance R, Vs30, mechanism) every
ground-motion model gives, at every period, the median and the standard
deviation σ of ln Sa. The four NGA-West2 models ASK14, BSSA14, CB14 and
CY14 (pygmm) are averaged with equal weights: the mean of their ln medians,
and σ = √(mean of their σ²) (the aleatory variability of the average model;
the spread of the four medians is epistemic, which the site's hazard curve
already integrates, and is left out).

The ε of ln Sa at two periods are correlated by ρ(T1, T2) of Baker & Jayaram
(2008, pygmm's ``baker_jayaram_2008.calc_correls``), PGA taken as Sa at
0.01 s, the shortest period of the models and of the correlation. So ln Sa
over a set of periods is multivariate normal, mean μ and covariance
C_kl = ρ_kl σ_k σ_l. The conditioning measure is a linear function wᵀ x of
that vector x of ln Sa: w picks one entry for PGA or PSA(T*); for Sa_avg,
the geometric mean of Sa over its n periods, ln Sa_avg = (1/n) Σ_k ln Sa(T_k),
w_k = 1/n. Then ln IM* is normal with mean wᵀμ and variance wᵀCw (for
Sa_avg: (1/n²) Σ_kl ρ_kl σ_k σ_l), and given ln IM* = ln x,

    ε* = (ln x − wᵀμ) / √(wᵀCw)
    mean | x = μ + C w ε* / √(wᵀCw)
    cov | x  = C − C w wᵀ C / (wᵀCw).

For PSA(T*) this is the familiar μ(T) + ρ(T, T*) ε* σ(T) and σ(T) √(1 − ρ²);
for Sa_avg the correlation of ln Sa(T) with ln Sa_avg is
(1/n) Σ_k ρ(T, T_k) σ_k / σ_avg. At T* the conditional mean is ln x and the
σ is 0.

Scenario inputs the magnitude, distance, Vs30 and mechanism do not fix (the
toolkit's estimates, stated in docs/intensity.md): the rupture reaches the
surface (Z_tor = 0) and the site is on its footwall side, so R_JB = R_rup
and R_x = −R_rup (no hanging-wall term); the dip is 90° for strike-slip,
40° for reverse and 50° for normal faulting (Kaklamanos et al. 2011);
region California, Vs30 measured; the basin depths Z1.0 and Z2.5, the
rupture width and the hypocentral depth are each model's own default
estimate in pygmm (from Vs30, M and the dip). A scenario's ``geometry``
(:data:`GEOMETRY_FIELDS`: R_JB, R_x, Z_tor, dip, Z1.0, Z2.5, e.g. a
rupture of a site's table, :class:`stochpound.analysis.RuptureSite`) replaces
those estimates field by field; the site is on the hanging wall where R_x ≥ 0.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import xarray as xr

from stochpound._errors import SiteError
from stochpound.motions._measure import Measure
from stochpound.motions._scenario import GEOMETRY_FIELDS, MECHANISMS, Scenario, given_scenario, ground_motion_models, is_finite_number

#: Measures a conditional spectrum can be conditioned on.
CONDITIONING_MEASURES = ("pga", "psa", "sa_avg")
#: Periods (s) of the models and of the correlation.
PERIOD_RANGE = (0.01, 10.0)
#: Period (s) at which PGA enters the correlation.
PGA_PERIOD = 0.01
#: Damping ratio of the models' spectra.
MODEL_DAMPING = 0.05
#: ε (standard deviations above the models' median) at which hazard models truncate the ground motion: a level beyond it
#: is not caused by the scenario in such a model (the USGS models of the bundled curves: nshmp-haz's upper truncation at 3σ).
TRUNCATION_EPSILON = 3.0


@dataclass(frozen=True)
class ConditionalDistribution:
    """ln Sa (g) at ``periods`` given the conditioning measure at each of ``levels`` (g), in one scenario.

    ``mean_ln`` [level, period] and ``covariance`` [period, period] (the
    same at every level) of the conditional normal, ``epsilon`` [level] the
    levels' ε*; the scenario's unconditional moments at ``periods``, and
    those of ln IM* (``measure_mean_ln``, ``measure_sigma_ln``).
    """

    periods: np.ndarray
    levels: np.ndarray
    mean_ln: np.ndarray
    covariance: np.ndarray
    unconditional_mean_ln: np.ndarray
    unconditional_sigma_ln: np.ndarray
    epsilon: np.ndarray
    measure_mean_ln: float
    measure_sigma_ln: float


def _pygmm_scenario(scenario: Scenario):
    """pygmm's scenario: the estimates of the module docstring, replaced by the scenario's geometry given."""
    import pygmm

    code, dip = MECHANISMS[scenario.mechanism]
    distance = scenario.distance_km
    fields = {"mag": scenario.magnitude, "dist_rup": distance, "dist_jb": distance, "dist_x": -distance,
              "v_s30": scenario.vs30, "mechanism": code, "dip": dip, "depth_tor": 0.0, "region": "california", "vs_source": "measured"}
    given = {GEOMETRY_FIELDS[field]: value for field, value in scenario.geometry.items()}
    if given:
        fields.update(given)
        fields["on_hanging_wall"] = fields["dist_x"] >= 0.0
    return pygmm.Scenario(**fields)


def _average_model(nodes: Sequence[float | None], scenario: Scenario) -> tuple[np.ndarray, np.ndarray]:
    """Mean ln median (g) and σ of the four models at every node (a period in s, or None for PGA)."""
    models_scenario = _pygmm_scenario(scenario)
    periods = np.array([PGA_PERIOD if node is None else node for node in nodes], dtype=float)
    is_pga = np.array([node is None for node in nodes])
    means, variances = [], []
    with warnings.catch_warnings():  # a Scenario is within the models' limits
        warnings.simplefilter("ignore", UserWarning)
        for model_class in ground_motion_models():
            model = model_class(models_scenario)
            means.append(np.where(is_pga, np.log(model.pga), model.interp_ln_spec_accels(periods)))
            variances.append(np.where(is_pga, model.ln_std_pga, model.interp_ln_stds(periods)) ** 2)
    return np.mean(means, axis=0), np.sqrt(np.mean(variances, axis=0))


def _check_periods(values: Sequence[float], field: str) -> np.ndarray:
    """Periods (s) within :data:`PERIOD_RANGE`, or a one-line error naming ``field``."""
    periods = np.atleast_1d(np.asarray(values, dtype=float))
    low, high = PERIOD_RANGE
    if periods.ndim != 1 or not periods.size:
        raise SiteError(f"{field}: must be one or more periods in s, got {values!r}")
    for period in periods:
        if not low <= period <= high:
            raise SiteError(f"{field}: periods must be within {low:g}-{high:g} s (the NGA-West2 models' range), got {period:g}")
    return periods


def conditioning_measure(measure: str, period: float | Sequence[float] | None) -> Measure:
    """The measure a conditional spectrum can be conditioned on (:data:`CONDITIONING_MEASURES`, periods within
    :data:`PERIOD_RANGE`), or a one-line :class:`SiteError` naming ``measure`` or ``period``."""
    if measure not in CONDITIONING_MEASURES:
        raise SiteError(f"measure: must be one of {', '.join(CONDITIONING_MEASURES)} (no PGV–Sa correlation in the model), got {measure!r}")
    if measure == "pga":
        if period is not None:
            raise SiteError(f"period: pga takes no period, got {period!r}")
        return Measure("pga")
    if measure == "psa":
        if period is None or np.ndim(period) != 0:
            raise SiteError(f"period: psa needs one period T* in s, got {period!r}")
        return Measure("psa", float(_check_periods([period], "period")[0]))
    if period is None or np.ndim(period) != 1 or len(period) < 2:
        raise SiteError(f"period: sa_avg needs a list of at least 2 periods in s, got {period!r}")
    return Measure("sa_avg", periods=tuple(float(p) for p in _check_periods(period, "period")))


def _conditioning_nodes(measure: Measure) -> list[float | None]:
    """The nodes (a period in s, or None for PGA) the measure averages ln Sa over."""
    return [None] if measure.kind == "pga" else [measure.period] if measure.kind == "psa" else list(measure.periods)


def _joint_nodes(conditioning: Sequence[float | None], output: Sequence[float | None]) -> tuple[list[float | None], np.ndarray]:
    """The joint model's nodes, the ``output`` ones followed by the measure's own (``conditioning``, :func:`_conditioning_nodes`)
    not among them, and the measure's weights w over those nodes."""
    nodes: list[float | None] = list(output)
    weights = np.zeros(len(nodes) + len(conditioning))
    for node in conditioning:
        index = next((i for i, known in enumerate(nodes) if known == node), None)
        if index is None:
            nodes.append(node)
            index = len(nodes) - 1
        weights[index] += 1.0 / len(conditioning)
    return nodes, weights[: len(nodes)]


def _node_correlation(nodes: Sequence[float | None]) -> np.ndarray:
    """ρ of ln Sa between every two nodes (Baker & Jayaram 2008; PGA at :data:`PGA_PERIOD`)."""
    from pygmm.baker_jayaram_2008 import calc_correls

    at = np.array([PGA_PERIOD if node is None else node for node in nodes])
    return np.array([calc_correls(at, t) for t in at])


def _joint_model(conditioning: Sequence[float | None], output: Sequence[float | None],
                 scenario: Scenario) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """ln Sa at the nodes of :func:`_joint_nodes` in a scenario: mean μ, covariance C and the measure's weights w."""
    nodes, weights = _joint_nodes(conditioning, output)
    mean, sigma = _average_model(nodes, scenario)
    return mean, _node_correlation(nodes) * np.outer(sigma, sigma), weights


def _conditioned(mean: np.ndarray, covariance: np.ndarray, weights: np.ndarray,
                 ln_levels: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Given wᵀx = ln x_j for each level j (module docstring): the conditional mean [level, node], the conditional
    covariance [node, node] and ε* [level]."""
    cw = covariance @ weights
    variance = float(weights @ cw)
    epsilon = (np.asarray(ln_levels, dtype=float) - float(weights @ mean)) / np.sqrt(variance)
    conditional_mean = mean[None, :] + np.outer(epsilon, cw) / np.sqrt(variance)
    return conditional_mean, covariance - np.outer(cw, cw) / variance, epsilon


def scenario_distribution(measure: str, period: float | Sequence[float] | None = None, *, magnitude: float | None = None,
                          distance_km: float | None = None, vs30: float | None = None, mechanism: str | None = None,
                          geometry: Mapping[str, float | None] | None = None, scenario: Scenario | None = None) -> tuple[float, float]:
    """The median (g) and the standard deviation of ln of a measure in a scenario: the conditional spectrum's own model.

    Parameters
    ----------
    measure : {"pga", "psa", "sa_avg"}
        The measure.
    period : float or list of float, optional
        T (s) for ``psa``; the averaging periods (s) for ``sa_avg``; none for ``pga``.
    magnitude, distance_km, vs30 : float
        Moment magnitude, rupture distance (km) and Vs30 (m/s) of the scenario.
    mechanism : {"strike_slip", "reverse", "normal"}
        Faulting mechanism.
    geometry : mapping, optional
        The rupture's geometry and the site's basin depths (:data:`GEOMETRY_FIELDS`:
        ``distance_jb_km``, ``distance_x_km``, ``ztor_km``, ``dip`` in degrees,
        ``z1p0_km``, ``z2p5_km``); a field left out keeps the estimate of the module docstring.
    scenario : Scenario, optional
        The scenario as one value, instead of ``magnitude``, ``distance_km``, ``vs30``, ``mechanism`` and ``geometry``.

    Returns
    -------
    tuple of float
        exp(wᵀμ) (g) and √(wᵀCw) (module docstring): for PGA and PSA(T) the
        four models' average median and σ; for Sa_avg those of the geometric
        mean, the periods' correlation included.

    Raises
    ------
    SiteError
        Naming the field, as :func:`conditional_spectrum`.
    """
    conditioning = _conditioning_nodes(conditioning_measure(measure, period))
    return _measure_moments(conditioning, given_scenario(scenario, magnitude, distance_km, vs30, mechanism, geometry))


def measure_distribution(measure: str, period: float | Sequence[float] | None, scenario: Scenario) -> tuple[float, float]:
    """:func:`scenario_distribution` in a scenario already checked against the models' range (a site's rupture)."""
    return _measure_moments(_conditioning_nodes(conditioning_measure(measure, period)), scenario)


def _measure_moments(conditioning: list[float | None], scenario: Scenario) -> tuple[float, float]:
    """exp(wᵀμ) (g) and √(wᵀCw) of the measure of nodes ``conditioning`` in the scenario."""
    mean, covariance, weights = _joint_model(conditioning, [], scenario)
    return float(np.exp(weights @ mean)), float(np.sqrt(weights @ covariance @ weights))


def scenario_spectrum(periods: Sequence[float], scenario: Scenario) -> tuple[np.ndarray, np.ndarray]:
    """Mean ln PSA (g) and its σ at every period (s; 0 stands for PGA) in a scenario: :func:`scenario_distribution` of many periods at once."""
    nodes = [None if p == 0 else p for p in np.atleast_1d(np.asarray(periods, dtype=float))]
    _check_periods([p for p in nodes if p is not None] or [PGA_PERIOD], "periods")
    return _average_model(nodes, scenario)


def _check_level(level: object) -> None:
    if not is_finite_number(level) or level <= 0:
        raise SiteError(f"level: must be > 0 (g), got {level!r}")


def conditional_distribution(
    measure: str,
    period: float | Sequence[float] | None,
    levels: float | Sequence[float],
    periods: Sequence[float],
    scenario: Scenario,
) -> ConditionalDistribution:
    """ln Sa (g) at ``periods`` given the measure at each of ``levels`` (module docstring), after checking every input."""
    conditioning, output = _checked_inputs(measure, period, levels, periods)
    return _distribution(conditioning, output, levels, scenario)


def _checked_inputs(measure: str, period: float | Sequence[float] | None, levels: float | Sequence[float],
                    periods: Sequence[float]) -> tuple[list[float | None], np.ndarray]:
    """The measure's nodes (:func:`_conditioning_nodes`) and the output periods (s), after checking them and the levels."""
    conditioning = _conditioning_nodes(conditioning_measure(measure, period))
    for level in np.atleast_1d(levels).tolist():
        _check_level(level)
    output = _check_periods(periods, "periods")
    if np.unique(output).size != output.size:
        raise SiteError("periods: repeated period")
    return conditioning, output


def _distribution(conditioning: list[float | None], output: np.ndarray, levels: float | Sequence[float],
                  scenario: Scenario) -> ConditionalDistribution:
    """:func:`conditional_distribution` of checked inputs."""
    mean, covariance, weights = _joint_model(conditioning, list(output), scenario)
    sigma = np.sqrt(np.diag(covariance))
    levels = np.atleast_1d(np.asarray(levels, dtype=float))
    conditional_mean, conditional_cov, epsilon = _conditioned(mean, covariance, weights, np.log(levels))
    n = output.size
    return ConditionalDistribution(output, levels, conditional_mean[:, :n], conditional_cov[:n, :n], mean[:n], sigma[:n], epsilon,
                                   float(weights @ mean), float(np.sqrt(weights @ covariance @ weights)))


def spectrum_dataset(periods: np.ndarray, mean_ln: np.ndarray, covariance: np.ndarray, unconditional_mean_ln: np.ndarray,
                     unconditional_sigma_ln: np.ndarray, attrs: Mapping[str, float | str]) -> xr.Dataset:
    """A conditional spectrum as :func:`conditional_spectrum` returns it, from the conditional mean and covariance of ln Sa (g)."""
    sigma = np.sqrt(np.clip(np.diag(covariance), 0.0, None))
    with np.errstate(divide="ignore", invalid="ignore"):
        correlation = np.where(np.outer(sigma, sigma) > 0, covariance / np.outer(sigma, sigma), 0.0)
    np.fill_diagonal(correlation, 1.0)
    coords = {"period": ("period", periods, {"units": "s"}), "other_period": ("other_period", periods, {"units": "s"})}
    return xr.Dataset(
        {
            "median": ("period", np.exp(mean_ln), {"units": "g", "long_name": "median Sa given the level"}),
            "sigma_ln": ("period", sigma, {"units": "1", "long_name": "standard deviation of ln Sa given the level"}),
            "unconditional_median": ("period", np.exp(unconditional_mean_ln), {"units": "g", "long_name": "median Sa of the scenario"}),
            "unconditional_sigma_ln": ("period", unconditional_sigma_ln, {"units": "1", "long_name": "standard deviation of ln Sa of the scenario"}),
            "correlation": (("period", "other_period"), correlation, {"units": "1", "long_name": "correlation of ln Sa given the level"}),
        },
        coords=coords,
        attrs=dict(attrs),
    )


#: The models and the correlation of every conditional spectrum, in words (a dataset's ``models`` attribute).
MODELS_TEXT = "ASK14 BSSA14 CB14 CY14 (pygmm), mean of ln medians, sigma = rms of sigmas; Baker-Jayaram 2008 correlation"


def conditioning_attrs(measure: Measure, level: float) -> dict[str, float | str]:
    """The attributes of a conditional spectrum that name its conditioning: ``measure``, ``conditioning_period``, ``level``, ``damping``, ``models``."""
    period = measure.spectral_period
    return {"measure": measure.kind, "conditioning_period": "" if period is None else " ".join(f"{p:g}" for p in np.atleast_1d(period)),
            "level": float(level), "damping": MODEL_DAMPING, "models": MODELS_TEXT}


def check_damping(damping: float) -> None:
    """Raise :class:`SiteError` unless ``damping`` is the models' 5 %."""
    if damping != MODEL_DAMPING:
        raise SiteError(f"damping: the NGA-West2 models give 5 % damped spectra only (0.05), got {damping!r}")


def conditional_spectrum(
    measure: str,
    period: float | Sequence[float] | None = None,
    *,
    level: float,
    periods: Sequence[float],
    magnitude: float | None = None,
    distance_km: float | None = None,
    vs30: float | None = None,
    mechanism: str | None = None,
    damping: float = MODEL_DAMPING,
    geometry: Mapping[str, float | None] | None = None,
    scenario: Scenario | None = None,
) -> xr.Dataset:
    """The conditional spectrum: ln Sa given the measure at ``level``, for a scenario (module docstring).

    Parameters
    ----------
    measure : {"pga", "psa", "sa_avg"}
        The conditioning measure.
    period : float or list of float, optional
        T* (s) for ``psa``; the averaging periods (s) for ``sa_avg``; none for ``pga``.
    level : float
        The measure's value, g.
    periods : list of float
        Periods (s) of the spectrum, within 0.01–10 s.
    magnitude, distance_km, vs30 : float
        Moment magnitude, rupture distance (km), Vs30 (m/s) of the scenario
        (the hazard's disaggregation at that level).
    mechanism : {"strike_slip", "reverse", "normal"}
        Faulting mechanism.
    damping : float
        0.05 only (the models' damping).
    geometry : mapping, optional
        The rupture's geometry and the site's basin depths, as for :func:`scenario_distribution`.
    scenario : Scenario, optional
        The scenario as one value, instead of ``magnitude``, ``distance_km``, ``vs30``, ``mechanism`` and ``geometry``.

    Returns
    -------
    xarray.Dataset
        Over ``period`` (s): ``median`` (g) and ``sigma_ln`` of Sa given the
        level; ``unconditional_median`` (g) and ``unconditional_sigma_ln`` of
        the scenario; ``correlation`` (``period``, ``other_period``) of the
        conditional ln Sa. Attributes: ``epsilon`` (ε* of the level),
        ``measure``, the scenario (its geometry's given fields too) and the models.

    Raises
    ------
    SiteError
        Naming the field: an unknown measure or mechanism, a period outside
        0.01–10 s, a scenario outside the models' range, a damping other than 5 %.
    """
    check_damping(damping)
    _check_level(level)
    conditioning, output = _checked_inputs(measure, period, level, periods)
    scenario = given_scenario(scenario, magnitude, distance_km, vs30, mechanism, geometry)
    target = _distribution(conditioning, output, level, scenario)
    return spectrum_dataset(target.periods, target.mean_ln[0], target.covariance, target.unconditional_mean_ln, target.unconditional_sigma_ln,
                            {"epsilon": float(target.epsilon[0]), **conditioning_attrs(conditioning_measure(measure, period), level), **scenario.attrs()})
