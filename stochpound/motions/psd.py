"""Power spectral densities of filtered white noise: Kanai–Tajimi and Clough–Penzien.

Convention (one for the whole package)
--------------------------------------
S(ω) is **two-sided in ω (rad/s) on (−∞, ∞)**, so that the variance is

    σ² = ∫_{−∞}^{∞} S(ω) dω.

The bedrock excitation is white noise w(t) with S_w(ω) = S0, i.e.
E[w(t) w(t+τ)] = 2π S0 δ(τ); S0 is in (m/s²)²/(rad/s) = m²/s³. The one-sided
density in ω is G(ω) = 2 S(ω) (ω ≥ 0); in Hz it is 4π S(2πf).

Kanai–Tajimi (Kanai 1957; Tajimi 1960)::

    S_KT(ω) = S0 (ω_g⁴ + 4 ζ_g² ω_g² ω²) / ((ω_g² − ω²)² + 4 ζ_g² ω_g² ω²)
    σ²_KT   = π S0 ω_g (1 + 4 ζ_g²) / (2 ζ_g)

Clough–Penzien (Clough & Penzien 1975) adds a second-order high-pass filter::

    S_CP(ω) = S_KT(ω) · ω⁴ / ((ω_f² − ω²)² + 4 ζ_f² ω_f² ω²)

Both are abs(H(iω))² S0 for a rational transfer function H(s) = N(s)/D(s),
strictly proper, so the process has a finite variance and a state-space
realisation (A, B, C). :class:`FilteredWhiteNoise` holds H and computes the
variance exactly (Lyapunov equation), the exact discretisation at a step dt,
and the PSD of the sampled sequence (the aliased PSD).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
from scipy.linalg import expm, solve_continuous_lyapunov


def kanai_tajimi_psd(omega: np.ndarray | float, omega_g: float, zeta_g: float, S0: float = 1.0) -> np.ndarray:
    """Kanai–Tajimi PSD, two-sided in ω.

    Parameters
    ----------
    omega : array_like
        Circular frequency, rad/s (any sign).
    omega_g : float
        Ground (soil) frequency, rad/s.
    zeta_g : float
        Ground damping ratio.
    S0 : float
        Two-sided PSD of the bedrock white noise, m²/s³.

    Returns
    -------
    np.ndarray
        S(ω), m²/s³ (i.e. (m/s²)² per rad/s).
    """
    w2 = np.asarray(omega, dtype=float) ** 2
    g2 = omega_g**2
    damping = 4.0 * zeta_g**2 * g2 * w2
    return S0 * (g2**2 + damping) / ((g2 - w2) ** 2 + damping)


def high_pass_gain(omega: np.ndarray | float, omega_f: float, zeta_f: float) -> np.ndarray:
    """abs(H_f(iω))² = ω⁴ / ((ω_f² − ω²)² + 4 ζ_f² ω_f² ω²), the Clough–Penzien high-pass filter."""
    w2 = np.asarray(omega, dtype=float) ** 2
    f2 = omega_f**2
    return w2**2 / ((f2 - w2) ** 2 + 4.0 * zeta_f**2 * f2 * w2)


def clough_penzien_psd(
    omega: np.ndarray | float, omega_g: float, zeta_g: float, omega_f: float, zeta_f: float, S0: float = 1.0
) -> np.ndarray:
    """Clough–Penzien PSD, two-sided in ω (m²/s³): Kanai–Tajimi times the high-pass gain.

    Parameters are those of :func:`kanai_tajimi_psd`, plus ``omega_f`` (rad/s)
    and ``zeta_f``, the frequency and damping ratio of the high-pass filter.
    """
    return kanai_tajimi_psd(omega, omega_g, zeta_g, S0) * high_pass_gain(omega, omega_f, zeta_f)


def kanai_tajimi_variance(omega_g: float, zeta_g: float, S0: float = 1.0) -> float:
    """Closed-form ∫ S_KT dω = π S0 ω_g (1 + 4 ζ_g²) / (2 ζ_g), (m/s²)²."""
    return np.pi * S0 * omega_g * (1.0 + 4.0 * zeta_g**2) / (2.0 * zeta_g)


@dataclass(frozen=True)
class FilteredWhiteNoise:
    """White noise of PSD S0 through a strictly proper rational filter H(s) = N(s)/D(s).

    Parameters
    ----------
    numerator, denominator : tuple of float
        Polynomial coefficients of N and D in s, highest power first
        (``len(numerator) < len(denominator)``).
    S0 : float
        Two-sided PSD of the input white noise, m²/s³.
    name : str
        Model name (``"kanai_tajimi"``, ``"clough_penzien"``).
    parameters : dict[str, float]
        Physical parameters (for attributes and messages), e.g. ``omega_g`` (rad/s) and ``zeta_g``.
    """

    numerator: tuple[float, ...]
    denominator: tuple[float, ...]
    S0: float = 1.0
    name: str = "filtered_white_noise"
    parameters: dict[str, float] = field(default_factory=dict, compare=False)

    def __post_init__(self) -> None:
        if len(self.numerator) >= len(self.denominator):
            raise ValueError("the filter must be strictly proper (numerator degree < denominator degree)")
        if not np.all(np.real(np.roots(self.denominator)) < 0.0):
            raise ValueError("the filter must be stable (all poles in the left half-plane)")

    def with_S0(self, S0: float) -> "FilteredWhiteNoise":
        """The same filter driven by white noise of PSD ``S0``."""
        return FilteredWhiteNoise(self.numerator, self.denominator, float(S0), self.name, dict(self.parameters))

    def psd(self, omega: np.ndarray | float) -> np.ndarray:
        """S(ω) = S0 abs(H(iω))², two-sided, m²/s³."""
        s = 1j * np.asarray(omega, dtype=float)
        return self.S0 * np.abs(np.polyval(self.numerator, s) / np.polyval(self.denominator, s)) ** 2

    @cached_property
    def _state_space(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        return controllable_form(self.numerator, self.denominator)

    def state_space(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(A, B, C) with ẋ = A x + B w, output C x (controllable canonical form)."""
        return self._state_space

    @cached_property
    def _unit_covariance(self) -> np.ndarray:
        A, B, _ = self._state_space
        P = solve_continuous_lyapunov(A, -2.0 * np.pi * (B @ B.T))
        return 0.5 * (P + P.T)

    def state_covariance(self) -> np.ndarray:
        """Stationary covariance P of the state: A P + P Aᵀ + 2π S0 B Bᵀ = 0."""
        return self.S0 * self._unit_covariance

    def variance(self, omega_max: float | None = None) -> float:
        """σ² = ∫ S dω, (m/s²)².

        Over (−∞, ∞) exactly (Lyapunov equation), or over abs(ω) ≤ ``omega_max``
        (rad/s) by adaptive quadrature.
        """
        if omega_max is None:
            _, _, C = self._state_space
            return float((C @ self.state_covariance() @ C.T)[0, 0])
        from scipy.integrate import quad

        poles = np.abs(np.roots(self.denominator))
        breaks = sorted(p for p in poles if 0.0 < p < omega_max)
        total = quad(lambda w: float(self.psd(w)), 0.0, omega_max, points=breaks or None, limit=500, epsrel=1e-10)[0]
        return 2.0 * total

    def decay_rate(self) -> float:
        """Slowest decay rate of the filter's impulse response, min −Re(pole), 1/s."""
        return float(np.min(-np.real(np.roots(self.denominator))))

    def discretize(self, dt: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Exact discretisation of the filter driven by continuous white noise.

        Returns
        -------
        Phi : np.ndarray
            State transition e^{A dt}.
        noise_factor : np.ndarray
            L with L Lᵀ = Q_d = P − Φ P Φᵀ, the covariance of the state noise
            accumulated over one step (exact for the stationary process).
        C : np.ndarray
            Output row.
        P_factor : np.ndarray
            L_P with L_P L_Pᵀ = P (to start from the stationary distribution).
        """
        A, _, C = self._state_space
        P = self.state_covariance()
        Phi = expm(A * dt)
        Qd = P - Phi @ P @ Phi.T
        return Phi, _psd_factor(Qd), C, _psd_factor(P)

    def sampled_psd(self, omega: np.ndarray | float, dt: float) -> np.ndarray:
        """PSD of the sampled sequence a_k = a(k dt), on abs(ω) ≤ π/dt (aliased PSD).

        S_d(ω) = Σ_m S(ω + 2πm/dt) = (dt/2π) Σ_k R(k dt) e^{−iωk dt}, computed
        exactly from R(k dt) = C Φ^k P Cᵀ. Its integral over (−π/dt, π/dt) is σ².
        """
        omega = np.asarray(omega, dtype=float)
        A, _, C = self._state_space
        P = self.state_covariance()
        Phi = expm(A * dt)
        n = Phi.shape[0]
        z = np.exp(-1j * omega.ravel() * dt)
        systems = np.eye(n)[None, :, :] - z[:, None, None] * Phi[None, :, :]
        rhs = np.broadcast_to((P @ C.T)[None, :, :], (z.size, n, 1))
        one_sided = (C[None, :, :] @ np.linalg.solve(systems, rhs))[:, 0, 0]
        r0 = float((C @ P @ C.T)[0, 0])
        return (dt / (2.0 * np.pi) * (2.0 * one_sided.real - r0)).reshape(omega.shape)

    def spectral_moment(self, order: int, dt: float, n_points: int = 20001) -> float:
        """λ_k = ∫ abs(ω)^k S_d(ω) dω over abs(ω) ≤ π/dt (the sampled process), (m/s²)² (rad/s)^k."""
        omega = np.linspace(0.0, np.pi / dt, n_points)
        return 2.0 * float(np.trapezoid(omega**order * self.sampled_psd(omega, dt), omega))


def controllable_form(numerator: tuple[float, ...], denominator: tuple[float, ...]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(A, B, C) of the strictly proper H(s) = N(s)/D(s) in controllable canonical form, as ``scipy.signal.tf2ss`` gives them.

    The same arithmetic as scipy's (bit for bit: ``tests/test_motions.py``),
    without importing ``scipy.signal`` (about a second of CPU, with
    ``scipy.stats``): D's leading zeros dropped, N and D divided by D's
    leading coefficient, N's leading coefficients of magnitude ≤ 1e-14 taken
    as zeros, N padded with zeros to D's length; A's first row is −D[1:],
    ones below the diagonal, B = e₁, C = N[1:] − N[0] D[1:].

    Parameters
    ----------
    numerator, denominator : tuple of float
        Coefficients of N and D, highest power first (D's degree greater than N's).
    """
    den = np.trim_zeros(np.atleast_1d(np.asarray(denominator, dtype=float)), "f")
    num, den = np.asarray(numerator, dtype=float) / den[0], den / den[0]
    tiny = np.flatnonzero(np.abs(num) > 1e-14)
    num = num[min(tiny[0], num.size - 1) if tiny.size else num.size - 1:]
    num = np.concatenate((np.zeros(den.size - num.size), num))
    A = np.vstack((-den[np.newaxis, 1:], np.eye(den.size - 2, den.size - 1)))
    return A, np.eye(den.size - 1, 1), (num[1:] - num[0] * den[1:])[np.newaxis, :]


def _psd_factor(matrix: np.ndarray) -> np.ndarray:
    """L with L Lᵀ = M for a symmetric positive semi-definite M (round-off negatives clipped)."""
    values, vectors = np.linalg.eigh(0.5 * (matrix + matrix.T))
    return vectors * np.sqrt(np.clip(values, 0.0, None))


def kanai_tajimi_model(omega_g: float, zeta_g: float, S0: float = 1.0) -> FilteredWhiteNoise:
    """Kanai–Tajimi filter H(s) = (2ζ_g ω_g s + ω_g²) / (s² + 2ζ_g ω_g s + ω_g²) driven by S0."""
    _check_positive(omega_g=omega_g, zeta_g=zeta_g)
    numerator = (2.0 * zeta_g * omega_g, omega_g**2)
    denominator = (1.0, 2.0 * zeta_g * omega_g, omega_g**2)
    return FilteredWhiteNoise(
        numerator, denominator, float(S0), "kanai_tajimi", {"omega_g": float(omega_g), "zeta_g": float(zeta_g)}
    )


def clough_penzien_model(
    omega_g: float, zeta_g: float, omega_f: float, zeta_f: float, S0: float = 1.0
) -> FilteredWhiteNoise:
    """Clough–Penzien filter: Kanai–Tajimi times s² / (s² + 2ζ_f ω_f s + ω_f²), driven by S0."""
    _check_positive(omega_g=omega_g, zeta_g=zeta_g, omega_f=omega_f, zeta_f=zeta_f)
    kt = kanai_tajimi_model(omega_g, zeta_g)
    numerator = tuple(np.polymul(kt.numerator, (1.0, 0.0, 0.0)))
    denominator = tuple(np.polymul(kt.denominator, (1.0, 2.0 * zeta_f * omega_f, omega_f**2)))
    parameters = {**kt.parameters, "omega_f": float(omega_f), "zeta_f": float(zeta_f)}
    return FilteredWhiteNoise(numerator, denominator, float(S0), "clough_penzien", parameters)


def _check_positive(**values: float) -> None:
    for key, value in values.items():
        if not (isinstance(value, (int, float, np.floating, np.integer)) and not isinstance(value, bool)):
            raise ValueError(f"{key}: must be a number > 0, got {value!r}")
        if not (np.isfinite(value) and value > 0.0):
            raise ValueError(f"{key}: must be > 0, got {value!r}")
