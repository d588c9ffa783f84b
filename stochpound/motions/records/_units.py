"""Units of a ground acceleration: their spellings, the units a file's header names, and the plausible peak.

Three units are known: ``"g"``, ``"m/s2"`` and ``"cm/s2"`` (= gal). A
length over a second squared is read in any of the usual spellings
(``cm/s2``, ``cm/s^2``, ``cm/s²``, ``cm/s**2``, ``cm/s/s``, ``cm/sec2``,
``cm/sec/sec``, ``cm s-2``, ``cm·s⁻²``, the same with ``m``), and
``gal``; g only where a header says so: ``UNITS OF G``, ``units are (g)``,
``units: g``, ``IN G``, ``(g)``, ``[g]``, ``FRACTION OF G``.

A header's units (:func:`header_units`) are those it states after
``UNITS OF / ARE / IS / IN`` or ``UNITS:`` (``UNITS OF G``); failing that,
those it names anywhere else (``ACCELERATION IN GAL``, ``(cm/s^2)``). A
header naming units the reader does not know (``mm/s2``, ``in/s/s``,
``UNITS OF CM/S``), or two different units at the same rank, is refused.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

from stochpound._errors import RecordError
from stochpound.motions._arias import DEFAULT_G

#: Spellings :func:`normalize_units` accepts beside those a header may use.
OTHER_SPELLINGS: dict[str, str] = {"mps2": "m/s2"}
#: The peak ground acceleration (g) beyond which a record is refused as implausible for its units.
PLAUSIBLE_PEAK_G = 5.0
#: Factor from each unit to m/s² (None for "g", whose factor is the chosen g).
TO_SI: dict[str, float | None] = {"g": None, "m/s2": 1.0, "cm/s2": 0.01}

_SECOND = r"(?:s|sec)"
_PER_SECOND_SQUARED = (
    rf"(?:\s*/\s*{_SECOND}\s*(?:\^\s*2|\*\*\s*2|2|²)"  # /s2 /s^2 /s² /s**2 /sec2
    rf"|\s*/\s*{_SECOND}\s*/\s*{_SECOND}"  # /s/s /sec/sec
    rf"|(?:\s*[.·*]\s*|\s+){_SECOND}\s*(?:\^\s*)?[-−]\s*2"  # s-2 s^-2 ·s^-2
    rf"|(?:\s*[.·*]\s*|\s*){_SECOND}\s*⁻²)"  # s⁻²
)
_LENGTHS = {"cm": "cm/s2", "centimeter": "cm/s2", "centimeters": "cm/s2", "centimetre": "cm/s2", "centimetres": "cm/s2",
            "m": "m/s2", "meter": "m/s2", "meters": "m/s2", "metre": "m/s2", "metres": "m/s2"}
#: A length over a second squared: cm or m in any spelling above; any other length (mm, in, ft: unknown) only before a slash.
_ACCELERATION = re.compile(
    rf"(?<![A-Za-z])(?P<length>(?:{'|'.join(sorted(_LENGTHS, key=len, reverse=True))})(?![A-Za-z])|[A-Za-z]+(?=\s*/))"
    rf"{_PER_SECOND_SQUARED}(?![A-Za-z0-9])",
    re.IGNORECASE,
)
_GAL = re.compile(r"(?<![A-Za-z])gals?(?![A-Za-z])", re.IGNORECASE)
_G = re.compile(r"g(?:'?s)?(?![A-Za-z0-9/'])", re.IGNORECASE)
_G_IN_CONTEXT = re.compile(rf"(?:\bin|\bfraction\s+of|\bmultiples?\s+of)(?:\s+|\s*[(\[]\s*){_G.pattern}|[(\[]\s*g\s*[)\]]", re.IGNORECASE)
_STATED = re.compile(r"\bunits?\s*(?:of\s+acceleration\s*)?(?:(?:of|are|is|in)\b\s*[:=]?|[:=])\s*[(\[]?\s*(?=\S)", re.IGNORECASE)
_TOKEN = re.compile(r"[^\s,;()\[\]]+")


def normalize_units(units: str) -> str:
    """Canonical name (``"g"``, ``"m/s2"`` or ``"cm/s2"``) of a unit spelling.

    Accepted: ``g``; ``gal``; a length in cm or m over a second squared in
    any usual spelling (``cm/s^2``, ``cm/s²``, ``cm/sec/sec``, ``m/s2``, ...).

    Raises
    ------
    ValueError
        If the spelling is none of these.
    """
    text = str(units).strip()
    found = _unit_at(text)
    if found is not None and found[0] is not None and found[1] == text:
        return found[0]
    if text.lower() in OTHER_SPELLINGS:
        return OTHER_SPELLINGS[text.lower()]
    raise ValueError(f"units must be one of g, m/s2, cm/s2 (or gal, cm/s^2, cm/s/s, m/s^2, ...); got {units!r}")


@dataclass(frozen=True)
class _Mention:
    """Units named in a header: canonical name (None: unknown), spelling, line number, and whether they are stated (``UNITS OF``)."""

    units: str | None
    spelling: str
    line: int
    stated: bool


def header_units(lines: list[tuple[int, str]], shown: str) -> str | None:
    """The units a file's header names (see the module docstring), or None if it names none.

    Parameters
    ----------
    lines : list of (int, str)
        The header's lines with their line numbers in the file.
    shown : str
        The file, as messages name it.

    Raises
    ------
    RecordError
        Units the reader does not know, or two different units of the same rank.
    """
    mentions = [mention for number, line in lines for mention in _mentions(line, number)]
    for mention in mentions:
        if mention.units is None:
            raise RecordError(
                f"{shown}, line {mention.line}: the header names units {mention.spelling!r}, not an acceleration unit this reader "
                "knows (g, m/s2, cm/s2 = gal); convert the values or state one of those"
            )
    stated = [mention for mention in mentions if mention.stated] or mentions
    found = {mention.units: mention for mention in stated}
    if len(found) > 1:
        first, second = list(found.values())[:2]
        raise RecordError(
            f"{shown}: the header names two units, {first.spelling!r} (line {first.line}) and {second.spelling!r} "
            f"(line {second.line}); state one (e.g. 'UNITS OF G')"
        )
    return next(iter(found), None)


def _mentions(line: str, number: int) -> list[_Mention]:
    """The units named in one header line: stated (after ``UNITS OF``, ...) or named elsewhere in it."""
    mentions = [_Mention(_LENGTHS.get(m.group("length").lower()), m.group(0), number, False) for m in _ACCELERATION.finditer(line)]
    mentions += [_Mention("cm/s2", m.group(0), number, False) for m in _GAL.finditer(line)]
    mentions += [_Mention("g", m.group(0), number, False) for m in _G_IN_CONTEXT.finditer(line)]
    for match in _STATED.finditer(line):
        rest = line[match.end():]
        token = _TOKEN.match(rest)
        units, spelling = _unit_at(rest) or (None, token.group(0) if token else rest.split()[0])
        mentions.append(_Mention(units, spelling, number, True))
    return mentions


def _unit_at(text: str) -> tuple[str | None, str] | None:
    """(canonical units or None if unknown, spelling) of the units ``text`` starts with, or None if it starts with none."""
    match = _ACCELERATION.match(text)
    if match:
        return _LENGTHS.get(match.group("length").lower()), match.group(0)
    match = _GAL.match(text)
    if match:
        return "cm/s2", match.group(0)
    match = _G.match(text)
    return ("g", match.group(0)) if match else None


def check_plausible_peak(values: np.ndarray, units: str, shown: str, source: str) -> None:
    """Refuse a record whose peak, in its units, exceeds :data:`PLAUSIBLE_PEAK_G`.

    Parameters
    ----------
    values : numpy.ndarray
        The samples, in ``units``.
    units : {"g", "m/s2", "cm/s2"}
        Their units.
    shown : str
        The file, as messages name it.
    source : str
        Where the units come from, for the message (e.g. ``"the header"``).

    Raises
    ------
    RecordError
        Naming the peak, the units and which other units would make it plausible.
    """
    peak = float(np.max(np.abs(values), initial=0.0))
    in_g = {name: peak * (1.0 if factor is None else factor / DEFAULT_G) for name, factor in TO_SI.items()}
    if in_g[units] <= PLAUSIBLE_PEAK_G:
        return
    others = [name for name in TO_SI if name != units and in_g[name] <= PLAUSIBLE_PEAK_G]
    hint = f"; are the values in {' or '.join(others)}? state the units in the file or give units=" if others else ""
    raise RecordError(
        f"{shown}: peak {peak:g} {units} ({in_g[units]:.3g} g; units from {source}) is more than {PLAUSIBLE_PEAK_G:g} g, "
        f"not a plausible ground acceleration{hint}"
    )
