"""The reference study's published numbers (``data/study/reference_tables.toml``).

Source: V. K. Agarwal, "Pounding and impact of base isolated buildings due to
earthquakes", M.S. thesis, Texas A&M University, 2004, Tables 4.1–4.10 (and
Table 3.2, kept with the records in ``data/records/registry.toml``).
"""

from __future__ import annotations

import tomllib
from functools import lru_cache
from typing import Any

from stochpound._data_files import bundled_data_dir
from stochpound._errors import StochpoundError

_FILE = "reference_tables.toml"


@lru_cache(maxsize=1)
def published_tables() -> dict[str, Any]:
    """The study's tables as a dict (the TOML file's structure).

    Returns
    -------
    dict
        ``columns.mu``, ``table.<number>`` (against μ), ``by_record`` (by
        record at μ = 0.2) and ``correlation`` (Tables 4.9–4.10).
    """
    folder = bundled_data_dir("study", _FILE)
    if folder is None:
        raise StochpoundError(f"the study's published tables ({_FILE}) are not bundled with this installation")
    with open(folder / _FILE, "rb") as handle:
        return tomllib.load(handle)


def study_number(value: Any) -> float:
    """A published cell as a float (``"NA"`` and ``"inf"`` labels aside: NA is NaN)."""
    if isinstance(value, str):
        return float("nan") if value.upper() == "NA" else float(value)
    return float(value)
