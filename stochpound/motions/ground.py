"""Ground acceleration as the solvers see it: a_g(t) and its derivatives, interval by interval.

Two kinds of motion exist:

* :class:`SampledMotion`: samples a_k at times t_k = k·dt, interpolated between
  samples by a polynomial per interval: linear (first-order hold, the default,
  as structural-dynamics codes do) or a natural cubic spline (the reference
  study's choice).
* :class:`HarmonicMotion`: a_g(t) = A sin(Ω t + φ), evaluated exactly (not sampled).

Both expose the output times (``times``) and, for a time ``t`` inside output
interval ``k`` (``times[k] <= t <= times[k+1]``), the value and the first three
time derivatives of a_g from the right-hand side of ``times[k]``. Solvers restart
at every output time, so the forcing is smooth inside every integration span.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


class GroundMotion:
    """Interface of a ground motion (m/s²) as used by the solvers."""

    times: np.ndarray
    description: str

    def derivatives(self, t: float, k: int) -> np.ndarray:
        """[a_g, ȧ_g, ä_g, a⃛_g] at time ``t`` in interval ``k`` (m/s², m/s³, ...)."""
        raise NotImplementedError

    def acceleration(self, t: np.ndarray | float, k: int) -> np.ndarray | float:
        """a_g at time(s) ``t`` inside interval ``k``, m/s²."""
        raise NotImplementedError

    def polynomial(self, k: int) -> np.ndarray | None:
        """Coefficients c0..c3 of a_g = Σ c_j τ^j, τ = t − times[k], or None if not polynomial."""
        return None

    def at_times(self) -> np.ndarray:
        """a_g at every output time, m/s²."""
        raise NotImplementedError


@dataclass
class SampledMotion(GroundMotion):
    """A sampled accelerogram with polynomial interpolation between samples.

    Parameters
    ----------
    dt : float
        Sample spacing, s.
    values : np.ndarray
        Ground acceleration samples, m/s², the first at t = 0.
    interpolation : {"linear", "spline"}
        First-order hold, or a natural cubic spline through the samples.
    description : str
        Human-readable origin (record name, scaling).
    """

    dt: float
    values: np.ndarray
    interpolation: str = "linear"
    description: str = ""
    times: np.ndarray = field(init=False, repr=False)
    coefficients: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        self.values = np.asarray(self.values, dtype=float)
        self.times = np.arange(len(self.values)) * self.dt
        self.coefficients = _interval_polynomials(self.times, self.values, self.interpolation)

    def polynomial(self, k: int) -> np.ndarray:
        return self.coefficients[k]

    def at_times(self) -> np.ndarray:
        return self.values

    def derivatives(self, t: float, k: int) -> np.ndarray:
        c0, c1, c2, c3 = self.coefficients[k]
        tau = t - self.times[k]
        return np.array(
            [
                c0 + tau * (c1 + tau * (c2 + tau * c3)),
                c1 + tau * (2.0 * c2 + 3.0 * tau * c3),
                2.0 * c2 + 6.0 * tau * c3,
                6.0 * c3,
            ]
        )

    def acceleration(self, t, k):
        c0, c1, c2, c3 = self.coefficients[k]
        tau = np.asarray(t) - self.times[k]
        return c0 + tau * (c1 + tau * (c2 + tau * c3))


def _interval_polynomials(times: np.ndarray, values: np.ndarray, interpolation: str) -> np.ndarray:
    """Per-interval cubic coefficients (n-1, 4) in powers of τ = t − t_k."""
    n_intervals = max(len(values) - 1, 0)
    coefficients = np.zeros((n_intervals, 4))
    if n_intervals == 0:
        return coefficients
    if interpolation == "linear":
        coefficients[:, 0] = values[:-1]
        coefficients[:, 1] = np.diff(values) / np.diff(times)
    elif interpolation == "spline":
        from scipy.interpolate import CubicSpline  # a second of CPU to import: only where a spline is asked for

        spline = CubicSpline(times, values, bc_type="natural")
        coefficients[:] = spline.c[::-1].T  # scipy stores the highest power first
    else:
        raise ValueError(f"interpolation must be 'linear' or 'spline', got {interpolation!r}")
    return coefficients


@dataclass
class HarmonicMotion(GroundMotion):
    """Harmonic ground acceleration a_g = A sin(Ω t + φ), integrated exactly.

    Parameters
    ----------
    amplitude : float
        A, m/s².
    omega : float
        Ω, rad/s.
    duration : float
        Length, s.
    dt : float
        Spacing of the output times, s.
    phase : float
        φ, rad.
    """

    amplitude: float
    omega: float
    duration: float
    dt: float
    phase: float = 0.0
    description: str = ""
    times: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        n_steps = int(round(self.duration / self.dt))
        self.times = np.arange(n_steps + 1) * self.dt
        if not self.description:
            self.description = f"harmonic: {self.amplitude:g} sin({self.omega:g} t + {self.phase:g}) m/s²"

    def derivatives(self, t: float, k: int) -> np.ndarray:
        angle = self.omega * t + self.phase
        a, w = self.amplitude, self.omega
        return np.array([a * np.sin(angle), a * w * np.cos(angle), -a * w**2 * np.sin(angle), -a * w**3 * np.cos(angle)])

    def acceleration(self, t, k):
        return self.amplitude * np.sin(self.omega * np.asarray(t) + self.phase)

    def at_times(self) -> np.ndarray:
        return self.acceleration(self.times, 0)
