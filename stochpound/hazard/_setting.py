"""The ``[hazard]`` table of an experiment file: the site's hazard curve, carried in the store.

One of three sources (docs/risk.md):

* ``file = "site.csv"``: a hazard-curve file (stochpound's CSV, OpenQuake's
  hazard-curve CSV or nshmp-haz's curve output, read by
  :func:`~stochpound.analysis.read_hazard_file`), the path relative to the
  experiment file;
* ``bundled = "fox_plaza_los_angeles_sa2p0s"``: a curve shipped with
  stochpound (:meth:`~stochpound.analysis.HazardCurve.bundled`);
* ``power_law = { k0 = 2.0e-4, k = 2.2 }``: λ(x) = k0 x^(−k);
* ``ruptures = "site.csv"`` (or a bundled site's name), with ``vs30``,
  ``z1p0_km``, ``z2p5_km`` where the table does not state them: the curve of
  ``[intensity]``'s measure from the site's ruptures
  (:meth:`~stochpound.analysis.RuptureSite.hazard_curve`), the same ruptures
  as ``[site]``'s for stripes chosen to their exact conditional spectra.

**A hazard is read, never guessed.** A hazard curve is only meaningful
with the fragility's intensity measure, so the hazard's measure must be the
``[intensity]`` table's: the same ``measure``, the same ``period`` (PSA)
or ``periods`` (Sa_avg), the same ``damping``. A file states its measure
and units (its header, or the format's convention); what it does not state,
``[hazard]`` must (``measure``, ``period``/``periods``, ``damping``,
``units``), and a field that contradicts the file is an error naming both.
Intensities in other units than the levels' (g, m/s², cm/s² for
accelerations) are converted with the scene's g; probabilities of
exceedance in an investigation time are converted to annual rates; both
conversions are recorded in the provenance. A bundled curve knows its
measure (from its name, in g). A power law is in ``[intensity]``'s
measure, its x in ``units`` (default: the levels'). A table that does not
cover the stripes is an error unless ``extrapolate = true``.

The canonical entry holds the table itself (``im``, ``rate``, in the
levels' units and annual rates), its provenance (the file's comment lines
and the conversions) and the file's sha256, so a store carries everything
needed to redo the risk chain without the file. No run depends on it, so it is not part of the
experiment's identity (``stochpound.store.NOT_IN_IDENTITY``): a run after
the hazard changed keeps the store's cases and records the new entry.
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import replace
from pathlib import Path
from collections.abc import Sequence
from typing import Any

import xarray as xr

from stochpound._errors import IntensityError
from stochpound.hazard._curve import BUNDLED_UNITS, HazardCurve, bundled_curves, bundled_measure, bundled_path
from stochpound.hazard._files import HazardFile, StatedMeasure, parse_units, read_hazard_file, unit_factor
from stochpound.hazard._ruptures import SITE_FIELDS as RUPTURE_SITE_FIELDS, named_rupture_site
from stochpound.motions import Measure
from stochpound.store import MEASURES, Hazard, Intensity, TomlTable
from stochpound.model.fields import is_number
from stochpound.motions import DEFAULT_G

SOURCES = ("file", "bundled", "power_law", "ruptures")
"""The keys that name a hazard's source (exactly one per ``[hazard]`` table)."""
STATED = ("measure", "period", "periods", "damping", "units", "investigation_time")
"""The ``[hazard]`` fields (and ``stochpound risk`` options) that state what a file's curve is of, when the file does not."""
_KEYS = {*SOURCES, *STATED, "site", "extrapolate", *RUPTURE_SITE_FIELDS}
_REQUIRED = {"pga": ("units",), "pgv": ("units",), "psa": ("period", "damping", "units"), "sa_avg": ("periods", "damping", "units")}
_TOLERANCE = 1e-9


def parse_hazard(file: TomlTable, intensity: Intensity | None, base_dir: Path, g: float = DEFAULT_G) -> Hazard | None:
    """The ``[hazard]`` table of a definition, typed (None without a ``[hazard]`` table).

    Parameters
    ----------
    file : TomlTable
        The parsed experiment file (its top level).
    intensity : Intensity or None
        The ``[intensity]`` setting (a hazard needs one).
    base_dir : Path
        The experiment file's folder (a ``file`` is relative to it).
    g : float
        The scene's g (m/s²), to convert a hazard in g to levels in m/s² or back.

    Returns
    -------
    Hazard or None
        ``source`` (one of :data:`SOURCES`), the source's key as given,
        the measure (``[intensity]``'s), ``units``, ``extrapolate``,
        ``im`` and ``rate`` (a table, in the units of the levels and in
        annual rates; a power law: ``power_law``), ``provenance`` (with
        any conversion) and, for a file, ``file_sha256``.

    Raises
    ------
    IntensityError
        Naming the field: no ``[intensity]``, not exactly one source, an
        unreadable or invalid table, a measure other than ``[intensity]``'s,
        a measure or units the file and ``[hazard]`` both leave unstated or
        state differently, a curve that misses the stripes.
    """
    table = file.table("hazard", _KEYS)
    if table is None:
        return None
    if intensity is None:
        raise IntensityError("hazard: needs an [intensity] table (the hazard is a curve of its measure, in the units of its levels)")
    given = [key for key in SOURCES if key in table]
    if len(given) != 1:
        raise IntensityError(f"hazard: give exactly one of {', '.join(SOURCES)}, got {', '.join(given) or 'none'}")
    source = given[0]
    for key in RUPTURE_SITE_FIELDS:
        if key in table and source != "ruptures":
            raise IntensityError(f"hazard.{key}: only with ruptures = ... (the site of a rupture table)")
    extrapolate = table.boolean("extrapolate", default=False)
    measure, units = intensity.measure, intensity.units
    stated, investigation_time = stated_fields(table), table.number("investigation_time", None, low=0.0, low_open=True)
    sources: dict[str, str] = {}
    power_law = None
    if source == "bundled":
        sources["bundled"] = table.string("bundled")
        curve = _bundled(sources["bundled"], measure, units, g, extrapolate, "hazard.bundled")
    elif source == "file":
        name = table.string("file")
        path = base_dir / name
        if not path.is_file():
            raise IntensityError(f"hazard.file: {name!r} not found (a hazard-curve file, relative to the experiment file)")
        curve = _read(path, stated, investigation_time, table.raw("site"), measure, units, g, extrapolate, "hazard")
        sources.update(file=name, file_sha256=hashlib.sha256(path.read_bytes()).hexdigest())
    elif source == "ruptures":
        _check_measure("hazard", stated, measure)
        curve = _rupture_curve(table, measure, units, base_dir, g, extrapolate)
        sources["ruptures"] = table.raw("ruptures")
    else:
        _check_measure("hazard", stated, measure)
        power_law = _power_law(table.table("power_law", {"k0", "k"}, hint="{ k0 = ..., k = ... } (rate = k0 x^-k, 1/yr)"), stated.units or units, units, g)
        curve = HazardCurve.power_law(**power_law)
    if curve.power is None and intensity.ran == "stripes":
        check_covers(curve, intensity.levels, "hazard", "intensity.levels", "extrapolate = true")
    table_values = ((), ()) if curve.power is not None else (tuple(float(x) for x in curve.im), tuple(float(y) for y in curve.rate))
    return Hazard(source, measure, units, extrapolate, curve.source, *table_values, power_law=power_law, **sources)


def _rupture_curve(table: TomlTable, measure: Measure, units: str, base_dir: Path, g: float, extrapolate: bool) -> HazardCurve:
    """The hazard curve of ``[intensity]``'s measure from the site of ruptures ``[hazard]`` names, in the levels' units."""
    from stochpound._errors import SiteError

    given = {key: table.raw(key) for key in RUPTURE_SITE_FIELDS if key in table}
    try:
        site = named_rupture_site(table.raw("ruptures"), base_dir, given, "hazard")
        if measure.damping is not None and measure.damping != 0.05:
            raise SiteError(f"hazard.ruptures: the NGA-West2 models give 5 % damped spectra only; intensity.damping is {measure.damping!r}")
        curve = site.hazard_curve(measure.kind, measure.spectral_period, extrapolate=extrapolate)
        factor = unit_factor("g", units, g)
    except (SiteError, ValueError) as error:
        message = str(error)
        raise IntensityError(message if message.startswith("hazard.") else f"hazard.ruptures: {message}") from None
    return HazardCurve(curve.im * factor, curve.rate, extrapolate=extrapolate, measure=measure.description, units=units,
                       source=f"{curve.source}; {site.source}" if site.source else curve.source)


def hazard_curve(hazard: Hazard, extrapolate: bool | None = None) -> HazardCurve:
    """The :class:`~stochpound.analysis.HazardCurve` of a store's hazard (from its stored values, not its file).

    ``extrapolate`` overrides the hazard's own (``stochpound risk --extrapolate``).
    """
    description = {"measure": hazard.description, "units": hazard.units, "source": hazard.provenance}
    if hazard.power_law is not None:
        return HazardCurve.power_law(**hazard.power_law, **description)
    return HazardCurve(hazard.im, hazard.rate, extrapolate=hazard.extrapolate if extrapolate is None else extrapolate, **description)


def check_covers(curve: HazardCurve, levels: Sequence[float], where: str, what: str, remedy: str) -> None:
    """Raise unless the curve's table covers ``levels`` (or extrapolates, as it states).

    A table says nothing outside its intensities: a risk integral over stripes
    beyond them would silently count nothing (below) or the last rate (above).
    """
    low, high = curve.support
    if min(levels) < low or max(levels) > high:
        raise IntensityError(f"{where}: the hazard curve covers [{low:g}, {high:g}] {curve.units}, the stripes ({what}) "
                             f"[{min(levels):g}, {max(levels):g}] {curve.units}: give a curve that covers them, or {remedy} "
                             "to extend it as power laws (stated in the report)")


def stated_fields(table: TomlTable) -> StatedMeasure:
    """What a table (``[hazard]``, an entry of ``[site] curves``) states of its curve's measure: measure, period(s), damping, units
    (each None when not stated); its errors name the table's fields."""
    kind = table.string("measure", None, choices=MEASURES)
    period = table.number("period", None, low=0.0, low_open=True)
    damping = table.number("damping", None, low=0.0, high=1.0, high_open=True)
    periods = table.numbers("periods", (), low=0.0, low_open=True)
    units = table.string("units", None)
    try:
        return StatedMeasure(kind, period, periods, damping, None if units is None else parse_units(units))
    except ValueError as error:
        raise IntensityError(f"{table.name}.{error}") from None


def _read(path: Path, given: StatedMeasure, investigation_time: float | None, site: Any, measure: Measure, units: str, g: float,
          extrapolate: bool, where: str) -> HazardCurve:
    """A hazard file's curve, its measure (the file's, completed by ``given``) checked against ``measure``, converted to ``units`` and to rates."""
    read = read_stated(path, given, investigation_time, site, where)
    _check_measure(where, read.stated, measure)
    return stated_curve(read, path, units, g, investigation_time, extrapolate, measure.description, where)


def read_stated(path: Path, given: StatedMeasure, investigation_time: float | None, site: Any, where: str) -> HazardFile:
    """A hazard file as read, its measure the file's completed by ``given`` and every part its kind needs stated.

    Raises
    ------
    IntensityError
        Naming ``where``'s field: an unreadable file, a part the file and ``given`` state differently, a part nobody states.
    """
    try:
        read = read_hazard_file(path, site=site)
    except (ValueError, UnicodeDecodeError) as error:
        raise IntensityError(f"{where}.file: {error}") from None
    if investigation_time is not None and read.investigation_time is not None and not _equal(investigation_time, read.investigation_time):
        raise IntensityError(f"{_field(where, 'investigation_time')}: {investigation_time!r} years, but {path.name} states "
                             f"{read.investigation_time:g} years")
    read.stated = _completed(read.stated, given, path.name, where)
    if read.stated.kind is None:
        raise IntensityError(f"{_field(where, 'measure')}: not stated: {path.name} does not say which measure its curve is of "
                             "(a '# Measure:' line, e.g. '# Measure: 5 %-damped spectral acceleration at T = 1.0 s, in g'); state it")
    stated = read.stated.entry()
    for key in _REQUIRED.get(read.stated.kind, ()):
        if key not in stated:
            example = " (e.g. 'PSA(1.0 s, 5 %) in g')" if key in ("period", "damping") and where.startswith("--") else ""
            raise IntensityError(f"{_field(where, key)}: not stated: {path.name} does not give its curve's {key}; state it{example}")
    return read


def stated_curve(read: HazardFile, path: Path, units: str, g: float, investigation_time: float | None, extrapolate: bool, description: str,
                 where: str) -> HazardCurve:
    """The annual-rate curve of a file read by :func:`read_stated`, in ``units`` (:meth:`~stochpound.analysis.HazardFile.curve`)."""
    try:
        return read.curve(units, g, investigation_time=investigation_time, extrapolate=extrapolate, description=description)
    except ValueError as error:
        message = str(error)
        if message.startswith("investigation_time:"):
            raise IntensityError(f"{_field(where, 'investigation_time')}{message.removeprefix('investigation_time')}") from None
        raise IntensityError(f"{where}.file: {path.name}: {message}") from None


def _completed(file: StatedMeasure, given: StatedMeasure, name: str, where: str) -> StatedMeasure:
    """What the file ``name`` states of its measure, completed by what ``given`` states; a part both state differently is an error."""
    stated = file.entry()
    for key, value in given.entry().items():
        if key in stated and not _equal(value, stated[key]):
            named = "" if _field(where, key).endswith(key) else f"{key} "
            raise IntensityError(f"{_field(where, key)}: {named}{value!r}, but {name} states {key} = {stated[key]!r}")
        stated[key] = value
    return StatedMeasure.from_entry(stated)


_OPTIONS = {"measure": "{where}-measure", "period": "{where}-measure", "periods": "{where}-measure", "damping": "{where}-measure",
            "units": "{where}-units", "site": "{where}-site", "investigation_time": "--investigation-time"}
"""The command-line option that states each field (a spectral measure's period and damping are in ``--hazard-measure``'s text)."""


def _field(where: str, key: str) -> str:
    """The name of a stated field: ``hazard.units`` in a file, the option that states it on the command line (``--hazard-units``;
    ``--hazard-measure`` for a period or damping, which its text gives)."""
    return f"{where}.{key}" if not where.startswith("--") else _OPTIONS[key].format(where=where)


def _bundled(name: str, measure: Measure, units: str, g: float, extrapolate: bool, where: str) -> HazardCurve:
    """A bundled curve, its measure (from its name) checked against ``measure``, converted to ``units``."""
    if name not in bundled_curves():
        raise IntensityError(f"{where}: no bundled hazard curve {name!r} (bundled: {', '.join(bundled_curves())})")
    read = read_hazard_file(bundled_path(name))
    read.stated = StatedMeasure.of(bundled_measure(name), BUNDLED_UNITS)
    _check_measure(where, read.stated, measure, bundled=name)
    return read.curve(units, g, extrapolate=extrapolate, description=measure.description)


def _check_measure(where: str, stated: StatedMeasure, measure: Measure, bundled: str = "") -> None:
    """Raise unless every stated part of the hazard's measure equals ``[intensity]``'s (units are converted, not matched)."""
    wanted = measure.entry()
    for key, value in replace(stated, units=None).entry().items():
        field = where if bundled else _field(where, key)
        what = f"{bundled!r} is {stated.measure.description}" if bundled else f"the hazard's {key} is {value!r}"
        if key not in wanted or not _equal(value, wanted[key]):
            detail = f" (intensity.{key} = {wanted[key]!r})" if key in wanted else ""
            raise IntensityError(f"{field}: the hazard's measure must be [intensity]'s, {measure.description}{detail}; {what}")


def _equal(a: Any, b: Any) -> bool:
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(_equal(x, y) for x, y in zip(a, b))
    if is_number(a) and is_number(b):
        return math.isclose(float(a), float(b), rel_tol=_TOLERANCE, abs_tol=0.0)
    return a == b


def _power_law(table: TomlTable, units: str, target: str, g: float) -> dict[str, float]:
    """``k0`` and ``k`` of λ(x) = k0 x^(−k), k0 converted to x in the levels' units (x in ``units`` → c x in ``target``: k0 c^k)."""
    law = {key: table.number(key, low=0.0, low_open=True) for key in ("k0", "k")}
    try:
        factor = unit_factor(units, target, g)
    except ValueError as error:
        raise IntensityError(f"hazard.{error}") from None
    if factor != 1.0:
        law["k0"] = law["k0"] * factor ** law["k"]
    return law


def stored_hazard(store: xr.Dataset) -> HazardCurve | None:
    """The hazard an experiment store carries (``store.pound.hazard``, typed), as a curve; None without one."""
    hazard = store.pound.hazard
    return None if hazard is None else hazard_curve(hazard)


def hazard_option(value: str, measure: Measure, units: str, g: float = DEFAULT_G, *, stated: StatedMeasure | None = None,
                  investigation_time: float | None = None, site: Any = None, extrapolate: bool = False, option: str = "--hazard") -> HazardCurve:
    """A hazard named on the command line: a bundled curve's name or a hazard-curve file, checked against the store's measure.

    Parameters
    ----------
    value : str
        A bundled curve's name or a hazard-curve file
        (:func:`~stochpound.analysis.read_hazard_file`).
    measure : Measure
        The store's intensity measure (its ``[intensity]``'s).
    units : str
        The units of the store's intensity levels (the curve's intensities are converted to them).
    g : float
        The store's g (m/s²), for a conversion to or from g.
    stated : StatedMeasure, optional
        What the options state of the file's curve, where the file does not say (``--hazard-measure``, ``--hazard-units``).
    investigation_time : float, optional
        Years of a file of probabilities of exceedance that does not state them (``--investigation-time``).
    site : int or str, optional
        The site of a file of several.
    extrapolate : bool
        Extend the table beyond its intensities as power laws.

    Raises
    ------
    IntensityError
        Neither a bundled name nor a file, an invalid file, a measure other
        than the store's or one nobody states.
    """
    if value in bundled_curves():
        return _bundled(value, measure, units, g, extrapolate, option)
    path = Path(value)
    if not path.is_file():
        raise IntensityError(f"{option}: {value!r} is neither a file nor a bundled hazard curve (bundled: {', '.join(bundled_curves())})")
    return _read(path, stated or StatedMeasure(), investigation_time, site, measure, units, g, extrapolate, option)
