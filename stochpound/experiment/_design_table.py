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
  Type 1 spectrum) and the behaviour factor q (≥ 1).

No run depends on it, so it is not part of the experiment's identity
(``stochpound.store.NOT_IN_IDENTITY``), like ``[hazard]``.
"""

from __future__ import annotations

from typing import Any, Mapping

from stochpound._errors import SceneError
from stochpound.model import fields as toml_fields
from stochpound.store import Design, DesignEc8

ASCE7_FIELDS = ("sds", "sd1", "tl", "r", "cd", "omega0", "ie")
"""The ASCE 7-16 fields of ``[design]``."""
EC8_GROUNDS = ("A", "B", "C", "D", "E")
"""Eurocode 8's ground types (Table 3.1)."""
_DEFAULTS = {"tl": 8.0, "ie": 1.0}
_LIMITS = {"sds": (0.0, 5.0), "sd1": (0.0, 5.0), "tl": (0.0, 20.0), "r": (1.0, 10.0), "cd": (1.0, 10.0), "omega0": (1.0, 5.0),
           "ie": (1.0, 1.5), "sm1": (0.0, 5.0), "ag": (0.0, 2.0), "q": (1.0, 8.0)}


def parse_design(data: Mapping[str, Any]) -> Design | None:
    """The ``[design]`` table of a definition, typed (None without a ``[design]`` table).

    Parameters
    ----------
    data : mapping
        The parsed experiment file.

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
    design = toml_fields.table(data, "design", "")
    if design is None:
        return None
    toml_fields.reject_unknown(design, {*ASCE7_FIELDS, "sm1", "ec8"}, "design")
    asce7 = [_number(design, name, "design", required=name not in _DEFAULTS) for name in ASCE7_FIELDS]
    sm1 = _number(design, "sm1", "design", required=True) if "sm1" in design else None
    return Design(*asce7, sm1=sm1, ec8=_ec8(design))


def _ec8(design: Mapping[str, Any]) -> DesignEc8 | None:
    """The ``ec8`` part of ``[design]`` (None when absent)."""
    ec8 = toml_fields.table(design, "ec8", "design")
    if ec8 is not None:
        toml_fields.reject_unknown(ec8, {"ag", "ground", "q"}, "design.ec8")
        ground = toml_fields.string(ec8, "ground", "design.ec8")
        if ground not in EC8_GROUNDS:
            raise SceneError(f"design.ec8.ground: must be one of {', '.join(EC8_GROUNDS)}, got {ground!r}")
        return DesignEc8(_number(ec8, "ag", "design.ec8", required=True), ground, _number(ec8, "q", "design.ec8", required=True))
    return None


def _number(table: Mapping[str, Any], name: str, prefix: str, required: bool) -> float:
    low, high = _LIMITS[name]
    value = toml_fields.number(table, name, prefix, default=_DEFAULTS.get(name), required=required, low=low,
                               low_open=low == 0.0, high=high)
    return float(value)
