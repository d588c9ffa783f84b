"""The :class:`Record` type: one uniformly sampled ground-acceleration history."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Mapping

import numpy as np

from stochpound.motions._arias import DEFAULT_G
from stochpound.motions.records._units import TO_SI, normalize_units


@dataclass
class Record:
    """A ground-acceleration record sampled at a uniform step.

    Parameters
    ----------
    name : str
        Registry name (``"el_centro_1940"``) or the file name it was read from.
    dt : float
        Sample spacing, s.
    values : np.ndarray
        Samples in ``units`` (float64). Sample ``k`` is at ``t = k·dt``: the
        time axis starts at the first sample. A file whose first sample is at
        a later source time (e.g. ``t = dt``, as in Chopra's El Centro table or
        the SCT file) is shifted, not padded; the source time of the first
        sample is kept in ``source_start_time``.
    units : {"g", "m/s2", "cm/s2"}
        Units of ``values``.
    description : str
        What the record is (event, station, component, version).
    provenance : str
        Where it comes from: source, file name, sha256, transformations, and
        ``SUBSTITUTE for ...`` where the record stands in for another one.
    source_start_time : float
        Time of the first sample in the source file's own clock, s.
    metadata : Mapping[str, float | str]
        Registry fields (e.g. ``substitute_for``, ``study_row``) or a suite motion's (``event``, ``magnitude``...), informative only.
    """

    name: str
    dt: float
    values: np.ndarray
    units: str
    description: str = ""
    provenance: str = ""
    source_start_time: float = 0.0
    metadata: Mapping[str, float | str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.values = np.asarray(self.values, dtype=np.float64)
        self.units = normalize_units(self.units)
        self.dt = float(self.dt)

    @property
    def npts(self) -> int:
        """Number of samples."""
        return int(self.values.size)

    @property
    def time(self) -> np.ndarray:
        """Sample times ``k·dt``, s (first sample at 0)."""
        return np.arange(self.npts) * self.dt

    @property
    def duration(self) -> float:
        """Time of the last sample, ``(npts − 1)·dt``, s."""
        return (self.npts - 1) * self.dt

    def acceleration(self, g: float = DEFAULT_G) -> np.ndarray:
        """The samples in m/s².

        Parameters
        ----------
        g : float
            Acceleration of gravity used to convert values in g, m/s². The
            reference study used 9.814. Ignored for records in m/s² or cm/s².
        """
        factor = TO_SI[self.units]
        return self.values * (float(g) if factor is None else factor)
