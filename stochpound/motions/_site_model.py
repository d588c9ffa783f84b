"""The site-based stochastic ground-motion model of Rezaeian & Der Kiureghian (2010): from standard normals to motions.

A motion is a modulated, filtered white noise whose filter frequency varies
linearly in time, then high-passed:

    x(t) = q(t) · Σ_{τ_i < t} h(t − τ_i; ω_f(τ_i), ζ_f) w_i / σ_f(t),
    σ_f(t)² = Σ_{τ_i < t} h(t − τ_i; ω_f(τ_i), ζ_f)²,
    h(s; ω, ζ) = ω/√(1 − ζ²) · exp(−ζ ω s) · sin(ω √(1 − ζ²) s),
    ω_f(τ) = max(2π [f_mid + f_slope (τ − t_mid)], 2π F_MIN),

w_i independent standard normals at the samples τ_i = i dt, so x has unit
variance times q(t)². The modulation is gamma-shaped, q(t) = α1 t^(α2−1) e^(−α3 t):
∫_0^t q² / ∫_0^∞ q² is the distribution function of a gamma variable of shape
k = 2α2 − 1 and rate λ = 2α3, so the time of 45 % of the Arias intensity is
t_mid = G_k⁻¹(0.45)/λ and D5–95 = (G_k⁻¹(0.95) − G_k⁻¹(0.05))/λ: k solves
G_k⁻¹(0.45)/(G_k⁻¹(0.95) − G_k⁻¹(0.05)) = t_mid/D5–95 (that ratio rises with k),
then λ, and α1² = (2g/π) I_a λ^k/Γ(k) gives the expected Arias intensity I_a.
The high-pass post-filter is a critically damped oscillator of corner
frequency f_c, ü + 2ω_c u̇ + ω_c² u = x, the motion its ü = x − 2ω_c u̇ − ω_c² u
(integrated exactly for x linear between samples); the baseline correction
of :mod:`stochpound.motions.baseline` then removes the small velocity and
displacement the filter's tail leaves at the end of the window.

The six parameters (I_a, D5–95, t_mid, f_mid, f_slope, ζ_f) come from
predictive equations in the standard normal space with correlated residuals
(data/site_motions/rezaeian_2010.toml), each mapped to its marginal; the
corner f_c is lognormal about a line in M (a constant for the published
model). The hazard-compatible calibration (data/site_motions/calibration.toml)
may scale the residuals and adjust the equations, and adds a spectral-shape
layer (:class:`SpectralShape`): after the post-filter, each motion passes
through a minimum-phase filter whose ln gain, linear in ln T between the layer's
periods and held beyond them, is drawn per motion (:func:`shape_filter`);
then the baseline correction. A motion is a deterministic function of
``model.normals`` + n_time independent standard normals: the first 6 give its
parameters (through the residuals' covariance), the 7th its corner, the next
K (the shape layer's periods; none for the published model) its gains, the
rest are the w_i.
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
import numba
from numba import njit

from stochpound._data_files import bundled_data_dir
from stochpound.motions._arias import DEFAULT_G
from stochpound.motions._scenario import Scenario
from stochpound.motions.baseline import baseline_correct

#: The folder of the model's data (data/site_motions).
DATA_FOLDER = "site_motions"
#: The published model's file and the calibration's.
PUBLISHED_FILE, CALIBRATION_FILE = "rezaeian_2010.toml", "calibration.toml"
#: The models ``site_motions`` offers: the published equations, and with the hazard-compatible calibration.
MODELS = ("hazard_compatible", "rezaeian_2010")
#: The physical parameters of a motion, in the order of its first six normals, then the post-filter's corner.
PARAMETERS = ("arias_intensity", "d5_95", "t_mid", "f_mid", "f_slope", "zeta_f")
#: Normals that give a motion's parameters: the six above and the post-filter's corner.
PARAMETER_NORMALS = 7
#: Units of the parameters as :func:`motion_parameters` returns them (``spectral_shape``: ln gains, one per SHAPE_PERIODS).
UNITS = {"arias_intensity": "m/s", "d5_95": "s", "t_mid": "s", "f_mid": "Hz", "f_slope": "Hz/s", "zeta_f": "1", "f_corner": "Hz", "spectral_shape": "1"}
#: Periods (s) of the spectral-shape layer's gains (the hazard-compatible calibration; data/site_motions/calibration.toml lists them).
SHAPE_PERIODS = (0.05, 0.1, 0.2, 0.3, 0.5, 0.75, 1.0, 1.5, 2.0, 3.0, 4.0, 5.0)
#: Lowest filter frequency (Hz): ω_f(t) is held there where the linear trend would fall below it.
F_MIN = 0.1
#: Highest filter damping ratio (the marginal reaches 1, where h degenerates).
ZETA_MAX = 0.95
#: The impulse response is followed until its envelope falls below this fraction of its start.
IRF_TOLERANCE = 1e-4
#: Features of the calibration's adjustments: 1, M − 7, ln(R/25), ln(Vs30/750), reverse, normal, (M − 7)², (M − 7) ln(R/25).
FEATURES = ("intercept", "magnitude", "ln_distance", "ln_vs30", "reverse", "normal", "magnitude_squared", "magnitude_ln_distance")
#: Features of the spectral-shape layer's regressions: FEATURES, then ln(R/25)², ln(Vs30/750)² and ln(R/25) ln(Vs30/750).
SHAPE_FEATURES = FEATURES + ("ln_distance_squared", "ln_vs30_squared", "ln_distance_ln_vs30")


@dataclass(frozen=True)
class Lognormal:
    """A lognormal marginal: ln x is normal with mean ``mu`` and standard deviation ``sigma``."""

    mu: float
    sigma: float

    def ppf(self, p: np.ndarray) -> np.ndarray:
        """The quantiles at probabilities ``p``."""
        from scipy import stats
        return np.exp(stats.norm.ppf(p, self.mu, self.sigma))


@dataclass(frozen=True)
class Beta:
    """A beta marginal of shapes ``a``, ``b`` on [``low``, ``high``]."""

    a: float
    b: float
    low: float
    high: float

    def ppf(self, p: np.ndarray) -> np.ndarray:
        """The quantiles at probabilities ``p``."""
        from scipy import stats
        return self.low + (self.high - self.low) * stats.beta.ppf(p, self.a, self.b)


@dataclass(frozen=True)
class Gamma:
    """A gamma marginal of ``shape`` and ``scale``."""

    shape: float
    scale: float

    def ppf(self, p: np.ndarray) -> np.ndarray:
        """The quantiles at probabilities ``p``."""
        from scipy import stats
        return stats.gamma.ppf(p, self.shape, scale=self.scale)


@dataclass(frozen=True)
class TwoSidedExponential:
    """The density c e^(b x) on [``low``, 0) and c e^(−a x) on [0, ``high``]."""

    a: float
    b: float
    c: float
    low: float
    high: float

    def ppf(self, p: np.ndarray) -> np.ndarray:
        """The quantiles at probabilities ``p``."""
        return _two_sided_exponential_ppf(p, self.a, self.b, self.c, self.low, self.high)


Marginal = Lognormal | Beta | Gamma | TwoSidedExponential
"""A parameter's marginal distribution (the data file's ``kind``)."""
_MARGINALS = {"lognormal": Lognormal, "beta": Beta, "gamma": Gamma, "two_sided_exponential": TwoSidedExponential}


def _marginal(table: Mapping[str, float | str]) -> Marginal:
    """A ``[marginals]`` entry of the data file: its ``kind`` with that kind's parameters."""
    fields = dict(table)
    return _MARGINALS[str(fields.pop("kind"))](**fields)


@dataclass(frozen=True)
class SpectralShape:
    """The hazard-compatible calibration's spectral-shape layer (docs/site-motions.md).

    At its ``periods`` T_j (s) a motion's filter gain is ln H_j = μ_j − r_j + d_j (L z)_j:
    μ_j and σ_j the NGA-West2 average's mean ln Sa and σ of the scenario (its geometry
    included), r_j = ``mean`` · x and v_j = ``variance`` · x (x the scenario's
    :data:`SHAPE_FEATURES`) the mean and variance of ln Sa the base model gives there
    (as fitted), d_j = √max(σ_j² − v_j, 0), L = ``cholesky`` the lower factor of the
    gains' correlation and z the motion's shape normals.
    """

    periods: tuple[float, ...]
    mean: np.ndarray
    variance: np.ndarray
    cholesky: np.ndarray


@dataclass(frozen=True)
class SiteModel:
    """A model's predictive equations in the standard normal space, its marginals and its post-filter.

    ``coefficients`` [6, 5]: b0, b_m, b_f, b_r, b_v of the published equations;
    ``cholesky`` [6, 6]: lower factor of the residuals' covariance;
    ``adjustments`` [6, len(FEATURES)]: added to ν (zero for the published model);
    ``corner`` [3]: ln f_c = corner[0] + corner[1] (M − 7) + corner[2] z (f_c in Hz, z the motion's
    seventh normal); ``shape``: the spectral-shape layer (None for the published model).
    """

    name: str
    coefficients: np.ndarray
    cholesky: np.ndarray
    marginals: tuple[Marginal, ...]
    adjustments: np.ndarray
    corner: np.ndarray
    provenance: str
    shape: SpectralShape | None = None

    @property
    def normals(self) -> int:
        """Standard normals of a motion before its noise: :data:`PARAMETER_NORMALS` and the shape layer's one per period."""
        return PARAMETER_NORMALS + (len(self.shape.periods) if self.shape is not None else 0)


def _read(name: str) -> dict:
    folder = bundled_data_dir(DATA_FOLDER, PUBLISHED_FILE)
    if folder is None:  # pragma: no cover - a broken installation
        raise FileNotFoundError(f"{DATA_FOLDER}/{PUBLISHED_FILE}: the site-motion model's data is missing from this installation")
    return tomllib.loads((folder / name).read_text())


@lru_cache(maxsize=None)
def load_site_model(model: str) -> SiteModel:
    """The model ``model`` (one of :data:`MODELS`) from its bundled data."""
    published = _read(PUBLISHED_FILE)
    if published["parameters"] != list(PARAMETERS):  # pragma: no cover - the data file's own consistency
        raise ValueError(f"{PUBLISHED_FILE}: parameters must be {PARAMETERS}")
    residuals = published["residuals"]
    scale = np.hypot(residuals["sigma"], residuals["tau"])
    adjustments = np.zeros((len(PARAMETERS), len(FEATURES)))
    corner = np.array([math.log(published["post_filter"]["corner_hz"]), 0.0, 0.0])
    provenance = published["name"]
    shape = None
    if model == "hazard_compatible":
        calibration = _read(CALIBRATION_FILE)
        for parameter, values in (calibration["adjustments"] if "adjustments" in calibration else {}).items():
            adjustments[PARAMETERS.index(parameter), : len(values)] = values
        for parameter, factor in calibration["residual_scale"].items():
            scale[PARAMETERS.index(parameter)] *= factor
        corner = np.array(calibration["corner"]["ln_hz"] + [calibration["corner"]["sigma_ln"]], dtype=float)
        provenance = f"{published['name']} + {calibration['name']}"
        shape = _shape(calibration["spectral_shape"])
    elif model != "rezaeian_2010":
        raise ValueError(f"model: must be one of {', '.join(MODELS)}, got {model!r}")
    covariance = np.asarray(residuals["correlation"]) * np.outer(scale, scale)
    return SiteModel(model, np.array([published["coefficients"][p] for p in PARAMETERS]), np.linalg.cholesky(covariance),
                     tuple(_marginal(published["marginals"][p]) for p in PARAMETERS), adjustments, corner, provenance, shape)


def _shape(table: Mapping[str, list]) -> SpectralShape:
    """The calibration file's ``[spectral_shape]`` table: periods, the base's mean and variance regressions, the gains' correlation."""
    if tuple(table["periods"]) != SHAPE_PERIODS:  # pragma: no cover - the data file's own consistency
        raise ValueError(f"{CALIBRATION_FILE}: spectral_shape.periods must be {SHAPE_PERIODS}")
    if any(len(row) != len(SHAPE_FEATURES) for row in (*table["mean"], *table["variance"])):  # pragma: no cover - the same
        raise ValueError(f"{CALIBRATION_FILE}: spectral_shape.mean and .variance need one coefficient per feature {SHAPE_FEATURES}")
    return SpectralShape(tuple(float(p) for p in table["periods"]), np.array(table["mean"], dtype=float),
                         np.array(table["variance"], dtype=float), np.linalg.cholesky(np.array(table["correlation"], dtype=float)))


def shape_features(scenario: Scenario) -> np.ndarray:
    """The spectral-shape layer's features (:data:`SHAPE_FEATURES`) of a scenario."""
    x = scenario_features(scenario)
    return np.concatenate([x, [x[2] ** 2, x[3] ** 2, x[2] * x[3]]])


def shape_gains(shape: SpectralShape, scenario: Scenario) -> tuple[np.ndarray, np.ndarray]:
    """The shape layer's mean gain μ − r and spread d (ln, at its periods) for a scenario (:class:`SpectralShape`)."""
    from stochpound.motions._conditional import _average_model

    mean, sigma = _average_model(list(shape.periods), scenario)
    return layer_gains(mean, sigma, shape.mean, shape.variance, shape_features(scenario))


def layer_gains(mean: np.ndarray, sigma: np.ndarray, mean_coefficients: np.ndarray, variance_coefficients: np.ndarray,
                features: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The shape layer's mean gain μ − r and spread d = √max(σ² − v, 0) (ln, at its periods) from the regressions of the base's
    mean r and variance v (coefficients [period, feature]) at ``features`` ([feature], or [scenario, feature] with ``mean`` and
    ``sigma`` [scenario, period]): :class:`SpectralShape`'s rule, for a model and for its fit alike."""
    r, v = (np.asarray(coefficients) @ np.asarray(features).T for coefficients in (mean_coefficients, variance_coefficients))
    return mean - r.T, np.sqrt(np.maximum(sigma**2 - v.T, 0.0))


def scenario_features(scenario: Scenario) -> np.ndarray:
    """The calibration's features (:data:`FEATURES`) of a scenario."""
    m, r = scenario.magnitude - 7.0, math.log(scenario.distance_km / 25.0)
    mechanism = scenario.mechanism
    return np.array([1.0, m, r, math.log(scenario.vs30 / 750.0), float(mechanism == "reverse"), float(mechanism == "normal"), m * m, m * r])


def mean_normals(model: SiteModel, scenario: Scenario) -> np.ndarray:
    """ν of the scenario before its residuals: the published equations (F = 1 for reverse faulting) plus the adjustments."""
    magnitude, distance_km, vs30 = scenario.magnitude, scenario.distance_km, scenario.vs30
    f = float(scenario.mechanism == "reverse")
    b = model.coefficients
    first = b[0] @ [1.0, magnitude / 7.0, f, math.log(distance_km / 25.0), math.log(vs30 / 750.0)]
    others = b[1:] @ [1.0, magnitude, f, distance_km, vs30]
    return np.concatenate([[first], others]) + model.adjustments @ scenario_features(scenario)


def _two_sided_exponential_ppf(p: np.ndarray, a: float, b: float, c: float, low: float, high: float) -> np.ndarray:
    """Inverse of the distribution c e^(b x) (low ≤ x < 0), c e^(−a x) (0 ≤ x ≤ high)."""
    at_zero = c / b * (1.0 - math.exp(b * low))
    with np.errstate(divide="ignore", invalid="ignore"):
        below = np.log(np.clip(p * b / c + math.exp(b * low), 1e-300, None)) / b
        above = -np.log(np.clip(1.0 - (p - at_zero) * a / c, 1e-300, None)) / a
    return np.clip(np.where(p < at_zero, below, above), low, high)


def motion_parameters(model: SiteModel, scenario: Scenario, normals: np.ndarray) -> dict[str, np.ndarray]:
    """Each motion's parameters (:data:`UNITS`) from its ``model.normals`` standard normals ``normals`` [n, model.normals].

    With a shape layer, ``spectral_shape`` [n, K] holds each motion's ln gains at the layer's periods.
    """
    from scipy import stats

    normals = np.asarray(normals, dtype=float)
    correlated = np.sum(normals[:, None, :6] * model.cholesky[None, :, :], axis=2)  # L z row by row: a BLAS product's rounding depends on n
    nu = mean_normals(model, scenario)[None, :] + correlated
    p = np.clip(stats.norm.cdf(nu), 1e-12, 1.0 - 1e-12)
    values = {name: marginal.ppf(p[:, i]) for i, (name, marginal) in enumerate(zip(PARAMETERS, model.marginals))}
    values["arias_intensity"] = values["arias_intensity"] * DEFAULT_G  # s·g → m/s
    values["zeta_f"] = np.minimum(values["zeta_f"], ZETA_MAX)
    values["f_corner"] = np.exp(model.corner[0] + model.corner[1] * (scenario.magnitude - 7.0) + model.corner[2] * normals[:, 6])
    if model.shape is not None:
        mean, spread = shape_gains(model.shape, scenario)
        z = normals[:, PARAMETER_NORMALS:model.normals]
        values["spectral_shape"] = mean + spread * np.sum(z[:, None, :] * model.shape.cholesky[None, :, :], axis=2)
    return values


def shape_filter(acceleration: np.ndarray, dt: float, periods: Sequence[float], gains: np.ndarray) -> np.ndarray:
    """Motions [n, n_time] through their minimum-phase filters: ln |H| interpolated in ln T between ``gains`` [n, K] at ``periods`` (s).

    |H| is held at the end values beyond the periods; its phase is the minimum
    phase of that amplitude (the real cepstrum of ln |H| folded onto positive
    quefrencies), so the filter is causal: a motion at rest before t = 0 stays
    so, and the filter delays rather than spreads. The motion is padded with
    zeros to 1.5 times its length (a fast FFT size); what the filter moves past
    the window is cut, and the baseline correction follows.
    """
    from scipy import fft

    n_time = acceleration.shape[1]
    size = fft.next_fast_len(int(1.5 * n_time) + 1, real=True)
    size += size % 2
    frequency = fft.rfftfreq(size, dt)
    ln_period = -np.log(np.maximum(frequency, 1e-12))
    nodes = np.log(np.asarray(periods, dtype=float))
    basis = np.stack([np.interp(ln_period, nodes, np.eye(len(nodes))[j]) for j in range(len(nodes))], axis=1)
    out = np.empty_like(acceleration)
    for m, row in enumerate(np.asarray(gains, dtype=float)):  # one motion at a time: batched FFTs and products round by batch
        cepstrum = fft.irfft(basis @ row, size)
        folded = np.zeros(size)
        folded[0] = cepstrum[0]
        folded[1:size // 2] = 2.0 * cepstrum[1:size // 2]
        folded[size // 2] = cepstrum[size // 2]
        out[m] = fft.irfft(fft.rfft(acceleration[m], size) * np.exp(fft.rfft(folded)), size)[:n_time]
    return out


def gamma_shape(t_mid: np.ndarray, d5_95: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Shape k and rate λ (1/s) of the gamma distribution whose 45 % point is ``t_mid`` and 5–95 % range ``d5_95`` (s)."""
    from scipy import special

    ratio = np.asarray(t_mid, dtype=float) / np.asarray(d5_95, dtype=float)
    low, high = np.full(ratio.shape, math.log(1e-2)), np.full(ratio.shape, math.log(1e4))
    for _ in range(50):  # bisection in ln k: the ratio rises with k
        middle = 0.5 * (low + high)
        k = np.exp(middle)
        rises = special.gammaincinv(k, 0.45) / (special.gammaincinv(k, 0.95) - special.gammaincinv(k, 0.05)) < ratio
        low, high = np.where(rises, middle, low), np.where(rises, high, middle)
    k = np.exp(0.5 * (low + high))
    return k, special.gammaincinv(k, 0.45) / t_mid


def modulation_constants(parameters: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """ln α1² (α1 in m/s^(α2+1)), k and λ (1/s) of every motion's modulation q² = α1² t^(k−1) e^(−λt) (module docstring)."""
    from scipy import special

    k, rate = gamma_shape(parameters["t_mid"], parameters["d5_95"])
    return np.log(2.0 * DEFAULT_G / np.pi * parameters["arias_intensity"]) + k * np.log(rate) - special.gammaln(k), k, rate


@njit(cache=True, nogil=True)
def _modulation_row(ln_alpha1_sq, k, rate, times, out):  # pragma: no cover - compiled
    """out[i] = q(times[i]) of one motion (m/s²); q(times[0]) = 0 multiplies a zero noise sample."""
    out[0] = 0.0
    for i in range(1, out.shape[0]):
        t = times[i]
        out[i] = math.exp(0.5 * ln_alpha1_sq + 0.5 * (k - 1.0) * math.log(t) - 0.5 * rate * t)


def modulation(parameters: dict[str, np.ndarray], times: np.ndarray) -> np.ndarray:
    """q(t) [n, n_time] (m/s²) of every motion at the samples ``times`` = 0, dt, 2 dt, … (s): its gamma-shaped envelope."""
    times = np.asarray(times, dtype=float)
    out = np.empty((np.size(parameters["t_mid"]), times.size))
    for m, constants in enumerate(zip(*modulation_constants(parameters))):
        _modulation_row(*constants, times, out[m])
    return out


@njit(cache=True, nogil=True)
def _impulse(dt, f_mid, f_slope, t_mid, zeta, i):  # pragma: no cover - compiled
    """h at lag 1 of impulse i, the recurrence's two coefficients and the lags to follow it (module docstring)."""
    omega = 2.0 * math.pi * max(f_mid + f_slope * (i * dt - t_mid), F_MIN)
    root = math.sqrt(1.0 - zeta * zeta)
    decay = math.exp(-zeta * omega * dt)
    first = omega / root * decay * math.sin(omega * root * dt)
    return first, 2.0 * decay * math.cos(omega * root * dt), decay * decay, int(math.log(1.0 / IRF_TOLERANCE) / (zeta * omega * dt)) + 1


@njit(cache=True, nogil=True, fastmath={"contract"})  # fused multiply-adds: round-off only
def _normalized_row(noise, dt, f_mid, f_slope, t_mid, zeta, out, total, energy):  # pragma: no cover - compiled
    """out = Σ h w / σ_f of one motion (module docstring); ``total`` and ``energy`` are work arrays of 2 n_time + 4.

    h(s) of an impulse at the samples s = lag·dt follows the recurrence
    h_{l+1} = 2e^{−ζω dt} cos(ω_d dt) h_l − e^{−2ζω dt} h_{l−1} (h_0 = 0). The
    impulses go in groups of four consecutive ones, each followed for as
    many lags as the slowest of its group needs for its envelope to fall
    below :data:`IRF_TOLERANCE` of its start. A group's four impulses reach
    the outputs k, k+1, k+2, k+3 at one lag: their sums for k+1 to k+3 wait
    in registers (s, r) and each output is added to memory once a group.
    """
    n_time = noise.shape[0]
    total[:] = 0.0
    energy[:] = 0.0
    for start in range(0, n_time - 1, 4):
        b0, p0, q0, l0 = _impulse(dt, f_mid, f_slope, t_mid, zeta, start)
        b1, p1, q1, l1 = _impulse(dt, f_mid, f_slope, t_mid, zeta, start + 1)
        b2, p2, q2, l2 = _impulse(dt, f_mid, f_slope, t_mid, zeta, start + 2)
        b3, p3, q3, l3 = _impulse(dt, f_mid, f_slope, t_mid, zeta, start + 3)
        w0 = noise[start]
        w1 = noise[start + 1] if start + 1 < n_time - 1 else 0.0
        w2 = noise[start + 2] if start + 2 < n_time - 1 else 0.0
        w3 = noise[start + 3] if start + 3 < n_time - 1 else 0.0
        a0 = a1 = a2 = a3 = 0.0
        s1 = s2 = s3 = r1 = r2 = r3 = 0.0
        length = min(n_time - 1 - start, max(max(l0, l1), max(l2, l3)))
        t = total[start + 1:]  # views indexed from 0: no negative-index handling in the loop
        e = energy[start + 1:]
        for k in range(length):
            t[k] += s1 + b0 * w0
            e[k] += r1 + b0 * b0
            s1, s2, s3 = s2 + b1 * w1, s3 + b2 * w2, b3 * w3
            r1, r2, r3 = r2 + b1 * b1, r3 + b2 * b2, b3 * b3
            a0, b0 = b0, p0 * b0 - q0 * a0
            a1, b1 = b1, p1 * b1 - q1 * a1
            a2, b2 = b2, p2 * b2 - q2 * a2
            a3, b3 = b3, p3 * b3 - q3 * a3
        t[length] += s1
        e[length] += r1
        t[length + 1] += s2
        e[length + 1] += r2
        t[length + 2] += s3
        e[length + 2] += r3
    out[0] = 0.0
    for k in range(1, n_time):
        out[k] = total[k] / math.sqrt(energy[k]) if energy[k] > 0.0 else 0.0


@njit(cache=True, nogil=True)
def _normalized_noise(noise, dt, f_mid, f_slope, t_mid, zeta, out):  # pragma: no cover - compiled
    """out[m] = Σ h w / σ_f of every motion m (:func:`_normalized_row`)."""
    n_time = noise.shape[1]
    total = np.empty(2 * n_time + 4)
    energy = np.empty(2 * n_time + 4)
    for m in range(noise.shape[0]):
        _normalized_row(noise[m], dt, f_mid[m], f_slope[m], t_mid[m], zeta[m], out[m], total, energy)


@njit(cache=True, nogil=True)
def _product(a, b):  # pragma: no cover - compiled
    """a @ b of 4 × 4 matrices, in loops (no BLAS call)."""
    out = np.zeros((4, 4))
    for i in range(4):
        for j in range(4):
            for m in range(4):
                out[i, j] += a[i, m] * b[m, j]
    return out


@njit(cache=True, nogil=True)
def _hold_matrices(omega_c, dt):  # pragma: no cover - compiled
    """Exact step of ü + 2ω_c u̇ + ω_c² u = x for x linear in the step: s⁺ = Φ s + g0 x_k + g1 (x_{k+1} − x_k)/dt.

    The exponential of the augmented system's matrix M dt (state u, u̇, then
    the input's value and slope) by its Taylor series, the matrix halved
    until its largest entry is below 1/8 (then 30 terms reach round-off) and
    the result squared back.
    """
    squarings = 0
    scale = 1.0
    while max(dt, omega_c * omega_c * dt, 2.0 * omega_c * dt) * scale > 0.125:
        scale *= 0.5
        squarings += 1
    augmented = np.zeros((4, 4))
    augmented[0, 1] = dt * scale
    augmented[1, 0] = -omega_c * omega_c * dt * scale
    augmented[1, 1] = -2.0 * omega_c * dt * scale
    augmented[1, 2] = dt * scale
    augmented[2, 3] = dt * scale
    exponential = np.zeros((4, 4))
    term = np.zeros((4, 4))
    for i in range(4):
        exponential[i, i] = term[i, i] = 1.0
    for n in range(1, 30):
        term = _product(term, augmented)
        for i in range(4):
            for j in range(4):
                term[i, j] /= n
                exponential[i, j] += term[i, j]
    for _ in range(squarings):
        exponential = _product(exponential, exponential)
    phi = np.empty((2, 2))
    g0, g1 = np.empty(2), np.empty(2)
    for i in range(2):
        phi[i, 0], phi[i, 1] = exponential[i, 0], exponential[i, 1]
        g0[i], g1[i] = exponential[i, 2], exponential[i, 3] / dt
    return phi, g0, g1


@njit(cache=True, nogil=True)
def _high_pass_kernel(x, omega_c, phi, g0, g1, out):  # pragma: no cover - compiled
    """out[k] = ü_k = x_k − 2ω_c u̇_k − ω_c² u_k, the state stepped exactly (:func:`_hold_matrices`)."""
    u, v = 0.0, 0.0
    n = x.shape[0]
    for k in range(n):
        out[k] = x[k] - 2.0 * omega_c * v - omega_c * omega_c * u
        if k + 1 < n:
            slope = x[k + 1] - x[k]
            u, v = (phi[0, 0] * u + phi[0, 1] * v + g0[0] * x[k] + g1[0] * slope,
                    phi[1, 0] * u + phi[1, 1] * v + g0[1] * x[k] + g1[1] * slope)


def high_pass(acceleration: np.ndarray, dt: float, f_corner: np.ndarray) -> np.ndarray:
    """The post-filter's output ü [n, n_time] (m/s²) of every motion, its corner ``f_corner`` [n] in Hz."""
    out = np.empty_like(acceleration)
    for m, corner in enumerate(f_corner):
        omega_c = 2.0 * math.pi * float(corner)
        _high_pass_kernel(acceleration[m], omega_c, *_hold_matrices(omega_c, float(dt)), out[m])
    return out


@njit(cache=True, nogil=True)
def _filtered_motions(noise, dt, f_mid, f_slope, t_mid, zeta, ln_alpha1_sq, k, rate, f_corner, out):  # pragma: no cover - compiled
    """out[m] = the post-filtered q · Σ h w / σ_f of every motion m (before the baseline correction)."""
    n_time = noise.shape[1]
    total = np.empty(2 * n_time + 4)
    energy = np.empty(2 * n_time + 4)
    unit = np.empty(n_time)
    envelope = np.empty(n_time)
    times = np.arange(n_time) * dt
    for m in range(noise.shape[0]):
        _normalized_row(noise[m], dt, f_mid[m], f_slope[m], t_mid[m], zeta[m], unit, total, energy)
        _modulation_row(ln_alpha1_sq[m], k[m], rate[m], times, envelope)
        envelope *= unit
        omega_c = 2.0 * math.pi * f_corner[m]
        phi, g0, g1 = _hold_matrices(omega_c, dt)
        _high_pass_kernel(envelope, omega_c, phi, g0, g1, out[m])


#: Motions computed together by one thread (the split depends on nothing else, so neither do the results).
BATCH = 16


def motion_threads() -> int:
    """Threads :func:`motions_from_parameters` uses: numba's ``NUMBA_NUM_THREADS`` (default: the cores; its threading layer is not started)."""
    return int(numba.config.NUMBA_NUM_THREADS)


def on_motion_threads(batch: Callable[[int], None], starts: range) -> None:
    """Call ``batch(start)`` for every start, on :func:`motion_threads` threads (each call writes its own rows: no value depends on them)."""
    threads = min(motion_threads(), len(starts))
    if threads <= 1:
        for start in starts:
            batch(start)
    else:
        with ThreadPoolExecutor(threads) as pool:
            list(pool.map(batch, starts))


def motions_from_parameters(parameters: dict[str, np.ndarray], noise: np.ndarray, dt: float) -> np.ndarray:
    """Accelerations [n, n_time] (m/s², from t = 0 at ``dt``) of motions of given parameters and white noise ``noise`` [n, n_time]."""
    noise = np.asarray(noise, dtype=float)
    return motions_from_noise_rows(parameters, lambda rows: noise[rows], noise.shape[1], dt)


def motions_from_noise_rows(parameters: dict[str, np.ndarray], noise_rows: Callable[[slice], np.ndarray], n_time: int,
                            dt: float) -> np.ndarray:
    """Accelerations [n, n_time] (m/s²) of motions of given parameters, ``noise_rows(rows)`` giving the white noise of ``rows``.

    The motions are computed in batches of :data:`BATCH` on :func:`motion_threads`
    threads (``noise_rows`` is called once per batch, from its thread); each
    motion depends on its own parameters and noise alone. Memory: the result
    (8 n_time bytes a motion) and a batch's work arrays.
    """
    n = np.size(parameters["t_mid"])
    out = np.empty((n, n_time))

    def batch(start: int) -> None:
        rows = slice(start, min(start + BATCH, n))
        chosen = {name: np.ascontiguousarray(values[rows], dtype=float) for name, values in parameters.items()}
        ln_alpha1_sq, k, rate = modulation_constants(chosen)
        noise = np.ascontiguousarray(noise_rows(rows), dtype=float)
        _filtered_motions(noise, float(dt), chosen["f_mid"], chosen["f_slope"], chosen["t_mid"], chosen["zeta_f"],
                          ln_alpha1_sq, k, rate, chosen["f_corner"], out[rows])
        if "spectral_shape" in chosen:
            out[rows] = shape_filter(out[rows], dt, SHAPE_PERIODS, chosen["spectral_shape"])
        out[rows] = baseline_correct(out[rows], dt)

    on_motion_threads(batch, range(0, n, BATCH))
    return out


def motions_from_normals(model: SiteModel, scenario: Scenario, normals: np.ndarray, dt: float) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Accelerations [n, n_time] (m/s², from t = 0 at ``dt``) and parameters of the motions of ``normals`` [n, model.normals + n_time]."""
    normals = np.asarray(normals, dtype=float)
    parameters = motion_parameters(model, scenario, normals[:, :model.normals])
    return motions_from_parameters(parameters, normals[:, model.normals:], dt), parameters
