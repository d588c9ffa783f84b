"""The metadata of a folder of PEER NGA-West2 downloads: the search's ``_SearchResults.csv``.

A download from the PEER NGA-West2 database (ngawest2.berkeley.edu) is a
folder of ``.AT2`` files, three per recording (two horizontal components,
H1 and H2, and the vertical), and the search's report ``_SearchResults.csv``:

* a title line, then `` -- Summary of PEER Ground Motion Database Search Criteria --``
  and the criteria, one ``key:, value`` line each;
* `` -- Summary of Metadata of Selected Records --``, a header line
  (``Result ID, Spectral Ordinate, Record Sequence Number, Mean Squared Error,
  Scale Factor, Tp-Pulse Period (sec), 5-75% Duration (sec), 5-95% Duration (sec),
  Arias Intensity (m/sec), Earthquake Name, Year, Station Name, Magnitude,
  Mechanism, Rjb (km), Rrup (km), Vs30 (m/sec), Lowest Useable Frequency (Hz),
  Initial-search Scale Factor, Horizontal-1 Acc. Filename, Horizontal-2 Acc.
  Filename, Vertical Acc. Filename``), one line per recording, a blank line;
* notes, and the spectra of the search (`` -- Scaled Spectra used in Search & Scaling --``).

Fields are separated by ``", "``; names are quoted (``"Duzce_ Turkey"``,
PEER writing ``_`` for a comma); a missing file is ``-----`` and a record
without a velocity pulse has ``-`` as its pulse period. A copy saved again
by a spreadsheet has its lines padded with commas and its names quoted
twice (a quote, a space and the name in doubled quotes): both read the same.

Every component a row names gets the row's metadata (the fields of
``stochpound.motions.records.METADATA_FIELDS`` and more): ``event`` is
``"<name> <year>"`` with PEER's ``_`` given back its comma (``"Duzce, Turkey
1999"``, as the FEMA P695 sets write it), ``distance`` the rupture distance
R_rup, ``distance_joyner_boore`` R_jb, ``fault_type`` the mechanism as
written, ``orientation`` ``H1``, ``H2`` or ``V``, ``component`` the file
name's event code and station component as the FEMA P695 sets write them
(``NORTHR/MUL009`` for ``RSN953_NORTHR_MUL009.AT2``, ``IMPVALL/H-DLT262`` for
``RSN169_IMPVALL.H_H-DLT262.AT2``: with the record sequence number, the same
recording in both is one recording to the selection), ``pulse`` (where the
file has the pulse-period column: true where it gives a period) and
``search_scale_factor`` (the search's scale factor, kept, never applied: the
files are as recorded, and scaling is the experiment's).
"""

from __future__ import annotations

import csv
import math
import re
from functools import lru_cache
from pathlib import Path

from stochpound._errors import RecordError

SEARCH_RESULTS = "_SearchResults.csv"
"""The name PEER gives the search's report in a download."""
METADATA_TITLE = "Summary of Metadata of Selected Records"
"""The line that opens the table of the selected records."""
#: Columns every search report must have, by the metadata field they fill.
REQUIRED_COLUMNS = {
    "rsn": "Record Sequence Number",
    "earthquake": "Earthquake Name",
    "year": "Year",
    "station": "Station Name",
    "magnitude": "Magnitude",
    "mechanism": "Mechanism",
    "distance_joyner_boore": "Rjb (km)",
    "distance": "Rrup (km)",
    "vs30": "Vs30 (m/sec)",
    "H1": "Horizontal-1 Acc. Filename",
    "H2": "Horizontal-2 Acc. Filename",
}
#: Columns read where the report has them.
OPTIONAL_COLUMNS = {"V": "Vertical Acc. Filename", "pulse_period": "Tp-Pulse Period (sec)", "search_scale_factor": "Scale Factor"}
_NO_FILE = re.compile(r"^-+$")
_RSN_PREFIX = re.compile(r"^RSN\d+_", re.IGNORECASE)


def search_results_file(folder: str | Path) -> Path | None:
    """The folder's ``_SearchResults.csv`` (None where it has none)."""
    path = Path(folder) / SEARCH_RESULTS
    return path if path.is_file() else None


def folder_metadata(folder: str | Path) -> dict[str, dict[str, float | str]]:
    """The metadata of every component the folder's ``_SearchResults.csv`` lists, by file name ({} without that file).

    Raises
    ------
    RecordError
        A report without the metadata table or one of its columns, or with a
        value that is not a number where one is due (the file, line and column named).
    """
    path = search_results_file(folder)
    if path is None:
        return {}
    status = path.stat()
    return _read(str(path.resolve()), status.st_mtime_ns, status.st_size)


def file_metadata(path: str | Path) -> dict[str, float | str]:
    """The metadata of one record file from the ``_SearchResults.csv`` beside it ({} where none lists it)."""
    path = Path(path)
    return dict(folder_metadata(path.parent).get(path.name, {}))


@lru_cache(maxsize=16)
def _read(path: str, mtime_ns: int, size: int) -> dict[str, dict[str, float | str]]:
    """The components of a report, by file name (cached while the file is unchanged)."""
    del mtime_ns, size  # the cache's key only
    shown = f"{Path(path).parent.name}/{SEARCH_RESULTS}"
    with open(path, newline="", encoding="utf-8", errors="replace") as handle:
        lines = list(csv.reader(handle, skipinitialspace=True))
    start = next((i for i, row in enumerate(lines) if row and METADATA_TITLE in row[0]), None)
    if start is None or start + 1 >= len(lines):
        raise RecordError(f"{shown}: no '-- {METADATA_TITLE} --' table (is it a PEER NGA-West2 search report?)")
    header = [_cell(cell) for cell in lines[start + 1]]
    columns = {}
    for key, name in {**REQUIRED_COLUMNS, **OPTIONAL_COLUMNS}.items():
        if name in header:
            columns[key] = header.index(name)
        elif key in REQUIRED_COLUMNS:
            raise RecordError(f"{shown}, line {start + 2}: no column {name!r} in the metadata table")
    components: dict[str, dict[str, float | str]] = {}
    for number, row in enumerate(lines[start + 2 :], start=start + 3):
        cells = [_cell(cell) for cell in row]
        if not any(cells):
            break  # the blank line that ends the table
        fields = {key: cells[index] if index < len(cells) else "" for key, index in columns.items()}
        metadata = _row_metadata(fields, f"{shown}, line {number}")
        for orientation in ("H1", "H2", "V"):
            name = fields.get(orientation, "")
            if name and not _NO_FILE.match(name):
                components[name] = {**metadata, "orientation": orientation, "component": _component(name)}
    return components


def _row_metadata(fields: dict[str, str], where: str) -> dict[str, float | str]:
    """A row's metadata, common to its components."""
    numbers = {key: _number(fields[key], REQUIRED_COLUMNS[key], where) for key in ("magnitude", "distance", "distance_joyner_boore", "vs30")}
    rsn, year = (_number(fields[key], REQUIRED_COLUMNS[key], where) for key in ("rsn", "year"))
    earthquake = fields["earthquake"].replace("_ ", ", ")
    metadata: dict[str, float | str] = {
        "event": f"{earthquake} {int(year)}",
        "year": int(year),
        "station": fields["station"].replace("_ ", ", "),
        **numbers,
        "rsn": int(rsn),
        "fault_type": fields["mechanism"],
        "source": "PEER NGA-West2 search report (_SearchResults.csv)",
    }
    if "pulse_period" in fields:
        period = fields["pulse_period"]
        metadata["pulse"] = not _NO_FILE.match(period) and period != ""
        metadata["pulse_period"] = _number(period, OPTIONAL_COLUMNS["pulse_period"], where) if metadata["pulse"] else math.nan
    if fields.setdefault("search_scale_factor", ""):
        metadata["search_scale_factor"] = _number(fields["search_scale_factor"], OPTIONAL_COLUMNS["search_scale_factor"], where)
    return metadata


def _cell(text: str) -> str:
    """A cell without its padding and quotes (a spreadsheet's copy quotes them twice)."""
    return text.strip().strip('"').strip()


def _number(text: str, column: str, where: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise RecordError(f"{where}: {column!r} must be a number, got {text!r}") from None
    if not math.isfinite(value):
        raise RecordError(f"{where}: {column!r} must be finite, got {text!r}")
    return value


def _component(file_name: str) -> str:
    """The event code and station component of an NGA-West2 file name, as NGA-West1 (and the FEMA P695 sets) write them:
    ``RSN953_NORTHR_MUL009.AT2`` → ``NORTHR/MUL009``, ``RSN169_IMPVALL.H_H-DLT262.AT2`` → ``IMPVALL/H-DLT262`` (the
    event code's ``.H``, NGA-West2's mark of the event in a sequence, left out)."""
    stem = _RSN_PREFIX.sub("", Path(file_name).stem)
    event, _, station = stem.partition("_")
    return f"{event.split('.')[0]}/{station}" if station else stem
