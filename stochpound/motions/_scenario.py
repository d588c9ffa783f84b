"""An earthquake scenario at a site as one value, checked here and nowhere else.

A :class:`Scenario` is a moment magnitude, a rupture distance R_rup (km), the
site's Vs30 (m/s) and a faulting mechanism, with the optional geometry of
the rupture and the site (:data:`GEOMETRY_FIELDS`; a field left as None
keeps the conditional spectrum's estimate, stochpound.motions._conditional).
It is frozen and hashable; made, its values are finite numbers (floats
whatever number type they were given as, so two scenarios of the same
earthquake are equal) and its mechanism a known one. Whether a model can
be used for it is the model's range: :meth:`Scenario.check` checks it
against the four NGA-West2 models' (:func:`scenario_limits`,
:func:`geometry_limits`, the default) or another (the site-motion model's
calibration), and every public function that takes a scenario checks it
so, once, at its door (:func:`given_scenario`). pygmm's ``Scenario`` plays
this part for its ground-motion models, which check their own limits.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, fields
from functools import lru_cache
from typing import Any

import numpy as np

from stochpound._errors import SiteError

#: Mechanisms of a scenario: pygmm's code and the dip (°) assumed.
MECHANISMS: dict[str, tuple[str, float]] = {"strike_slip": ("SS", 90.0), "reverse": ("RS", 40.0), "normal": ("NS", 50.0)}
#: A scenario's geometry beyond its magnitude, rupture distance, Vs30 and mechanism, by the toolkit's name (km and degrees),
#: with pygmm's name: the Joyner–Boore distance, the site's distance from the top edge's strike line (R_x, ≥ 0 on the
#: hanging wall), the depth to the top of rupture, the dip, the site's depths to 1.0 and 2.5 km/s.
GEOMETRY_FIELDS = {"distance_jb_km": "dist_jb", "distance_x_km": "dist_x", "ztor_km": "depth_tor", "dip": "dip",
                   "z1p0_km": "depth_1_0", "z2p5_km": "depth_2_5"}
_SCENARIO_FIELDS = {"magnitude": "mag", "distance_km": "dist_rup", "vs30": "v_s30"}
_POSITIVE = ("vs30",)
MODELS_RANGE = "the NGA-West2 models' range"
"""Whose range a scenario is checked against by default (in the messages)."""


def ground_motion_models() -> tuple[type, ...]:
    """The four NGA-West2 models of pygmm the toolkit averages: ASK14, BSSA14, CB14, CY14."""
    import pygmm

    return (pygmm.AbrahamsonSilvaKamai2014, pygmm.BooreStewartSeyhanAtkinson2014, pygmm.CampbellBozorgnia2014, pygmm.ChiouYoungs2014)


@lru_cache(maxsize=None)
def _common_limits(fields: tuple[tuple[str, str], ...]) -> dict[str, tuple[float, float]]:
    """The range (from 0 up) of each field (toolkit's name, pygmm's) every one of the four models is meant for: the intersection of their limits."""
    limits = {}
    for field, name in fields:
        low, high = 0.0, np.inf
        for model in ground_motion_models():
            for parameter in model.PARAMS:
                if parameter.name == name:
                    low = max(low, parameter.min if parameter.min is not None else low)
                    high = min(high, parameter.max if parameter.max is not None else high)
        limits[field] = (low, high)
    return limits


def scenario_limits() -> dict[str, tuple[float, float]]:
    """The range of magnitude, distance_km and vs30 every one of the four models is meant for (the intersection of their limits)."""
    return dict(_common_limits(tuple(_SCENARIO_FIELDS.items())))


def geometry_limits(distance_km: float) -> dict[str, tuple[float, float]]:
    """The range of every :data:`GEOMETRY_FIELDS` entry for a scenario at rupture distance ``distance_km``.

    The four models' common limits (Z_tor 0–20 km, dip 15–90°, Z2.5 0–10 km,
    R_JB ≤ 300 km), and what a geometry must be: 0 ≤ R_JB ≤ R_rup,
    |R_x| ≤ 300 km, Z1.0 ≥ 0.
    """
    given = {"distance_jb_km": (0.0, min(300.0, float(distance_km))), "distance_x_km": (-300.0, 300.0), "z1p0_km": (0.0, np.inf)}
    return _common_limits(tuple((field, name) for field, name in GEOMETRY_FIELDS.items() if field not in given)) | given


def is_finite_number(value: object) -> bool:
    """Whether ``value`` is a finite int or float (numpy's too), not a bool."""
    return isinstance(value, (int, float, np.floating, np.integer)) and not isinstance(value, bool) and bool(np.isfinite(value))


def _check(values: Mapping[str, float | str], geometry: Mapping[str, float], names: Mapping[str, str],
           limits: Mapping[str, tuple[float, float]] | None, source: str) -> None:
    """Raise :class:`SiteError` naming (``names``) the first field of a scenario outside its range or of an unknown mechanism."""
    for field, (low, high) in (limits or scenario_limits()).items():
        value = values[field]
        if not is_finite_number(value) or not low <= value <= high:
            raise SiteError(f"{names.get(field, field)}: must be within {low:g}-{high:g} ({source}), got {value!r}")
    if values["mechanism"] not in MECHANISMS:
        raise SiteError(f"{names.get('mechanism', 'mechanism')}: must be one of {', '.join(MECHANISMS)}, got {values['mechanism']!r}")
    unknown = set(geometry) - set(GEOMETRY_FIELDS)
    if unknown:
        raise SiteError(f"geometry: unknown field(s) {', '.join(sorted(unknown))}; known: {', '.join(GEOMETRY_FIELDS)}")
    for field, (low, high) in geometry_limits(values["distance_km"]).items():
        value = geometry.get(field)
        if value is not None and (not is_finite_number(value) or not low <= value <= high):
            what = "at most the rupture distance, " if field == "distance_jb_km" else ""
            raise SiteError(f"{names.get(field, field)}: must be within {low:g}-{high:g} ({what}{MODELS_RANGE}), got {value!r}")


@dataclass(frozen=True)
class Scenario:
    """An earthquake scenario at a site: what the ground-motion models are evaluated for (module docstring).

    Attributes
    ----------
    magnitude : float
        Moment magnitude.
    distance_km : float
        Rupture distance R_rup, km.
    vs30 : float
        The site's time-averaged shear-wave velocity of the top 30 m, m/s.
    mechanism : str
        ``"strike_slip"``, ``"reverse"`` or ``"normal"``.
    distance_jb_km, distance_x_km, ztor_km, dip, z1p0_km, z2p5_km : float or None
        The geometry (:data:`GEOMETRY_FIELDS`: km, the dip in degrees; R_x ≥ 0 on the hanging wall); None keeps the estimate.

    Raises
    ------
    stochpound.SiteError
        On construction, naming the field: a value not a finite number (a Vs30 not > 0), an unknown mechanism.

    Examples
    --------
    >>> Scenario(7.0, 10.0, 760.0, "strike_slip") == Scenario(7, 10, 760, "strike_slip")
    True
    """

    magnitude: float
    distance_km: float
    vs30: float
    mechanism: str
    distance_jb_km: float | None = None
    distance_x_km: float | None = None
    ztor_km: float | None = None
    dip: float | None = None
    z1p0_km: float | None = None
    z2p5_km: float | None = None

    def __post_init__(self) -> None:
        for item in fields(self):
            value = getattr(self, item.name)
            if item.name == "mechanism" or (value is None and item.name in GEOMETRY_FIELDS):
                continue
            if not is_finite_number(value) or (item.name in _POSITIVE and value <= 0):
                raise SiteError(f"{item.name}: must be a finite number{' > 0' if item.name in _POSITIVE else ''}, got {value!r}")
            object.__setattr__(self, item.name, float(value))
        if self.mechanism not in MECHANISMS:
            raise SiteError(f"mechanism: must be one of {', '.join(MECHANISMS)}, got {self.mechanism!r}")

    @classmethod
    def of(cls, magnitude: float, distance_km: float, vs30: float, mechanism: str, geometry: Mapping[str, float | None] | None = None, *,
           names: Mapping[str, str] | None = None, limits: Mapping[str, tuple[float, float]] | None = None,
           source: str = MODELS_RANGE) -> Scenario:
        """The scenario of loose fields and a ``geometry`` mapping (:data:`GEOMETRY_FIELDS`, None values left to the estimates).

        ``names`` spells a field in the messages (e.g. ``site.magnitude``); ``limits`` (default: the four NGA-West2
        models' common range) are the ranges of magnitude, distance_km and vs30, ``source`` says whose.

        Raises
        ------
        stochpound.SiteError
            As :meth:`check`, and for a geometry field not in :data:`GEOMETRY_FIELDS`.
        """
        loose = {"magnitude": magnitude, "distance_km": distance_km, "vs30": vs30, "mechanism": mechanism}
        _check(loose, geometry or {}, names or {}, limits, source)
        return cls(**loose, **(geometry or {}))

    def check(self, *, names: Mapping[str, str] | None = None, limits: Mapping[str, tuple[float, float]] | None = None,
              source: str = MODELS_RANGE) -> Scenario:
        """The scenario itself, once checked against ``limits`` (default: the four NGA-West2 models' common range; ``source`` says whose).

        Raises
        ------
        stochpound.SiteError
            Naming the field (as ``names`` spells it): a magnitude, distance or Vs30 outside ``limits``, an
            unknown mechanism, a geometry outside the models' common range (0 ≤ R_JB ≤ R_rup, R_x within ±300 km, Z_tor 0–20 km,
            dip 15–90°, Z2.5 0–10 km, Z1.0 ≥ 0).
        """
        _check(self.loose(), self.geometry, names or {}, limits, source)
        return self

    def loose(self) -> dict[str, float | str]:
        """``magnitude``, ``distance_km``, ``vs30`` and ``mechanism``, the keywords of the public functions that take a scenario."""
        return {"magnitude": self.magnitude, "distance_km": self.distance_km, "vs30": self.vs30, "mechanism": self.mechanism}

    @property
    def geometry(self) -> dict[str, float]:
        """The geometry given (:data:`GEOMETRY_FIELDS` order), without the fields left to the estimates."""
        return {field: value for field in GEOMETRY_FIELDS if (value := getattr(self, field)) is not None}

    def attrs(self) -> dict[str, float | str]:
        """The scenario as a dataset's attributes: :meth:`loose` and the geometry given."""
        return {**self.loose(), **self.geometry}


def given_scenario(scenario: Scenario | None, magnitude: Any, distance_km: Any, vs30: Any, mechanism: Any,
                   geometry: Mapping[str, float | None] | None = None, **check: Any) -> Scenario:
    """The scenario a public function was given: its ``scenario=``, or one of its loose keywords, checked once (``check``:
    the ``limits`` and ``source`` of :meth:`Scenario.check`).

    Raises
    ------
    stochpound.SiteError
        Both or neither given, a ``scenario`` that is not a :class:`Scenario`, or as :meth:`Scenario.of`.
    """
    loose = (magnitude, distance_km, vs30, mechanism)
    if scenario is None:
        if any(value is None for value in loose):
            missing = [name for name, value in zip(("magnitude", "distance_km", "vs30", "mechanism"), loose) if value is None]
            raise SiteError(f"{missing[0]}: missing (give magnitude, distance_km, vs30 and mechanism, or scenario=)")
        return Scenario.of(*loose, geometry, **check)
    if not isinstance(scenario, Scenario):
        raise SiteError(f"scenario: must be a stochpound.motions.Scenario, got {scenario!r}")
    if any(value is not None for value in loose) or geometry:
        raise SiteError("scenario: give either scenario= or magnitude, distance_km, vs30, mechanism (and geometry), not both")
    return scenario.check(**check)
