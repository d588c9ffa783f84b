"""How far g* moves under the choices the answer rests on, from one store: the sensitivity table beside g*.

The interval of g* (and "the gap to design to", its upper bound) covers the
sampling of the motions only. Larger, systematic choices move g* too; those
one store can answer are recomputed here, each alone, with no bootstrap:

* **the gap grid**: g* read off a grid ``REFINEMENT`` times finer over the same
  range (the chain's grid is log-spaced; g* is interpolated between its gaps);
* **the collapse treatment**: the runs beyond the model counted apart as
  collapses (:func:`~stochpound.risk.collapse_risk`), where some run is;
* **modelling dispersion**: β_m folded into every fitted fragility,
  β' = √(β² + β_m²) (the square root of the sum of squares by which FEMA
  P-58 and FEMA P695 combine independent dispersions; a step at θ becomes a
  lognormal of β_m; P-58's range for modelling uncertainty is 0.2–0.4,
  ``MODELLING_DISPERSIONS``).

The selection seed, the conditioning measure and the moat wall's stiffness
need other runs (another store): the table names them as not evaluated.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np
import pandas as pd
import xarray as xr

from stochpound.risk._collapse import CollapseRisk
from stochpound.risk._fragility import DECREASING, EMPTY, NEVER, ALWAYS
from stochpound.risk._maf import mean_annual_frequency, risk_targeted_separation

REFINEMENT = 4
"""How many times finer the refined gap grid is."""
MODELLING_DISPERSIONS = (0.2, 0.4)
"""β_m folded into the fragility: the ends of FEMA P-58's range for modelling uncertainty."""
NOT_EVALUATED = ("the selection seed", "the conditioning measure", "the moat wall's stiffness")
"""Choices one store cannot vary: each needs other runs."""


@dataclasses.dataclass(frozen=True)
class Sensitivity:
    """The sensitivity table of g* (:func:`separation_sensitivity`).

    Attributes
    ----------
    frame : pandas.DataFrame
        Indexed by the configuration and ``target``; columns ``g* (m)`` and, per choice, its g* and ``Δ (%)``.
    """

    frame: pd.DataFrame

    def text(self) -> str:
        """The table's message in words (:func:`sensitivity_text`)."""
        return sensitivity_text(self.frame)


def separation_sensitivity(risk: object, store: xr.Dataset, collapse: CollapseRisk | None = None,
                           dispersions: Sequence[float] = MODELLING_DISPERSIONS, refinement: int = REFINEMENT) -> Sensitivity:
    """g* under each choice one store can vary, per configuration and target (m), with its change from g* (%).

    Parameters
    ----------
    risk : StoreRisk
        The chain's answer (:func:`~stochpound.risk.store_risk`) of a stripes store.
    store : xarray.Dataset
        The same store (refitted on the finer grid).
    collapse : CollapseRisk, optional
        The answer with collapses counted apart (a column where some run collapsed).
    dispersions : sequence of float
        β_m values folded into the fragility (> 0).
    refinement : int
        How many times finer the refined grid is (>= 2).

    Returns
    -------
    Sensitivity
        Its ``frame``: indexed by the configuration and ``target``; columns ``g* (m)`` and, per choice, its g* and ``Δ (%)``.
    """
    from stochpound.risk._chain import store_risk

    if refinement < 2:
        raise ValueError(f"refinement: must be an integer >= 2, got {refinement!r}")
    for value in dispersions:
        if not value > 0.0:
            raise ValueError(f"dispersions: each β_m must be > 0, got {value!r}")
    gaps = risk.fragility["gap"].values
    targets, years = risk.separation["target"].values, risk.years
    columns = {"g* (m)": risk.separation["separation"]}
    fine = store_risk(store, risk.hazard, targets, years, gaps=np.geomspace(gaps[0], gaps[-1], refinement * (gaps.size - 1) + 1), bootstrap=0,
                      partial=bool(risk.progress))  # an unfinished store answered from what ran, as the chain's answer was
    columns[f"grid ×{refinement} finer"] = fine.separation["separation"]
    if collapse is not None and collapse.collapsed:
        columns["collapses apart"] = collapse.separation["separation"]
    for value in dispersions:
        columns[f"β_m = {value:g}"] = _with_dispersion(risk.fragility, value, risk.hazard, targets, years)
    table = xr.Dataset({name: _dims_only(data) for name, data in columns.items()}).to_dataframe()
    frame = table.reset_index()
    frame["target"] = [f"{100 * p:g} % in {years:g} yr" for p in frame["target"]]
    config = [name for name in frame.columns if name not in columns and name != "target"]
    frame = frame.set_index([*config, "target"])
    base = frame["g* (m)"]
    for name in [c for c in columns if c != "g* (m)"]:
        with np.errstate(invalid="ignore", divide="ignore"):
            frame[f"{name}: Δ (%)"] = 100.0 * (frame[name] / base - 1.0)
    return Sensitivity(frame[["g* (m)", *(c for name in columns if name != "g* (m)" for c in (name, f"{name}: Δ (%)"))]])


def _with_dispersion(fragility: xr.Dataset, dispersion: float, hazard: object, targets: np.ndarray, years: float) -> xr.DataArray:
    """g* with β_m folded into every fit: β' = √(β² + β_m²); steps 'never', 'always', flat and empty fits as they are."""
    status = fragility["status"]
    kept = (status == NEVER) | (status == ALWAYS) | (status == DECREASING) | (status == EMPTY)
    beta = np.sqrt(fragility["beta"] ** 2 + dispersion**2).where(~kept, fragility["beta"])
    maf = mean_annual_frequency(fragility.assign(beta=beta), hazard)
    return risk_targeted_separation(xr.Dataset({"maf": maf}), targets, years)["separation"]


def sensitivity_text(frame: pd.DataFrame) -> str:
    """The table's message in words: the largest change of each choice, and what is not evaluated."""
    changes = [column for column in frame.columns if column.endswith("Δ (%)")]
    said = []
    for column in changes:
        values = frame[column].to_numpy(dtype=float)
        finite = values[np.isfinite(values)]
        what = column.removesuffix(": Δ (%)")
        said.append(f"{what}: up to {np.max(np.abs(finite)):.1f} %" if finite.size else f"{what}: no finite change (g* inf on one side)")
    return ("Sensitivity of g* to the choices it rests on (each alone, no bootstrap; Δ from g*): " + "; ".join(said)
            + ". β_m cannot spread a gap no run closes (a 'never' step has no θ): its λ stays 0, so g* with β_m stops at the widest "
            f"gap some run closes. Not evaluated from this store (each needs other runs): {', '.join(NOT_EVALUATED)}. The interval of g* "
            "and the gap to design to bound the sampling of the motions only, not these.")


def _dims_only(data: xr.DataArray) -> xr.DataArray:
    """``data`` without its coordinates that are not dimensions."""
    return data.drop_vars([name for name in data.coords if name not in data.dims])
