"""One line, before any answer, for a store that lacks a variable a command reads (removed by hand, or written by another stochpound)."""

from __future__ import annotations

import re
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path

import click

_MISSING = re.compile(r"No variable named '([^']+)'")
"""xarray's ``KeyError`` for a variable a dataset lacks."""


@contextmanager
def store_variables(stores: Sequence[Path]) -> Iterator[None]:
    """Turn xarray's ``KeyError`` for a missing variable into a one-line command error naming the stores that lack it and the variable.

    Any other ``KeyError`` goes on (a fault of stochpound's, not of the store).
    """
    try:
        yield
    except KeyError as error:
        match = _MISSING.search(str(error))
        if match is None:
            raise
        name = match.group(1)
        lacking = [str(path) for path in stores if not _holds(path, name)] or [str(path) for path in stores]
        raise click.ClickException(f"{', '.join(lacking)}: the store has no variable {name!r}, which this command reads "
                                   "(removed from the store, or written by another stochpound?)") from None


def _holds(store: Path, name: str) -> bool:
    """Whether the store file holds the variable ``name`` (False if it cannot be read)."""
    import h5py

    try:
        with h5py.File(store, "r") as handle:
            return name in handle
    except OSError:
        return False
