"""The risk flagship's experiment files (experiments/risk/*.toml) carry the numbers their headers derive.

The buildings' yield shears are ASCE 7-16's from the design spectrum the header takes from the bundled 2 %/50 yr
hazard (S_MS = 1.1 SA(0.2 s), S_M1 = 1.3 SA(1 s), as chapter 17's part takes them), both neighbours sit on that spectrum's plateau (so one design serves both), and the stripes are the site's
intensities at the stated return periods.
"""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest

from stochpound.analysis import HazardCurve
from stochpound.codes import MceSpectrum
from stochpound.experiment._reseed import reseeded_text
from stochpound.model import design_yield_shears
from stochpound.risk import site_mce

ROOT = Path(__file__).resolve().parents[1]
FILES = {"fixed_pair": 1.0, "isolated": 2.0}  # file: its PSA period, s
RETURN_PERIODS = np.array([72.0, 224.0, 475.0, 975.0, 2475.0, 5000.0])
TWO_PERCENT = -np.log(1.0 - 0.02) / 50.0  # 1/yr: 2 % in 50 years, Poisson
HEIGHT = 6.0 / 0.3048  # ft: two 3.0 m storeys


def _experiment(name: str) -> dict:
    return tomllib.loads((ROOT / "experiments" / "risk" / f"{name}.toml").read_text())


def _buildings(experiment: dict) -> dict[str, dict]:
    return {b["name"]: b for b in experiment["scene"]["building"]}


def _first_mode_period(mass: list[float], stiffness: list[float]) -> float:
    (m1, m2), (k1, k2) = mass, stiffness
    omega2 = np.linalg.eigvals(np.linalg.solve(np.diag([m1, m2]), [[k1 + k2, -k2], [-k2, k2]])).real.min()
    return 2.0 * np.pi / np.sqrt(omega2)


def _design_spectrum() -> tuple[float, float, float]:
    """S_DS, S_D1 (g) and S_M1: two thirds of the MCE by chapter 17's rule (issue 45: one rule for both designs), the site's
    geometric-mean SA(0.2 s) and SA(1 s) at 2 %/50 yr times the maximum-direction factors."""
    sa_short, sa_long, _ = site_mce("fox_plaza_los_angeles_sa1p0s")
    assert sa_short == pytest.approx(float(HazardCurve.bundled("fox_plaza_los_angeles_sa0p2s").intensity_at(TWO_PERCENT)), rel=1e-12)
    mce = MceSpectrum.from_geometric_mean(sa_short, sa_long, 8.0)
    assert (mce.sms / sa_short, mce.sm1 / sa_long) == pytest.approx((1.1, 1.3))
    return 2.0 / 3.0 * mce.sms, 2.0 / 3.0 * mce.sm1, mce.sm1


@pytest.mark.parametrize("name", sorted(FILES))
def test_the_buildings_carry_the_code_design_of_the_header(name: str) -> None:
    experiment = _experiment(name)
    buildings = _buildings(experiment)
    sds, sd1, sm1 = _design_spectrum()
    design = experiment["design"]  # the [design] table the risk chain's design-analysis gaps read: the header's design
    np.testing.assert_allclose([design["sds"], design["sd1"]], [sds, sd1], atol=5e-6)  # the file gives 5 decimals
    assert (design["r"], design["omega0"], design["cd"], design["ie"]) == (8.0, 3.0, 5.5, 1.0)
    if "sm1" in design:
        assert design["sm1"] == pytest.approx(sm1, abs=5e-6)
    sds, sd1 = design["sds"], design["sd1"]
    b1 = buildings["B1"]
    period = _first_mode_period(b1["mass"], b1["stiffness"])
    assert period < 1.4 * 0.028 * HEIGHT**0.8  # the computed period is the design period (below C_u T_a)
    expected = design_yield_shears(b1["mass"], b1["storey_height"], period=period, sds=sds, sd1=sd1, r=design["r"],
                                   overstrength=design["omega0"], importance=design["ie"], s1=sm1)
    for building in buildings.values():
        np.testing.assert_allclose(building["yield_force"], expected, atol=0.5)  # N: the file rounds to 1 N
        assert building["hardening"] == 0.02 and building["p_delta"] is True
    # every neighbour variant is on the design spectrum's plateau (T < T_s = S_D1 / S_DS): its design strength is B1's
    for variant in experiment["variants"]["neighbour"].values():
        neighbour = {**buildings["B2"], **variant["building"]["B2"]}
        t = _first_mode_period(neighbour["mass"], neighbour["stiffness"])
        assert t < sd1 / sds
        np.testing.assert_allclose(design_yield_shears(neighbour["mass"], neighbour["storey_height"], period=t, sds=sds, sd1=sd1, r=design["r"],
                                                       overstrength=design["omega0"], importance=design["ie"], s1=sm1), expected, rtol=1e-12)


@pytest.mark.parametrize("name", sorted(FILES))
def test_the_stripes_are_the_site_intensities_of_the_stated_return_periods(name: str) -> None:
    experiment = _experiment(name)
    intensity = experiment["intensity"]
    assert intensity["period"] == FILES[name] and intensity["selection"] == "conditional_spectrum"
    # the scenario is fitted to the site's four bundled curves, the conditioning measure's among them (no disaggregation is bundled)
    assert experiment["site"]["scenario"] == "fitted" and experiment["hazard"]["bundled"] in experiment["site"]["curves"]
    assert len(experiment["site"]["curves"]) == 4
    hazard = HazardCurve.bundled(experiment["hazard"]["bundled"])
    expected = [float(hazard.intensity_at(1.0 / rp)) for rp in RETURN_PERIODS]
    expected.append(1.5 * float(hazard.intensity_at(TWO_PERCENT)))
    np.testing.assert_allclose(intensity["levels"], expected, rtol=2e-3)  # the file gives 4 significant digits


@pytest.mark.parametrize("name", sorted(FILES))
def test_the_seed_runs_differ_in_the_seed_alone(name: str) -> None:
    """``stochpound experiment run NAME.toml --seed k`` (the README's seed runs, the report's selection-seed columns) edits
    the file's [intensity] seed line alone."""
    path = ROOT / "experiments" / "risk" / f"{name}.toml"
    main = _experiment(name)
    for seed in (2, 3, 4, 5):
        text = reseeded_text(path.read_text(), seed, name)
        alternative = tomllib.loads(text)
        assert alternative["intensity"]["seed"] == seed and text.count("\n") == path.read_text().count("\n")
        alternative["intensity"]["seed"] = main["intensity"]["seed"]
        assert alternative == main
