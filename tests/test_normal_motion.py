"""Synthetic motions as functions of standard normals (model §13), and the white-noise kind."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.special import ndtri

from stochpound import motions
from stochpound import scene_from_dict
from stochpound.motions import normal_motion, realization_rng, white_noise

KT = {"type": "kanai_tajimi", "omega_g": 15.0, "zeta_g": 0.6, "pga": 3.0, "envelope": "jennings", "duration": 4.0, "dt": 0.01}
CP = {"type": "clough_penzien", "omega_g": 15.0, "zeta_g": 0.6, "omega_f": 1.5, "zeta_f": 0.6, "rms": 1.0, "duration": 3.0, "dt": 0.02}


def _seeded(table: dict, count: int, seed: int, start: int = 0) -> np.ndarray:
    parameters = {k: v for k, v in table.items() if k != "type"}
    return getattr(motions, table["type"])(count, start=start, seed=seed, **parameters).values


@pytest.mark.parametrize("table", [
    {**KT, "method": "filter", "baseline": True},
    {**CP, "method": "filter", "envelope": "saragoni_hart"},
    {"type": "white_noise", "S0": 0.5, "duration": 2.0, "dt": 0.02, "envelope": "trapezoidal"},
])
def test_seeded_realization_is_the_map_of_its_own_normals(table):
    """Filter and white noise: realization i is f(u_i), u_i the normals of its own stream, bit for bit."""
    motion = normal_motion({**table, "seed": 4, "count": 3})
    u = np.stack([realization_rng(4, i).standard_normal(motion.dimension) for i in (2, 3, 4)])
    assert np.array_equal(motion(u), _seeded(table, 3, seed=4, start=2))
    assert np.array_equal(motion(u[1]), motion(u)[1])


@pytest.mark.parametrize("table", [KT, {**CP, "band_limit": True}])
def test_spectral_realization_is_the_map_of_the_normals_of_its_phases(table):
    """Spectral: φ = 2π Φ(u), so u = Φ⁻¹(φ / 2π) of the seeded phases gives the seeded realization (to round-off)."""
    motion = normal_motion(table)
    phases = np.stack([realization_rng(9, i).uniform(0.0, 2.0 * np.pi, motion.dimension) for i in range(2)])
    expected = _seeded(table, 2, seed=9)
    assert np.allclose(motion(ndtri(phases / (2.0 * np.pi))), expected, rtol=0.0, atol=1e-9 * np.abs(expected).max())


def test_white_noise_is_the_sampled_white_noise_of_its_psd():
    """a_k = √(2π S0/dt) u_k: variance 2π S0/dt, uncorrelated samples; rms gives the same process."""
    S0, dt = 0.3, 0.02
    a = white_noise(400, 10.0, dt, S0=S0, seed=2).values
    variance = 2.0 * math.pi * S0 / dt
    assert a.shape == (400, 501)
    assert abs(a.var() / variance - 1.0) < 4.0 * math.sqrt(2.0 / a.size)  # 4 standard errors of a sample variance
    lag1 = np.mean(a[:, 1:] * a[:, :-1]) / variance
    assert abs(lag1) < 4.0 / math.sqrt(a[:, 1:].size)
    same = white_noise(3, 10.0, dt, rms=math.sqrt(variance), seed=2)
    assert np.allclose(same.values, a[:3], rtol=1e-12)
    assert same.attrs["S0"] == pytest.approx(S0, rel=1e-12) and same.attrs["sigma"] == pytest.approx(math.sqrt(variance))
    assert np.array_equal(white_noise(1, 10.0, dt, S0=S0, seed=2, start=5).values[0], white_noise(6, 10.0, dt, S0=S0, seed=2).values[5])


def test_normal_motion_dimension_and_time():
    white = normal_motion({"type": "white_noise", "S0": 1.0, "duration": 30.0, "dt": 0.02})
    assert white.dimension == 1501 and white.time[-1] == pytest.approx(30.0)
    kt_filter = normal_motion({**KT, "method": "filter"})
    assert kt_filter.dimension == 402 * 2  # (n_time + 1) × the filter's order
    assert kt_filter.attrs["S0"] == normal_motion(KT).attrs["S0"]  # the intensity resolved as the generator does


@pytest.mark.parametrize(("table", "message"), [
    ({"type": "white_noise", "S0": 1.0, "duration": 3.0, "dt": 0.02, "omega_g": 3.0}, "motion.omega_g: unknown field"),
    ({"type": "kanai_tajimi", "zeta_g": 0.6, "S0": 1.0, "duration": 3.0, "dt": 0.02}, "motion.omega_g: required"),
    ({"type": "brown_noise", "S0": 1.0}, "motion.type: must be one of"),
    ({"type": "white_noise", "duration": 3.0, "dt": 0.02}, "give exactly one of S0, rms"),
    ({"type": "white_noise", "S0": -1.0, "duration": 3.0, "dt": 0.02}, "S0: must be > 0"),
])
def test_bad_motion_tables_are_named(table, message):
    with pytest.raises(ValueError, match=message):
        normal_motion(table)


def test_normals_of_the_wrong_size_are_refused():
    motion = normal_motion({"type": "white_noise", "S0": 1.0, "duration": 1.0, "dt": 0.1})
    with pytest.raises(ValueError, match=r"u: must have shape \(n,\) or \(m, n\) with n = 11"):
        motion(np.zeros(10))


def test_a_scene_runs_a_white_noise_realization():
    table = {"type": "white_noise", "S0": 0.2, "seed": 3, "realization": 4, "duration": 2.0, "dt": 0.01}
    scene = scene_from_dict({"building": [{"name": "A", "mass": [1.0e5], "stiffness": [4.0e7], "damping_ratio": 0.05}], "motion": table})
    assert np.array_equal(scene.motion.values, white_noise(1, 2.0, 0.01, S0=0.2, seed=3, start=4).values[0])


def test_the_report_describes_a_white_noise_ensemble():
    from stochpound.report.sections._description import _synthetic_parameters
    from stochpound.store import MotionSource

    table = {"type": "white_noise", "rms": 2.0, "seed": 1, "duration": 5.0, "dt": 0.01}
    text, attrs = _synthetic_parameters(MotionSource("noise", "synthetic", "synthetic.noise", table, 0, 1))
    assert text.startswith("White noise: independent samples; RMS 2 m/s², S0 = ")
    assert "method" not in text and attrs["sigma"] == pytest.approx(2.0)


def test_an_experiment_takes_a_white_noise_ensemble():
    from stochpound._errors import ExperimentError
    from stochpound.experiment._spec import parse_experiment

    data = {"experiment": {"name": "white"}, "scene": {"bundled": "elastic_pair"},
            "synthetic": {"white": {"type": "white_noise", "S0": 0.01, "count": 3, "seed": 2, "duration": 2.0, "dt": 0.02}}}
    definition = parse_experiment(data)
    assert [m["motion"]["type"] for m in definition["motions"]] == ["white_noise"]
    with pytest.raises(ExperimentError, match="synthetic.white.omega_g: unknown field"):
        parse_experiment({**data, "synthetic": {"white": {**data["synthetic"]["white"], "omega_g": 3.0}}})
