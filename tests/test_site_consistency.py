"""The done-when check of conditional-spectrum selection, reduced: the same buildings at the same site get about the same g*
whichever measure their stripes are conditioned on.

Two configurations at the bundled Fox Plaza site, contact-free: the fixed pair of experiments/risk/fixed_pair.toml
(Building 1 beside a stiff or a flexible neighbour) and the isolated Building 1 of experiments/risk/isolated.toml
(friction pendulum, mu 0.05, no moat wall, stiff neighbour). Stripes at the intensities of return periods 72-5000 years
of PGA, of PSA(1 s) and of PSA(2 s), 20 motions per stripe chosen from the 100 FEMA P695 motions (factor <= 5), the
scenario of every level fitted to the site's four curves ([site] scenario = "fitted"; no disaggregation is bundled).

Run: ``pytest -m slow tests/test_site_consistency.py -s`` (prints the g* table).
"""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from stochpound import open_store
from stochpound.analysis import HazardCurve, store_risk
from stochpound.experiment._runner import load_experiment, run_experiment
from tests.helpers import write_experiment

RETURN_PERIODS = np.array([72.0, 224.0, 475.0, 975.0, 2475.0, 5000.0])
CURVES = ["fox_plaza_los_angeles_pga", "fox_plaza_los_angeles_sa1p0s", "fox_plaza_los_angeles_sa2p0s", "fox_plaza_los_angeles_sa3p0s"]
CASES = {  # measure: ([intensity] lines, bundled hazard)
    "PGA": ('measure = "pga"', CURVES[0]),
    "PSA(1 s)": ('measure = "psa"\nperiod = 1.0', CURVES[1]),
    "PSA(2 s)": ('measure = "psa"\nperiod = 2.0', CURVES[2]),
}
PAIR = """
[scene]
g = 9.81
[[scene.building]]
name = "B1"
mass = [26268.0, 17512.0]
stiffness = [24516800.0, 17512000.0]
damping_ratio = 0.05
{base}
[[scene.building]]
name = "B2"
mass = [26268.0, 17512.0]
stiffness = [24516800.0, 17512000.0]
damping_ratio = 0.05
[[scene.contact]]
between = [["B1", 1], ["B2", 1]]
gap = 0.02
stiffness = 42747262.6
restitution = 0.5
[[scene.contact]]
between = [["B1", 2], ["B2", 2]]
gap = 0.02
stiffness = 28498175.1
restitution = 0.5
{variants}
[grid]
gap = [inf]
[[records]]
suite = "fema_p695_far_field"
[[records]]
suite = "fema_p695_near_field"
"""


CONFIGURATIONS = {  # name: (B1's base, the neighbour's variants)
    "fixed pair": ("", "[variants.neighbour.stiff.building.B2]\nmass_factor = 0.5\n[variants.neighbour.flexible.building.B2]\nmass_factor = 2.0"),
    "isolated": ("base = { mass = 13134.0, mu = 0.05, radius = 2.24 }", "[variants.neighbour.stiff.building.B2]\nmass_factor = 0.5"),
}


def _text(measure: str, configuration: str) -> str:
    lines, curve = CASES[measure]
    levels = HazardCurve.bundled(curve).intensity_at(1.0 / RETURN_PERIODS)
    base, variants = CONFIGURATIONS[configuration]
    curves = ", ".join(f'"{name}"' for name in CURVES)
    return (f'[experiment]\nname = "site_{curve}"\nstudied = "B1"\n{PAIR.format(base=base, variants=variants)}\n[intensity]\n{lines}\n'
            f"levels = [{', '.join(f'{x:.4f}' for x in levels)}]\n"
            'selection = "conditional_spectrum"\nmotions = 20\nmax_scale_factor = 5.0\n'
            f'[site]\nscenario = "fitted"\ncurves = [{curves}]\nvs30 = 400.0\nmechanism = "reverse"\n')


@pytest.mark.slow
@pytest.mark.parametrize("configuration", [
    "fixed pair",
    pytest.param("isolated", marks=pytest.mark.xfail(strict=True, reason=(
        "not yet within x1.3: measured x1.39-1.41 (PGA-conditioned stripes give the lowest g*; the scaled suite gave x1.9-2.1); "
        "strict: it fails the day it passes, to be un-marked"))),
])
def test_g_star_hardly_depends_on_the_conditioning_measure(tmp_path, configuration: str) -> None:
    separations = {}
    for measure, (_, curve) in CASES.items():
        name = f"{measure.replace('(', '').replace(' s)', '').replace(' ', '').lower()}.toml"
        experiment = load_experiment(write_experiment(tmp_path, _text(measure, configuration), name))
        report = run_experiment(experiment, workers=0, progress=False)
        assert report.complete
        risk = store_risk(open_store(report.store).load(), HazardCurve.bundled(curve), targets=(0.1, 0.02), bootstrap=0)
        separations[measure] = risk.separation["separation"]
    stacked = xr.concat(list(separations.values()), dim="measure")
    ratio = stacked.max("measure") / stacked.min("measure")
    print(f"\n{configuration}: g* (m) by conditioning measure, and max/min:")
    for measure, value in separations.items():
        print(measure, value.to_pandas().to_string())
    print("max/min", ratio.to_pandas().to_string())
    assert float(ratio.max()) <= 1.3
