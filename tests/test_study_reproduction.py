"""The single fixed-base building and the μ = ∞ (fixed–fixed) columns of the study's Tables 4.1/4.3/4.9/4.10.

With the study's own input interpolation (natural cubic spline of El Centro,
first 2500 samples scaled by 1/1.0197, g = 9.814) the corrected model
reproduces these columns to 3–4 digits. Two documented deviations remain,
both caused by the study deciding contact only at its 0.02 s restarts (a
contact that opens and closes between two restarts is merged or missed):
the study counts fewer impacts (38 against our 43 for the flexible
neighbour, 8 against 9 for the stiff one), and the excess of the stiff case,
whose impacts last ~0.02–0.05 s, is ~10 % lower in the study.
"""

import pytest

import stochpound
from stochpound.analysis import moments, run_summary
from stochpound.analysis._summary import top_floor_total_displacement
from stochpound.studies.agarwal2004 import reference_building, study_scene

STUDY_MOTION = {"record": "el_centro_1940_study", "interpolation": "spline"}
# the reference study's Tables 4.1 and 4.3 (cm), 4.9 and 4.10 (data/study/reference_tables.toml)
SINGLE = {"mean": 0.0, "variance": 0.49, "std": 0.7, "skewness": 0.0246, "excess": 1.8417}
FIXED_FIXED = {
    "stiff": {"factor": 0.5, "mean": -0.0021, "std": 0.66, "skewness": -0.0107, "excess": 0.9556, "impacts": 8, "correlation": 0.9529},
    "flexible": {"factor": 2.0, "mean": -0.027, "std": 0.40, "skewness": -0.1577, "excess": 2.8934, "impacts": 38, "correlation": 0.4468},
}


@pytest.fixture(scope="module")
def fixed_base_response():
    scene = stochpound.scene_from_dict({"g": 9.814, "building": [reference_building()], "motion": STUDY_MOTION})
    return top_floor_total_displacement(stochpound.simulate(scene), "B1")


def test_single_fixed_base_building(fixed_base_response):
    ours = moments(fixed_base_response * 100.0)  # cm
    assert float(ours["mean"]) == pytest.approx(SINGLE["mean"], abs=0.001)
    for name in ("variance", "std", "skewness", "excess"):
        assert float(ours[name]) == pytest.approx(SINGLE[name], rel=0.01), name


@pytest.mark.parametrize("neighbour", ["stiff", "flexible"])
def test_fixed_fixed_column(neighbour, fixed_base_response):
    study = FIXED_FIXED[neighbour]
    run = stochpound.simulate(stochpound.scene_from_dict(study_scene(None, None, study["factor"], motion=STUDY_MOTION)))
    ours = run_summary(run, "B1", fixed_base_response)
    assert float(ours["response_mean"]) * 100 == pytest.approx(study["mean"], abs=0.001)
    assert float(ours["response_std"]) * 100 == pytest.approx(study["std"], rel=0.02)
    assert float(ours["response_skewness"]) == pytest.approx(study["skewness"], abs=0.005)
    assert float(ours["fixed_base_correlation"]) == pytest.approx(study["correlation"], rel=0.03)
    # documented deviations (module docstring): more impacts resolved, stiff excess ~10 % higher
    assert study["impacts"] <= int(ours["impacts"]) <= 1.15 * study["impacts"]
    assert float(ours["response_excess"]) == pytest.approx(study["excess"], rel=0.015 if neighbour == "flexible" else 0.12)
