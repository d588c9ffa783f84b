"""The ``isolation`` part of a ``[design]`` table: ASCE 7-16 chapter 17's inputs for a building on a sliding base.

Every field is optional; a missing one takes chapter 17's default where the
risk chain designs the building (:func:`stochpound.codes.chapter17_design`),
and the answer states it as assumed. The MCE_R spectral values are the
site's geometric-mean SA(0.2 s) and SA(1 s): read from the site's own hazard
where it has them (``spectrum_source`` says from where), else as given.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import asdict, dataclass

IsolationValue = float | str | list[float]
"""A value of the canonical ``isolation`` entry: a number, the spectrum's source, or the plan."""


@dataclass(frozen=True)
class DesignIsolation:
    """Chapter 17's inputs for the studied building on a sliding base (``[design.isolation]``).

    Attributes
    ----------
    plan : tuple of float or None
        (b, d), shortest and longest plan dimensions (m) for eq. 17.5-3; None: a square plan assumed.
    eccentricity : float or None
        e (m), actual plus accidental (>= 0.05 d); None: accidental only, 0.05 d.
    distance : float or None
        y (m), centre of rigidity to the element of interest; None: d/2.
    lambda_max, lambda_min : float or None
        Property-modification factors on μ (§17.2.8.4); None: ASCE 7's wide defaults.
    breakaway : float or None
        Nominal breakaway friction coefficient (§17.5.4.3 item 3c); None: μ.
    wind_shear : float or None
        Factored design wind base shear (N), §17.5.4.3 item 2; None: not checked.
    sa_short, sa_long : float or None
        Geometric-mean MCE_R SA(0.2 s) and SA(1 s) of the site (g).
    s1 : float or None
        The mapped S_1 (g) of eq. 12.8-6 in §17.5.4.3 item 1; None: S_M1 stands for it.
    spectrum_source : str or None
        Where ``sa_short``/``sa_long`` come from (the site's hazard curves at 2 %/50 yr), None: given in the table.
    """

    plan: tuple[float, float] | None = None
    eccentricity: float | None = None
    distance: float | None = None
    lambda_max: float | None = None
    lambda_min: float | None = None
    breakaway: float | None = None
    wind_shear: float | None = None
    sa_short: float | None = None
    sa_long: float | None = None
    s1: float | None = None
    spectrum_source: str | None = None

    @classmethod
    def from_entry(cls, entry: Mapping[str, IsolationValue]) -> DesignIsolation:
        """The typed record of a canonical ``isolation`` entry."""
        values = {name: entry[name] for name in cls.__dataclass_fields__ if name in entry}
        if "plan" in values:
            values["plan"] = tuple(values["plan"])
        return cls(**values)

    def entry(self) -> dict[str, IsolationValue]:
        """The canonical ``isolation`` entry: its given fields only."""
        return {name: list(value) if name == "plan" else value for name, value in asdict(self).items() if value is not None}
