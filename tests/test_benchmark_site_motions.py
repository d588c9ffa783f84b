"""The held-out check of the site motions' calibration (``python -m benchmarks site_motions check --held-out``, issue 43):
its scenarios are not the fit's (read from the calibration file), its section states whether the thresholds are met, and a
reduced version of it against the NGA-West2 models."""

from __future__ import annotations

import math

import numpy as np
import pytest

from benchmarks import site_motions
from benchmarks.site_motions import (
    HELD_OUT, HELD_OUT_SCENARIOS, TAIL, check_section, fitted_scenarios, held_out_scenarios, rupture_exceedance, tail_section,
)  # fmt: skip
from stochpound.hazard import RuptureSite
from stochpound.motions._site_calibration import CHECK_PERIODS, FIT_SCENARIOS, CheckTable, calibration_table, target

INFO = {"commit": "abc1234", "date": "2026-12-02 07:00 UTC", "load average (1 min) at start": "1.00"}


def test_the_held_out_scenarios_are_not_the_fits_and_span_the_issues_range():
    fitted = fitted_scenarios()
    assert fitted == FIT_SCENARIOS  # the calibration file's header lists the scenarios fit_calibration used
    assert not set(held_out_scenarios()) & set(fitted)
    magnitudes, distances, vs30s, mechanisms = zip(*HELD_OUT_SCENARIOS)
    assert len(HELD_OUT_SCENARIOS) >= 8 and set(mechanisms) == {"strike_slip", "reverse", "normal"}
    assert (min(magnitudes), max(magnitudes), min(distances), max(distances), min(vs30s), max(vs30s)) == (5.5, 8.0, 5.0, 100.0, 200.0, 1100.0)


def test_a_calibration_fitted_at_a_held_out_scenario_refuses_the_held_out_check(tmp_path):
    text = site_motions.CALIBRATION.read_text()
    m, r, vs30, mechanism = HELD_OUT_SCENARIOS[3]
    path = tmp_path / "calibration.toml"
    path.write_text(text.replace("mechanism): ", f"mechanism): {m:g} {r:g} {vs30:g} {mechanism}; ", 1))
    with pytest.raises(ValueError, match="among the fit's scenarios"):
        held_out_scenarios(path)
    path.write_text("name = 'x'\n")
    with pytest.raises(ValueError, match="no '# Scenarios"):
        fitted_scenarios(path)


def _table(ln_ratio: float, sigma_difference: float, correlation_difference: float) -> CheckTable:
    shape = (2, len(CHECK_PERIODS))
    return CheckTable(CHECK_PERIODS, HELD_OUT_SCENARIOS[:2], np.full(shape, ln_ratio), np.full(shape, sigma_difference),
                      {(1.0, 2.0): (0.75 + correlation_difference, 0.75)}, n=10)


def test_the_held_out_section_states_whether_the_thresholds_are_met():
    met = check_section(_table(0.05, 0.02, 0.01), INFO, 60.0, held_out=True)
    assert met.startswith(HELD_OUT.start) and met.rstrip().endswith(HELD_OUT.end) and "load 1.00 at start" in met
    assert "**The issue's thresholds are met**" in met and "100 % within 0.15 of Baker–Jayaram" in met
    table = _table(0.05, 0.02, 0.2)
    table.ln_median_ratio[1, 4] = -0.3
    missed = check_section(table, INFO, 60.0, held_out=True)
    assert "**The issue's thresholds are not met**" in missed and "|ln ratio| up to 0.30 > 0.2" in missed and "|Δρ| up to 0.20 > 0.15" in missed
    assert "96 % of the cells within" in missed and "0 % within 0.15 of Baker–Jayaram" in missed


@pytest.mark.slow  # 400 motions and their spectra: about 10 s on the loaded 2-core machine
def test_reduced_held_out_check_against_nga_west2():
    """Two held-out scenarios, 200 motions each: the medians and σ of ln Sa within the full check's targets (0.2, 0.1)
    widened by three standard errors of the sample's mean (σ/√n) and standard deviation (σ/√(2n)), as the reduced check
    at the fit's scenarios; the bound on the medians stays below 0.5, so a calibration whose medians were 0.5 off fails."""
    scenarios = [(6.75, 30.0, 350.0, "strike_slip"), (7.25, 60.0, 200.0, "normal")]
    assert set(scenarios) <= set(held_out_scenarios())
    table = calibration_table(scenarios=scenarios, n=200, seed=3)
    sigma = np.array([target(s)[1] for s in scenarios])
    median_bound, sigma_bound = 0.2 + 3 * sigma / math.sqrt(200), 0.1 + 3 * sigma / math.sqrt(400)
    assert np.all(np.abs(table.ln_median_ratio) <= median_bound)
    assert np.all(np.abs(table.sigma_difference) <= sigma_bound)
    for shift in (-0.5, 0.5):  # the same check on a calibration whose medians are 0.5 off
        assert not np.all(np.abs(table.ln_median_ratio + shift) <= median_bound)


def test_the_tail_section_states_whether_the_ratios_are_within_the_band():
    result = {"site": "demo_three_sources", "n": 10, "seed": 11, "periods": [None, 1.0], "return_periods": [475.0, 2475.0], "names": ["a", "b"],
              "levels": np.full((2, 2), 0.5), "hazard": np.full((2, 2), 1e-3), "ratio": np.array([[1.0, 0.9], [1.1, 1.2]]),
              "low": np.full((2, 2), 0.7), "high": np.full((2, 2), 1.4), "largest_share": [["a", "b"], ["a", "a"]]}
    met = tail_section(result, INFO, 60.0)
    assert met.startswith(TAIL.start) and met.rstrip().endswith(TAIL.end) and "**met** at every row" in met
    result["ratio"][1, 1] = 0.42
    assert "**not met** at every row" in tail_section(result, INFO, 60.0)


@pytest.mark.slow  # 300 motions and their spectra: a few seconds
def test_reduced_tail_check_on_the_hanging_wall():
    """The demo site's reverse fault, its hanging-wall geometry given (the largest share of its 475- and 2475-year PGA):
    300 simulated motions exceed the levels of its own NGA-West2 ε = 0, 1 and 2 at PGA and PSA(1 s) as often as the lognormal
    says, within three binomial standard errors (±0.087, ±0.063, ±0.026). Without its geometry the NGA-West2 medians of
    this rupture are 0.6 lower at both measures (σ 0.55–0.69): motions following them would exceed the ε = 0 level about
    0.14–0.21 of the time instead of 0.5, so the test can fail."""
    demo = RuptureSite.bundled("demo_three_sources")
    site = RuptureSite.from_scenarios([(demo.scenario(1), demo.rate[1])])
    assert site.scenario(0).geometry["distance_x_km"] == 10.0
    epsilons = np.array([0.0, 1.0, 2.0])
    levels = np.array([np.exp(site.moments(measure, period)[0][0] + epsilons * site.moments(measure, period)[1][0])
                       for measure, period in (("pga", None), ("psa", 1.0))])
    counted = rupture_exceedance(site, 300, 11, levels, periods=(None, 1.0))[0]
    expected = np.array([0.5 * math.erfc(e / math.sqrt(2.0)) for e in epsilons])[None, :]
    assert np.all(np.abs(counted - expected) <= 3.0 * np.sqrt(expected * (1.0 - expected) / 300))
