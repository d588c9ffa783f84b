"""A count in words: the number and its noun, singular for one (``1 motion``, ``2 motions``)."""

from __future__ import annotations


def counted(count: int, noun: str) -> str:
    """``count`` and ``noun``, the noun in the plural (``noun + "s"``) unless ``count`` is 1.

    >>> counted(1, "motion"), counted(3, "record file")
    ('1 motion', '3 record files')
    """
    return f"{count} {noun}" if count == 1 else f"{count} {noun}s"
