"""What the benchmarks compare between solvers, and how errors are measured.

Every solver of the suite (stochpound's ``exact`` and ``ivp`` paths, the
emulation of the study's scheme, OpenSeesPy) is reduced to one
:class:`Outcome`: Building 1's top-floor total displacement at the motion's
sample times, the number of impacts, the peak impact force and Building 1's
final sliding displacement. :func:`compare` measures one outcome against a
reference outcome.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import xarray as xr


@dataclass(frozen=True)
class Outcome:
    """The quantities compared between solvers (Building 1 = the leftmost building).

    Attributes
    ----------
    times : np.ndarray
        Sample times of the ground motion, s.
    top_displacement : np.ndarray
        Total displacement y = s + u of Building 1's top floor at ``times``, m.
    impacts : int
        Number of impacts (contact closures) over all contacts.
    peak_force : float
        Largest contact force of the run, N (0 without impacts).
    final_sliding : float
        Sliding displacement of Building 1's base at the end, m (0 for a fixed base).
    """

    times: np.ndarray
    top_displacement: np.ndarray
    impacts: int
    peak_force: float
    final_sliding: float


@dataclass(frozen=True)
class Errors:
    """Errors of one outcome against a reference outcome.

    Attributes
    ----------
    displacement : float
        max over the samples of |y − y_ref| for Building 1's top floor, m.
    impacts : int
        Number of impacts minus the reference's.
    peak_force : float
        Relative error of the peak impact force (0 when both have no impact).
    final_sliding : float
        |s_end − s_end,ref| of Building 1's base, m.
    """

    displacement: float
    impacts: int
    peak_force: float
    final_sliding: float


def outcome_from_dataset(run: xr.Dataset) -> Outcome:
    """Reduce a stochpound result dataset to an :class:`Outcome`.

    Plain numpy on the variables' arrays (xarray's label selection would add
    about half a millisecond to every timed run of the fast solvers).
    """
    floors = _first_building(run["total_displacement"], ("floor", "time"))
    top = floors[~np.all(np.isnan(floors), axis=1)][-1]
    impacts = int(run.sizes.get("impact", 0))
    return Outcome(
        times=np.asarray(run["time"].values, float),
        top_displacement=np.asarray(top, float),
        impacts=impacts,
        peak_force=float(np.max(run["impact_peak_force"].values)) if impacts else 0.0,
        final_sliding=float(_first_building(run["sliding_displacement"], ("time",))[-1]),
    )


def _first_building(variable: xr.DataArray, dims: tuple[str, ...]) -> np.ndarray:
    """The values of ``variable`` for the scene's first building, with axes ``dims``."""
    axes = [variable.get_axis_num(name) for name in ("building", *dims)]
    return np.moveaxis(variable.values, axes, range(len(axes)))[0]


def compare(outcome: Outcome, reference: Outcome) -> Errors:
    """Errors of ``outcome`` against ``reference`` (same sample times)."""
    if outcome.times.shape != reference.times.shape or not np.allclose(outcome.times, reference.times, atol=1e-9):
        raise ValueError("outcomes are sampled at different times")
    scale = max(abs(reference.peak_force), 1e-300)
    return Errors(
        displacement=float(np.max(np.abs(outcome.top_displacement - reference.top_displacement))),
        impacts=outcome.impacts - reference.impacts,
        peak_force=abs(outcome.peak_force - reference.peak_force) / scale if reference.peak_force else abs(outcome.peak_force),
        final_sliding=abs(outcome.final_sliding - reference.final_sliding),
    )
