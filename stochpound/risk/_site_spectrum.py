"""The site's MCE_R spectral values for chapter 17: SA(0.2 s) and SA(1 s) read off the site's own hazard curves.

ASCE 7-16's MCE_R is risk-targeted (§21.2); a site's hazard curves give the
uniform-hazard stand-in, the intensity exceeded at 2 % in 50 years. The
bundled sites' curves are geometric means (the USGS models'); chapter 17
takes them to the maximum direction with the factors of
:class:`stochpound.codes.MceSpectrum` (1.1 at 0.2 s, 1.3 at 1 s).
"""

from __future__ import annotations

import math

from stochpound.hazard import HazardCurve, bundled_measure, bundled_site_curves, rate_from_probability

MCE_PROBABILITY = 0.02
"""The probability of exceedance in 50 years of the uniform-hazard stand-in for the MCE_R."""
SHORT_PERIOD, LONG_PERIOD = 0.2, 1.0
"""The periods (s) of S_MS and S_M1."""


def site_mce(bundled: str) -> tuple[float, float, str] | None:
    """Geometric-mean SA(0.2 s) and SA(1 s) (g) at 2 %/50 yr of the site of bundled curve ``bundled``, and their source in words.

    None where the site's bundled curves lack either period.
    """
    curves = {bundled_measure(name).period: name for name in bundled_site_curves(bundled)}
    names = [next((name for period, name in curves.items() if period is not None and math.isclose(period, wanted)), None)
             for wanted in (SHORT_PERIOD, LONG_PERIOD)]
    if None in names:
        return None
    rate = rate_from_probability(MCE_PROBABILITY, 50.0)
    short, long = (float(HazardCurve.bundled(name).intensity_at(rate)) for name in names)
    return short, long, (f"the site's bundled curves {names[0]} and {names[1]} at {100 * MCE_PROBABILITY:g} %/50 yr (geometric mean, "
                         "uniform hazard standing in for the risk-targeted MCE_R)")
