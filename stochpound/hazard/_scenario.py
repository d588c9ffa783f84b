"""The hazard of a site shaken by one earthquake scenario: consistent with the ground-motion models by construction.

A scenario (magnitude M, rupture distance R, Vs30, mechanism) recurring at
an annual rate ν, its ground motion ln IM normal with the median and σ of
the models the conditional spectrum uses
(:func:`stochpound.motions.scenario_distribution`), gives the site

    λ(IM > x) = ν P(ln IM > ln x) = ν Φc((ln x − ln median) / σ),

untruncated, as the conditional spectrum assumes. Its curves of every
measure come from the same earthquakes and the same models, and its
disaggregation is that scenario at every level: stripes chosen to this
site's conditional spectra are hazard-consistent by construction, so a risk
chain run on them must give one answer whatever measure they are
conditioned on (Lin, Haselton & Baker 2013). That is the check
``python -m benchmarks.site_consistency --site scenario`` makes of the
toolkit (docs/intensity.md). It also stands for a characteristic
earthquake of a fault that dominates a site. A one-scenario hazard is one
lognormal, so it is written here rather than taken from a hazard code
(OpenQuake and nshmp-haz integrate source models: far more than this needs).
It is the site of one rupture (:class:`~stochpound.analysis.RuptureSite`)
whose geometry is the conditional spectrum's estimate for the scenario.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from stochpound.hazard._curve import HazardCurve
from stochpound.hazard._ruptures import RuptureSite
from stochpound.motions import Scenario, given_scenario


def scenario_hazard(measure: str, period: float | Sequence[float] | None = None, *, magnitude: float | None = None,
                    distance_km: float | None = None, vs30: float | None = None, mechanism: str | None = None, rate: float,
                    extrapolate: bool = False, scenario: Scenario | None = None) -> HazardCurve:
    """The hazard curve of a site shaken by one scenario recurring at ``rate`` per year (module docstring).

    Parameters
    ----------
    measure, period, magnitude, distance_km, vs30, mechanism
        The measure and the scenario, as for :func:`stochpound.motions.scenario_distribution`.
    rate : float
        ν, the scenario's annual rate of occurrence (1/yr), > 0.
    extrapolate : bool
        As :class:`HazardCurve`: beyond the table's ε of −4 to 6, extend it as a power law.
    scenario : stochpound.motions.Scenario, optional
        The scenario as one value, instead of ``magnitude``, ``distance_km``, ``vs30`` and ``mechanism``;
        its geometry given replaces the conditional spectrum's estimates.

    Returns
    -------
    HazardCurve
        λ(x) (1/yr) tabulated at 401 intensities (g), log-spaced over ε −4
        to 6 (:meth:`~stochpound.analysis.RuptureSite.hazard_curve`); its ``source`` names the scenario and the rate.

    Raises
    ------
    ValueError
        ``rate`` not a finite number > 0.
    stochpound.SiteError
        Naming the field: an unknown measure or mechanism, a period or a scenario outside the models' range.
    """
    if not isinstance(rate, (int, float)) or isinstance(rate, bool) or not np.isfinite(rate) or rate <= 0:
        raise ValueError(f"rate: must be a finite annual rate > 0 (1/yr), got {rate!r}")
    scenario = given_scenario(scenario, magnitude, distance_km, vs30, mechanism)
    curve = RuptureSite.from_scenarios([(scenario, rate)]).hazard_curve(measure, period, extrapolate=extrapolate)
    curve.source = (f"one scenario, M {scenario.magnitude:g} at {scenario.distance_km:g} km, Vs30 {scenario.vs30:g} m/s, "
                    f"{scenario.mechanism.replace('_', '-')}, {rate:g} per year; NGA-West2 average (pygmm)")
    return curve
