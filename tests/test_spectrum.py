"""Response spectrum and intensity measures against exact answers.

* an independent integration (scipy's DOP853 at rtol 1e-13, one call per
  step so that the kinks of a_g fall on step ends, maxima located with its
  events) of a bundled record;
* the closed-form step response, the exact response to a sine from rest;
* homogeneity (scaling by λ);
* PGV, PGD, Arias intensity and D5–95 of inputs whose integrals are known.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import minimize_scalar

from stochpound.motions import intensity_measures, peak_ground_motion, response_spectrum, sa_avg, significant_duration
from stochpound.motions._measures import arias_intensity
from stochpound.motions.records import load_record

RECORD = "el_centro_1940_ngaw2_rsn6"


def _reference_peaks(a: np.ndarray, dt: float, period: float, zeta: float) -> tuple[float, float]:
    """max abs(u) and max abs(ü + a_g) by DOP853 step by step, extrema located by its events."""
    w = 2.0 * math.pi / period
    y = np.zeros(2)
    sd = sa = 0.0
    for k in range(a.size - 1):
        slope = (a[k + 1] - a[k]) / dt

        def ground(t: float, k: int = k, slope: float = slope) -> float:
            return a[k] + slope * (t - k * dt)

        def rhs(t: float, y: np.ndarray) -> list[float]:
            return [y[1], -ground(t) - 2 * zeta * w * y[1] - w * w * y[0]]

        def jerk(t: float, y: np.ndarray) -> float:  # d/dt of −(2ζω u̇ + ω² u)
            return 2 * zeta * w * (ground(t) + 2 * zeta * w * y[1] + w * w * y[0]) - w * w * y[1]

        velocity = lambda t, y: y[1]  # noqa: E731
        sol = solve_ivp(rhs, (k * dt, (k + 1) * dt), y, method="DOP853", rtol=1e-13, atol=1e-16, events=[velocity, jerk])
        y = sol.y[:, -1]
        for state in [y, *sol.y_events[0]]:
            sd = max(sd, abs(state[0]))
        for state in [y, *sol.y_events[1]]:
            sa = max(sa, abs(2 * zeta * w * state[1] + w * w * state[0]))
    return sd, sa


def test_agrees_with_an_independent_integration_of_a_record():
    record = load_record(RECORD)
    a = record.acceleration(9.81)[: int(round(6.0 / record.dt)) + 1]
    periods = np.array([0.05, 0.1, 0.5, 2.0, 5.0])
    spectrum = response_spectrum(a, record.dt, periods)
    for period, sd, sa in zip(periods, spectrum.sd.values, spectrum.sa.values):
        ref_sd, ref_sa = _reference_peaks(a, record.dt, period, 0.05)
        assert sd == pytest.approx(ref_sd, rel=1e-9), period
        assert sa == pytest.approx(ref_sa, rel=1e-9), period
    omega = 2 * np.pi / periods
    np.testing.assert_allclose(spectrum.psa.values, omega**2 * spectrum.sd.values, rtol=1e-15)
    np.testing.assert_allclose(spectrum.psv.values, omega * spectrum.sd.values, rtol=1e-15)


def test_maxima_are_located_between_samples():
    """At T = 0.1 s and dt = 0.01 s the sampled maximum is visibly low; the located one is not."""
    record = load_record(RECORD)
    a = record.acceleration(9.81)[:600]
    located = response_spectrum(a, record.dt, [0.1]).sd.item()
    fine = np.interp(np.arange(0, 599 * 20 + 1) * record.dt / 20, record.time[:600], a)
    assert response_spectrum(fine, record.dt / 20, [0.1]).sd.item() == pytest.approx(located, rel=1e-11)


@pytest.mark.parametrize("zeta", [0.0, 0.05, 0.3])
def test_step_response_closed_form(zeta):
    amplitude, period, dt = 2.0, 0.37, 0.013
    w = 2 * math.pi / period
    a = np.full(400, amplitude)
    spectrum = response_spectrum(a, dt, [period], damping=zeta)
    exact = amplitude / w**2 * (1 + math.exp(-zeta * math.pi / math.sqrt(1 - zeta**2)))
    assert spectrum.sd.item() == pytest.approx(exact, rel=1e-12)
    # total acceleration −(2σu̇ + ω²u) of the closed form, maximised independently
    wd, sigma = w * math.sqrt(1 - zeta**2), zeta * w

    def total(t: float) -> float:
        e = math.exp(-sigma * t)
        u = -amplitude / w**2 * (1 - e * (math.cos(wd * t) + sigma / wd * math.sin(wd * t)))
        v = -amplitude / w**2 * e * (w**2 / wd) * math.sin(wd * t)
        return -abs(2 * sigma * v + w * w * u)

    grid = np.linspace(0, 399 * dt, 40001)
    start = grid[np.argmin([total(t) for t in grid])]
    best = minimize_scalar(total, bounds=(start - 1e-3, start + 1e-3), method="bounded", options={"xatol": 1e-12})
    assert spectrum.sa.item() == pytest.approx(-best.fun, rel=1e-10)


def test_harmonic_response_from_rest():
    """A sine sampled finely (its linear interpolation is within 1e-7 of it) against the exact response from rest."""
    amplitude, forcing, period, zeta, dt = 1.5, 5.0, 0.9, 0.05, 0.0005
    w = 2 * math.pi / period
    t_end = 6.0
    t = np.arange(0, round(t_end / dt) + 1) * dt
    spectrum = response_spectrum(amplitude * np.sin(forcing * t), dt, [period], damping=zeta)
    # steady state u_p = X sin(Ωt) + Y cos(Ωt) plus the free vibration that starts the motion at rest
    det = (w**2 - forcing**2) ** 2 + (2 * zeta * w * forcing) ** 2
    X = -amplitude * (w**2 - forcing**2) / det
    Y = amplitude * 2 * zeta * w * forcing / det
    sigma, wd = zeta * w, w * math.sqrt(1 - zeta**2)
    c1 = -Y
    c2 = (-X * forcing + sigma * c1) / wd

    def u(time: float) -> float:
        homogeneous = math.exp(-sigma * time) * (c1 * math.cos(wd * time) + c2 * math.sin(wd * time))
        return X * math.sin(forcing * time) + Y * math.cos(forcing * time) + homogeneous

    grid = np.linspace(0, t_end, 60001)
    values = np.abs([u(time) for time in grid])
    start = grid[np.argmax(values)]
    best = minimize_scalar(lambda s: -abs(u(s)), bounds=(start - 1e-3, start + 1e-3), method="bounded", options={"xatol": 1e-12})
    assert spectrum.sd.item() == pytest.approx(-best.fun, rel=1e-6)


def test_scaling_by_lambda():
    record = load_record(RECORD)
    periods = np.geomspace(0.05, 5, 12)
    base = response_spectrum(record, None, periods)
    for scale in (3.7, -0.25):
        scaled = response_spectrum(scale * record.acceleration(9.81), record.dt, periods)
        for name in ("sd", "psv", "psa", "sa"):
            np.testing.assert_allclose(scaled[name].values, abs(scale) * base[name].values, rtol=1e-12)
    measures = intensity_measures(record)
    scaled = intensity_measures(2.5 * record.acceleration(9.81), record.dt)
    for name in ("pga", "pgv", "pgd"):
        assert scaled[name].item() == pytest.approx(2.5 * measures[name].item(), rel=1e-12)
    assert scaled.arias_intensity.item() == pytest.approx(6.25 * measures.arias_intensity.item(), rel=1e-12)
    assert scaled.significant_duration.item() == pytest.approx(measures.significant_duration.item(), rel=1e-12)


def test_ground_motion_peaks_of_a_linear_acceleration():
    """a = 1 − t (exactly linear): v = t − t²/2 peaks at t = 1 (0.5), d = t²/2 − t³/6 at t = 2 (2/3), between samples."""
    dt = 0.3
    t = np.arange(8) * dt  # to 2.1 s
    pga, pgv, pgd = peak_ground_motion(1.0 - t, dt)
    assert pga == pytest.approx(1.1, rel=1e-15)
    assert pgv == pytest.approx(0.5, rel=1e-14)
    assert pgd == pytest.approx(2.0 / 3.0, rel=1e-14)


def test_arias_intensity_and_significant_duration_closed_forms():
    dt, n, g = 0.01, 1001, 9.81
    t = np.arange(n) * dt
    T = t[-1]
    # a = c t: ∫ a² = c² T³ / 3; the cumulative integral ∝ t³, so t_p = T p^(1/3)
    c = 0.7
    assert arias_intensity(c * t, dt, g) == pytest.approx(math.pi / (2 * g) * c * c * T**3 / 3, rel=1e-13)
    assert significant_duration(c * t, dt) == pytest.approx(T * (0.95 ** (1 / 3) - 0.05 ** (1 / 3)), rel=1e-12)
    assert significant_duration(np.full(n, 2.0), dt) == pytest.approx(0.9 * T, rel=1e-12)
    # the trapezoid rule on a² is off for a real record; the exact formula is what intensity_measures reports
    record = load_record(RECORD)
    a = record.acceleration(g)
    measures = intensity_measures(a, record.dt, g=g)
    assert measures.arias_intensity.item() == pytest.approx(arias_intensity(a, record.dt, g), rel=1e-15)


def test_sa_avg_is_the_geometric_mean():
    record = load_record(RECORD)
    periods = np.geomspace(0.2, 3.0, 7)
    psa = response_spectrum(record, None, periods).psa.values
    assert sa_avg(record, None, periods) == pytest.approx(float(np.prod(psa) ** (1 / 7)), rel=1e-12)


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [(dict(periods=[0.0]), "periods"), (dict(periods=[1.0], damping=1.0), "damping"), (dict(periods=[1.0], dt=-1.0), "dt")],
)
def test_bad_input_names_the_field(kwargs, field):
    arguments = {"dt": 0.01, **kwargs}
    with pytest.raises(ValueError, match=f"^{field}"):
        response_spectrum(np.ones(10), **arguments)


def test_cli_spectrum(tmp_path):
    from click.testing import CliRunner

    from stochpound.cli._records import records

    plot = tmp_path / "spectrum.png"
    result = CliRunner().invoke(records, ["spectrum", RECORD, "--periods", "0.1,1.0", "--plot", str(plot)])
    assert result.exit_code == 0, result.output
    expected = response_spectrum(RECORD, None, [0.1, 1.0])
    rows = [line.split() for line in result.output.splitlines() if line.strip().startswith(("0.1 ", "1 "))]
    assert [float(row[1]) for row in rows] == pytest.approx(expected.sd.values, rel=1e-5)
    assert plot.stat().st_size > 0
    bad = CliRunner().invoke(records, ["spectrum", RECORD, "--periods", "a,b"])
    assert bad.exit_code != 0 and "--periods" in bad.output


@pytest.mark.parametrize("zeta", [0.0, 0.05, 0.7])
def test_same_motion_resampled_gives_the_same_spectrum(zeta):
    """White noise, periods from below dt (several turns per step) to 5 s: the located maxima of the same
    piecewise-linear motion sampled 16 times finer agree to round-off."""
    rng = np.random.default_rng(7)
    dt, n = 0.02, 400
    a = rng.standard_normal(n)
    fine_dt = dt / 16
    fine = np.interp(np.arange((n - 1) * 16 + 1) * fine_dt, np.arange(n) * dt, a)
    periods = [0.013, 0.03, 0.07, 0.2, 1.0, 5.0]
    coarse, refined = response_spectrum(a, dt, periods, zeta), response_spectrum(fine, fine_dt, periods, zeta)
    for name in ("sd", "sa"):
        np.testing.assert_allclose(coarse[name].values, refined[name].values, rtol=1e-9)


def test_a_motions_peaks_are_computed_once_a_period_and_equal_a_fresh_computation_bit_for_bit(monkeypatch):
    """The process's cache of peaks (by the motion's content, step and damping): a period known is not computed again, and
    every call gives the kernel's values of that period bit for bit, whatever the other periods and their order."""
    from stochpound.motions import _spectrum

    record = load_record(RECORD)
    a, dt = record.acceleration(9.81), record.dt
    periods = np.array([2.0, 0.1, 0.7, 0.1, 3.3])
    kernel = _spectrum._spectrum_kernel

    def fresh(values: np.ndarray, zeta: float) -> tuple[np.ndarray, np.ndarray]:
        sd, sa = np.empty_like(values), np.empty_like(values)
        kernel(a, dt, 2.0 * np.pi / values, zeta, sd, sa)
        return sd, sa

    computed: list[list[float]] = []
    monkeypatch.setattr(_spectrum, "_PEAKS", type(_spectrum._PEAKS)())
    monkeypatch.setattr(_spectrum, "_spectrum_kernel", lambda a, h, omega, *rest: (computed.append(list(2.0 * np.pi / omega)), kernel(a, h, omega, *rest)))
    for values, zeta in ((periods[:3], 0.05), (periods, 0.05), (periods[::-1], 0.05), (periods, 0.02)):
        spectrum = response_spectrum(a, dt, values, zeta)
        sd, sa = fresh(values, zeta)
        assert spectrum.sd.values.tobytes() == sd.tobytes() and spectrum.sa.values.tobytes() == sa.tobytes()
        assert spectrum.psa.values.tobytes() == ((2.0 * np.pi / values) ** 2 * sd).tobytes()
    assert computed == [[0.1, 0.7, 2.0], [3.3], [0.1, 0.7, 2.0, 3.3]]  # the new periods only; another damping is another motion's
    response_spectrum(a * 2.0, dt, [0.7], 0.05)
    assert computed[-1] == [0.7]  # other samples: computed
