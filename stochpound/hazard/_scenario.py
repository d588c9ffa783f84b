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
from stochpound.motions import MECHANISMS, check_scenario


def scenario_hazard(measure: str, period: float | Sequence[float] | None = None, *, magnitude: float, distance_km: float, vs30: float,
                    mechanism: str, rate: float, extrapolate: bool = False) -> HazardCurve:
    """The hazard curve of a site shaken by one scenario recurring at ``rate`` per year (module docstring).

    Parameters
    ----------
    measure, period, magnitude, distance_km, vs30, mechanism
        The measure and the scenario, as for :func:`stochpound.motions.scenario_distribution`.
    rate : float
        ν, the scenario's annual rate of occurrence (1/yr), > 0.
    extrapolate : bool
        As :class:`HazardCurve`: beyond the table's ε of −4 to 6, extend it as a power law.

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
    check_scenario(magnitude, distance_km, vs30, mechanism)
    site = RuptureSite((magnitude,), (distance_km,), (distance_km,), (-distance_km,), (0.0,), (MECHANISMS[mechanism][1],), (mechanism,), (rate,), vs30)
    curve = site.hazard_curve(measure, period, extrapolate=extrapolate)
    curve.source = (f"one scenario, M {magnitude:g} at {distance_km:g} km, Vs30 {vs30:g} m/s, {mechanism.replace('_', '-')}, "
                    f"{rate:g} per year; NGA-West2 average (pygmm)")
    return curve
