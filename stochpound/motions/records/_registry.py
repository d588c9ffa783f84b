"""The registry of bundled records (``data/records/registry.toml``) and :func:`load_record`.

Bundled files are looked up first inside the installed package
(``stochpound/_data/records``, where the wheel puts them), then in the
repository's ``data/records`` next to the package (editable installs).
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any, Mapping

from stochpound._data_files import bundled_data_dir
from stochpound._errors import RecordError
from stochpound.motions.records._readers import read_record_file, record_from_file
from stochpound.motions.records._record import Record
from stochpound.motions.records._units import normalize_units
from stochpound.motions.records._suites import is_suite_member, load_suite_member

REGISTRY_FILE = "registry.toml"
_VARIANT_KEYS = {"base", "first", "scale", "divide_by"}


@dataclass(frozen=True)
class RegistryEntry:
    """One named record of the registry.

    Attributes
    ----------
    name : str
        Registry name.
    fields : Mapping[str, Any]
        The entry's table in ``registry.toml``.
    """

    name: str
    fields: Mapping[str, Any]

    @property
    def is_variant(self) -> bool:
        """True for a transformation of another entry (``base = ...``)."""
        return "base" in self.fields

    @property
    def description(self) -> str:
        """One-line description."""
        return str(self.fields.get("description", ""))

    @property
    def substitute_for(self) -> str | None:
        """What the record stands in for, if it is a labelled substitute."""
        value = self.fields.get("substitute_for")
        return None if value is None else str(value)

    @property
    def study_row(self) -> str | None:
        """Key of the study's Table 3.2 row this record relates to, if any."""
        value = self.fields.get("study_row")
        return None if value is None else str(value)


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
def _registry() -> dict[str, Any]:
    with open(records_dir() / REGISTRY_FILE, "rb") as handle:
        return tomllib.load(handle)


def registry_entries() -> dict[str, RegistryEntry]:
    """All registry entries by name, in file order."""
    return {name: RegistryEntry(name, fields) for name, fields in _registry().get("records", {}).items()}


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
    return record_from_file(path, dt=dt, units=units, column=column, fmt=fmt)


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
    fields = entry.fields
    if entry.is_variant:
        return _load_variant(entries, entry, _depth)
    folder = records_dir()
    filename = str(fields["file"])
    path = folder / filename
    shown = f"data/records/{filename}"
    if not path.is_file():
        raise RecordError(f"{name}: bundled file {shown} is missing")
    series = read_record_file(
        path, dt=fields.get("dt"), units=fields.get("units"), column=fields.get("column"), fmt=fields.get("format")
    )
    expected = fields.get("sha256")
    if expected and series.sha256 != expected:
        raise RecordError(f"{name}: bundled file {shown} has sha256 {series.sha256}, the registry says {expected}")
    start = float(fields.get("source_start_time", series.source_start_time))
    provenance = f"{fields.get('source', '')}; file {filename}, sha256 {series.sha256}"
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
        metadata=dict(fields),
    )


def _load_variant(entries: dict[str, RegistryEntry], entry: RegistryEntry, depth: int) -> Record:
    fields = entry.fields
    unknown = set(fields) - _VARIANT_KEYS - {"description", "substitute_for", "study_row", "study_relation"}
    base_name = str(fields["base"])
    if unknown or base_name not in entries or depth > 8:
        raise RecordError(f"{entry.name}: malformed registry variant (base {base_name!r}, fields {sorted(unknown)})")
    base = _load_entry(entries, base_name, depth + 1)
    values = base.values
    steps = []
    if "first" in fields:
        first = int(fields["first"])
        values = values[:first]
        steps.append(f"first {first} samples")
    if "scale" in fields:
        values = values * float(fields["scale"])
        steps.append("sign reversed" if float(fields["scale"]) == -1.0 else f"multiplied by {fields['scale']}")
    if "divide_by" in fields:
        values = values / float(fields["divide_by"])
        steps.append(f"divided by {fields['divide_by']}")
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
        metadata={**base.metadata, **dict(fields)},
    )
