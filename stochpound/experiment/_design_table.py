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

from stochpound.store import Design, DesignEc8, TomlTable

ASCE7_FIELDS = ("sds", "sd1", "tl", "r", "cd", "omega0", "ie")
"""The ASCE 7-16 fields of ``[design]``."""
EC8_GROUNDS = ("A", "B", "C", "D", "E")
"""Eurocode 8's ground types (Table 3.1)."""
_DEFAULTS = {"tl": 8.0, "ie": 1.0}
_LIMITS = {"sds": (0.0, 5.0), "sd1": (0.0, 5.0), "tl": (0.0, 20.0), "r": (1.0, 10.0), "cd": (1.0, 10.0), "omega0": (1.0, 5.0),
           "ie": (1.0, 1.5), "sm1": (0.0, 5.0), "ag": (0.0, 2.0), "q": (1.0, 8.0)}


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
    design = file.table("design", {*ASCE7_FIELDS, "sm1", "ec8"})
    if design is None:
        return None
    asce7 = [_number(design, name) for name in ASCE7_FIELDS]
    return Design(*asce7, sm1=_number(design, "sm1", optional=True), ec8=_ec8(design.table("ec8", {"ag", "ground", "q"})))


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
