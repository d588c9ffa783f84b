"""One earthquake, one identity: record event names normalised across suites.

Record suites name the same earthquake differently. PEER's NGA database
numbers the events of a sequence that share a name with a suffix
("Northridge-01" the 1994 mainshock, "Northridge-02" to "-06" its
aftershocks; "Superstition Hills-01" and "-02", two events of 1987), while
the FEMA P695 far-field table names the mainshock alone ("Northridge",
"Imperial Valley", "Superstition Hills"). Two motions' events, each written
``"<name> <year>"`` (:mod:`stochpound.motions.records`' ``event``), are the
same earthquake by this rule:

1. the same name and year, character for character; or
2. a name without a suffix and a name with a two-digit suffix ``-NN``
   whose base (the name without ``-NN``) equals it, in the same year, with
   magnitudes that agree to their printed precision (|ΔM| <= 0.05) and the
   suffixed event the **only** one among the motions that matches so:
   the unsuffixed name then takes the suffixed one.

Two different suffixes are two earthquakes, whatever their magnitudes
("Chi-Chi, Taiwan-03" and "-04" are both M 6.2 of 1999); a name whose
magnitude is unknown, or that matches two suffixed events, is left as it
is. The identity is the name the rule arrives at, with its year.
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence

_EVENT = re.compile(r"^(?P<base>.*?)(?P<suffix>-\d{2})?\s+(?P<year>\d{4})$")
MAGNITUDE_AGREEMENT = 0.05
"""Largest difference of two magnitudes that name one earthquake: half a unit of the 0.1 to which tables print them."""


def earthquake_identities(events: Sequence[object], magnitudes: Sequence[float] | None = None) -> list[str]:
    """The earthquake of each motion, one identity per earthquake across suites (the module's rule).

    Parameters
    ----------
    events : sequence of str
        Each motion's event, ``"<name> <year>"`` ("" where unknown, kept blank).
    magnitudes : sequence of float, optional
        Each motion's moment magnitude (NaN where unknown); None: all unknown
        (only identical names are then one earthquake).

    Returns
    -------
    list of str
        One identity per motion, e.g. ``"Northridge-01 1994"`` for both
        ``"Northridge 1994"`` (M 6.7) and ``"Northridge-01 1994"`` (M 6.7).
    """
    events = [str(event).strip() for event in events]
    magnitudes = [math.nan] * len(events) if magnitudes is None else [float(m) for m in magnitudes]
    if len(magnitudes) != len(events):
        raise ValueError(f"magnitudes: must hold one per motion ({len(events)}), got {len(magnitudes)}")
    suffixed: dict[tuple[str, str], list[tuple[str, float]]] = {}
    for event, magnitude in zip(events, magnitudes, strict=True):
        parts = _EVENT.match(event)
        if parts and parts["suffix"] and math.isfinite(magnitude):
            suffixed.setdefault((parts["base"], parts["year"]), []).append((event, magnitude))
    return [_identity(event, magnitude, suffixed) for event, magnitude in zip(events, magnitudes, strict=True)]


def _identity(event: str, magnitude: float, suffixed: dict[tuple[str, str], list[tuple[str, float]]]) -> str:
    parts = _EVENT.match(event)
    if not parts or parts["suffix"] or not math.isfinite(magnitude):
        return event
    matches = {name for name, other in suffixed.get((parts["base"], parts["year"]), []) if abs(other - magnitude) <= MAGNITUDE_AGREEMENT + 1e-9}
    return matches.pop() if len(matches) == 1 else event
