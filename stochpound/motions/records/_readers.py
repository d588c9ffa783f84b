"""Readers for accelerogram files: PEER ``.AT2`` and plain text columns.

Every reader returns a :class:`RawSeries` (:func:`record_from_file` makes
it a :class:`Record`) and raises :class:`RecordError`
naming the file (as the caller spelled it) and the line for malformed input.

Formats
-------
PEER ``.AT2``
    Free-text header lines, then a line giving the number of points and the
    step, in either of PEER's two styles::

        NPTS=   5372, DT=   .0100 SEC,          (NGA-West2)
          2688    0.0200    NPTS, DT            (NGA-West1 / older)

    then the samples, any number per line. Units are read from the header
    in any of the usual spellings (``UNITS OF G``, ``units are (g)``, ``IN GAL``,
    ``(cm/s^2)``, ``CM/S/S``, ``m/s²``; the list is in docs/records.md); g if
    the header names none. Velocity or displacement series are refused.
Text
    Blank lines and comment lines (``#``, ``%`` or ``!``) are skipped; values
    are separated by spaces, tabs, commas or semicolons, and every data line
    must have the same number of columns.

    * one column: accelerations; ``dt`` must be given;
    * two columns: time (s) and acceleration; dt comes from the time column,
      which must be uniform (within 1 % of a step at every sample);
    * more columns: time first, and ``column`` says which one holds the
      acceleration (0-based, e.g. ``column=1``).

    Units: the ``units`` argument, else units named in the comment lines
    (read as an AT2 header's), else g.

Both readers refuse a header naming units they do not know, or two units,
and a record whose peak is more than ``PLAUSIBLE_PEAK_G`` (5 g) in its units.
"""

from __future__ import annotations

import hashlib
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from stochpound._errors import RecordError
from stochpound._text_files import decode_text
from stochpound.motions.records._record import Record
from stochpound.motions.records._units import check_plausible_peak, header_units, normalize_units

#: Relative tolerance on the uniformity of a time column (fraction of a step).
TIME_STEP_TOLERANCE = 0.01
#: How many leading lines of an .AT2 file may precede the NPTS/DT line.
AT2_MAX_HEADER_LINES = 40

_NGA_WEST2 = re.compile(r"NPTS\s*=\s*(\d+)\s*[,;]?\s*DT\s*=\s*([-+0-9.eEdD]+)", re.IGNORECASE)
_NGA_WEST1 = re.compile(r"^\s*(\d+)\s+([-+0-9.eEdD]+)\s+NPTS\s*[,;]?\s*DT", re.IGNORECASE)
_SEPARATORS = re.compile(r"[,;\s]+")
_COMMENT_PREFIXES = ("#", "%", "!")


@dataclass
class RawSeries:
    """What a reader found in a file, before any registry transformation.

    Attributes
    ----------
    values : np.ndarray
        The samples, float64, in ``units``.
    dt : float
        Step, s.
    units : str
        ``"g"``, ``"m/s2"`` or ``"cm/s2"``.
    source_start_time : float
        Time of the first sample in the file's clock (from a time column), s.
    header : list[str]
        Header or comment lines, without line ends.
    sha256 : str
        Hash of the file's bytes.
    fmt : str
        ``"at2"`` or ``"text"``.
    """

    values: np.ndarray
    dt: float
    units: str
    source_start_time: float = 0.0
    header: list[str] = field(default_factory=list)
    sha256: str = ""
    fmt: str = ""


def read_record_file(
    path: str | Path,
    *,
    dt: float | None = None,
    units: str | None = None,
    column: int | None = None,
    fmt: str | None = None,
) -> RawSeries:
    """Read an accelerogram file, choosing the reader from ``fmt`` or the file.

    Parameters
    ----------
    path : str or Path
        The file. Messages quote it as given.
    dt : float, optional
        Step, s. Required for one-column text; elsewhere it must agree with the file.
    units : str, optional
        ``"g"``, ``"m/s2"`` or ``"cm/s2"`` (aliases accepted). Must agree with
        units stated in the file.
    column : int, optional
        Acceleration column (0-based) of a multi-column text file.
    fmt : {"at2", "text"}, optional
        Force a format. Default: ``.AT2`` files (any case), or files with a
        PEER NPTS/DT line near the top, are read as AT2; the rest as text.
    """
    shown = str(path)
    raw = _read_bytes(path, shown)
    lines = _decode(raw, shown).splitlines()
    if fmt is None:
        uncommented = [line for line in lines if not line.lstrip().startswith(_COMMENT_PREFIXES)]
        fmt = "at2" if str(path).lower().endswith(".at2") or _find_at2_header(uncommented) is not None else "text"
    if fmt == "at2":
        series = _parse_at2(lines, shown, dt=dt, units=units)
    elif fmt == "text":
        series = _parse_text(lines, shown, dt=dt, units=units, column=column)
    else:
        raise RecordError(f"{shown}: format must be 'at2' or 'text', got {fmt!r}")
    series.sha256 = hashlib.sha256(raw).hexdigest()
    series.fmt = fmt
    return series


def record_from_file(
    path: str | Path,
    *,
    dt: float | None = None,
    units: str | None = None,
    column: int | None = None,
    fmt: str | None = None,
) -> Record:
    """A record file (arguments as :func:`read_record_file`) as a :class:`Record` named after the file."""
    series = read_record_file(path, dt=dt, units=units, column=column, fmt=fmt)
    return Record(
        name=Path(path).name,
        dt=series.dt,
        values=series.values,
        units=series.units,
        description=_header_description(series),
        provenance=f"file {path} ({series.fmt}), sha256 {series.sha256}",
        source_start_time=series.source_start_time,
    )


def _header_description(series: RawSeries) -> str:
    lines = [line.lstrip("#%! ").strip() for line in series.header[:2]]
    return " / ".join(line for line in lines if line)


def read_at2(path: str | Path, *, dt: float | None = None, units: str | None = None) -> RawSeries:
    """Read a PEER ``.AT2`` file (either header style); see the module docstring."""
    return read_record_file(path, dt=dt, units=units, fmt="at2")


def read_text(
    path: str | Path, *, dt: float | None = None, units: str | None = None, column: int | None = None
) -> RawSeries:
    """Read a one-, two- or multi-column text file; see the module docstring."""
    return read_record_file(path, dt=dt, units=units, column=column, fmt="text")


def sha256_of(path: str | Path) -> str:
    """Hex sha256 of a file's bytes."""
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


# ---------------------------------------------------------------- helpers


def _read_bytes(path: str | Path, shown: str) -> bytes:
    try:
        return Path(path).read_bytes()
    except FileNotFoundError:
        raise RecordError(f"{shown}: no such file") from None
    except IsADirectoryError:
        raise RecordError(f"{shown}: is a directory, not a record file") from None
    except OSError as error:
        raise RecordError(f"{shown}: cannot be read ({error.strerror})") from None


def _decode(raw: bytes, shown: str) -> str:
    try:
        return decode_text(raw, shown, RecordError, lenient=True)
    except RecordError as error:
        raise RecordError(f"{error}; expected a PEER .AT2 or a text file of numbers") from None


def _find_at2_header(lines: list[str]) -> tuple[int, int, str] | None:
    """(line index, npts, dt text) of the NPTS/DT line, or None."""
    for index, line in enumerate(lines[:AT2_MAX_HEADER_LINES]):
        match = _NGA_WEST2.search(line) or _NGA_WEST1.search(line)
        if match:
            return index, int(match.group(1)), match.group(2)
    return None


def _number(text: str, shown: str, line_no: int) -> float:
    try:
        value = float(text.replace("D", "E").replace("d", "e"))
    except ValueError:
        raise RecordError(
            f"{shown}, line {line_no}: cannot read {text!r} as a number "
            "(expected numbers separated by spaces; comment header lines with '#')"
        ) from None
    if not math.isfinite(value):
        raise RecordError(f"{shown}, line {line_no}: non-finite value {text!r} (NaN or infinity)")
    return value


def _positive_dt(value: float, shown: str, where: str) -> float:
    if not (math.isfinite(value) and value > 0.0):
        raise RecordError(f"{shown}{where}: dt must be a finite number > 0 s, got {value!r}")
    return float(value)


def _check_given_dt(given: float | None, found: float, shown: str, where: str) -> None:
    if given is not None and not math.isclose(float(given), found, rel_tol=1e-6):
        raise RecordError(f"{shown}: dt={given:g} s was given but {where} says dt={found:g} s")


def _resolve_units(values: np.ndarray, given: str | None, stated: str | None, shown: str) -> str:
    """The units of ``values``: ``given``, which must agree with those the file states, else the stated ones, else g; a peak implausible in them is refused."""
    try:
        given_n = normalize_units(given) if given is not None else None
    except ValueError as error:
        raise RecordError(f"{shown}: {error}") from None
    if given_n is not None and stated is not None and given_n != stated:
        raise RecordError(f"{shown}: units={given!r} was given but the file states {stated!r}")
    units = given_n or stated or "g"
    source = f"units={given!r}" if given_n else "the file's header" if stated else "the default, g (the file names no units)"
    check_plausible_peak(values, units, shown, source)
    return units


def _parse_at2(lines: list[str], shown: str, *, dt: float | None, units: str | None) -> RawSeries:
    found = _find_at2_header(lines)
    if found is None:
        raise RecordError(
            f"{shown}: no PEER header line found in the first {AT2_MAX_HEADER_LINES} lines; expected "
            "'NPTS= n, DT= dt SEC' (NGA-West2) or 'n dt NPTS, DT' (NGA-West1)"
        )
    index, npts, dt_text = found
    file_dt = _positive_dt(_number(dt_text, shown, index + 1), shown, f", line {index + 1}")
    _check_given_dt(dt, file_dt, shown, "its header")
    header = lines[: index + 1]
    head_text = "\n".join(header).upper()
    if ("VELOCITY" in head_text or "DISPLACEMENT" in head_text) and "ACCELERATION" not in head_text:
        raise RecordError(f"{shown}: the header describes a velocity or displacement series; an acceleration is needed")
    stated = header_units(list(enumerate(header, start=1)), shown)
    values: list[float] = []
    for line_no, line in enumerate(lines[index + 1 :], start=index + 2):
        for token in line.split():
            values.append(_number(token, shown, line_no))
    if npts <= 0 or not values:
        raise RecordError(f"{shown}: the record is empty (NPTS={npts}, {len(values)} values read)")
    if len(values) != npts:
        raise RecordError(
            f"{shown}: header line {index + 1} says NPTS={npts} but {len(values)} values follow "
            f"(lines {index + 2}-{len(lines)})"
        )
    samples = np.asarray(values, dtype=np.float64)
    return RawSeries(samples, file_dt, _resolve_units(samples, units, stated, shown), 0.0, header)


def _parse_text(
    lines: list[str], shown: str, *, dt: float | None, units: str | None, column: int | None
) -> RawSeries:
    header: list[tuple[int, str]] = []
    rows: list[list[float]] = []
    row_lines: list[int] = []
    n_columns = None
    for line_no, line in enumerate(lines, start=1):
        stripped = line.strip()
        if not stripped:
            continue
        if stripped.startswith(_COMMENT_PREFIXES):
            header.append((line_no, stripped))
            continue
        tokens = [token for token in _SEPARATORS.split(stripped) if token]
        if n_columns is None:
            n_columns = len(tokens)
        elif len(tokens) != n_columns:
            raise RecordError(
                f"{shown}, line {line_no}: {len(tokens)} column(s), but the first data line "
                f"(line {row_lines[0]}) has {n_columns}"
            )
        rows.append([_number(token, shown, line_no) for token in tokens])
        row_lines.append(line_no)
    if not rows:
        raise RecordError(f"{shown}: no data lines (the record is empty)")
    stated = header_units(header, shown)
    comments = [line for _, line in header]
    table = np.asarray(rows, dtype=np.float64)
    if n_columns == 1:
        if column not in (None, 0):
            raise RecordError(f"{shown}: column={column} was given but the file has one column")
        if dt is None:
            raise RecordError(f"{shown}: missing dt: a one-column file holds no times, so give dt (s), e.g. dt=0.02")
        step = _positive_dt(float(dt), shown, "")
        return RawSeries(table[:, 0], step, _resolve_units(table[:, 0], units, stated, shown), 0.0, comments)
    if column is None:
        if n_columns != 2:
            raise RecordError(
                f"{shown}: {n_columns} columns; column 0 is taken as time, say which column holds "
                f"the acceleration with column=1..{n_columns - 1}"
            )
        column = 1
    if not (isinstance(column, int) and 1 <= column < n_columns):
        raise RecordError(f"{shown}: column must be an integer in 1..{n_columns - 1} (0 is time), got {column!r}")
    times = table[:, 0]
    if times.size < 2:
        if dt is None:
            raise RecordError(f"{shown}: a single sample cannot define the time step; give dt (s)")
        step = _positive_dt(float(dt), shown, "")
    else:
        step = _uniform_step(times, row_lines, shown)
        _check_given_dt(dt, step, shown, "its time column")
    return RawSeries(table[:, column], step, _resolve_units(table[:, column], units, stated, shown), float(times[0]), comments)


def _uniform_step(times: np.ndarray, row_lines: list[int], shown: str) -> float:
    steps = np.diff(times)
    bad = np.flatnonzero(steps <= 0.0)
    if bad.size:
        k = int(bad[0]) + 1
        raise RecordError(
            f"{shown}, line {row_lines[k]}: time {times[k]:g} s does not increase (previous {times[k - 1]:g} s)"
        )
    typical = float(np.median(steps))
    bad = np.flatnonzero(np.abs(steps - typical) > TIME_STEP_TOLERANCE * typical)
    if bad.size:
        k = int(bad[0]) + 1
        raise RecordError(
            f"{shown}, line {row_lines[k]}: non-uniform time step: {times[k - 1]:g} s to {times[k]:g} s "
            f"is {steps[k - 1]:g} s, the file's step is {typical:g} s (allowed deviation {TIME_STEP_TOLERANCE:g} of a step)"
        )
    step = float(times[-1] - times[0]) / (times.size - 1)
    drift = np.abs(times - (times[0] + step * np.arange(times.size)))
    bad = np.flatnonzero(drift > TIME_STEP_TOLERANCE * step)
    if bad.size:
        k = int(bad[0])
        raise RecordError(
            f"{shown}, line {row_lines[k]}: non-uniform time step: t = {times[k]:g} s drifts from the "
            f"uniform grid {times[0]:g} + k x {step:g} s by more than {TIME_STEP_TOLERANCE:g} of a step"
        )
    return step
