"""benchmarks.short_period_lift: the lift of a short-period Sa by a motion's content below 1 Hz, and the command's tables."""

from __future__ import annotations

import numpy as np

from benchmarks.short_period_lift import lifts, main
from stochpound.motions import Scenario


def _motion(low_amplitude: float) -> np.ndarray:
    """60 s at 0.005 s of a 6 Hz sine (1 m/s²) plus a 0.4 Hz one, both under a smooth window."""
    t = np.arange(0.0, 60.0, 0.005)
    window = np.sin(np.pi * t / t[-1]) ** 2
    return (window * (np.sin(2 * np.pi * 6.0 * t) + low_amplitude * np.sin(2 * np.pi * 0.4 * t)))[None, :]


def test_the_lift_is_what_content_below_1_hz_adds_to_the_short_period_peak() -> None:
    """No content below 1 Hz: no lift (the high-pass leaves the motion as it is); as much low-frequency acceleration as high:
    the stiff oscillator's peak nearly doubles (the two peaks meet in 60 s), lift near ln 2."""
    scenario = Scenario(7.0, 20.0, 400.0, "reverse")
    assert abs(float(lifts(_motion(0.0), 0.005, scenario, 2.0).lift[0])) < 0.01
    lifted = float(lifts(_motion(1.0), 0.005, scenario, 2.0).lift[0])
    assert 0.55 < lifted < np.log(2.0) + 0.02, lifted


def test_the_command_prints_the_records_and_the_simulated_motions_by_epsilon(capsys) -> None:
    assert main(["--limit", "4", "--n", "2"]) == 0
    out = capsys.readouterr().out
    assert "**Records (FEMA P695)** (4 motions;" in out and "| ε(2 s) | motions | mean ε(0.043 s) | lift: mean | median | peak below / above 1 Hz: median | peaks within 1 s |" in out
    assert "**Simulated, 2 of each record's scenario (" in out
