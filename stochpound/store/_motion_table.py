"""A motion's ``[motion]`` table as the definition holds it, read once into a typed record.

A definition keeps each motion's scene ``[motion]`` table as the file gave
it (with a record's ``file_sha256``): it is what the workers run and what the
identity hashes. The readers above the store (the report, the store's
layout, the accessor) ask it the same few questions (which kind, which
record file, at what scale, for how long, interpolated how): they read them
here, as the fields of a :class:`MotionTable`, each with the default the
scene file's reader gives it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from stochpound.store._definition import MotionSource
from stochpound.model.fields import TomlTable

__all__ = ["MotionTable"]

RECORD = "record"
"""The ``type`` of a ``[motion]`` table that gives none: a record."""


@dataclass(frozen=True)
class MotionTable:
    """What a ``[motion]`` table says of its motion (the generator's own parameters of an ensemble stay in its table).

    Attributes
    ----------
    type : str
        ``record`` (the default), ``harmonic``, ``constant``, a synthetic generator's name, ``site_motions``.
    record : str or None
        A record's bundled name, suite member or file (None for other motions).
    scale : float
        The factor the record is scaled by (1).
    duration : float
        The duration kept of a record, s (∞: the whole record).
    interpolation : str
        How a record is interpolated between its samples (``linear``).
    file_sha256 : str or None
        The sha256 of a record file (None: a bundled record).
    phase : float
        The phase of a harmonic motion, rad (0).
    """

    type: str = RECORD
    record: str | None = None
    scale: float = 1.0
    duration: float = math.inf
    interpolation: str = "linear"
    file_sha256: str | None = None
    phase: float = 0.0

    @classmethod
    def of(cls, table: TomlTable) -> MotionTable:
        """The typed fields of a ``[motion]`` table."""
        record = table.raw("record")
        sha256 = table.raw("file_sha256")
        return cls(table.string("type", RECORD), None if record is None else str(record), float(table.number("scale", 1.0)),
                   float(table.number("duration", math.inf, allow_inf=True)), table.string("interpolation", "linear"),
                   None if sha256 is None else str(sha256), float(table.number("phase", 0.0)))

    @classmethod
    def of_source(cls, source: MotionSource) -> MotionTable:
        """The typed fields of a motion of the definition."""
        return cls.of(TomlTable(source.motion, source.field))

    @property
    def is_record(self) -> bool:
        """Whether the table gives a record (``type = "record"``, or no type)."""
        return self.type == RECORD
