"""The ``[design]`` table of an experiment file: the code design its buildings were given, for the codes' own separations.

The risk chain applies the codes' separation rules as the codes apply them,
to the displacements of the design analysis (docs/risk.md, "The codes'
own gaps"); this table states that design:

* ASCE 7-16 (required when the table is given): ``sds``, ``sd1`` (g), the
  design spectrum's S_DS and S_D1 (§11.4.5); ``tl`` (s), the long-period
  transition T_L (§11.4.6, default 8 s); ``r``, ``cd``, ``omega0``, the
  system's R, C_d and Ω0 (Table 12.2-1); ``ie``, the importance factor I_e
  (Table 1.5-2, default 1);
* ``sm1`` (g, optional): the MCE_R spectral acceleration at 1 s, S_M1, of
  ASCE 7-16 eq. 17.5-1 for a building on a friction pendulum (its μ and
  radius are read from the scene of each case);
* ``ec8 = { ag, ground, q }`` (optional): Eurocode 8's design ground
  acceleration a_g on type A ground (g), the ground type (``A``–``E``,
  Type 1 spectrum) and the behaviour factor q (≥ 1);
* ``[design.isolation]`` (optional; ASCE 7-16 chapter 17 for a studied
  building on a sliding base, docs/separation.md): ``plan = [b, d]`` (m),
  ``eccentricity`` e and ``distance`` y (m) of eq. 17.5-3, ``lambda_max``,
  ``lambda_min`` (property-modification factors on μ), ``breakaway``
  (friction coefficient), ``wind_shear`` (N), ``sa_short``, ``sa_long``
  (g, the site's geometric-mean MCE_R SA(0.2 s) and SA(1 s)), ``s1`` (g,
  the mapped S_1 of §17.5.4.3 item 1; default S_M1). Without
  ``sa_short``/``sa_long``, a ``[hazard]`` naming a bundled curve whose
  site has SA(0.2 s) and SA(1 s) gives them at 2 %/50 yr (the source is
  recorded); the other fields take chapter 17's defaults, stated as assumed.

No run depends on it, so it is not part of the experiment's identity
(``stochpound.store.NOT_IN_IDENTITY``), like ``[hazard]``.
"""

from __future__ import annotations

from stochpound.store import Design, DesignEc8, DesignIsolation, TomlTable

ASCE7_FIELDS = ("sds", "sd1", "tl", "r", "cd", "omega0", "ie")
"""The ASCE 7-16 fields of ``[design]``."""
EC8_GROUNDS = ("A", "B", "C", "D", "E")
"""Eurocode 8's ground types (Table 3.1)."""
_DEFAULTS = {"tl": 8.0, "ie": 1.0}
_LIMITS = {"sds": (0.0, 5.0), "sd1": (0.0, 5.0), "tl": (0.0, 20.0), "r": (1.0, 10.0), "cd": (1.0, 10.0), "omega0": (1.0, 5.0),
           "ie": (1.0, 1.5), "sm1": (0.0, 5.0), "ag": (0.0, 2.0), "q": (1.0, 8.0), "eccentricity": (0.0, 1000.0),
           "distance": (0.0, 1000.0), "lambda_max": (1.0, 5.0), "lambda_min": (0.0, 1.0), "breakaway": (0.0, 0.3), "wind_shear": (0.0, 1e12),
           "sa_short": (0.0, 10.0), "sa_long": (0.0, 10.0), "s1": (0.0, 5.0)}
ISOLATION_FIELDS = ("plan", "eccentricity", "distance", "lambda_max", "lambda_min", "breakaway", "wind_shear", "sa_short", "sa_long", "s1")
"""The fields of ``[design.isolation]``."""


def parse_design(file: TomlTable) -> Design | None:
    """The ``[design]`` table of a definition, typed (None without a ``[design]`` table).

    Parameters
    ----------
    file : TomlTable
        The parsed experiment file (its top level).

    Returns
    -------
    Design or None
        ``sds``, ``sd1`` (g), ``tl`` (s), ``r``, ``cd``, ``omega0``, ``ie``;
        ``sm1`` (g) and ``ec8`` (``ag`` in g, ``ground``, ``q``) when given.

    Raises
    ------
    SceneError
        A field missing, unknown or out of its range, named with the range.
    """
    design = file.table("design", {*ASCE7_FIELDS, "sm1", "ec8", "isolation"})
    if design is None:
        return None
    asce7 = [_number(design, name) for name in ASCE7_FIELDS]
    return Design(*asce7, sm1=_number(design, "sm1", optional=True), ec8=_ec8(design.table("ec8", {"ag", "ground", "q"})),
                  isolation=_isolation(design.table("isolation", ISOLATION_FIELDS), file))


def _isolation(isolation: TomlTable | None, file: TomlTable) -> DesignIsolation | None:
    """The ``isolation`` part of ``[design]`` (None when absent), its spectrum from the bundled site's curves where not given."""
    if isolation is None:
        return None
    plan = isolation.numbers("plan", None, low=0.0, low_open=True)
    if plan is not None and (len(plan) != 2 or plan[0] > plan[1]):
        raise isolation.error("plan", f"must be [b, d], the shortest and longest plan dimensions (m), 0 < b <= d, got {list(plan)!r}")
    for name in ("eccentricity", "distance"):
        if plan is None and name in isolation:
            raise isolation.error(name, "needs plan = [b, d] (m) beside it")
    values = {name: _number(isolation, name, optional=True) for name in ISOLATION_FIELDS if name != "plan"}
    source = None
    if values["sa_short"] is None and values["sa_long"] is None:
        found = _site_spectrum(file)
        if found is not None:
            values["sa_short"], values["sa_long"], source = found
    elif values["sa_short"] is None or values["sa_long"] is None:
        raise isolation.error("sa_long" if values["sa_long"] is None else "sa_short", "give sa_short and sa_long together (g), or neither")
    return DesignIsolation(plan=plan, spectrum_source=source, **values)


def _site_spectrum(file: TomlTable) -> tuple[float, float, str] | None:
    """SA(0.2 s), SA(1 s) at 2 %/50 yr of the bundled site ``[hazard]`` names, and their source (None without one, or lacking either)."""
    hazard = file.raw("hazard")
    bundled = TomlTable(hazard, "hazard").string("bundled", None) if isinstance(hazard, dict) else None
    if bundled is None:
        return None
    from stochpound.risk import site_mce

    return site_mce(bundled)


def _ec8(ec8: TomlTable | None) -> DesignEc8 | None:
    """The ``ec8`` part of ``[design]`` (None when absent)."""
    if ec8 is None:
        return None
    ground = ec8.string("ground", choices=EC8_GROUNDS)
    return DesignEc8(_number(ec8, "ag"), ground, _number(ec8, "q"))


def _number(table: TomlTable, name: str, optional: bool = False) -> float | None:
    """A design number within its range (:data:`_LIMITS`, open at 0): its default (:data:`_DEFAULTS`) or None when absent and
    ``optional``, else required."""
    low, high = _LIMITS[name]
    limits = {"low": low, "low_open": low == 0.0, "high": high}
    if name in _DEFAULTS or optional:
        return table.number(name, _DEFAULTS.get(name), **limits)
    return table.number(name, **limits)
