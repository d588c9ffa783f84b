"""The study's records: its g, its Table 3.2 and a record's statistics with that table beside ours.

These were ``stochpound.motions.records.STUDY_G`` and ``study_table_3_2`` (now
deprecated there: the records package keeps no study's convention) and the
text of ``stochpound records show``.
"""

from __future__ import annotations

import tomllib
from functools import lru_cache
from typing import Any

from stochpound.motions.records import Record, record_statistics, records_dir
from stochpound.store import TomlTable

#: The reference study's g, m/s².
STUDY_G = 9.814


def study_table_3_2(row: str | None = None) -> dict[str, Any]:
    """The reference study's Table 3.2 (acceleration statistics of its four records).

    Parameters
    ----------
    row : str, optional
        ``"mexico_city"``, ``"el_centro"``, ``"loma_prieta"`` or ``"northridge"``;
        all rows (a dict of dicts) if omitted.

    Returns
    -------
    dict
        ``label, dt (s), npts, peak_g, mean, std (m/s²), skewness, excess``.
    """
    table = _table_3_2()
    return dict(table) if row is None else dict(table[row])


@lru_cache(maxsize=1)
def _table_3_2() -> dict[str, Any]:
    """The ``study_table_3_2`` table of the bundled records' ``registry.toml``."""
    with open(records_dir() / "registry.toml", "rb") as handle:
        return dict(TomlTable(tomllib.load(handle)).table_or_empty("study_table_3_2").values)

_ROWS = (
    ("npts", "points", "{:d}"),
    ("dt", "dt (s)", "{:g}"),
    ("duration", "duration (s)", "{:.2f}"),
    ("peak_g", "peak (g)", "{:.4f}"),
    ("mean", "mean (m/s2)", "{:.5g}"),
    ("std", "std (m/s2)", "{:.4f}"),
    ("skewness", "skewness", "{:.4f}"),
    ("excess", "excess (kurtosis-3)", "{:.4f}"),
    ("arias", "Arias intensity (m/s)", "{:.4f}"),
)


def record_report(record: Record, g: float = STUDY_G) -> str:
    """Multi-line report: identity, provenance and statistics of a record.

    For records related to one of the study's four records (registry field
    ``study_row``), the study's Table 3.2 values are printed beside ours,
    with the relation (same record, reconstruction, substitute).

    Parameters
    ----------
    record : Record
        The record.
    g : float
        m/s² for unit conversion, the peak in g and the Arias intensity.
    """
    stats = record_statistics(record, g=g).as_dict()
    metadata = TomlTable(record.metadata, f"records.{record.name}")
    row_key = metadata.string("study_row", None)
    study = study_table_3_2(str(row_key)) if row_key else None
    lines = [
        f"{record.name}",
        f"  {record.description}" if record.description else "",
        f"  provenance: {record.provenance}",
        f"  units in file: {record.units}"
        + (f"; the source's first sample is at t = {record.source_start_time:g} s (shifted to t = 0)" if record.source_start_time else ""),
        f"  statistics: population moments, excess = kurtosis - 3, g = {g:g} m/s2",
        "",
    ]
    if study:
        lines.append(f"  {'':24s}{'this record':>16s}{'study Table 3.2':>18s}")
    for key, label, fmt in _ROWS:
        ours = fmt.format(stats[key])
        theirs = ""
        if study and key in study:
            theirs = fmt.format(study[key]) if key != "npts" else f"{int(study[key]):d}"
        elif study and key == "npts":
            theirs = f"{int(study['npts']):d}"
        lines.append(f"  {label:24s}{ours:>16s}{theirs:>18s}" if study else f"  {label:24s}{ours:>16s}")
    if study:
        relation = metadata.string("study_relation", "")
        lines += ["", f"  study record: {study['label']}; relation: {relation}"]
    return "\n".join(line for line in lines if line is not None)
