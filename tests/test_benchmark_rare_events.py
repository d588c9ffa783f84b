"""The rare-event benchmark's linear maps are the solver's responses (benchmarks/rare_events.py)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

import stochpound
from benchmarks.rare_events import OSCILLATOR, PAIR_WHITE_NOISE, linear_pair, oscillator, pounding_pair
from stochpound.motions import normal_motion
from stochpound.motions.ground import SampledMotion


def test_the_linear_pair_is_the_pair_s_closure_run_by_the_solver():
    """The map's largest top-floor closure at the samples is the run's peak_contact_closure (located between them) or at most 3 % below
    it (the pair's first mode holds about 15 samples a period: a peak between samples is at most 1 − cos(π/15) ≈ 2 % above them)."""
    pair = linear_pair(**PAIR_WHITE_NOISE)
    motion = normal_motion({"type": "white_noise", **PAIR_WHITE_NOISE})
    scene = pounding_pair()
    u = np.random.default_rng(3).standard_normal((2, pair.n))
    for a, peak in zip(motion(u), pair.peak(u)):
        closure = float(stochpound.simulate(replace(scene, motion=SampledMotion(motion.dt, a)))["peak_contact_closure"].values[1])
        assert peak * (1.0 - 1e-9) <= closure <= peak * 1.03


def test_the_oscillator_map_is_the_convolution_of_its_impulse_response():
    """X = A u by FFT convolution equals the explicit lower-triangular product."""
    response = oscillator(**{**OSCILLATOR, "duration": 2.0})
    A = np.zeros((response.n, response.n))
    for j in range(1, response.n):
        A[j:, j] = response.kernel[: response.n - j]
    A[:, 0] = response.first
    u = np.random.default_rng(1).standard_normal((3, response.n))
    assert np.allclose(response.displacements(u), u @ A.T, rtol=0.0, atol=1e-12 * np.abs(u @ A.T).max())
