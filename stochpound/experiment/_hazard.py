"""The ``[hazard]`` table of an experiment file: the site's hazard curve, carried in the store.

One of three sources (docs/risk.md):

* ``file = "site.csv"``: rows of intensity and annual rate of exceedance
  (:meth:`~stochpound.analysis.HazardCurve.from_file`), the path relative to
  the experiment file;
* ``bundled = "fox_plaza_los_angeles_sa2p0s"``: a curve shipped with
  stochpound (:meth:`~stochpound.analysis.HazardCurve.bundled`);
* ``power_law = { k0 = 2.0e-4, k = 2.2 }``: λ(x) = k0 x^(−k).

**The measure rule.** A hazard curve is only meaningful with the
fragility's intensity measure, so the hazard's measure must be the
``[intensity]`` table's: the same ``measure``, the same ``period`` (PSA)
or ``periods`` (Sa_avg), the same ``damping``, and intensities in the units
of ``levels``. A bundled curve knows its measure (from its name, in g) and
is checked against ``[intensity]``; a file or power law may state
``measure`` (and ``period``/``periods``, ``damping``), which are then
checked, and is otherwise taken to be in ``[intensity]``'s measure and
units. A mismatch is an error naming the field.

The canonical entry holds the table itself (``im``, ``rate``), its
provenance (the file's comment lines) and the file's sha256, so a store
carries everything needed to redo the risk chain without the file. No run
depends on it, so it is not part of the experiment's identity
(``stochpound.store.NOT_IN_IDENTITY``): a run after the hazard changed keeps
the store's cases and records the new entry.
"""

from __future__ import annotations

import hashlib
import math
from pathlib import Path
from typing import Any, Mapping

import xarray as xr

from stochpound.analysis._hazard import HazardCurve, bundled_curves, bundled_measure
from stochpound.store import describe_measure
from stochpound.experiment._intensity import IntensityError
from stochpound.model import fields as toml_fields

SOURCES = ("file", "bundled", "power_law")
"""The keys that name a hazard's source (exactly one per ``[hazard]`` table)."""
_KEYS = {*SOURCES, "measure", "period", "periods", "damping", "extrapolate"}
_MATCHED = ("measure", "period", "periods", "damping")
_TOLERANCE = 1e-9


def parse_hazard(data: Mapping[str, Any], intensity: Mapping[str, Any] | None, base_dir: Path) -> dict[str, Any] | None:
    """The canonical ``hazard`` entry of a definition (None without a ``[hazard]`` table).

    Parameters
    ----------
    data : mapping
        The parsed experiment file.
    intensity : mapping or None
        The canonical ``intensity`` entry (a hazard needs one).
    base_dir : Path
        The experiment file's folder (a ``file`` is relative to it).

    Returns
    -------
    dict or None
        ``source`` (one of :data:`SOURCES`), the source's key as given,
        the measure (as ``[intensity]``'s), ``units``, ``extrapolate``,
        ``im`` and ``rate`` (a table; a power law: ``power_law``),
        ``provenance`` and, for a file, ``file_sha256``.

    Raises
    ------
    IntensityError
        Naming the field: no ``[intensity]``, not exactly one source, an
        unreadable or invalid table, a measure other than ``[intensity]``'s.
    """
    table = toml_fields.table(data, "hazard", "")
    if table is None:
        return None
    toml_fields.reject_unknown(table, _KEYS, "hazard")
    if intensity is None:
        raise IntensityError("hazard: needs an [intensity] table (the hazard is a curve of its measure, in the units of its levels)")
    given = [key for key in SOURCES if key in table]
    if len(given) != 1:
        raise IntensityError(f"hazard: give exactly one of {', '.join(SOURCES)}, got {', '.join(given) or 'none'}")
    source = given[0]
    extrapolate = toml_fields.boolean(table, "extrapolate", "hazard", default=False)
    entry: dict[str, Any] = {"source": source, **_measure_of(intensity), "units": intensity["units"], "extrapolate": extrapolate}
    if source == "bundled":
        name = toml_fields.string(table, "bundled", "hazard")
        if name not in bundled_curves():
            raise IntensityError(f"hazard.bundled: no bundled hazard curve {name!r} (bundled: {', '.join(bundled_curves())})")
        _check_measure("hazard.bundled", {**bundled_measure(name)}, intensity, bundled=name)
        curve = HazardCurve.bundled(name)
        entry["bundled"] = name
    else:
        _check_measure("hazard", {key: table[key] for key in _MATCHED if key in table}, intensity)
        if source == "file":
            entry["file"], entry["file_sha256"], curve = _file(table, base_dir)
        else:
            entry["power_law"] = _power_law(table["power_law"])
            curve = HazardCurve.power_law(**entry["power_law"])
    if curve.power is None:
        entry["im"], entry["rate"] = [float(x) for x in curve.im], [float(y) for y in curve.rate]
    entry["provenance"] = curve.source
    return entry


def hazard_curve(entry: Mapping[str, Any]) -> HazardCurve:
    """The :class:`~stochpound.analysis.HazardCurve` of a canonical ``hazard`` entry (from its stored values, not its file)."""
    description = {"measure": describe_measure(entry), "units": entry["units"], "source": entry["provenance"]}
    if "power_law" in entry:
        return HazardCurve.power_law(**entry["power_law"], **description)
    return HazardCurve(entry["im"], entry["rate"], extrapolate=entry["extrapolate"], **description)


def _measure_of(intensity: Mapping[str, Any]) -> dict[str, Any]:
    """The keys of ``[intensity]`` that define its measure."""
    return {key: intensity[key] for key in _MATCHED if key in intensity}


def _check_measure(where: str, stated: Mapping[str, Any], intensity: Mapping[str, Any], bundled: str = "") -> None:
    """Raise unless every stated key of the hazard's measure equals ``[intensity]``'s (``units`` too, for a bundled curve)."""
    wanted = {**_measure_of(intensity), "units": intensity["units"]}
    for key, value in stated.items():
        if key not in wanted:
            raise IntensityError(f"{where if bundled else f'hazard.{key}'}: the hazard's measure must be [intensity]'s, "
                                 f"{describe_measure(intensity)} in {intensity['units']}; "
                                 f"{f'{bundled!r} has' if bundled else 'got'} {key} = {value!r}")
        if not _equal(value, wanted[key]):
            what = (f"{bundled!r} is {describe_measure(stated)} in {stated['units']}" if bundled
                    else f"got {value!r}")
            field = where if bundled else f"hazard.{key}"
            raise IntensityError(f"{field}: the hazard's measure must be [intensity]'s, {describe_measure(intensity)} in "
                                 f"{intensity['units']} (intensity.{key} = {wanted[key]!r}); {what}")


def _equal(a: Any, b: Any) -> bool:
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(_equal(x, y) for x, y in zip(a, b))
    if toml_fields.is_number(a) and toml_fields.is_number(b):
        return math.isclose(float(a), float(b), rel_tol=_TOLERANCE, abs_tol=0.0)
    return a == b


def _file(table: Mapping[str, Any], base_dir: Path) -> tuple[str, str, HazardCurve]:
    """The file's path as given, its sha256 and its curve."""
    name = toml_fields.string(table, "file", "hazard")
    path = base_dir / name
    if not path.is_file():
        raise IntensityError(f"hazard.file: {name!r} not found (a CSV of rows 'im, rate', relative to the experiment file)")
    try:
        curve = HazardCurve.from_file(path)
    except ValueError as error:
        raise IntensityError(f"hazard.file: {name!r}: {error}") from None
    return name, hashlib.sha256(path.read_bytes()).hexdigest(), curve


def _power_law(table: Any) -> dict[str, float]:
    if not isinstance(table, dict):
        raise IntensityError(f"hazard.power_law: must be a table {{ k0 = ..., k = ... }} (rate = k0 x^-k, 1/yr), got {table!r}")
    toml_fields.reject_unknown(table, {"k0", "k"}, "hazard.power_law")
    return {key: toml_fields.number(table, key, "hazard.power_law", required=True, low=0.0, low_open=True) for key in ("k0", "k")}


def stored_hazard(store: xr.Dataset) -> HazardCurve | None:
    """The hazard an experiment store carries (``store.pound.hazard``, typed), as a curve; None without one."""
    entry = store.pound.hazard
    return None if entry is None else hazard_curve(entry)


def hazard_option(value: str, intensity: Mapping[str, Any], option: str = "--hazard") -> HazardCurve:
    """A hazard named on the command line: a bundled curve's name (its measure checked against ``intensity``) or a CSV file.

    A file is taken to be in ``intensity``'s measure and the units of its
    levels (it cannot say otherwise); a bundled curve must match them.

    Raises
    ------
    IntensityError
        Neither a bundled name nor a file, an invalid file, or a bundled curve of another measure.
    """
    if value in bundled_curves():
        _check_measure(option, bundled_measure(value), intensity, bundled=value)
        return HazardCurve.bundled(value)
    path = Path(value)
    if not path.is_file():
        raise IntensityError(f"{option}: {value!r} is neither a file nor a bundled hazard curve (bundled: {', '.join(bundled_curves())})")
    try:
        curve = HazardCurve.from_file(path, measure=describe_measure(intensity), units=intensity["units"])
    except ValueError as error:
        raise IntensityError(f"{option}: {error}") from None
    return curve
