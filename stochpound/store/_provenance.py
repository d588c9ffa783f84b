"""What a store's attributes say, read once into typed records: the store's provenance and a variable's CF attributes.

A store (and any selection of it) carries its provenance as netCDF
attributes (written by the experiment's session: its name, description,
file, identity, studied building, solver, version, commit and how many of
its cases ran), and each variable its CF ``units`` and ``long_name`` (an
interval's bounds also their ``method``). The readers above the store read
them here, as attributes of :class:`Provenance` (``ds.pound.provenance``)
and of :class:`VariableAttributes`, each field typed and with its default
when the store lacks it, rather than by name from the dataset's attributes.
"""

from __future__ import annotations

from collections.abc import Hashable, Mapping
from dataclasses import dataclass, fields

import xarray as xr

__all__ = ["Provenance", "VariableAttributes"]

_CONVERTERS: dict[str, type] = {"str": str, "int": int, "str | None": str}
"""How a field's stored value becomes its type (netCDF returns numpy scalars for numbers)."""


def _read(record: type, attrs: Mapping[Hashable, object], defaults: dict[str, str]) -> dict[str, str | int]:
    """The fields of the dataclass ``record`` found in ``attrs``, converted to their types, over ``defaults``."""
    present = {field.name: _CONVERTERS[str(field.type)](attrs[field.name]) for field in fields(record) if field.name in attrs}
    return {**defaults, **present}


@dataclass(frozen=True)
class Provenance:
    """A store's provenance attributes (empty, or the default shown, when the store lacks one).

    Attributes
    ----------
    experiment_name, experiment_description, experiment_file : str
        The experiment's name, description and file (as given to ``stochpound run``).
    experiment_sha256 : str
        The sha256 of the experiment file's text as it ran (recorded in the store with the text itself).
    definition_sha256 : str
        The identity of the store's runs.
    studied_building : str
        The building whose response the store's summaries describe.
    solver, stochpound_version : str
        The solver's method and the stochpound version that wrote the store.
    git_commit : str
        The commit of stochpound's sources (``unknown`` when not recorded).
    cases_done, cases_total : int
        How many of the experiment's cases (and references) ran, of how many.
    """

    experiment_name: str = ""
    experiment_description: str = ""
    experiment_file: str = ""
    experiment_sha256: str = ""
    definition_sha256: str = ""
    studied_building: str = ""
    solver: str = ""
    stochpound_version: str = ""
    git_commit: str = "unknown"
    cases_done: int = 0
    cases_total: int = 0

    @classmethod
    def of(cls, store: xr.Dataset) -> Provenance:
        """The provenance of ``store`` (a store or a selection of one, its attributes kept)."""
        return cls(**_read(cls, store.attrs, {}))


@dataclass(frozen=True)
class VariableAttributes:
    """A variable's CF attributes: ``units``, ``long_name`` and, for an interval's bounds, the ``method`` that made it (None when absent).

    Examples
    --------
    >>> VariableAttributes.of(xr.DataArray(1.0, attrs={"units": "m"}), long_name="gap").long_name
    'gap'
    """

    units: str | None = None
    long_name: str | None = None
    method: str | None = None

    @classmethod
    def of(cls, data: xr.DataArray, **defaults: str) -> VariableAttributes:
        """The attributes of ``data``; ``defaults`` (by field) stand for those it lacks."""
        return cls(**_read(cls, data.attrs, defaults))
