"""An intensity measure as one value: parsed, named and described here, and nowhere else.

A :class:`Measure` is the kind (``pga``, ``pgv``, ``psa``, ``sa_avg``) with
what a spectral kind needs: the period of ``psa`` or the periods of
``sa_avg`` (s) and the damping ratio. It is frozen and hashable, so it can key
a table; :meth:`Measure.from_entry` reads it from a canonical entry (an
experiment's ``[intensity]`` or ``[hazard]``, a bundled curve's measure) and
:meth:`Measure.entry` writes the same keys back, so stored definitions and
their sha256 are unchanged. Its two names are :attr:`Measure.label`, short
(``PSA(1 s)``, for tables and store attributes), and
:attr:`Measure.description`, in words with the damping (``PSA(T = 1 s, 5 %
damping)``, for reports and errors), which :meth:`Measure.axis_label` gives
with the units of its values for a figure's axis. OpenQuake's ``hazardlib.imt`` does the
same for its intensity measure types.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

KINDS = ("pga", "pgv", "psa", "sa_avg")
"""The kinds of intensity measure a measure may be: peak ground acceleration, peak ground velocity, pseudo-spectral
acceleration at one period, and the geometric mean of PSA over several periods."""

SPECTRAL_KINDS = ("psa", "sa_avg")
"""The kinds that need a damping ratio and a period (``psa``) or periods (``sa_avg``)."""

_ENTRY_KEYS = ("measure", "period", "periods", "damping")


@dataclass(frozen=True)
class Measure:
    """An intensity measure: its kind and, for a spectral kind, its period(s) and damping.

    Attributes
    ----------
    kind : str
        ``pga``, ``pgv``, ``psa`` or ``sa_avg`` (:data:`~stochpound.motions.MEASURE_KINDS`).
    period : float or None
        The period of ``psa``, s (None for other kinds).
    periods : tuple of float
        The periods of ``sa_avg``, s, ascending (empty for other kinds).
    damping : float or None
        The damping ratio of a spectral kind (fraction of critical; None for PGA and PGV, and for a
        spectral measure whose damping is not stated, e.g. one read from a file's ``SA(1.0)``).

    Raises
    ------
    ValueError
        On construction, naming the field: an unknown kind, a missing or non-positive period, a damping
        outside (0, 1), or a period given to a kind that takes none.
    """

    kind: str
    period: float | None = None
    periods: tuple[float, ...] = ()
    damping: float | None = None

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"measure: must be one of {', '.join(KINDS)}, got {self.kind!r}")
        if self.kind == "psa":
            _check_period("period", self.period)
        elif self.period is not None:
            raise ValueError(f"period: only psa takes a period, got {self.period!r} for {self.kind}")
        if self.kind == "sa_avg":
            if len(self.periods) < 2:
                raise ValueError(f"periods: sa_avg needs at least 2 periods, got {list(self.periods)!r}")
            for index, value in enumerate(self.periods):
                _check_period(f"periods[{index}]", value)
        elif self.periods:
            raise ValueError(f"periods: only sa_avg takes periods, got {list(self.periods)!r} for {self.kind}")
        if self.damping is not None and self.kind not in SPECTRAL_KINDS:
            raise ValueError(f"damping: only a spectral measure (psa, sa_avg) takes a damping, got {self.damping!r} for {self.kind}")
        if self.damping is not None and not (_is_number(self.damping) and 0.0 < self.damping < 1.0):
            raise ValueError(f"damping: must be a ratio in (0, 1), got {self.damping!r}")

    @classmethod
    def from_entry(cls, entry: Mapping[str, Any]) -> Measure:
        """The measure of a canonical entry's ``measure``, ``period``, ``periods`` and ``damping`` keys (other keys are ignored).

        Raises
        ------
        ValueError
            As the constructor, naming the entry's key.
        """
        if "measure" not in entry:
            raise ValueError("measure: missing (one of " + ", ".join(KINDS) + ")")
        period = entry.get("period")
        periods = entry.get("periods")
        damping = entry.get("damping")
        return cls(str(entry["measure"]), None if period is None else float(period),
                   tuple(float(p) for p in periods) if periods is not None else (),
                   None if damping is None else float(damping))

    @classmethod
    def of(cls, kind: str, period: float | Sequence[float] | None = None, damping: float | None = None) -> Measure:
        """A measure from the loose form many functions take: ``period`` a number for ``psa``, a sequence for ``sa_avg``."""
        if kind == "sa_avg":
            return cls(kind, None, tuple(float(p) for p in (period if period is not None else ())), damping)
        return cls(kind, None if period is None else float(period), (), damping)  # type: ignore[arg-type]

    def entry(self) -> dict[str, str | float | list[float]]:
        """The canonical keys (``measure`` and those of ``period``, ``periods``, ``damping`` that are set), as definitions store them."""
        written: dict[str, str | float | list[float]] = {"measure": self.kind}
        if self.period is not None:
            written["period"] = self.period
        if self.periods:
            written["periods"] = list(self.periods)
        if self.damping is not None:
            written["damping"] = self.damping
        return written

    @property
    def is_spectral(self) -> bool:
        """Whether the measure is a spectral acceleration (``psa`` or ``sa_avg``)."""
        return self.kind in SPECTRAL_KINDS

    @property
    def is_velocity(self) -> bool:
        """Whether the measure is a velocity (``pgv``, m/s); every other kind is an acceleration."""
        return self.kind == "pgv"

    @property
    def spectral_period(self) -> float | tuple[float, ...] | None:
        """The period argument of the loose form (:meth:`of`): the period of ``psa``, the periods of ``sa_avg``, else None."""
        return self.period if self.kind == "psa" else (self.periods if self.kind == "sa_avg" else None)

    @property
    def label(self) -> str:
        """The short name: ``PGA``, ``PGV``, ``PSA(1 s)``, ``Sa_avg(0.5-4 s)`` (its first and last periods; :meth:`named`)."""
        return self.named()

    def named(self, precision: str = "g", note: str = "") -> str:
        """The short name, its periods formatted by ``precision`` (a format spec, e.g. ``".3g"``) and, for a spectral
        measure, followed by a ``note`` (which of several it is): ``PSA(0.305 s, B1 first mode)``, ``Sa_avg(0.06-3 s)``, ``PGA``."""
        after = f", {note}" if note else ""
        if self.kind == "psa":
            return f"PSA({self.period:{precision}} s{after})"
        if self.kind == "sa_avg":
            return f"Sa_avg({self.periods[0]:{precision}}-{self.periods[-1]:{precision}} s{after})"
        return self.kind.upper()

    @property
    def description(self) -> str:
        """The measure in words with its damping: ``PSA(T = 1 s, 5 % damping)``, ``Sa_avg(0.5-4 s, 8 periods, 5 % damping)``,
        ``PGA``; a spectral measure without a stated damping is described without one."""
        damping = "" if self.damping is None else f", {100 * self.damping:g} % damping"
        if self.kind == "psa":
            return f"PSA(T = {self.period:g} s{damping})"
        if self.kind == "sa_avg":
            return f"Sa_avg({self.periods[0]:g}-{self.periods[-1]:g} s, {len(self.periods)} periods{damping})"
        return self.kind.upper()

    def axis_label(self, units: str) -> str:
        """The measure in words (:attr:`description`) with the ``units`` of its values, for a figure's axis:
        ``PSA(T = 1 s, 5 % damping) (g)``."""
        return f"{self.description} ({units})"

    def __str__(self) -> str:
        return self.label

    def matches(self, other: Measure, rel_tol: float = 1e-9) -> bool:
        """Whether ``other`` is the same measure: the same kind and periods, and the same damping where both state one."""
        if self.kind != other.kind:
            return False
        if not _close(self.period, other.period, rel_tol) or len(self.periods) != len(other.periods):
            return False
        if not all(math.isclose(a, b, rel_tol=rel_tol) for a, b in zip(self.periods, other.periods)):
            return False
        return self.damping is None or other.damping is None or math.isclose(self.damping, other.damping, rel_tol=rel_tol)


def _is_number(value: object) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def _check_period(field: str, value: object) -> None:
    if not (_is_number(value) and value > 0.0):  # type: ignore[operator]
        raise ValueError(f"{field}: must be a period > 0 (s), got {value!r}")


def _close(a: float | None, b: float | None, rel_tol: float) -> bool:
    if a is None or b is None:
        return a is b
    return math.isclose(a, b, rel_tol=rel_tol)
