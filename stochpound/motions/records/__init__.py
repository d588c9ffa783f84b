"""Ground-motion records: the bundled registry, the record suites, file readers and statistics.

>>> from stochpound.motions.records import load_record
>>> rec = load_record("el_centro_1940_study")      # a registry name or a file path
>>> rec.dt, rec.units, rec.acceleration(g=9.814)[:3]  # doctest: +SKIP

See ``docs/records.md`` for the names, the formats and the conventions.
"""

from stochpound.motions.records._readers import RawSeries, read_at2, read_record_file, read_text
from stochpound.motions.records._record import Record, normalize_units
from stochpound.motions.records._registry import (
    RegistryEntry,
    list_records,
    load_record,
    records_dir,
    registry_entries,
    study_table_3_2,
)
from stochpound.motions.records._suites import SUITES, is_suite_member, list_suites, load_suite, load_suite_member, select_members, suite_members
from stochpound.motions.records._statistics import (
    STUDY_G,
    RecordStatistics,
    arias_intensity,
    moments,
    record_statistics,
)

__all__ = [
    "STUDY_G",
    "SUITES",
    "RawSeries",
    "Record",
    "RecordStatistics",
    "RegistryEntry",
    "arias_intensity",
    "list_records",
    "list_suites",
    "load_record",
    "load_suite",
    "load_suite_member",
    "select_members",
    "is_suite_member",
    "moments",
    "normalize_units",
    "read_at2",
    "read_record_file",
    "read_text",
    "record_statistics",
    "records_dir",
    "registry_entries",
    "study_table_3_2",
    "suite_members",
]
