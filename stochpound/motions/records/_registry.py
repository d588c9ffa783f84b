"""The registry of bundled records (``data/records/registry.toml``) and :func:`load_record`.

Bundled files are looked up first inside the installed package
(``stochpound/_data/records``, where the wheel puts them), then in the
repository's ``data/records`` next to the package (editable installs).
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, fields
from functools import lru_cache
from pathlib import Path
from typing import Mapping

from stochpound._data_files import bundled_data_dir
from stochpound._errors import RecordError
from stochpound.motions.records._peer import file_metadata
from stochpound.motions.records._readers import read_record_file, record_from_file
from stochpound.motions.records._record import Record
from stochpound.motions.records._units import normalize_units
from stochpound.motions.records._suites import is_suite_member, load_suite_member

REGISTRY_FILE = "registry.toml"
_FILE_FIELDS = ("source", "file", "format", "units", "dt", "column", "sha256", "source_start_time")
"""The fields of a file entry, which a variant (its base's file) does not take."""


@dataclass(frozen=True)
class RegistryEntry:
    """One named record of the registry: a ``[records.<name>]`` table of ``registry.toml``, read once.

    A *file entry* names a bundled file (``file``, with its ``format``,
    ``units``, ``dt``...); a *variant* transforms another entry (``base``,
    with ``first``, ``scale``, ``divide_by``).

    Attributes
    ----------
    name : str
        Registry name.
    description : str
        One-line description.
    source : str
        Where the file comes from (empty for a variant: its base's).
    file, format, units : str or None
        A file entry's file (in the records folder), format (``at2``, ``text``) and units.
    dt : float or None
        The file's sample step, s, where the registry states it.
    column : int or None
        The acceleration column of a text file with several.
    sha256 : str or None
        The file's checksum, checked at every load.
    source_start_time : float or None
        Time of the file's first sample in its source, s, where it is not 0.
    substitute_for : str or None
        What the record stands in for, if it is a labelled substitute.
    study_row : str or None
        Key of the study's Table 3.2 row this record relates to, if any.
    study_relation : str
        How the record relates to the study's own record (empty: unrelated).
    base : str or None
        A variant's base entry (None: a file entry).
    first : int or None
        A variant keeps its base's first samples.
    scale, divide_by : float or None
        A variant multiplies (divides) its base's samples.
    """

    name: str
    description: str = ""
    source: str = ""
    file: str | None = None
    format: str | None = None
    units: str | None = None
    dt: float | None = None
    column: int | None = None
    sha256: str | None = None
    source_start_time: float | None = None
    substitute_for: str | None = None
    study_row: str | None = None
    study_relation: str = ""
    base: str | None = None
    first: int | None = None
    scale: float | None = None
    divide_by: float | None = None

    @classmethod
    def from_table(cls, name: str, table: Mapping[str, object]) -> RegistryEntry:
        """The entry ``name`` from its ``registry.toml`` table; an unknown field raises :class:`~stochpound._errors.RecordError`."""
        unknown = sorted(set(table) - _FIELDS)
        if unknown:
            raise RecordError(f"{name}: malformed registry entry (unknown fields {unknown})")
        return cls(name, **table)

    @property
    def is_variant(self) -> bool:
        """True for a transformation of another entry (``base = ...``)."""
        return self.base is not None

    def to_dict(self) -> dict[str, float | str]:
        """The entry's table as ``registry.toml`` gives it (the fields it sets; a loaded record's metadata)."""
        return {item.name: getattr(self, item.name) for item in fields(self)[1:] if getattr(self, item.name) != item.default}


_FIELDS = {item.name for item in fields(RegistryEntry)[1:]}
"""The fields a ``[records.<name>]`` table may set."""


def records_dir() -> Path:
    """Folder holding the bundled record files and ``registry.toml``.

    Raises
    ------
    RecordError
        If neither the packaged copy nor the repository copy exists.
    """
    return _records_dir()


def _records_dir() -> Path:
    folder = bundled_data_dir("records", REGISTRY_FILE)
    if folder is None:
        raise RecordError(
            "the bundled records are missing: neither stochpound/_data/records (installed package) "
            "nor data/records (source tree) holds registry.toml"
        )
    return folder


@lru_cache(maxsize=1)
def _registry() -> tuple[RegistryEntry, ...]:
    """The ``[records.<name>]`` tables of ``registry.toml``, read once, in file order."""
    with open(records_dir() / REGISTRY_FILE, "rb") as handle:
        return tuple(RegistryEntry.from_table(name, table) for name, table in tomllib.load(handle)["records"].items())


def registry_entries() -> dict[str, RegistryEntry]:
    """All registry entries by name, in file order."""
    return {entry.name: entry for entry in _registry()}


def list_records() -> list[str]:
    """Names of the bundled records and their named variants, in registry order."""
    return list(registry_entries())


def load_record(
    source: str | Path,
    dt: float | None = None,
    units: str | None = None,
    *,
    column: int | None = None,
    fmt: str | None = None,
) -> Record:
    """Load a bundled record by name, or a record file by path.

    Parameters
    ----------
    source : str or Path
        A registry name (see :func:`list_records`; named variants included), a
        suite's motion (``fema_p695_far_field/01a``, see
        :func:`~stochpound.motions.records.load_suite`) or the path of a PEER
        ``.AT2`` or text file.
    dt : float, optional
        Sample step, s. Required for one-column text files; for other files and
        bundled records it must agree with the file.
    units : {"g", "m/s2", "cm/s2"}, optional
        Units of the file's values. For text files without a ``units:``
        comment the default is g; it must agree with units the file or the
        registry states.
    column : int, optional
        Acceleration column (0-based; 0 is time) of a text file with more than two columns.
    fmt : {"at2", "text"}, optional
        Force the file format (default: from the extension and content).

    Returns
    -------
    Record
        Samples from t = 0 (a file whose first sample is at a later time is
        shifted; see :class:`Record`).

    Raises
    ------
    RecordError
        Unknown name and no such file (the message lists the known names),
        unreadable or malformed file (file and line named), inconsistent
        ``dt``/``units``, or a bundled file whose sha256 does not match the registry.
    """
    entries = registry_entries()
    key = str(source)
    if key in entries or is_suite_member(key):
        record = _load_entry(entries, key) if key in entries else load_suite_member(key)
        _check_override(record, dt, units)
        return record
    path = Path(source)
    if not path.exists():
        known = ", ".join(entries)
        raise RecordError(f"{key}: no bundled record of that name and no such file; bundled records: {known}")
    record = record_from_file(path, dt=dt, units=units, column=column, fmt=fmt)
    record.metadata = file_metadata(path)
    return record


def record_metadata(source: str | Path, base_dir: str | Path = ".") -> dict[str, float | str]:
    """The metadata :func:`load_record` gives ``source``, without reading its samples.

    A registry entry's fields, a suite motion's metadata (event, magnitude,
    distance, Vs30, mechanism...), a file's row of the PEER ``_SearchResults.csv``
    beside it; {} for a file without one.

    Parameters
    ----------
    source : str or Path
        As :func:`load_record` takes it.
    base_dir : str or Path
        The folder a relative file path is relative to.
    """
    entries = registry_entries()
    key = str(source)
    if key in entries:
        return dict(entries[key].to_dict())
    if is_suite_member(key):
        return dict(load_suite_member(key).metadata)
    return file_metadata(Path(base_dir) / source)


def _check_override(record: Record, dt: float | None, units: str | None) -> None:
    if dt is not None and not math.isclose(float(dt), record.dt, rel_tol=1e-6):
        raise RecordError(f"{record.name}: dt={dt:g} s was given but the bundled record has dt={record.dt:g} s")
    if units is not None:
        try:
            canonical = normalize_units(units)
        except ValueError as error:
            raise RecordError(f"{record.name}: {error}") from None
        if canonical != record.units:
            raise RecordError(f"{record.name}: units={units!r} was given but the bundled record is in {record.units}")


def _load_entry(entries: dict[str, RegistryEntry], name: str, _depth: int = 0) -> Record:
    entry = entries[name]
    if entry.is_variant:
        return _load_variant(entries, entry, _depth)
    path = records_dir() / str(entry.file)
    shown = f"data/records/{entry.file}"
    if not path.is_file():
        raise RecordError(f"{name}: bundled file {shown} is missing")
    series = read_record_file(path, dt=entry.dt, units=entry.units, column=entry.column, fmt=entry.format)
    if entry.sha256 and series.sha256 != entry.sha256:
        raise RecordError(f"{name}: bundled file {shown} has sha256 {series.sha256}, the registry says {entry.sha256}")
    start = float(entry.source_start_time if entry.source_start_time is not None else series.source_start_time)
    provenance = f"{entry.source}; file {entry.file}, sha256 {series.sha256}"
    if entry.substitute_for:
        provenance = f"SUBSTITUTE for {entry.substitute_for}; {provenance}"
    return Record(
        name=name,
        dt=series.dt,
        values=series.values,
        units=series.units,
        description=entry.description,
        provenance=provenance,
        source_start_time=start,
        metadata=entry.to_dict(),
    )


def _load_variant(entries: dict[str, RegistryEntry], entry: RegistryEntry, depth: int) -> Record:
    base_name = str(entry.base)
    stray = sorted(key for key in _FILE_FIELDS if key in entry.to_dict())
    if stray or base_name not in entries or depth > 8:
        raise RecordError(f"{entry.name}: malformed registry variant (base {base_name!r}, fields {stray})")
    base = _load_entry(entries, base_name, depth + 1)
    values = base.values
    steps = []
    if entry.first is not None:
        values = values[: entry.first]
        steps.append(f"first {entry.first} samples")
    if entry.scale is not None:
        values = values * float(entry.scale)
        steps.append("sign reversed" if float(entry.scale) == -1.0 else f"multiplied by {entry.scale}")
    if entry.divide_by is not None:
        values = values / float(entry.divide_by)
        steps.append(f"divided by {entry.divide_by}")
    transform = ", ".join(steps) if steps else "unchanged"
    provenance = f"variant of {base_name} ({transform}); {base.provenance}"
    if entry.substitute_for:
        provenance = f"SUBSTITUTE for {entry.substitute_for}; {provenance}"
    return Record(
        name=entry.name,
        dt=base.dt,
        values=values.copy(),
        units=base.units,
        description=entry.description,
        provenance=provenance,
        source_start_time=base.source_start_time,
        metadata={**base.metadata, **entry.to_dict()},
    )
