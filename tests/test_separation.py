"""The pounding-probability identity: a run pounds at gap g exactly when its contact-free twin's peak closure D reaches g.

The same Kanai–Tajimi realizations are run contact-free (gap = inf) and with
gaps, for the study's pair (Building 1 next to the flexible Building 2, both
floors in contact) on fixed and on sliding bases. Gaps 10 nm either side of
each run's D check that D is located on the solution (in these runs the
largest closure at the 0.01 s output samples falls short of it by up to 0.16 mm).
"""

import dataclasses
import math

import numpy as np
import pytest
import xarray as xr

import stochpound
from stochpound.analysis import contact_demands, pounding_curve
from stochpound.model.scene import Scene
from tests.conftest import study_scene

KANAI_TAJIMI = {"type": "kanai_tajimi", "omega_g": 15.0, "zeta_g": 0.6, "pga": 3.4, "envelope": "jennings", "seed": 3, "duration": 20.0, "dt": 0.01}
REALIZATIONS = (0, 1, 2)
GRID = (0.02, 0.06, 0.095)  # m, the same at both contacts (the largest splits both ensembles)
SHARP = 1e-8  # m: gaps this far from D
TIE = 1e-9  # m: closer than this to D, either outcome is right


def contact_free_scene(mu1: float | None, realization: int) -> Scene:
    return stochpound.scene_from_dict(study_scene(mu1=mu1, gap=math.inf, motion={**KANAI_TAJIMI, "realization": realization}))


def with_gaps(scene: Scene, gaps: tuple[float, float]) -> Scene:
    """``scene`` with contact c's gap set to ``gaps[c]`` (m)."""
    return dataclasses.replace(scene, contacts=tuple(dataclasses.replace(c, gap=float(g)) for c, g in zip(scene.contacts, gaps)))


@pytest.mark.parametrize("mu1", [None, 0.2], ids=["fixed", "sliding"])
def test_a_run_pounds_at_gap_g_exactly_when_its_contact_free_peak_closure_reaches_g(mu1):
    peak, pounded = [], []
    for realization in REALIZATIONS:
        free_scene = contact_free_scene(mu1, realization)
        free = stochpound.simulate(free_scene)
        assert free.sizes["impact"] == 0 and np.all(np.isinf(free["contact_gap"]))
        closure = free["peak_contact_closure"].values
        assert np.all(closure >= free["contact_closure"].max("time").values)  # located on the solution, at or above the samples
        peak.append(closure)
        d, top = closure.max(), int(np.argmax(closure))
        # (gaps of the two contacts, the contact whose peak is the only place the run touches, if any)
        cases = [((g, g), None) for g in GRID]
        cases += [((d - SHARP, d - SHARP), top), ((d + SHARP, d + SHARP), None)]
        cases += [((closure[0] - SHARP, closure[1] + SHARP), 0), ((closure[0] + SHARP, closure[1] + SHARP), None)]  # each contact its own gap
        outcomes = {}
        for gaps, touched in cases:
            run = stochpound.simulate(with_gaps(free_scene, gaps))
            margin = np.max(closure - np.array(gaps))
            assert abs(margin) > TIE
            outcomes[gaps] = run.sizes["impact"] > 0
            assert outcomes[gaps] == (margin >= 0.0), (realization, gaps, margin)
            if touched is not None:  # the first impact is at that contact's peak
                assert int(run["impact_contact"][0]) == touched
                assert float(run["impact_start"][0]) == pytest.approx(float(free["peak_contact_closure_time"][touched]), abs=1e-3)
        pounded.append([outcomes[(g, g)] for g in GRID])
    curve = pounding_curve(xr.DataArray(np.array(peak), dims=("realization", "contact")), GRID)
    np.testing.assert_array_equal(curve["probability"], np.mean(pounded, axis=0))
    assert 0 < np.sum(pounded) < np.size(pounded)  # the grid separates pounding from non-pounding runs


def test_contact_demands_of_a_contact_free_run():
    free = stochpound.simulate(contact_free_scene(0.2, 0))
    demands = contact_demands(free)
    for c in range(free.sizes["contact"]):
        left = free["total_displacement"].sel(building=str(free["contact_left"][c].values), floor=int(free["contact_left_floor"][c]))
        right = free["total_displacement"].sel(building=str(free["contact_right"][c].values), floor=int(free["contact_right_floor"][c]))
        row = demands.sel(contact=c)
        assert float(row["peak_displacement_left"]) == np.max(np.abs(left.values))
        assert float(row["peak_displacement_right"]) == np.max(np.abs(right.values))
        assert float(row["correlation"]) == pytest.approx(np.corrcoef(left.values, right.values)[0, 1], rel=1e-12)
        assert float(row["peak_closure"]) == float(free["peak_contact_closure"][c])
        # the closure is the difference of the two histories: D is at least their largest sampled difference
        assert float(row["peak_closure"]) >= np.max(left.values - right.values)
