"""Importance sampling with a linear surrogate's elementary events (issue 46): unbiased whatever the surrogate, against exact
references (a half-space, Φ(−b); Au & Beck's oscillator by ISEE with its exact map), with a surrogate that is not the response."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.special import ndtr, ndtri

from stochpound.analysis import linear_importance_sampling, oscillator_rows, surrogate_level, uncovered_share
from tests.au_beck_oscillator import DT, N_TIME, OMEGA, S, ZETA
from tests.au_beck_oscillator import displacements as _displacements
from tests.au_beck_oscillator import isee as _isee
from tests.au_beck_oscillator import peak as _peak

TILTED = np.array([[1.0, 0.3] + [0.0] * 48]) / math.hypot(1.0, 0.3)
"""A surrogate of g(u) = u_0 that is not it: the direction (1, 0.3) in 50 normals."""


def _white(u: np.ndarray) -> np.ndarray:
    return math.sqrt(2.0 * math.pi * S / DT) * np.asarray(u)


def test_the_oscillator_s_rows_are_the_reference_map():
    """oscillator_rows under the white noise of u is the test's own discretisation of Au & Beck's oscillator (rows a_1 ..)."""
    rows = oscillator_rows(_white, N_TIME, DT, 2.0 * math.pi / OMEGA, ZETA)
    assert np.allclose(rows, _displacements(np.eye(N_TIME)).T[1:], rtol=0.0, atol=1e-12 * np.abs(rows).max())


def test_a_half_space_with_a_tilted_surrogate_has_its_exact_probability():
    """g(u) = u_0, P(g > 4.75) = Φ(−4.75) ≈ 1e-6 exactly, the surrogate tilted off it (its events cover all but about 1 %
    of the failures): one run within 3 CoV; over 40 runs the mean estimate within 3 standard errors and the mean
    reported CoV within 25 % of the empirical one."""
    b, exact = 4.75, float(ndtr(-4.75))
    level = surrogate_level(TILTED, 1e-4)
    runs = [linear_importance_sampling(lambda u: u[:, 0], TILTED, level, thresholds=[b], samples=1000, seed=seed) for seed in range(40)]
    estimates = np.array([r.probability.values[0] for r in runs]) / exact
    reported = np.array([r.cov.values[0] for r in runs])
    assert abs(estimates[0] - 1.0) < 3.0 * reported[0]
    assert abs(estimates.mean() - 1.0) < 3.0 * estimates.std(ddof=1) / math.sqrt(40)
    empirical = math.sqrt(np.mean((estimates - 1.0) ** 2))
    assert abs(reported.mean() / empirical - 1.0) < 0.25
    assert runs[0].attrs["runs"] == 1000 and runs[0].attrs["surrogate_probability"] == pytest.approx(1e-4, rel=1e-6)


def test_a_surrogate_that_misses_failures_is_biased_and_its_coverage_says_so():
    """The same surrogate at b = 3 (below its level): the failures with |a · u| under the level are left to the defensive
    share, so the estimate falls far below Φ(−3) with a small reported CoV; the share of exact failure samples
    (u_0 > b, the rest standard normal) in no event says so: about 0.9 there, under 0.02 at b = 4.75."""
    level = surrogate_level(TILTED, 1e-4)
    result = linear_importance_sampling(lambda u: u[:, 0], TILTED, level, thresholds=[3.0], samples=1000, seed=0)
    assert result.probability.values[0] < 0.2 * ndtr(-3.0) and result.cov.values[0] < 0.1
    rng = np.random.default_rng(1)
    for b, low, high in ((3.0, 0.8, 1.0), (4.75, 0.0, 0.02)):
        failures = rng.standard_normal((4000, 50))
        failures[:, 0] = -ndtri(ndtr(-b) * rng.random(4000))  # u_0 given u_0 > b
        assert low <= uncovered_share(TILTED, level, failures) <= high


def test_the_oscillator_with_its_own_surrogate_agrees_with_isee():
    """Au & Beck's oscillator sampled with its own oscillator's events (the surrogate is the response: ISEE, but with
    the defensive share and the level set from S = 1e-4, about 2.2 m): at 2.4 m (P ≈ 6e-7) within 3 combined CoV of ISEE."""
    rows = oscillator_rows(_white, N_TIME, DT, 2.0 * math.pi / OMEGA, ZETA)
    result = linear_importance_sampling(_peak, rows, surrogate_level(rows, 1e-4), thresholds=[2.4], samples=1000, seed=4)
    reference, reference_cov = _isee(2.4, 600, seed=1)
    probability, cov = float(result.probability.values[0]), float(result.cov.values[0])
    assert cov < 0.15 and abs(probability - reference) < 3.0 * math.hypot(cov, reference_cov) * reference


@pytest.mark.parametrize(("arguments", "message"), [
    ({"rows": np.zeros((1, 50))}, r"rows: must be a \(K, n\) array of finite, non-zero rows"),
    ({"level": 0.0}, "level: must be a number > 0, got 0.0"),
    ({"samples": 1}, "samples: must be an integer >= 2, got 1"),
    ({"seed": -1}, "seed: must be an integer >= 0"),
    ({"defensive": 1.0}, r"defensive: must be a number in \(0, 1\), got 1.0"),
    ({"thresholds": []}, "thresholds: must be one or more finite numbers"),
])
def test_bad_arguments_are_named(arguments, message):
    settings = {"rows": TILTED, "level": 3.0, "thresholds": [4.0], "samples": 10, "seed": 0, **arguments}
    with pytest.raises(ValueError, match=message):
        linear_importance_sampling(lambda u: u[:, 0], **settings)
