"""The report's self-checks can fail: the solver cross-check re-runs a stored case as it ran, and stops the build on a mismatch."""

from __future__ import annotations

from pathlib import Path

import pytest
import xarray as xr

from stochpound._errors import VerificationError
from stochpound.experiment import load_experiment, run_experiment
from stochpound.analysis import ReferenceRun
from stochpound.report.sections._accuracy import cross_check
from stochpound.report.sections._description import StoreDefinition

PAIR = """
[scene]
g = 9.81
[[scene.building]]
name = "B1"
mass = [26268.0, 17512.0]
stiffness = [24516800.0, 17512000.0]
damping_ratio = 0.02
[[scene.building]]
name = "B2"
mass = [13134.0, 8756.0]
stiffness = [24516800.0, 17512000.0]
damping_ratio = 0.02
[[scene.contact]]
between = [["B1", 2], ["B2", 2]]
gap = 0.0
stiffness = 3.8e7
restitution = 0.5
"""
STRIPES = """
[experiment]
name = "verify"
{pair}
[grid]
gap = [0.005]
[[records]]
record = "fema_p695_far_field/01a"
duration = 6.0
[[records]]
record = "fema_p695_far_field/05a"
duration = 6.0
[intensity]
measure = "pga"
levels = [0.9]
[output]
impacts = true
[solver]
method = "exact"
"""


@pytest.fixture(scope="module")
def stripes_store(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("verify")
    (folder / "verify.toml").write_text(STRIPES.format(pair=PAIR))
    report = run_experiment(load_experiment(folder / "verify.toml"), workers=0, progress=False)
    assert report.complete and not report.failed
    return report.store


def test_the_cross_check_reruns_a_scaled_case_and_counts_the_stores_impacts(stripes_store):
    with xr.open_dataset(stripes_store) as store:
        store = store.load()
    labels, _ = ReferenceRun.pounding_case(store)
    case = store["impacts"].sel(labels)
    assert float(store["scale_factor"].sel(labels)) != pytest.approx(1.0, abs=0.05)  # the case ran scaled
    paragraph = cross_check([StoreDefinition("verify", store)])
    assert f"both count the {int(case)} impacts the store holds" in paragraph.text
    assert "motion scale factor" in paragraph.text


def test_a_corrupted_store_makes_the_check_fail_in_one_line(stripes_store):
    with xr.open_dataset(stripes_store) as store:
        store = store.load()
    labels, _ = ReferenceRun.pounding_case(store)
    store["impacts"].loc[labels] = store["impacts"].sel(labels) + 1
    with pytest.raises(VerificationError, match=r"^cross-check: the stored case of verify \(.*\) re-run counts \d+ impacts, the store holds \d+$"):
        cross_check([StoreDefinition("verify", store)])


def test_the_cross_check_gives_the_peak_sliding_not_its_range():
    """Issue 45: 'sliding over 123 cm' was the range between the extremes (−61.4 to +61.6 cm); the peak |s| is 61.6 cm."""
    from stochpound.analysis import ReferenceRun

    exact = xr.Dataset({"sliding_displacement": (("time", "building"), [[0.0, 0.0], [-0.614, 0.0], [0.616, 0.0]])})
    run = ReferenceRun(None, exact, exact, 0.0, 1.0)
    assert run.sliding == pytest.approx(0.616, rel=1e-12)
