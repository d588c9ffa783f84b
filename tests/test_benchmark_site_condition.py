"""``benchmarks.site_condition``: the rupture fit gives back curves a site of its own candidates made, at their Vs30 only."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

from benchmarks.site_condition import fit_ruptures, site_curves, stripe_epsilons
from stochpound.hazard import RuptureSite
from stochpound.motions import Scenario

REPOSITORY = Path(__file__).resolve().parents[1]


def _curves_of(site: RuptureSite) -> list:
    """PGA and PSA(0.2, 1, 3 s) curves of ``site`` at 16 intensities from 0.01 to 2 g, as the bundled ones are tabulated."""
    im = np.geomspace(0.01, 2.0, 16)
    return [(kind, period, im, site.rate_of_exceedance(kind, period, im)) for kind, period in (("pga", None), ("psa", 0.2), ("psa", 1.0), ("psa", 3.0))]


def test_the_fit_gives_back_a_site_of_its_candidates_at_its_vs30_and_not_at_another():
    """Curves of two candidate ruptures at Vs30 300 m/s (M 7.75 at 20 km strike-slip, M 6.25 at 5 km reverse): the fit at 300
    recomputes them to 1e-6 in ln rate; at 760 m/s no rates of the candidates do (the long periods' shortfall, the benchmark's point)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        made = RuptureSite.from_scenarios([(Scenario(7.75, 20.0, 300.0, "strike_slip"), 0.004), (Scenario(6.25, 5.0, 300.0, "reverse"), 0.01)])
        curves = _curves_of(made)
        exact, _, kept = fit_ruptures(300.0, curves)
        other, periods, _ = fit_ruptures(760.0, curves)
    assert np.abs(exact).max() < 1e-6 and len(kept) >= 1 and min(kept.rate) > 0  # not necessarily the two: M and R trade off
    assert np.sqrt(np.mean(other**2)) > 0.3 and other[periods >= 1.0].mean() < -0.3


def test_the_bundled_site_and_the_isolated_flagship_as_docs_quote_them():
    """All 17 Fox Plaza curves are fitted; at 400 m/s the isolated flagship's fitted scenario is M 7.6 at 30 km, its stripes at
    ε 0.81 to 3.53 (the file's header)."""
    assert len(site_curves()) == 17
    scenario, epsilons = stripe_epsilons(REPOSITORY / "experiments" / "risk" / "isolated.toml", 400.0)
    assert (scenario.magnitude, scenario.distance_km) == (7.6, 30.0)
    assert epsilons[0] == pytest.approx(0.81, abs=0.005) and epsilons[-1] == pytest.approx(3.53, abs=0.005)
