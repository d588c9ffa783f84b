"""The report's rate axes (risk curves, demand hazard curves) are limited by the rates they draw, not by far tails or bands."""

import numpy as np
import pytest

from stochpound.report.render._figures import RATE_DECADES, rate_limits


def test_a_far_tail_does_not_stretch_the_rate_axis_beyond_its_decades():
    rates = np.array([3e-2, 1e-3, 1e-7, 1e-300, 0.0, np.nan, np.inf])
    low, high = rate_limits(rates, [1e-4])
    assert high == pytest.approx(2 * 3e-2)
    assert low == pytest.approx(high * 10.0**-RATE_DECADES)


def test_a_short_rate_range_is_framed_by_its_own_extremes_and_the_targets():
    low, high = rate_limits([[2e-3, 5e-4], [1e-3, np.nan]], [1e-4])
    assert (low, high) == (pytest.approx(0.5e-4), pytest.approx(4e-3))
    assert rate_limits([0.0, np.nan]) == (1e-6, 1.0)
