"""Findings qualified by their data: no ratio from too few runs, and where the sign of an effect flips, said where."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import xarray as xr

from stochpound.report.sections._ensemble_findings import isolation_across, isolation_effect, spread
from stochpound.report.sections._ensembles import MIN_RUNS


def _ensemble(label: str, p_isolated: dict[str, float], size: int = 200, forces: int = 0) -> SimpleNamespace:
    """An ensemble-like object whose statistics give P(pounding) per neighbour: 0.5 on a fixed base, ``p_isolated`` at μ = 0.1 (intervals ±0.05)."""
    neighbours, mus, gaps = list(p_isolated), [0.1, math.inf], [0.02, 0.06]
    p = np.array([[[p_isolated[n]] * len(gaps), [0.5] * len(gaps)] for n in neighbours])
    dims = ("neighbour", "mu", "gap")
    coords = {"neighbour": neighbours, "mu": mus, "gap": gaps}
    quantile = xr.DataArray(np.stack([np.ones(p.shape), 2 * np.ones(p.shape)], -1), dims=(*dims, "quantile"), coords={**coords, "quantile": [0.5, 0.95]})
    statistics = xr.Dataset(
        {
            "pounding_probability": (dims, p), "pounding_probability_lower": (dims, p - 0.05), "pounding_probability_upper": (dims, p + 0.05),
            "peak_total_displacement_quantile": quantile, "peak_impact_force_quantile": quantile * 1e5,
            "peak_impact_force_count": (dims, np.full(p.shape, forces)),
            **{f"peak_{kind}_displacement_{part}": (dims, np.full(p.shape, 0.1 + (0.01 if part == "upper" else -0.01 if part == "lower" else 0.0)))
               for kind in ("total", "relative") for part in ("mean", "lower", "upper")},
        },
        coords=coords,
    )
    return SimpleNamespace(statistics=statistics, grid=coords, mus=mus, label=label, name="x", size=size, confidence=0.95, studied="B1",
                           event="pounding")


def test_the_sign_flip_of_isolation_is_located_by_condition():
    """Isolation lowers P(pounding) next to a flexible neighbour and raises it next to a stiff one: the finding says so, by neighbour."""
    paragraph = isolation_effect(_ensemble("kt_firm", {"stiff": 0.8, "flexible": 0.2}))[0]
    assert "lowers the probability of pounding in 2 and raises it in 2" in paragraph.text
    assert "flips with neighbour" in paragraph.text and "stiff: 0 lower, 2 higher; flexible: 2 lower, 0 higher" in paragraph.text
    same = isolation_effect(_ensemble("kt_firm", {"stiff": 0.2, "flexible": 0.2}))[0]
    assert "flips" not in same.text


def test_a_sign_flip_between_ensembles_is_named():
    firm, soft = _ensemble("kt_firm", {"stiff": 0.2, "flexible": 0.2}), _ensemble("kt_soft", {"stiff": 0.8, "flexible": 0.8})
    text = isolation_across([firm, soft]).text
    assert "changes sign between the ensembles" in text and "than it raises it in kt_firm" in text and "raises it in more cells than it lowers it in kt_soft" in text
    assert "the same way in every ensemble" in isolation_across([firm, _ensemble("kt_rock", {"stiff": 0.1, "flexible": 0.3})]).text
    assert isolation_across([firm]) is None


def test_no_ratio_from_cells_with_too_few_runs():
    """Below MIN_RUNS realizations (pounding realizations for the force) the spread is not estimated, and the count is stated."""
    few = spread(_ensemble("kt", {"stiff": 0.8, "flexible": 0.2}, size=MIN_RUNS - 1, forces=4)).text
    assert f"With {MIN_RUNS - 1} realizations per cell (fewer than {MIN_RUNS})" in few and "times its median" not in few
    assert f"No cell has {MIN_RUNS} pounding realizations (at most 4)" in few
    enough = spread(_ensemble("kt", {"stiff": 0.8, "flexible": 0.2}, size=200, forces=MIN_RUNS)).text
    assert "2.00 to 2.00 times its median (n = 200 per cell)" in enough
    assert f"In the 8 cells with at least {MIN_RUNS} pounding realizations (n = {MIN_RUNS}–{MIN_RUNS})" in enough


def test_convergence_starts_at_min_runs_in_a_handful_of_panels():
    """40 realizations on a 5 gaps × 3 μ grid: estimates at n = 30 … 40, in CONVERGENCE_PANELS panels, those nearest P = 0.5."""
    from stochpound.analysis._store_ensemble import CONVERGENCE_PANELS
    from stochpound.report.sections._ensembles import Ensemble

    rng = np.random.default_rng(4)
    gaps, mus, n = [0.0, 0.01, 0.02, 0.04, 0.08], [0.1, 0.2, math.inf], 40
    shape = (1, n, len(gaps), len(mus))
    rate = np.array([2.0, 0.7, 0.3, 0.05, 0.0])[None, None, :, None]
    dims = ("record", "realization", "gap", "mu")
    store = xr.Dataset(
        {
            "case_status": (dims, np.ones(shape, int)),
            "impacts": (dims, rng.poisson(np.broadcast_to(rate, shape)).astype(float)),
            "peak_total_displacement": ((*dims, "building"), rng.lognormal(-3.0, 0.4, shape + (1,)), {"units": "m"}),
            "record_kind": ("record", ["synthetic"]),
        },
        coords={"record": ["kt"], "realization": np.arange(n), "gap": gaps, "mu": mus, "building": ["B1"]},
        attrs={"studied_building": "B1"},
    )
    ensemble = Ensemble("x", store, "kt")
    items = ensemble.convergence()
    assert [item.key for item in items] == ["figure-x-kt-convergence-pounding", "figure-x-kt-convergence-peak"]
    for item in items:
        assert len([ax for ax in item.figure.axes if ax.lines]) == CONVERGENCE_PANELS
        for ax in item.figure.axes:
            for line in ax.lines:
                assert min(line.get_xdata()) >= MIN_RUNS
    # μ is drawn as lines; of the 5 gaps the 4 with P(pounding) nearest 0.5 are panels (never pounding at 8 cm, the farthest, is left out)
    assert items[0].caption.endswith("nearest 0.5, the slowest to settle: gap 0 cm, 1 cm, 2 cm, 4 cm.")


def test_a_tie_is_not_a_sign_of_isolations_effect():
    from stochpound.report.sections._ensemble_findings import isolation_verdict

    tie_and_lower = isolation_verdict({"firm": (4, 4, 36), "soft": (9, 2, 36)})
    assert "changes sign" not in tie_and_lower and "in none" not in tie_and_lower
    assert "lowers it in more cells than it raises it in soft" in tie_and_lower and "as many cells in firm" in tie_and_lower
    flipped = isolation_verdict({"firm": (1, 6, 36), "soft": (9, 2, 36)})
    assert flipped.startswith("The effect of isolation on the probability of pounding changes sign")
    assert "raises it in more cells than it lowers it in firm" in flipped
