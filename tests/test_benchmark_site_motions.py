"""The held-out check of the site motions' calibration (``python -m benchmarks site_motions check --held-out``, issue 43):
its scenarios are not the fit's (read from the calibration file), its section states whether the thresholds are met, and a
reduced version of it against the NGA-West2 models."""

from __future__ import annotations

import math

import numpy as np
import pytest

from benchmarks import site_motions
from benchmarks.site_motions import HELD_OUT, HELD_OUT_SCENARIOS, check_section, fitted_scenarios, held_out_scenarios
from stochpound.motions._site_calibration import CHECK_PERIODS, SCENARIOS, CheckTable, calibration_table, target

INFO = {"commit": "abc1234", "date": "2026-12-02 07:00 UTC", "load average (1 min) at start": "1.00"}


def test_the_held_out_scenarios_are_not_the_fits_and_span_the_issues_range():
    fitted = fitted_scenarios()
    assert fitted == SCENARIOS  # the calibration file's header lists the scenarios fit_calibration used
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
