"""The site's hazard curves a fitted scenario is fitted to: the entries of ``[site] curves`` (docs/intensity.md).

An entry is one of

* a bundled curve's name (:func:`~stochpound.analysis.bundled_curves`), e.g. ``"fox_plaza_los_angeles_sa1p0s"``;
* a hazard-curve file, relative to the experiment file, whose header states its measure and units (stochpound's CSV,
  OpenQuake's or nshmp-haz's output, :func:`~stochpound.analysis.read_hazard_file`): ``"site_sa0p3s.csv"``;
* a table that names the file and states what it does not: ``{ file = "site_sa_avg.csv", measure = "sa_avg",
  periods = [0.5, 1.0, 2.0], damping = 0.05, units = "g" }`` (the keys of ``[hazard]``'s file form, and ``site`` for a file
  of several sites).

A curve is read as ``[hazard]`` reads one (a measure is never guessed: what the file and the entry leave unstated is an
error, a part they state differently too), in g (the conditional spectrum's levels: a curve in other units is refused,
not converted with an assumed g) and 5 % damping (the NGA-West2 models').
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from stochpound._errors import IntensityError, SiteError
from stochpound.hazard._curve import HazardCurve, bundled_curves, bundled_measure
from stochpound.hazard._setting import read_stated, stated_curve, stated_fields
from stochpound.motions import DEFAULT_G, Measure
from stochpound.store import TomlTable

ENTRY_KEYS = ("file", "measure", "period", "periods", "damping", "units", "investigation_time", "site")
"""The keys of a table entry of ``[site] curves``."""
MODEL_DAMPING = 0.05
"""The damping of the NGA-West2 models' spectra, the only one a fitted scenario can reproduce."""


def site_curve(entry: Any, base_dir: Path, where: str) -> tuple[Measure, HazardCurve]:
    """The measure and hazard curve (intensities in g, annual rates) of one entry of ``[site] curves`` (module docstring).

    Parameters
    ----------
    entry : str or mapping
        A bundled curve's name, a file's path (relative to ``base_dir``) or a table ``{ file = ..., measure = ..., ... }``.
    base_dir : Path
        The experiment file's folder.
    where : str
        The entry's field, for errors (e.g. ``site.curves[2]``).

    Raises
    ------
    SiteError
        Naming ``where``: neither a bundled curve nor a file, an unreadable file, a measure or units nobody states or both
        state differently, units other than g, a damping other than 5 %.
    """
    if isinstance(entry, str) and entry in bundled_curves():
        return bundled_measure(entry), HazardCurve.bundled(entry)
    if not isinstance(entry, (str, dict)):
        raise SiteError(f"{where}: a bundled hazard curve's name, a hazard-curve file or a table {{ file = ..., measure = ... }}, got {entry!r}")
    table = TomlTable({"file": entry} if isinstance(entry, str) else entry, where, ENTRY_KEYS, raises=SiteError)
    name = table.string("file")
    path = base_dir / name
    if not path.is_file():
        raise SiteError(f"{where}: {name!r} is neither a bundled hazard curve nor a file (relative to the experiment file); "
                        f"bundled: {', '.join(bundled_curves())}")
    investigation_time = table.number("investigation_time", None, low=0.0, low_open=True)
    try:
        read = read_stated(path, stated_fields(table), investigation_time, table.raw("site"), where)
        measure = read.stated.measure
        if read.stated.units != "g":
            raise SiteError(f"{where}.units: the fit takes curves in g (the conditional spectrum's levels), {path.name}'s are in "
                            f"{read.stated.units}; convert them")
        if measure.damping is not None and measure.damping != MODEL_DAMPING:
            raise SiteError(f"{where}.damping: the NGA-West2 models give 5 % damped spectra only (0.05), got {measure.damping!r}")
        return measure, stated_curve(read, path, "g", DEFAULT_G, investigation_time, False, measure.description, where)
    except SiteError:
        raise
    except IntensityError as error:
        raise SiteError(str(error)) from None
    except ValueError as error:  # a stated part out of its range (Measure's)
        raise SiteError(f"{where}.{error}") from None


def site_curve_label(entry: Any) -> str:
    """How an entry of ``[site] curves`` is named in a definition and a note: the curve's name or its file."""
    return str(entry["file"]) if isinstance(entry, dict) and "file" in entry else str(entry)
