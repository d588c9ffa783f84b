"""What a guard's zero crossing means: the event kinds the laws' guards signal.

Every event of the hybrid system is the upward zero crossing of a guard
(docs/model.md, "Modes and events"). A law module builds its guards' rows
(:mod:`stochpound.model.contact`, :mod:`stochpound.model.friction`) and
tags each with one of these kinds; the event engine
(:mod:`stochpound.solvers.engine`) applies the transition a kind stands for.
"""

from enum import IntEnum


class Guard(IntEnum):
    """The kinds of guard crossings."""

    CLOSE = 0
    """Open contact: its penetration δ crosses 0 upwards; the contact closes."""
    RECLOSE = 1
    """Open non-tensile contact still penetrated: its trial force crosses 0 upwards; it closes again."""
    OPEN = 2
    """Closed contact: δ (tensile) or its force (non-tensile) crosses 0 downwards; the contact opens."""
    SLIP = 3
    """Stuck base: the friction force it needs crosses the static limit μ_s W; the base slips that way."""
    STOP = 4
    """Slipping base: its sliding velocity crosses 0; the base sticks (or slips back, as settling decides)."""
