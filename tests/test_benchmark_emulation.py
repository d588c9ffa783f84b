"""The benchmark suite's emulation of the study's scheme and its OpenSees model build, run and behave as expected.

Nothing is timed here: the timings belong to ``python -m benchmarks``. These
tests check, on short records, that the emulation of the study's fixed-restart
scheme is a correct integrator where the study's rules do not act, and that it
reproduces the study's known artefacts; and that the OpenSees model agrees
with the exact solver to the accuracy its regularised elements allow.
"""

from __future__ import annotations

import dataclasses
import os

import numpy as np
import pytest

import stochpound
from benchmarks.opensees_model import OpenSeesUnavailable, load_opensees, run_opensees
from benchmarks.outcome import compare, outcome_from_dataset
from benchmarks.scenes import MAIN_SCENE, STUDY_SCENES, with_motion
from benchmarks.study_scheme import StudyScheme, run_study_scheme
from stochpound.studies.agarwal2004 import reference_building

FIXED_PAIR = STUDY_SCENES[1]


def exact_outcome(scene):
    return outcome_from_dataset(stochpound.simulate(scene))


def test_study_scheme_runs_on_a_short_record():
    scene = MAIN_SCENE.scene(2.0, interpolation="spline")
    run = run_study_scheme(scene, 0.02)
    assert run.states.shape == (len(scene.motion.times), 2 * run.system.n_dof)
    assert np.all(np.isfinite(run.states))
    outcome = run.outcome()
    assert np.array_equal(outcome.times, scene.motion.times)
    assert outcome.top_displacement[0] == 0.0


def test_study_scheme_is_an_accurate_integrator_without_contact_or_sliding():
    scene = dataclasses.replace(FIXED_PAIR, gap=1.0).scene(4.0, interpolation="spline")
    errors = compare(run_study_scheme(scene, 0.02).outcome(), exact_outcome(scene))
    assert errors.displacement < 1e-5  # RK45 at atol = rtol = 1e-3 on a response of ~1 cm
    assert errors.impacts == 0


def test_study_scheme_converges_with_h_when_no_base_slides():
    scene = FIXED_PAIR.scene(4.0, interpolation="spline")
    reference = exact_outcome(scene)
    coarse, fine = (compare(run_study_scheme(scene, h).outcome(), reference).displacement for h in (0.02, 0.005))
    assert reference.impacts > 0
    assert fine < coarse / 2


def sliding_pulse_scene():
    """An isolated reference building (μ = 0.1) under 3 m/s² for 1 s, then at rest for 3 s."""
    data = {"g": 9.814, "building": [reference_building("B1", 1.0, 0.1)], "motion": {"type": "constant", "acceleration": 0.0, "duration": 4.0, "dt": 0.02}}
    values = np.zeros(201)
    values[:51] = 3.0
    return with_motion(stochpound.scene_from_dict(data), values, 0.02)


def last_sliding_time(times, sliding):
    moving = np.flatnonzero(np.abs(np.diff(sliding)) > 1e-12)
    return times[moving[-1] + 1]


def test_study_scheme_zeroes_the_sliding_velocity_once_the_base_decelerates():
    """The study's artefact: a decelerating base fails its sliding test and its velocity is reset to zero."""
    scene = sliding_pulse_scene()
    exact = stochpound.simulate(scene)
    emulated = run_study_scheme(scene, 0.02)
    exact_sliding = exact.sliding_displacement.values[0]
    assert last_sliding_time(exact.time.values, exact_sliding) > 2.5  # slides on, decelerating at about μg
    assert last_sliding_time(emulated.times, emulated.sliding_displacement()) <= 1.0 + 2 * 0.02
    assert abs(emulated.sliding_displacement()[-1]) < 0.5 * abs(exact_sliding[-1])


def test_study_scheme_starts_stuck_and_decides_sliding_only_at_restarts():
    scene = sliding_pulse_scene()
    run = StudyScheme(scene, 0.02).run()
    steps = len(scene.motion.times) - 1
    assert 0 < run.sliding_steps[0] < steps
    assert run.sliding_displacement()[1] == 0.0  # the first step sticks: the study starts from zero accelerations


def test_study_scheme_rejects_a_restart_interval_that_does_not_divide_the_samples():
    with pytest.raises(ValueError, match="divide"):
        StudyScheme(MAIN_SCENE.scene(1.0), 0.015)


def opensees_or_skip():
    """OpenSeesPy (the test extra installs it); skip without it, except under CI, where the cross-check must run."""
    try:
        return load_opensees()
    except OpenSeesUnavailable as error:
        if os.environ.get("CI"):
            raise
        pytest.skip(str(error))


@pytest.mark.parametrize("spec", STUDY_SCENES, ids=lambda spec: spec.key)
@pytest.mark.slow
def test_opensees_model_agrees_with_the_exact_solver_on_a_short_record(spec):
    opensees_or_skip()
    scene = spec.scene(5.0)
    reference = exact_outcome(scene)
    errors = compare(run_opensees(scene, 0.001), reference)
    assert errors.displacement < 2e-3  # regularised friction (1e-5 m) and Newmark at 1 ms
    assert errors.impacts == 0
    assert errors.peak_force < 0.05
    assert errors.final_sliding < 1e-3


@pytest.mark.slow
def test_opensees_steel01_storeys_converge_to_the_exact_yielding_solution_at_second_order():
    """The yielding pair without contacts, 4 s of El Centro: OpenSees' error against the exact solution falls as dt² and is its own step error."""
    from benchmarks.yielding import yielding_pair

    opensees_or_skip()
    scene = yielding_pair(np.inf, 4.0)
    run = stochpound.simulate(scene)
    assert float(run["peak_storey_ductility"].max()) > 2.0  # it yields
    reference = outcome_from_dataset(run)
    coarse, fine = run_opensees(scene, 0.001), run_opensees(scene, 0.0005)
    errors = [compare(outcome, reference).displacement for outcome in (coarse, fine)]
    assert errors[0] < 1e-4 and 3.5 < errors[0] / errors[1] < 4.5  # second order
    assert compare(coarse, fine).displacement * 4 / 3 == pytest.approx(errors[0], rel=0.1)  # the error is OpenSees' step error


@pytest.mark.slow
def test_opensees_model_rejects_what_its_elements_cannot_represent():
    opensees_or_skip()
    with pytest.raises(ValueError, match="study_compat"):
        run_opensees(MAIN_SCENE.scene(1.0, study_compat=True), 0.001)
    with pytest.raises(ValueError, match="gap"):
        run_opensees(dataclasses.replace(FIXED_PAIR, gap=0.0).scene(1.0), 0.001)
    from benchmarks.yielding import yielding_pair

    p_delta = yielding_pair(np.inf, 1.0)
    p_delta = dataclasses.replace(p_delta, buildings=tuple(dataclasses.replace(b, p_delta=True, storey_height=(3.5, 3.0)) for b in p_delta.buildings))
    with pytest.raises(ValueError, match="p_delta"):
        run_opensees(p_delta, 0.001)


def test_outcome_reads_the_first_buildings_top_floor_as_label_selection_would():
    """The numpy reduction of a result equals xarray's selection, with the first building the shorter (NaN-padded floors)."""
    short = reference_building("B1", mu=0.2) | {"mass": [2.0e5], "stiffness": [4.0e7], "damping": [1.0e5]}
    tall = reference_building("B2") | {"mass": [2.0e5] * 3, "stiffness": [4.0e7] * 3, "damping": [1.0e5] * 3}
    scene = stochpound.scene_from_dict({
        "building": [short, tall],
        "contact": [{"between": [["B1", 1], ["B2", 1]], "gap": 0.0, "stiffness": 1e8, "restitution": 0.5}],
        "motion": {"type": "harmonic", "amplitude": 3.0, "omega": 9.0, "duration": 4.0, "dt": 0.01},
    })
    run = stochpound.simulate(scene)
    outcome = outcome_from_dataset(run)
    floors = run.total_displacement.sel(building="B1").dropna("floor", how="all")
    assert floors.sizes["floor"] == 1 and run.sizes["floor"] == 3 and run.sizes.get("impact", 0) > 0
    np.testing.assert_array_equal(outcome.top_displacement, floors.isel(floor=-1).values)
    assert outcome.final_sliding == float(run.sliding_displacement.sel(building="B1").values[-1]) != 0.0
    assert outcome.impacts == run.sizes["impact"]
    assert outcome.peak_force == float(run.impact_peak_force.max())


def test_compile_report_judges_the_engines_settings_and_compares_them_with_numbas_default():
    """The target uses the empty-cache runs under the engine's compile settings only; the comparison gives the medians of both."""
    from benchmarks.report import _compile_target, _level_comparison

    OURS, DEFAULT = "stochpound's (LLVM 1)", "numba's default (LLVM 3)"  # as benchmarks.probes.first_call labels them

    def run(settings, first, warm):
        return {"import": 1.0, "first": first, "second": 0.004, "warm": warm, "settings": settings, "numba": True}

    data = {
        "cold": [run(OURS, 8.004, 0.003), run(OURS, 9.004, 0.0031), run(OURS, 20.004, 0.0029)],
        "cold_default_level": [run(DEFAULT, 11.004, 0.003), run(DEFAULT, 10.004, 0.0033), run(DEFAULT, 12.004, 0.0028)],
        "cached": run(OURS, 0.5, 0.003),
    }
    target = _compile_target(data)
    assert target.met and target.measured.startswith("9 s (median of 3")
    assert "stochpound's (LLVM 1) settings against numba's default (LLVM 3): compile (first call minus second) 9 s against 11 s (0.82×)" in _level_comparison(data)
    assert "best warm call 3 ms against 3 ms (1.00×)" in _level_comparison(data)
    assert _level_comparison({"cold": data["cold"]}) == ""
