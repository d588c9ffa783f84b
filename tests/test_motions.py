"""Synthetic motions: PSD conventions, ensemble statistics, envelopes, seeding, intensity."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from scipy import integrate, signal, stats

from stochpound import motions
from stochpound.motions import (
    clough_penzien,
    clough_penzien_model,
    clough_penzien_psd,
    kanai_tajimi,
    kanai_tajimi_model,
    kanai_tajimi_psd,
    make_envelope,
)

FIRM = motions.soil_preset("firm")
SOFT = motions.soil_preset("soft")


def _quad_variance(psd) -> float:
    """∫_{−∞}^{∞} S dω by adaptive quadrature, independent of the state-space code."""
    pieces = [(0, 1), (1, 10), (10, 100), (100, np.inf)]
    return 2.0 * sum(integrate.quad(psd, a, b, limit=400, epsabs=0, epsrel=1e-11)[0] for a, b in pieces)


# ---------------------------------------------------------------- PSD conventions


@pytest.mark.parametrize("omega_g,zeta_g", [(15.0, 0.6), (5.0, 0.2), (25.0, 1.3)])
def test_kanai_tajimi_variance_three_ways(omega_g, zeta_g):
    closed = math.pi * 2.5 * omega_g * (1 + 4 * zeta_g**2) / (2 * zeta_g)
    assert motions.kanai_tajimi_variance(omega_g, zeta_g, 2.5) == pytest.approx(closed, rel=1e-14)
    assert kanai_tajimi_model(omega_g, zeta_g, 2.5).variance() == pytest.approx(closed, rel=1e-10)
    assert _quad_variance(lambda w: kanai_tajimi_psd(w, omega_g, zeta_g, 2.5)) == pytest.approx(closed, rel=1e-8)


@pytest.mark.parametrize("soil", ["firm", "medium", "soft"])
def test_clough_penzien_variance_and_psd(soil):
    p = motions.soil_preset(soil).clough_penzien()
    model = clough_penzien_model(**p, S0=0.7)
    assert model.variance() == pytest.approx(_quad_variance(lambda w: clough_penzien_psd(w, **p, S0=0.7)), rel=1e-8)
    omega = np.array([-3.0, 0.1, 1.0, 7.5, 40.0, 300.0])
    np.testing.assert_allclose(model.psd(omega), clough_penzien_psd(omega, **p, S0=0.7), rtol=1e-12)
    assert clough_penzien_psd(0.0, **p) == 0.0 and kanai_tajimi_psd(0.0, 15.0, 0.6, 2.0) == 2.0


def test_sampled_psd_is_the_aliased_psd():
    model = kanai_tajimi_model(15.0, 0.6, 1.0)
    dt = 0.02
    for omega in (0.0, 3.0, 50.0, 150.0):
        m = np.arange(-200_000, 200_001)
        brute = float(np.sum(kanai_tajimi_psd(omega + 2 * np.pi * m / dt, 15.0, 0.6)))
        tail = 2 * 4 * 0.6**2 * 15.0**2 / (2 * np.pi / dt) ** 2 / 200_000  # ≈ Σ_{|m|>M} S, S ~ c/ω²
        assert model.sampled_psd(omega, dt) == pytest.approx(brute + tail, rel=1e-6)
    grid = np.linspace(-np.pi / dt, np.pi / dt, 100_001)
    assert np.trapezoid(model.sampled_psd(grid, dt), grid) == pytest.approx(model.variance(), rel=1e-7)


def test_invalid_parameters():
    with pytest.raises(ValueError, match="omega_g: must be > 0"):
        kanai_tajimi_model(-1.0, 0.5)
    with pytest.raises(ValueError, match="zeta_f: must be > 0"):
        clough_penzien_model(10.0, 0.5, 1.0, 0.0)


# ---------------------------------------------------------------- ensemble statistics


def _mean_square_with_error(x: np.ndarray) -> tuple[float, float]:
    """Ensemble mean square and its standard error from independent realizations."""
    per_realization = np.mean(x**2, axis=1)
    return float(per_realization.mean()), float(per_realization.std(ddof=1) / math.sqrt(len(per_realization)))


CASES = [
    pytest.param("kt", "spectral", False, id="KT-spectral"),
    pytest.param("kt", "filter", False, id="KT-filter"),
    pytest.param("cp", "spectral", False, id="CP-spectral"),
    pytest.param("cp", "filter", False, id="CP-filter"),
    pytest.param("cp", "spectral", True, id="CP-spectral-band-limited"),
]


def _ensemble(kind: str, method: str, n: int, duration: float, dt: float, seed: int = 11, **kw):
    if kind == "kt":
        return kanai_tajimi(n, duration, dt, **FIRM.kanai_tajimi(), S0=0.05, seed=seed, method=method, **kw)
    return clough_penzien(n, duration, dt, **FIRM.clough_penzien(), S0=0.05, seed=seed, method=method, **kw)


def _psd_function(kind: str):
    if kind == "kt":
        return lambda w: kanai_tajimi_psd(w, **FIRM.kanai_tajimi(), S0=0.05)
    return lambda w: clough_penzien_psd(w, **FIRM.clough_penzien(), S0=0.05)


def _analytic_variance(kind: str, omega_max: float | None = None) -> float:
    """∫ S dω over (−∞, ∞), or over |ω| < omega_max, by quadrature of the formula."""
    if kind == "kt" and omega_max is None:
        return motions.kanai_tajimi_variance(FIRM.omega_g, FIRM.zeta_g, 0.05)
    if omega_max is None:
        return _quad_variance(_psd_function(kind))
    psd = _psd_function(kind)
    return 2.0 * sum(integrate.quad(psd, a, b, limit=400, epsrel=1e-11)[0] for a, b in [(0, 10), (10, 100), (100, omega_max)])


@pytest.mark.parametrize("kind,method,band_limit", CASES)
def test_ensemble_variance_matches_integral_of_psd(kind, method, band_limit):
    """Sample variance of a large stationary ensemble vs ∫ S dω (independent quadrature)."""
    dt = 0.01
    a = _ensemble(kind, method, 400, 40.0, dt, band_limit=band_limit)
    estimate, error = _mean_square_with_error(a.values)
    target = _analytic_variance(kind, np.pi / dt if band_limit else None)
    assert abs(estimate - target) < 4.0 * error, (estimate, target, error)
    assert error / target < 0.01  # the check is sharp: a 4 % bias would fail
    assert a.attrs["sigma"] ** 2 == pytest.approx(target, rel=1e-8)
    # stationary from t = 0: the first second has the same variance
    first, err_first = _mean_square_with_error(a.values[:, :100])
    assert abs(first - target) < 4.5 * err_first


def test_band_limit_loses_the_variance_above_nyquist():
    full = _analytic_variance("kt")
    limited = _analytic_variance("kt", np.pi / 0.01)
    tail = 2 * 4 * FIRM.zeta_g**2 * FIRM.omega_g**2 * 0.05 / (np.pi / 0.01)  # 2 ∫_{ω_N}^∞ c/ω² dω
    assert full - limited == pytest.approx(tail, rel=0.02)
    with pytest.raises(ValueError, match="band_limit: only available with method='spectral'"):
        kanai_tajimi(1, 1.0, 0.01, 10.0, 0.5, S0=1.0, method="filter", band_limit=True)


@pytest.mark.parametrize("kind,method,band_limit", CASES)
def test_welch_psd_within_confidence_band(kind, method, band_limit):
    """Ensemble-averaged periodogram (Hann, one segment per realization) vs the target, 0.5-50 rad/s.

    The target is the PSD of the sampled sequence: S_d (aliased), or S itself when band-limited.
    """
    dt, n_seg, k = 0.01, 16384, 96
    a = _ensemble(kind, method, k, (n_seg - 1) * dt, dt, seed=5, band_limit=band_limit).values
    freq, one_sided_hz = signal.welch(a, fs=1 / dt, window="hann", nperseg=n_seg, noverlap=0, detrend=False, axis=-1)
    omega = 2 * np.pi * freq
    estimate = one_sided_hz / (4 * np.pi)  # two-sided, per rad/s
    band = (omega >= 0.5) & (omega <= 50.0)
    w = omega[band]
    model = kanai_tajimi_model(**FIRM.kanai_tajimi(), S0=0.05) if kind == "kt" else clough_penzien_model(**FIRM.clough_penzien(), S0=0.05)
    target = _psd_function(kind)(w) if band_limit else model.sampled_psd(w, dt)
    if kind == "kt":  # the aliasing of a Kanai-Tajimi PSD is a 2 % effect in this band at dt = 0.01 s
        assert np.max(np.abs(model.sampled_psd(w, dt) / _psd_function(kind)(w) - 1)) < 0.025
    mean = estimate[:, band].mean(axis=0)
    # per frequency: chi-square with 2K degrees of freedom, family-wise level 1e-3 (Bonferroni)
    alpha = 1e-3 / band.sum()
    low, high = stats.chi2.ppf([alpha / 2, 1 - alpha / 2], 2 * k) / (2 * k)
    ratio = mean / target
    assert np.all((ratio > low) & (ratio < high)), (ratio.min(), ratio.max(), low, high)
    # sharper: averages over 12 log-spaced bands, against their sampling error across realizations
    edges = np.geomspace(0.5, 50.0, 13)
    for lo, hi in zip(edges[:-1], edges[1:]):
        sel = (w >= lo) & (w < hi)
        per_realization = estimate[:, band][:, sel].mean(axis=1) / target[sel].mean()
        err = per_realization.std(ddof=1) / math.sqrt(k)
        assert abs(per_realization.mean() - 1.0) < 4 * err + 0.01, (lo, hi, per_realization.mean(), err)


def test_spectral_and_filter_methods_have_the_same_autocovariance():
    """Both give R(k dt) = C Φ^k P Cᵀ at the sample lags (within sampling error)."""
    model = kanai_tajimi_model(**SOFT.kanai_tajimi(), S0=1.0)
    lags = np.array([0, 5, 20, 60])
    A, _, C = model.state_space()
    P = model.state_covariance()
    from scipy.linalg import expm

    exact = np.array([(C @ expm(A * 0.01 * lag) @ P @ C.T)[0, 0] for lag in lags])
    for method in ("spectral", "filter"):
        x = kanai_tajimi(300, 30.0, 0.01, **SOFT.kanai_tajimi(), S0=1.0, seed=2, method=method).values
        for lag, r in zip(lags, exact):
            products = np.mean(x[:, : x.shape[1] - lag] * x[:, lag:], axis=1)
            err = products.std(ddof=1) / math.sqrt(len(products))
            assert abs(products.mean() - r) < 4 * err + 1e-12, (method, lag, products.mean(), r, err)


def test_enveloped_variance_follows_envelope_squared():
    env = {"type": "jennings", "t1": 2.0, "t2": 6.0, "c": 0.4}
    a = kanai_tajimi(2000, 12.0, 0.01, **FIRM.kanai_tajimi(), S0=0.05, envelope=env, seed=4)
    shape = make_envelope(env, 12.0)
    sigma2 = a.attrs["sigma"] ** 2
    for t in (1.0, 4.0, 9.0):
        column = a.sel(time=t, method="nearest").values
        expected = sigma2 * float(shape(np.array(t))) ** 2
        err = column.var() * math.sqrt(2 / len(column))
        assert abs(np.mean(column**2) - expected) < 4 * err
    assert np.all(a.values[:, 0] == 0.0)


# ---------------------------------------------------------------- envelopes


def test_jennings_shape():
    e = motions.Jennings(t1=2.0, t2=8.0, c=0.5)
    t = np.array([-1.0, 0.0, 1.0, 2.0, 5.0, 8.0, 10.0])
    np.testing.assert_allclose(e(t), [0.0, 0.0, 0.25, 1.0, 1.0, 1.0, math.exp(-1.0)])
    np.testing.assert_array_equal(motions.AminAng(2.0, 8.0, 0.5)(t), e(t))
    d = make_envelope("jennings", 20.0)
    assert (d.t1, d.t2) == (2.0, 10.0) and d(np.array(20.0)) == pytest.approx(0.05)


def test_trapezoidal_shape():
    e = make_envelope({"type": "trapezoidal", "t1": 1.0, "t2": 3.0, "t3": 5.0}, 10.0)
    np.testing.assert_allclose(e(np.array([0.0, 0.5, 1.0, 2.0, 3.0, 4.0, 5.0, 7.0])), [0, 0.5, 1, 1, 1, 0.5, 0, 0])


def test_saragoni_hart_shape():
    e = motions.SaragoniHart(b=2.0, c=0.5)
    t = np.linspace(0.0, 30.0, 3001)
    values = e(t)
    assert values.max() == pytest.approx(1.0) and t[values.argmax()] == pytest.approx(4.0)
    a = (0.5 / 2.0) ** 2 * math.e**2  # a t^b e^{-ct} with unit peak
    np.testing.assert_allclose(values, a * t**2 * np.exp(-0.5 * t), rtol=1e-12, atol=1e-300)
    boore = make_envelope({"type": "saragoni_hart", "eps": 0.25, "eta": 0.1, "tw": 20.0}, 99.0)
    assert boore.peak_time == pytest.approx(5.0) and boore(np.array(20.0)) == pytest.approx(0.1)


def test_envelope_specifications():
    assert make_envelope(None, 10.0) is None and make_envelope("none", 10.0) is None
    custom = make_envelope(lambda t: np.minimum(t / 2.0, 1.0), 10.0)
    np.testing.assert_allclose(custom(np.array([1.0, 5.0])), [0.5, 1.0])
    with pytest.raises(ValueError, match="envelope.type: must be one of jennings"):
        make_envelope("gaussian", 10.0)
    with pytest.raises(ValueError, match=r"unknown parameter\(s\) \['tau'\]"):
        make_envelope({"type": "jennings", "tau": 1.0}, 10.0)
    with pytest.raises(ValueError, match="need 0 < t1 <= t2"):
        make_envelope({"type": "jennings", "t1": 5.0, "t2": 1.0}, 10.0)


# ---------------------------------------------------------------- reproducibility


@pytest.mark.parametrize("method", ["spectral", "filter"])
def test_same_seed_same_numbers_whatever_the_batching(method):
    kwargs = dict(duration=5.0, dt=0.01, omega_g=10.0, zeta_g=0.4, pga=2.0, envelope="saragoni_hart", seed=42, method=method, baseline=True)
    whole = kanai_tajimi(700, **kwargs)
    pieces = [kanai_tajimi(1, start=0, **kwargs), kanai_tajimi(9, start=1, **kwargs), kanai_tajimi(690, start=10, **kwargs)]
    np.testing.assert_array_equal(np.concatenate([p.values for p in pieces]), whole.values)
    np.testing.assert_array_equal(pieces[2].realization.values, np.arange(10, 700))
    np.testing.assert_array_equal(kanai_tajimi(1, start=333, **kwargs).values[0], whole.values[333])
    other = kanai_tajimi(3, **{**kwargs, "seed": 43})
    assert not np.allclose(other.values, whole.values[:3])


def test_realization_streams_are_seedsequence_children():
    children = np.random.SeedSequence(7).spawn(5)
    for i in (0, 4):
        expected = np.random.Generator(np.random.PCG64(children[i])).random(3)
        np.testing.assert_array_equal(motions.realization_rng(7, i).random(3), expected)


# ---------------------------------------------------------------- intensity, baseline, API


def test_rms_sets_the_standard_deviation():
    a = kanai_tajimi(200, 30.0, 0.01, **FIRM.kanai_tajimi(), rms=1.3, seed=8)
    assert a.attrs["sigma"] == pytest.approx(1.3)
    estimate, error = _mean_square_with_error(a.values)
    assert abs(estimate - 1.3**2) < 4 * error


@pytest.mark.parametrize("peak_factor,tolerance", [("simulated", 0.03), ("poisson", 0.06)])
def test_pga_is_the_expected_peak(peak_factor, tolerance):
    a = kanai_tajimi(400, 20.0, 0.01, **FIRM.kanai_tajimi(), pga=3.0, envelope="jennings", seed=3, peak_factor=peak_factor)
    peaks = np.max(np.abs(a.values), axis=1)
    assert abs(peaks.mean() / 3.0 - 1.0) < tolerance, peaks.mean()
    assert a.attrs["pga_target"] == 3.0 and a.attrs["peak_factor_method"] == peak_factor
    given = kanai_tajimi(1, 20.0, 0.01, **FIRM.kanai_tajimi(), pga=3.0, peak_factor=3.0)
    assert given.attrs["sigma"] == pytest.approx(1.0)


def test_baseline_correction_ends_at_rest():
    raw = kanai_tajimi(20, 15.0, 0.01, **SOFT.kanai_tajimi(), S0=0.2, envelope="jennings", seed=1)
    fixed = kanai_tajimi(20, 15.0, 0.01, **SOFT.kanai_tajimi(), S0=0.2, envelope="jennings", seed=1, baseline=True)
    v, d = motions.final_velocity_displacement(fixed.values, 0.01)
    v_raw, d_raw = motions.final_velocity_displacement(raw.values, 0.01)
    assert np.max(np.abs(v)) < 1e-12 * np.max(np.abs(v_raw)) + 1e-13 and np.max(np.abs(d)) < 1e-12 * np.max(np.abs(d_raw)) + 1e-13
    np.testing.assert_array_equal(fixed.values[:, [0, -1]], raw.values[:, [0, -1]])
    # the exact-integration weights agree with a step-by-step integration
    a = raw.values[0]
    vel = np.concatenate([[0.0], np.cumsum(0.01 * (a[:-1] + a[1:]) / 2)])
    disp = np.sum(0.01 * vel[:-1] + 0.01**2 * (2 * a[:-1] + a[1:]) / 6)
    assert v_raw[0] == pytest.approx(vel[-1], rel=1e-10) and d_raw[0] == pytest.approx(disp, rel=1e-10)


def test_dataarray_layout_and_attributes():
    a = clough_penzien(3, 2.0, 0.01, **FIRM.clough_penzien(), S0=0.1, seed=1, envelope="trapezoidal", start=5)
    assert a.dims == ("realization", "time") and a.shape == (3, 201)
    np.testing.assert_allclose(a.time.values, 0.01 * np.arange(201))
    assert list(a.realization.values) == [5, 6, 7]
    for key in ("omega_g", "zeta_g", "omega_f", "zeta_f", "S0", "sigma", "envelope", "seed", "method", "psd_convention"):
        assert key in a.attrs
    assert a.attrs["units"] == "m/s2" and a.attrs["model"] == "clough_penzien"
    assert all(isinstance(v, (str, int, float)) for v in a.attrs.values())  # netCDF-safe
    assert kanai_tajimi(0, 2.0, 0.01, 10.0, 0.5, S0=1.0).shape == (0, 201)


@pytest.mark.parametrize(
    "kwargs,message",
    [
        (dict(), "give exactly one of S0, pga, rms"),
        (dict(S0=1.0, pga=2.0), "give exactly one of S0, pga, rms"),
        (dict(S0=-1.0), "S0: must be > 0"),
        (dict(S0=1.0, method="euler"), "method: must be one of spectral, filter"),
        (dict(S0=1.0, seed=-3), "seed: must be an integer >= 0"),
        (dict(S0=1.0, seed=1.5), "seed: must be an integer >= 0"),
        (dict(S0=1.0, peak_factor=3.0), "peak_factor: only used with pga"),
        (dict(pga=2.0, peak_factor="gumbel"), "peak_factor: must be a number > 0 or one of poisson, simulated"),
        (dict(S0=1.0, start=-1), "start: must be an integer >= 0"),
        (dict(S0=1.0, envelope=3), "envelope: must be a name"),
    ],
)
def test_argument_errors(kwargs, message):
    with pytest.raises(ValueError, match=message):
        kanai_tajimi(2, 1.0, 0.01, 10.0, 0.5, **kwargs)
    with pytest.raises(ValueError, match="dt: must be <= duration"):
        kanai_tajimi(1, 0.01, 0.02, 10.0, 0.5, S0=1.0)


def test_scene_style_call():
    """How the scene loader calls it: keywords from a TOML table, one realization."""
    table = {"omega_g": 15.0, "zeta_g": 0.6, "pga": 2.5, "envelope": {"type": "jennings", "t1": 1.0, "t2": 5.0, "c": 0.5}, "seed": 9, "method": "filter"}
    one = kanai_tajimi(1, start=4, duration=8.0, dt=0.02, **table)
    many = kanai_tajimi(6, duration=8.0, dt=0.02, **table)
    np.testing.assert_array_equal(one.values[0], many.values[4])


@pytest.mark.parametrize(
    ("numerator", "denominator"),
    [
        (kanai_tajimi_model(15.0, 0.6).numerator, kanai_tajimi_model(15.0, 0.6).denominator),
        (clough_penzien_model(15.0, 0.6, 1.5, 0.6).numerator, clough_penzien_model(15.0, 0.6, 1.5, 0.6).denominator),
        ((5.0,), (2.0, 1.0)),  # first order, D's leading coefficient not 1
        ((0.0, 0.0, 1.0), (3.0, 2.0, 1.0, 7.0)),  # N's leading zeros
        ((1e-15, 2.0, 3.0), (0.0, 2.0, 3.0, 4.0, 5.0)),  # N's leading round-off, D's leading zero
        ((-0.0, 1.0), (1.0, 2.0, 3.0)),
    ],
)
def test_the_controllable_form_is_scipys_bit_for_bit(numerator, denominator):
    """motions.psd.controllable_form (no scipy.signal import at start-up) gives scipy.signal.tf2ss's (A, B, C), bit for bit."""
    from stochpound.motions.psd import controllable_form

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", signal.BadCoefficients)  # scipy's warning about N's leading zeros
        expected = signal.tf2ss(numerator, denominator)[:3]
    for ours, theirs in zip(controllable_form(numerator, denominator), expected):
        assert ours.shape == theirs.shape and ours.dtype == theirs.dtype
        assert ours.tobytes() == theirs.tobytes()
