"""Statistics of an accelerogram, in the convention of the reference study's Table 3.2.

* population moments (ddof = 0);
* skewness = m3 / m2^1.5, excess = m4 / m2² − 3 (the study's "coefficient of excess");
* peak = max abs(a), in g;
* Arias intensity I_A = π / (2 g) ∫ a(t)² dt, with a(t) interpolated linearly
  between samples (the first-order hold the solvers use), so that the integral
  over each step is dt (a_k² + a_k a_{k+1} + a_{k+1}²) / 3
  (``stochpound.motions._arias.arias_intensity``).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from stochpound.stats import kernels
from stochpound.motions._arias import DEFAULT_G, arias_intensity
from stochpound.motions.records._record import Record



@dataclass(frozen=True)
class RecordStatistics:
    """Summary statistics of one record (accelerations in m/s²).

    Attributes
    ----------
    npts : int
        Number of samples.
    dt : float
        Step, s.
    duration : float
        Time of the last sample, (npts − 1)·dt, s.
    peak_g : float
        max abs(a) / g.
    mean, std : float
        Population mean and standard deviation, m/s².
    skewness, excess : float
        m3/m2^1.5 and m4/m2² − 3.
    arias : float
        Arias intensity, m/s.
    g : float
        The g used for conversions, m/s².
    """

    npts: int
    dt: float
    duration: float
    peak_g: float
    mean: float
    std: float
    skewness: float
    excess: float
    arias: float
    g: float

    def as_dict(self) -> dict[str, float]:
        """The fields as a plain dict."""
        return asdict(self)


def moments(values: np.ndarray) -> tuple[float, float, float, float]:
    """Population mean, standard deviation, skewness and excess kurtosis.

    Parameters
    ----------
    values : np.ndarray
        A 1-D sample.

    Returns
    -------
    mean, std, skewness, excess : float
        ``std`` with ddof = 0; ``skewness = m3/m2**1.5``; ``excess = m4/m2**2 − 3``
        (NaN skewness and excess for a constant sample).
    """
    result = kernels.moments(np.asarray(values, dtype=np.float64))
    return float(result.mean), float(result.std), float(result.skewness), float(result.excess)


def record_statistics(record: Record, g: float = DEFAULT_G) -> RecordStatistics:
    """Statistics of a record in the study's convention (module docstring).

    Parameters
    ----------
    record : Record
        The record.
    g : float
        g for converting values in g to m/s² and for the peak in g and the
        Arias intensity, m/s². Default: 9.81 (the reference study's 9.814
        is :data:`stochpound.studies.agarwal2004.STUDY_G`).
    """
    a = record.acceleration(g=g)
    mean, std, skewness, excess = moments(a)
    return RecordStatistics(
        npts=record.npts,
        dt=record.dt,
        duration=record.duration,
        peak_g=float(np.max(np.abs(a))) / g,
        mean=mean,
        std=std,
        skewness=skewness,
        excess=excess,
        arias=arias_intensity(a, record.dt, g),
        g=g,
    )
