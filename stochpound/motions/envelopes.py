"""Intensity envelopes e(t) that modulate a stationary process: a(t) = e(t) x(t).

Named shapes (all normalised to a peak of 1, t in s):

``jennings`` / ``amin_ang`` — quadratic rise, plateau, exponential decay
    e = (t/t1)² for t < t1; 1 for t1 ≤ t ≤ t2; exp(−c (t − t2)) for t > t2.
    This is the envelope of Jennings, Housner & Tsai (1968) and of Amin & Ang
    (1968); the literature uses the same three-phase form under both names, so
    the two names give the same class. Defaults for a motion of duration D:
    t1 = 0.1 D, t2 = 0.5 D, c = ln(20)/(D − t2) (e(D) = 0.05).
``trapezoidal`` — linear rise to 1 at t1, plateau to t2, linear fall to 0 at t3.
    Defaults: t1 = 0.1 D, t2 = 0.6 D, t3 = D.
``saragoni_hart`` — e = a t^b exp(−c t) (Saragoni & Hart 1974), a chosen so that
    the peak (at t = b/c) is 1. Give ``b`` and ``c`` (1/s), or the shape of Boore
    (2003): ``eps`` (peak time as a fraction of tw), ``eta`` (e(tw)) and ``tw``
    (s). Defaults: eps = 0.2, eta = 0.05, tw = D.

An envelope is specified as ``None`` (stationary), a name (defaults above), a
mapping ``{"type": name, **parameters}`` (missing parameters take the
defaults; the form a TOML ``[motion.envelope]`` table gives), an
:class:`Envelope`, or any callable f(t) -> array (used as is, not normalised).
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass
from typing import Any, Callable, Mapping

import numpy as np


class Envelope:
    """Base class: a deterministic modulating function of time."""

    name: str = "envelope"

    def __call__(self, t: np.ndarray) -> np.ndarray:
        raise NotImplementedError

    def parameters(self) -> dict[str, float | str]:
        """Parameters, for attributes and reports."""
        return asdict(self) if hasattr(self, "__dataclass_fields__") else {}

    def describe(self) -> str:
        """JSON text ``{"type": name, **parameters}`` (netCDF-safe)."""
        return json.dumps({"type": self.name, **self.parameters()})


@dataclass(frozen=True)
class Jennings(Envelope):
    """Quadratic rise to t1, plateau to t2, exponential decay at rate c (1/s) after."""

    t1: float
    t2: float
    c: float
    name = "jennings"

    def __post_init__(self) -> None:
        _require(self.t1 > 0 and self.t2 >= self.t1 and self.c > 0, f"{self.name}: need 0 < t1 <= t2 and c > 0, got {self}")

    @classmethod
    def default(cls, duration: float, t1: float | None = None, t2: float | None = None, c: float | None = None) -> "Jennings":
        """t1 = 0.1 D, t2 = 0.5 D, c = ln(20)/(D − t2) for a motion of duration D (s), where not given (s, 1/s)."""
        t2 = 0.5 * duration if t2 is None else t2
        return cls(0.1 * duration if t1 is None else t1, t2, math.log(20.0) / max(duration - t2, 1e-12) if c is None else c)

    def __call__(self, t: np.ndarray) -> np.ndarray:
        t = np.asarray(t, dtype=float)
        rise = np.clip(t / self.t1, 0.0, 1.0) ** 2
        decay = np.exp(-self.c * np.clip(t - self.t2, 0.0, None))
        return np.where(t < 0.0, 0.0, rise * decay)


@dataclass(frozen=True)
class AminAng(Jennings):
    """Amin & Ang (1968): the same three-phase form as :class:`Jennings`."""

    name = "amin_ang"


@dataclass(frozen=True)
class Trapezoidal(Envelope):
    """Linear rise to 1 at t1, 1 until t2, linear fall to 0 at t3, 0 after (s)."""

    t1: float
    t2: float
    t3: float
    name = "trapezoidal"

    def __post_init__(self) -> None:
        _require(0 < self.t1 <= self.t2 < self.t3, f"trapezoidal: need 0 < t1 <= t2 < t3, got {self}")

    @classmethod
    def default(cls, duration: float, t1: float | None = None, t2: float | None = None, t3: float | None = None) -> "Trapezoidal":
        """t1 = 0.1 D, t2 = 0.6 D, t3 = D for a motion of duration D (s), where not given (s)."""
        return cls(0.1 * duration if t1 is None else t1, 0.6 * duration if t2 is None else t2, duration if t3 is None else t3)

    def __call__(self, t: np.ndarray) -> np.ndarray:
        return np.interp(np.asarray(t, dtype=float), [0.0, self.t1, self.t2, self.t3], [0.0, 1.0, 1.0, 0.0], left=0.0, right=0.0)


@dataclass(frozen=True)
class SaragoniHart(Envelope):
    """e(t) = a t^b exp(−c t), normalised to a peak of 1 at t = b/c (b > 0, c > 0 in 1/s)."""

    b: float
    c: float
    name = "saragoni_hart"

    def __post_init__(self) -> None:
        _require(self.b > 0 and self.c > 0, f"saragoni_hart: need b > 0 and c > 0, got {self}")

    @classmethod
    def from_shape(cls, tw: float, eps: float = 0.2, eta: float = 0.05) -> "SaragoniHart":
        """Boore (2003): peak at eps·tw, e(tw) = eta."""
        _require(tw > 0 and 0 < eps < 1 and 0 < eta < 1, f"saragoni_hart: need tw > 0, 0 < eps < 1, 0 < eta < 1; got tw={tw}, eps={eps}, eta={eta}")
        b = -eps * math.log(eta) / (1.0 + eps * (math.log(eps) - 1.0))
        return cls(b=b, c=b / (eps * tw))

    @classmethod
    def default(cls, duration: float, b: float | None = None, c: float | None = None, tw: float | None = None, eps: float | None = None,
                eta: float | None = None) -> "SaragoniHart":
        """``b`` and ``c`` if given (both, and no shape), else Boore's shape with eps = 0.2, eta = 0.05 and tw = D (s), where not given."""
        if b is not None or c is not None:
            _require(b is not None and c is not None and (tw, eps, eta) == (None, None, None),
                     f"saragoni_hart: give b and c (1/s), or the shape tw, eps, eta; got b={b}, c={c}, tw={tw}, eps={eps}, eta={eta}")
            return cls(b, c)
        return cls.from_shape(duration if tw is None else tw, 0.2 if eps is None else eps, 0.05 if eta is None else eta)

    @property
    def peak_time(self) -> float:
        """Time of the peak, b/c, s."""
        return self.b / self.c

    def __call__(self, t: np.ndarray) -> np.ndarray:
        s = np.clip(np.asarray(t, dtype=float), 0.0, None) / self.peak_time
        with np.errstate(divide="ignore"):
            log_e = self.b * (np.log(s) + 1.0 - s)
        return np.where(s > 0.0, np.exp(log_e), 0.0)


@dataclass(frozen=True)
class CallableEnvelope(Envelope):
    """A user function f(t) -> array, used as is."""

    function: Callable[[np.ndarray], np.ndarray]
    name = "callable"

    def __call__(self, t: np.ndarray) -> np.ndarray:
        values = np.asarray(self.function(np.asarray(t, dtype=float)), dtype=float)
        _require(values.shape == np.shape(t) and bool(np.all(np.isfinite(values))), "envelope: the callable must return finite values shaped like t")
        return values

    def parameters(self) -> dict[str, float | str]:
        """The function's name."""
        return {"function": getattr(self.function, "__name__", repr(self.function))}


ENVELOPES: dict[str, type[Envelope]] = {
    "jennings": Jennings,
    "amin_ang": AminAng,
    "trapezoidal": Trapezoidal,
    "saragoni_hart": SaragoniHart,
}


def make_envelope(spec: Any, duration: float) -> Envelope | None:
    """Build an envelope from a specification (see the module docstring).

    Parameters
    ----------
    spec : None, str, Mapping, Envelope or callable
        The specification.
    duration : float
        Duration of the motion, s (for the defaults).

    Raises
    ------
    ValueError
        Unknown name, unknown or invalid parameters.
    """
    if spec is None or (isinstance(spec, str) and spec.lower() in ("none", "stationary", "")):
        return None
    if isinstance(spec, Envelope):
        return spec
    if isinstance(spec, str):
        return _named(spec, duration, {})
    if isinstance(spec, Mapping):
        params = dict(spec)
        kind = params.pop("type", None)
        if kind is None:
            raise ValueError(f"envelope: a table needs type = one of {', '.join(ENVELOPES)}; got {dict(spec)!r}")
        return _named(str(kind), duration, params)
    if callable(spec):
        return CallableEnvelope(spec)
    raise ValueError(f"envelope: must be a name ({', '.join(ENVELOPES)}), a table with 'type', or a callable; got {spec!r}")


def _named(kind: str, duration: float, params: Mapping[str, float]) -> Envelope:
    cls = ENVELOPES.get(kind.lower())
    if cls is None:
        raise ValueError(f"envelope.type: must be one of {', '.join(ENVELOPES)}; got {kind!r}")
    allowed = {"saragoni_hart": {"b", "c", "eps", "eta", "tw"}}.get(cls.name, set(cls.__dataclass_fields__))
    unknown = set(params) - allowed
    if unknown:
        raise ValueError(f"envelope: unknown parameter(s) {sorted(unknown)} for {cls.name}; allowed: {sorted(allowed)}")
    for key, value in params.items():
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ValueError(f"envelope.{key}: must be a number, got {value!r}")
    return cls.default(duration, **{key: float(value) for key, value in params.items()})


def _require(condition: bool, message: str) -> None:
    if not condition:
        raise ValueError(message)
