"""Ground-motion records: the bundled registry, the record suites, file readers and statistics.

>>> from stochpound.motions.records import load_record
>>> rec = load_record("el_centro_1940_study")      # a registry name or a file path
>>> rec.dt, rec.units, rec.acceleration(g=9.814)[:3]  # doctest: +SKIP

See ``docs/records.md`` for the names, the formats and the conventions.
The reference study's ``STUDY_G`` and ``study_table_3_2`` moved to
:mod:`stochpound.studies.agarwal2004`; their old names here still work and
emit a ``DeprecationWarning``.
"""

import warnings
from typing import Any

from stochpound.motions.records._readers import RawSeries, read_at2, read_record_file, read_text
from stochpound.motions.records._record import Record
from stochpound.motions.records._units import normalize_units
from stochpound.motions.records._registry import (
    RegistryEntry,
    list_records,
    load_record,
    record_metadata,
    records_dir,
    registry_entries,
)
from stochpound.motions.records._suites import SUITES, is_suite_member, list_suites, load_suite, load_suite_member, select_members, suite_members
from stochpound.motions.records._plot import plot_record, plot_spectra
from stochpound.motions.records._peer import SEARCH_RESULTS, folder_metadata
from stochpound.motions.records._statistics import RecordStatistics, arias_intensity, moments, record_statistics
from stochpound.stats import earthquake_identities

# For the other packages of stochpound (their interface to this one, not public API: not in __all__).
from stochpound.motions.records._suites import METADATA_FIELDS, SELECTIONS  # noqa: F401

__all__ = [
    "SEARCH_RESULTS",
    "SUITES",
    "RawSeries",
    "Record",
    "RecordStatistics",
    "RegistryEntry",
    "arias_intensity",
    "earthquake_identities",
    "folder_metadata",
    "is_suite_member",
    "list_records",
    "list_suites",
    "load_record",
    "load_suite",
    "load_suite_member",
    "select_members",
    "moments",
    "normalize_units",
    "plot_record",
    "plot_spectra",
    "read_at2",
    "read_record_file",
    "read_text",
    "record_metadata",
    "record_statistics",
    "records_dir",
    "registry_entries",
    "suite_members",
]

_MOVED = {"STUDY_G": "agarwal2004", "study_table_3_2": "agarwal2004"}
"""Names that moved to a study's package: the old name here still works, with a warning."""


def __getattr__(name: str) -> Any:
    """The names of :data:`_MOVED`, from their study (loaded through the study registry), with a DeprecationWarning."""
    if name not in _MOVED:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    from stochpound._studies import load_study

    study = _MOVED[name]
    warnings.warn(f"stochpound.motions.records.{name} is deprecated: use stochpound.studies.{study}.{name}",
                  DeprecationWarning, stacklevel=2)
    return getattr(load_study(study), name)
