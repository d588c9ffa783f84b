"""The gap grid of the risk chain, refined near each g* until g* no longer moves with it.

λ_P(g) is known only at the grid's gaps, and g* is interpolated between the
two that bracket its target (``stochpound.risk._maf.risk_targeted_separation``:
linear in ln λ against ln g). That interpolation is exact for a power law, not
for the chain's λ_P of stripes: every gap's fit comes from the same runs'
events (pounding at g iff the contact-free closure D ≥ g), which change only
where g passes a run's closure, so λ_P(g) is a step function of g with its
steps at the closures. Within a bracket the step can be anywhere: the
interpolated g* is off by up to the bracket's width (about 8 % on 60 gaps
over a factor 100 of closures). So the chain splits every bracket that holds
a g* (:func:`refinement_gaps`), ``SPLIT`` times in ln g, and refits there
only, until each lies between two gaps at most ``GRID_TOLERANCE`` apart: a
finer grid then moves it by less than that wherever the non-increasing fit
of λ_P still crosses the target inside that bracket (the fit weighs each gap
by the share of ln g it stands for, ``stochpound.risk._maf.gap_weights``,
so the refined stretches do not outweigh the rest).

The bounds of g*'s interval are read on the same grid, not refined for
themselves: they are percentiles of g* over the resamples, each resample's
g* in a bracket of its own, and chasing them refines the tail of the
resamples (where a few resamples' fits turn flat and their g* jumps to the
widest gap some run closes) rather than the bounds' own digits.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

GRID_TOLERANCE = 0.005
"""The relative width g_(k+1)/g_k − 1 of the widest bracket a g* may lie in once the grid is refined."""
SPLIT = 4
"""How many parts (equal in ln g) a bracket is split into at each refinement."""
MAX_REFINEMENTS = 8
"""Refinements at most (each divides a bracket's width in ln g by ``SPLIT``: 4⁸ from 8 % is far below the tolerance)."""


def refinement_gaps(grid: np.ndarray, separation: xr.Dataset, tolerance: float = GRID_TOLERANCE, split: int = SPLIT) -> np.ndarray:
    """The gaps (m) that split, ``split`` times in ln g, every interval of ``grid`` wider than ``tolerance`` that holds a g*.

    Parameters
    ----------
    grid : numpy.ndarray
        The gap grid (m), strictly increasing.
    separation : xarray.Dataset
        g* (``separation``, m) solved on ``grid``.
    tolerance : float
        Relative width (g_(k+1)/g_k − 1) below which an interval is left as it is (≥ 0; 0: split every interval holding a value).
    split : int
        Parts each interval is split into (≥ 2).

    Returns
    -------
    numpy.ndarray
        The new gaps, sorted, none on ``grid`` (empty when every value lies in an interval narrow enough, is infinite,
        NaN, or is the grid's first gap: the target met at the narrowest gap, nothing below to resolve).
    """
    if not tolerance >= 0.0:
        raise ValueError(f"tolerance: must be >= 0, got {tolerance!r}")
    if split < 2:
        raise ValueError(f"split: must be an integer >= 2, got {split!r}")
    values = np.asarray(separation["separation"].values, dtype=float).ravel()
    values = values[np.isfinite(values) & (values > grid[0]) & (values <= grid[-1])]
    upper = np.searchsorted(grid, values, side="left")  # grid[upper - 1] < value <= grid[upper]
    on_gap = np.isclose(values, grid[upper], rtol=1e-12, atol=0.0) & (upper + 1 < grid.size)
    intervals = np.unique(np.concatenate([upper - 1, upper[on_gap]]))  # a value on a gap: the steps either side of it
    wide = intervals[grid[intervals + 1] / grid[intervals] - 1.0 > tolerance]
    parts = np.linspace(0.0, 1.0, split + 1)[1:-1]
    log_grid = np.log(grid)
    added = np.exp(log_grid[wide, None] + parts[None, :] * (log_grid[wide + 1] - log_grid[wide])[:, None]).ravel()
    return np.unique(added)


def grid_note(gaps: int, coarse: int, refinements: int, tolerance: float, converged: bool) -> str:
    """How the chain's gap grid was made, in words (the separation's ``grid`` attribute)."""
    refined = (f"refined {refinements} time{'s' if refinements != 1 else ''} near each g* to {gaps} gaps, "
               if refinements else "not refined: ")
    settled = (f"each g* between two gaps at most {100 * tolerance:g} % apart" if converged else
               f"NOT every g* between two gaps at most {100 * tolerance:g} % apart after {MAX_REFINEMENTS} refinements")
    return f"{coarse} log-spaced gaps, {refined}{settled}"
