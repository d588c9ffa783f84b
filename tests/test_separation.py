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
from stochpound.studies.agarwal2004 import study_scene
from tests.helpers import with_gaps

KANAI_TAJIMI = {"type": "kanai_tajimi", "omega_g": 15.0, "zeta_g": 0.6, "pga": 3.4, "envelope": "jennings", "seed": 3, "duration": 20.0, "dt": 0.01}
REALIZATIONS = (0, 1, 2)
GRID = (0.02, 0.06, 0.095)  # m, the same at both contacts (the largest splits both ensembles)
SHARP = 1e-8  # m: gaps this far from D
TIE = 1e-9  # m: closer than this to D, either outcome is right


def contact_free_scene(mu1: float | None, realization: int) -> Scene:
    return stochpound.scene_from_dict(study_scene(mu1=mu1, gap=math.inf, motion={**KANAI_TAJIMI, "realization": realization}))


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


def _floor(run: xr.Dataset, c: int, side: str) -> xr.DataArray:
    """Total displacement y over time of contact c's ``side`` floor, m."""
    return run["total_displacement"].sel(building=str(run[f"contact_{side}"][c].values), floor=int(run[f"contact_{side}_floor"][c]))


def _dense_peak(history: xr.DataArray) -> tuple[float, float]:
    """Largest |y| of a densely sampled history and its time, refined by the parabola through the three samples around the largest sample."""
    y, t = np.abs(history.values), history["time"].values
    i = min(max(int(np.argmax(y)), 1), len(y) - 2)
    a, b, c = np.polyfit(t[i - 1 : i + 2] - t[i], y[i - 1 : i + 2], 2)
    return (c - b**2 / (4 * a), t[i] - b / (2 * a)) if a < 0 else (float(y[i]), float(t[i]))


@pytest.mark.parametrize("mu1", [None, 0.2], ids=["fixed", "sliding"])
def test_contact_demands_of_a_contact_free_run_are_located_on_the_solution(mu1):
    """u1, u2 and D are all located peaks: ABS = u1 + u2 ≥ D exactly, and u1, u2 ≥ their sampled peaks.

    The same motion upsampled 20 times (its first-order hold is the same
    function of time) gives outputs every 0.5 ms: the located peaks of the
    0.01 s run agree with the dense samples' largest value refined by a
    parabola, and with the dense run's own located peaks, to 1e-9 m.
    """
    scene = contact_free_scene(mu1, 0)
    free = stochpound.simulate(scene)
    demands = contact_demands(free)
    motion = scene.motion
    upsampled = np.interp(np.arange((len(motion.values) - 1) * 20 + 1) * motion.dt / 20, motion.times, motion.values)
    dense = stochpound.simulate(dataclasses.replace(scene, motion=dataclasses.replace(motion, dt=motion.dt / 20, values=upsampled)))
    for c in range(free.sizes["contact"]):
        row = demands.sel(contact=c)
        u1, u2, closure = float(row["peak_displacement_left"]), float(row["peak_displacement_right"]), float(row["peak_closure"])
        assert u1 + u2 >= closure
        assert closure == float(free["peak_contact_closure"][c])
        left, right = _floor(free, c, "left"), _floor(free, c, "right")
        assert u1 >= np.max(np.abs(left.values)) and u2 >= np.max(np.abs(right.values))
        assert closure >= np.max(left.values - right.values)
        assert float(row["correlation"]) == pytest.approx(np.corrcoef(left.values, right.values)[0, 1], rel=1e-12)
        for side, located in (("left", u1), ("right", u2)):
            peak, when = _dense_peak(_floor(dense, c, side))
            assert located == pytest.approx(peak, abs=1e-9)
            assert located == pytest.approx(float(dense[f"peak_contact_displacement_{side}"][c]), abs=1e-9)
            assert float(free[f"peak_contact_displacement_{side}_time"][c]) == pytest.approx(when, abs=1e-4)


def test_only_contacts_with_an_infinite_gap_locate_their_floors_peaks():
    """u1, u2 are the contact-free runs' inputs: a contact with a finite gap reports NaN (its floors are not monitored), one with gap inf its located peaks.

    The second contact's gap is finite but never reached (10 m), so the run is
    the contact-free run: the first contact's u1, u2 and every closure are
    those of the contact-free run.
    """
    free = stochpound.simulate(contact_free_scene(0.2, 0))
    mixed = stochpound.simulate(with_gaps(contact_free_scene(0.2, 0), (math.inf, 10.0)))
    assert mixed.sizes["impact"] == 0
    for side in ("left", "right"):
        for name in (f"peak_contact_displacement_{side}", f"peak_contact_displacement_{side}_time"):
            assert math.isnan(float(mixed[name][1])) and not math.isnan(float(free[name][1]))
            assert float(mixed[name][0]) == pytest.approx(float(free[name][0]), rel=1e-12)
    np.testing.assert_allclose(mixed["peak_contact_closure"], free["peak_contact_closure"], rtol=1e-12)
