"""Reading a site's hazard curve from a file, with what it is a curve of.

A hazard curve is only usable with its measure (PGA, PSA at a period and
damping, ...), the units of its intensities and the kind of its values
(annual rates of exceedance, or probabilities of exceedance in an
investigation time). :func:`read_hazard_file` reads the curve and what the
file states about these; nothing is guessed: what the file leaves out, the
caller states (an experiment's ``[hazard]`` fields, ``stochpound risk``'s
options) and a statement that contradicts the file is an error naming both.

Three formats (docs/risk.md gives an example of each):

* **stochpound's CSV**: ``# Key: value`` comment lines (``Measure``,
  ``Units``, ``Investigation time``; any other comment is provenance), a
  header row naming the columns, ``im`` and ``rate`` (annual rate of
  exceedance, 1/yr) or ``poe`` (probability of exceedance in the
  investigation time), then one row per intensity.
* **OpenQuake engine's hazard-curve CSV** (``hazard_curve-<kind>-<IMT>_<id>.csv``):
  a first comment line whose last field lists ``investigation_time=...``
  and ``imt='...'``, a header ``lon,lat[,depth],poe-<level>,...``, one row
  per site of probabilities of exceedance in the investigation time. Its
  levels are in g (PGA, SA) or cm/s (PGV); its spectral accelerations are
  5 %-damped.
* **nshmp-haz's curve output** (the USGS hazard tools; ``curves/<IMT>/total.csv``):
  a header ``name,lon,lat,<level>,...`` (``name`` optional), one row per
  site of annual rates of exceedance. The measure is the folder's name
  (``PGA``, ``PGV``, ``SA1P0`` for SA(1.0 s)); levels in g (cm/s for PGV),
  spectral accelerations 5 %-damped.
"""

from __future__ import annotations

import csv
import re
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from stochpound._text_files import read_text_file
from stochpound.hazard._curve import HazardCurve, rate_from_probability
from stochpound.motions import Measure
from stochpound.motions.records import normalize_units
from stochpound.store import TomlTable

FORMATS = ("stochpound", "openquake", "nshmp-haz")
"""The hazard-file formats :func:`read_hazard_file` reads."""
UNITS = {"g": ("acceleration", None), "m/s2": ("acceleration", 1.0), "cm/s2": ("acceleration", 0.01),
         "m/s": ("velocity", 1.0), "cm/s": ("velocity", 0.01)}
"""Units of a hazard's intensities: what they measure and their value in SI (None: g, the experiment's)."""
_VELOCITY_UNITS = tuple(name for name, (kind, _) in UNITS.items() if kind == "velocity")
_TOOL_DAMPING = 0.05
"""Damping of the spectral accelerations of OpenQuake's and nshmp-haz's curves (their documented convention)."""
_TOOL_UNITS = {"pga": "g", "psa": "g", "pgv": "cm/s"}
_NUMBER = r"(\d+(?:\.\d*)?|\.\d+)"
_RATE_COLUMNS = ("rate", "annual_rate", "mafe", "lambda", "afe")
_POE_COLUMNS = ("poe", "probability")


@dataclass(frozen=True)
class StatedMeasure:
    """What a hazard file, a bundled curve's name or a command-line option states of a curve's measure: each part None
    (``periods`` empty) when not stated, e.g. a file's ``SA(0.2)`` states no damping and no units.

    Attributes
    ----------
    kind : str or None
        ``pga``, ``pgv``, ``psa`` or ``sa_avg`` (:data:`~stochpound.motions.MEASURE_KINDS`).
    period : float or None
        The period of ``psa``, s.
    periods : tuple of float
        The periods of ``sa_avg``, s.
    damping : float or None
        The damping ratio of a spectral measure.
    units : str or None
        The units of the intensities: ``g``, ``m/s2``, ``cm/s2``, ``m/s`` or ``cm/s``.
    """

    kind: str | None = None
    period: float | None = None
    periods: tuple[float, ...] = ()
    damping: float | None = None
    units: str | None = None

    @classmethod
    def parse(cls, text: str) -> StatedMeasure:
        """A measure as written in a file's ``# Measure:`` line or on the command line.

        Understands ``PGA``, ``PGV``, ``PSA``/``SA(T)``/``SA1P0``/"spectral
        acceleration at T = 1.0 s", a damping as a percentage ("5 %-damped",
        "5 %"), and units after "in" or a last comma.

        >>> StatedMeasure.parse("SA(0.2)")
        StatedMeasure(kind='psa', period=0.2, periods=(), damping=None, units=None)

        Raises
        ------
        ValueError
            Naming ``measure`` or ``units``: no measure stochpound knows, an average spectral acceleration, unknown units.
        """
        return _parsed(text)

    @classmethod
    def of(cls, measure: Measure, units: str | None = None) -> StatedMeasure:
        """The whole of a measure, and its units if known."""
        return cls(measure.kind, measure.period, measure.periods, measure.damping, units)

    @classmethod
    def from_entry(cls, entry: Mapping[str, str | float | list[float]]) -> StatedMeasure:
        """The stated keys (``measure``, ``period``, ``periods``, ``damping``, ``units``) of a mapping; other keys are ignored."""
        table = TomlTable(entry)
        return cls(table.string("measure", None), table.number("period", None), table.numbers("periods", (), low=0.0, low_open=True), table.number("damping", None),
                   table.string("units", None))

    def entry(self) -> dict[str, str | float | list[float]]:
        """The parts stated, by their keys in an experiment's ``[hazard]`` (``measure``, ``period``, ``periods``, ``damping``, ``units``)."""
        parts = {"measure": self.kind, "period": self.period, "periods": list(self.periods) or None, "damping": self.damping, "units": self.units}
        return {key: value for key, value in parts.items() if value is not None}

    @property
    def measure(self) -> Measure | None:
        """The measure once its kind and, for a spectral kind, its period(s) are stated (the damping may be unstated); else None.

        Raises
        ------
        ValueError
            As :class:`~stochpound.motions.Measure`: a stated part out of its range.
        """
        if self.kind is None or (self.kind == "psa" and self.period is None) or (self.kind == "sa_avg" and not self.periods):
            return None
        return Measure(self.kind, self.period, self.periods, self.damping)


@dataclass
class HazardFile:
    """A hazard curve as a file gives it, before it is checked against a store.

    Attributes
    ----------
    im : numpy.ndarray
        Intensities, in ``stated`` ``units`` (or the caller's).
    values : numpy.ndarray
        Annual rates of exceedance (1/yr) or probabilities of exceedance in
        ``investigation_time`` years, as ``quantity`` says.
    quantity : str
        ``"rate"`` or ``"poe"``.
    investigation_time : float or None
        Years of a ``poe`` curve, when the file states it.
    stated : StatedMeasure
        What the file states of its measure and units (None: not stated).
    format : str
        One of ``FORMATS`` (stochpound, openquake, nshmp-haz).
    provenance : str
        The file's comment lines (or its name), kept with the curve.
    """

    im: np.ndarray
    values: np.ndarray
    quantity: str
    investigation_time: float | None
    stated: StatedMeasure
    format: str
    provenance: str
    notes: list[str] = field(default_factory=list)
    """What was done to the file's values on reading (kept in the curve's provenance)."""

    def curve(self, units: str, g: float, *, investigation_time: float | None = None,
              extrapolate: bool = False, description: str = "") -> HazardCurve:
        """The annual-rate curve with intensities converted to ``units`` (g in m/s² for conversions to or from g).

        Parameters
        ----------
        units : str
            Units the intensities must be in (a key of ``g``, ``m/s2``, ``cm/s2``, ``m/s``, ``cm/s``, e.g. the experiment's levels').
        g : float
            Standard gravity (m/s²) for a conversion to or from g.
        investigation_time : float, optional
            Years of a ``poe`` curve, when the file does not state them.
        extrapolate : bool
            Passed to :class:`~stochpound.analysis.HazardCurve`.
        description : str
            The measure, for the curve's ``measure``.

        Raises
        ------
        ValueError
            The units are not stated or not convertible, a ``poe`` curve has
            no investigation time, or the table is not a decreasing curve.
        """
        notes = list(self.notes)
        im = self.im * unit_factor(self.stated.units, units, g)
        if self.stated.units != units:
            notes.append(f"intensities converted from {self.stated.units} to {units} (g = {g:g} m/s²)")
        values = self.values
        if self.quantity == "poe":
            years = self.investigation_time if self.investigation_time is not None else investigation_time
            if years is None:
                raise ValueError("investigation_time: the values are probabilities of exceedance (poe): state the "
                                 "investigation time in years they are for (they are converted to annual rates)")
            keep = values < 1.0
            if not np.all(keep):
                notes.append(f"{int(np.count_nonzero(~keep))} level(s) with probability 1 left out (an infinite rate)")
                im, values = im[keep], values[keep]
            values = rate_from_probability(values, years) if np.all(values > 0.0) else _rates_with_zeros(values, years)
            notes.append(f"probabilities of exceedance in {years:g} years converted to annual rates, λ = −ln(1 − P)/{years:g}")
        positive = values > 0.0
        if not np.all(positive):
            if np.any(positive[np.argmax(~positive):]):
                raise ValueError("rate: a zero inside the curve (a curve of exceedance is zero only above its last positive level)")
            notes.append(f"{int(np.count_nonzero(~positive))} level(s) of zero exceedance above {im[positive][-1]:g} {units} left out")
            im, values = im[positive], values[positive]
        source = "\n".join([self.provenance, *(f"stochpound: {note}" for note in notes)])
        return HazardCurve(im, values, extrapolate=extrapolate, measure=description, units=units, source=source)


def _rates_with_zeros(values: np.ndarray, years: float) -> np.ndarray:
    rates = np.zeros_like(values)
    positive = values > 0.0
    rates[positive] = rate_from_probability(values[positive], years)
    return rates


def unit_factor(source: str, target: str, g: float) -> float:
    """The factor that converts intensities in ``source`` units to ``target`` units.

    Raises
    ------
    ValueError
        Unknown units, or units of different quantities (acceleration and velocity).
    """
    for name in (source, target):
        if name not in UNITS:
            raise ValueError(f"units: must be one of {', '.join(UNITS)}, got {name!r}")
    (kind, to_si), (target_kind, target_si) = UNITS[source], UNITS[target]
    if kind != target_kind:
        raise ValueError(f"units: the hazard's intensities are in {source} (a {kind}), the store's in {target} (a {target_kind})")
    return (g if to_si is None else to_si) / (g if target_si is None else target_si)


def parse_units(text: str) -> str:
    """Units as written in the spelling of ``g``, ``m/s2``, ``cm/s2``, ``m/s``, ``cm/s``.

    An acceleration's units in any spelling the records' reader knows
    (:func:`~stochpound.motions.records.normalize_units`: ``gal``, ``m/s²``,
    ``cm/s/s``, ``cm/s^2``, ...); a velocity's as ``m/s`` or ``cm/s``.

    Raises
    ------
    ValueError
        Naming ``units``: a spelling of none of these.
    """
    velocity = text.strip().lower().replace(" ", "")
    if velocity in _VELOCITY_UNITS:
        return velocity
    try:
        return normalize_units(text)
    except ValueError:
        raise ValueError(f"units: must be one of {', '.join(UNITS)} (or gal, cm/s², cm/s/s, cm/s^2, ...), got {text!r}") from None


def _parsed(text: str) -> StatedMeasure:
    """What :meth:`StatedMeasure.parse` finds in ``text``."""
    lowered = text.strip().lower()
    units, body = _stated_units(lowered)
    tool = re.fullmatch(r"\s*sa(\d+)p(\d+)\s*", body)
    if tool:
        return StatedMeasure("psa", float(f"{tool.group(1)}.{tool.group(2)}"))
    if re.search(r"average|sa_avg|saavg", body):
        raise ValueError(f"measure: {text!r}: an average spectral acceleration is not read from a file; "
                         "state measure = \"sa_avg\", periods and damping in [hazard]")
    period = None
    if re.search(r"\bpga\b|peak ground acceleration", body):
        kind = "pga"
    elif re.search(r"\bpgv\b|peak ground velocity", body):
        kind = "pgv"
    elif re.search(r"\bp?sa\b|\bp?sa\(|spectral acceleration", body):
        kind = "psa"
        found = (re.search(rf"\bt\s*=\s*{_NUMBER}\s*s", body) or re.search(rf"\bp?sa\s*\(\s*{_NUMBER}", body)
                 or re.search(rf"{_NUMBER}\s*s\b", body))
        period = float(found.group(1)) if found else None
    else:
        raise ValueError(f"measure: {text!r} names no measure stochpound knows (PGA, PGV, PSA/SA(T))")
    damping = re.search(rf"{_NUMBER}\s*%", body)
    return StatedMeasure(kind, period, (), float(damping.group(1)) / 100.0 if damping else None, units)


def _stated_units(text: str) -> tuple[str | None, str]:
    """(units, the rest of ``text``) when ``text`` ends with units after "in" or a last comma, else (None, ``text``)."""
    ending = re.fullmatch(r"(?P<body>.*)(?:\bin\b|,)\s*(?P<units>[^,]*?)\s*\.?", text, re.DOTALL)
    if ending is None:
        return None, text
    try:
        return parse_units(ending.group("units")), ending.group("body")
    except ValueError:
        return None, text


def read_hazard_file(path: str | Path, *, site: int | str | None = None) -> HazardFile:
    """Read a hazard-curve file: stochpound's CSV, OpenQuake's or nshmp-haz's (recognised from its first lines).

    Parameters
    ----------
    path : str or Path
        The file.
    site : int or str, optional
        For a file of several sites (OpenQuake, nshmp-haz): the site's row
        (0-based) or, for nshmp-haz, its name. A file of one site needs none.

    Raises
    ------
    ValueError
        Starting with the file's name: an unreadable or ambiguous file.
    """
    path = Path(path)
    lines = [line.rstrip("\r\n") for line in read_text_file(path).splitlines() if line.strip()]
    if not lines:
        raise ValueError(f"{path.name}: empty")
    try:
        if lines[0].startswith("#") and "investigation_time=" in lines[0] and "imt=" in lines[0]:
            return _checked(_openquake(path, lines, site))
        first = [cell.strip().lower() for cell in next(csv.reader([lines[0]]))]
        if first[:3] == ["name", "lon", "lat"] or first[:2] == ["lon", "lat"]:
            return _checked(_nshmp(path, lines, site))
        if site is not None:
            raise ValueError("site: a stochpound hazard file holds one site's curve")
        return _checked(_stochpound(path, lines))
    except ValueError as error:
        raise ValueError(f"{path.name}: {error}") from None


def _checked(curve: HazardFile) -> HazardFile:
    """``curve``, its values checked: probabilities in [0, 1] (above 1 they look like per cent), rates ≥ 0."""
    values = curve.values
    if curve.quantity == "poe" and np.any(values > 1.0):
        raise ValueError(f"poe: {int(np.count_nonzero(values > 1.0))} value(s) above 1 (largest {float(values.max()):g}): these look like "
                         "per cent; give probabilities of exceedance in [0, 1] (divide by 100)")
    if np.any(~np.isfinite(values)) or np.any(values < 0.0):
        raise ValueError(f"{curve.quantity}: values must be finite and >= 0, got {', '.join(f'{v:g}' for v in values if not v >= 0.0 or not np.isfinite(v))}")
    return curve


def _stochpound(path: Path, lines: list[str]) -> HazardFile:
    comments, header, rows, stated = [], None, [], StatedMeasure()
    years = None
    for number, line in enumerate(lines, start=1):
        text = line.strip()
        if text.startswith("#"):
            comment = text.lstrip("#").strip()
            comments.append(comment)
            key, _, value = comment.partition(":")
            key = key.strip().lower()
            if key == "measure":
                measure_line = _parsed(value)
                stated = replace(measure_line, units=measure_line.units or stated.units)
            elif key == "units":
                stated = replace(stated, units=parse_units(value))
            elif key == "investigation time":
                years = _years(value)
            continue
        fields = [cell.strip() for cell in next(csv.reader([text]))]
        try:
            rows.append((float(fields[0]), float(fields[1])))
        except (ValueError, IndexError):
            if rows or header is not None:
                raise ValueError(f"line {number}: expected two numbers 'im, value', got {text!r}") from None
            header = [cell.lower() for cell in fields]
    if not rows:
        raise ValueError("no rows of 'im, value'")
    quantity = _quantity(header)
    im, values = (np.asarray(column, dtype=float) for column in zip(*rows))
    return HazardFile(im, values, quantity, years, stated, "stochpound", "\n".join(comments) or path.name)


def _quantity(header: list[str] | None) -> str:
    """``rate`` or ``poe`` from the header's second column."""
    name = header[1] if header and len(header) > 1 else ""
    if name in _RATE_COLUMNS:
        return "rate"
    if name in _POE_COLUMNS:
        return "poe"
    raise ValueError(f"header: name the second column 'rate' (annual rate of exceedance, 1/yr) or 'poe' (probability of "
                     f"exceedance in the '# Investigation time:'), got {name or 'no header row'!r}")


def _years(text: str) -> float:
    match = re.fullmatch(rf"\s*{_NUMBER}\s*(?:y|yr|yrs|year|years)?\s*", text.lower())
    if match is None or float(match.group(1)) <= 0.0:
        raise ValueError(f"investigation time: must be a number of years > 0, got {text.strip()!r}")
    return float(match.group(1))


def _openquake(path: Path, lines: list[str], site: int | str | None) -> HazardFile:
    banner = lines[0]
    time = re.search(rf"investigation_time\s*=\s*{_NUMBER}", banner)
    imt = re.search(r"imt\s*=\s*'([^']+)'", banner)
    if time is None or imt is None:
        raise ValueError("OpenQuake header: expected investigation_time=... and imt='...' in the first line")
    header = [cell.strip() for cell in next(csv.reader([lines[1]]))]
    columns = [i for i, name in enumerate(header) if name.startswith("poe-")]
    if header[:2] != ["lon", "lat"] or not columns:
        raise ValueError(f"OpenQuake header: expected columns lon, lat[, depth], poe-<level>..., got {lines[1]!r}")
    rows = [next(csv.reader([line])) for line in lines[2:]]
    row = _site_row(rows, site, names=None)
    stated = _tool_measure(imt.group(1))
    provenance = (f"OpenQuake hazard curve {path.name}: {banner.lstrip('#, ').strip(chr(34))}; site lon {row[0]}, lat {row[1]}")
    return HazardFile(np.array([float(header[i][4:]) for i in columns]), np.array([float(row[i]) for i in columns]),
                      "poe", float(time.group(1)), stated, "openquake", provenance)


def _nshmp(path: Path, lines: list[str], site: int | str | None) -> HazardFile:
    header = [cell.strip() for cell in next(csv.reader([lines[0]]))]
    start = 3 if header[0].lower() == "name" else 2
    rows = [next(csv.reader([line])) for line in lines[1:]]
    row = _site_row(rows, site, names=[r[0] for r in rows] if start == 3 else None)
    folder = path.parent.name
    stated = _tool_measure(folder) if re.fullmatch(r"(?i)pga|pgv|sa\d+p\d+", folder) else StatedMeasure()
    where = f"site {row[0]!r}, lon {row[start - 2]}, lat {row[start - 1]}" if start == 3 else f"lon {row[0]}, lat {row[1]}"
    provenance = f"nshmp-haz hazard curve {folder}/{path.name}: {where}" if stated.kind else f"nshmp-haz hazard curve {path.name}: {where}"
    return HazardFile(np.array([float(x) for x in header[start:]]), np.array([float(x) for x in row[start:]]),
                      "rate", None, stated, "nshmp-haz", provenance)


def _site_row(rows: list[list[str]], site: int | str | None, names: list[str] | None) -> list[str]:
    if not rows:
        raise ValueError("no site rows")
    if site is None:
        if len(rows) > 1:
            raise ValueError(f"{len(rows)} sites: choose one (site = its row, 0-based{', or its name' if names else ''})")
        return rows[0]
    if isinstance(site, str) and not site.isdigit():
        if names is None or site not in names:
            raise ValueError(f"site: no site named {site!r}{f' (sites: {chr(44).join(names)})' if names else ''}")
        return rows[names.index(site)]
    index = int(site)
    if not 0 <= index < len(rows):
        raise ValueError(f"site: must be a row in [0, {len(rows) - 1}], got {site!r}")
    return rows[index]


def _tool_measure(imt: str) -> StatedMeasure:
    """The measure of an OpenQuake IMT (``PGA``, ``SA(1.0)``) or nshmp-haz folder (``SA1P0``), with the tool's units and damping."""
    stated = StatedMeasure.parse(imt)
    return replace(stated, damping=_TOOL_DAMPING if stated.kind == "psa" else stated.damping, units=_TOOL_UNITS[stated.kind])

