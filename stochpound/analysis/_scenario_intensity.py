"""What a scenario ensemble's motions are, as run: their high-pass corner and their intensity beside the NGA-West2 average.

A store keeps a scenario ensemble (``type = "scenario_motions"``) as its table,
not its motions; :meth:`ScenarioIntensity.of` regenerates the motions the store
ran (realizations ``start`` .. ``start + count − 1`` of the table's seed, bit
for bit) and measures them: the range of their post-filter's corner, and the
median and σ of ln PGA and ln PSA(1 s, 5 % damping) over the motions, beside
the scenario's NGA-West2 average (the median and σ the hazard-compatible
calibration aims at; :func:`~stochpound.motions.scenario_distribution`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from stochpound.motions import DEFAULT_G, response_spectrum, scenario_distribution, scenario_motions

#: The measures compared: (name, measure of :func:`~stochpound.motions.scenario_distribution`, period in s or None).
MEASURES: tuple[tuple[str, str, float | None], ...] = (("PGA", "pga", None), ("PSA(1 s)", "psa", 1.0))


@dataclass(frozen=True)
class MeasureIntensity:
    """One measure over the motions as run (g; σ of ln, NaN from one motion) and the scenario's NGA-West2 average (g; σ of ln)."""

    name: str
    median: float
    sigma_ln: float
    target_median: float
    target_sigma_ln: float


@dataclass(frozen=True)
class ScenarioIntensity:
    """A scenario ensemble's motions as run: how many, their corner's range (Hz) and their intensity per measure."""

    count: int
    corner_low: float
    corner_high: float
    measures: tuple[MeasureIntensity, ...]

    @classmethod
    def of(cls, table: Mapping[str, float | str], start: int, count: int) -> ScenarioIntensity:
        """The motions ``start`` .. ``start + count − 1`` of a scenario ensemble's table, regenerated and measured (module docstring).

        Parameters
        ----------
        table : mapping
            The ensemble's ``[motion]`` table as the store keeps it (scenario, ``seed``, ``dt``, ``duration`` in s, ``model``, ``calibration``).
        start, count : int
            The first realization and the number of realizations the store ran (count ≥ 1).

        Returns
        -------
        ScenarioIntensity
            Medians in g (g = :data:`~stochpound.motions.DEFAULT_G`, as the calibration's check takes it), corner in Hz.
        """
        scenario = {"magnitude": float(table["magnitude"]), "distance_km": float(table["distance_km"]), "vs30": float(table["vs30"]),
                    "mechanism": str(table["mechanism"])}
        motions = scenario_motions(count, float(table["duration"]), float(table["dt"]), **scenario, seed=int(table["seed"]), start=start,
                                   model=str(table["model"]), calibration=str(table["calibration"]))
        values, dt = motions.values, float(motions.attrs["dt"])
        ln = {"pga": np.log(np.abs(values).max(axis=1) / DEFAULT_G),
              "psa": np.log([float(response_spectrum(row, dt, [1.0])["psa"][0]) / DEFAULT_G for row in values])}
        measures = []
        for name, measure, period in MEASURES:
            median, sigma = scenario_distribution(measure, period, **scenario)
            sample = ln[measure]
            measures.append(MeasureIntensity(name, float(np.exp(np.median(sample))), float(np.std(sample, ddof=1)) if count > 1 else float("nan"),
                                             float(median), float(sigma)))
        corners = motions["f_corner"].values
        return cls(count, float(corners.min()), float(corners.max()), tuple(measures))
