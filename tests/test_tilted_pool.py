"""A pool tilted to each stripe (issue 43): ``[site] simulated_sampling = "tilted"``, ``site_motions(normal_shift=...)``.

The shift moves a motion's parameter normals alone, along the pilot regression's direction, by what centres ln IM* on the
level; a chosen motion is regenerated bit for bit from its table; the default adds nothing to the definition; bad input is
one line naming the field."""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest

from stochpound.experiment import _stripe_pools
from stochpound.experiment._spec import ExperimentError, parse_experiment
from stochpound.model.scene_file import scene_from_dict
from stochpound.motions import Scenario, parameter_normals, site_model_provenance, site_motions, site_motions_from_normals
from stochpound.motions import _site_model
from stochpound.motions._site_motions import _after_parameters
from stochpound.store import SimulatedMotions
from tests.helpers import SIMULATED_SITE
from tests.helpers import tilted_site_text as _text

SCENARIO = Scenario(6.5, 20.0, 400.0, "strike_slip")
NORMALS = _site_model.load_site_model("hazard_compatible").normals
G = 9.81
def test_the_shift_moves_the_parameter_normals_alone_bit_for_bit():
    """site_motions with a shift is site_motions_from_normals of the seed's parameter normals plus the shift and its own noise."""
    shift = np.linspace(-1.0, 1.5, NORMALS)
    shifted = site_motions(n=3, seed=4, scenario=SCENARIO, duration=20.0, normal_shift=shift.tolist())
    n_time = shifted.sizes["time"]
    noise = np.array([_after_parameters(4, i, NORMALS).standard_normal(n_time) for i in range(3)])
    expected = site_motions_from_normals(np.hstack([parameter_normals(4, range(3)) + shift, noise]), scenario=SCENARIO)
    np.testing.assert_array_equal(shifted["acceleration"].values, expected["acceleration"].values)
    plain = site_motions(n=3, seed=4, scenario=SCENARIO, duration=20.0)
    assert not np.array_equal(plain["acceleration"].values, shifted["acceleration"].values)  # the shift changes the motions: can fail
    zero = site_motions(n=3, seed=4, scenario=SCENARIO, duration=20.0, normal_shift=[0.0] * NORMALS)
    assert zero["acceleration"].values.tobytes() == plain["acceleration"].values.tobytes()


@pytest.mark.parametrize("shift", [[0.5] * (NORMALS - 1), [math.nan] * NORMALS, ["a"] * NORMALS, [True] * NORMALS, 0.5])
def test_a_bad_shift_is_one_line_naming_the_field(shift):
    from stochpound._errors import SiteError

    with pytest.raises(SiteError, match=rf"^normal_shift: {NORMALS} finite numbers .*got") as error:
        site_motions(n=2, seed=1, scenario=SCENARIO, normal_shift=shift)
    assert "\n" not in str(error.value)
    table = {"type": "site_motions", "magnitude": 6.5, "distance_km": 20.0, "vs30": 400.0, "mechanism": "strike_slip", "n": 2, "seed": 1,
             "normal_shift": shift}
    with pytest.raises(Exception, match=r"^motion\.normal_shift: "):
        scene_from_dict({"building": [{"name": "B1", "mass": [1.0e5], "stiffness": [1.5e7], "damping_ratio": 0.05}], "motion": table})


def test_the_fit_is_least_squares_and_the_shift_centres_the_line_on_the_level_along_its_slope():
    """Tilt.fit gives back an exact line and numpy's least squares of a noisy one; the shift is t·a with b0 + a·shift = ln level."""
    rng = np.random.default_rng(8)
    z = rng.standard_normal((500, 6))
    slope = np.array([0.3, -0.1, 0.0, 0.25, 0.05, -0.2])
    exact = _stripe_pools.Tilt.fit(z, -1.2 + z @ slope)
    assert exact.intercept == pytest.approx(-1.2, abs=1e-12) and np.allclose(exact.slope, slope, atol=1e-12)
    noisy = -1.2 + z @ slope + 0.3 * rng.standard_normal(500)
    expected = np.linalg.lstsq(np.column_stack([np.ones(500), z]), noisy, rcond=None)[0]
    fitted = _stripe_pools.Tilt.fit(z, noisy)
    np.testing.assert_allclose([fitted.intercept, *fitted.slope], expected, rtol=0, atol=1e-12)
    shift = np.array(exact.shift(0.9))
    t = (math.log(0.9) + 1.2) / float(slope @ slope)
    np.testing.assert_allclose(shift, t * slope, rtol=1e-12, atol=1e-15)
    assert -1.2 + slope @ shift == pytest.approx(math.log(0.9), abs=1e-12)


def test_the_shift_keeps_the_normals_distribution_given_their_projection_and_moves_the_line_to_the_level():
    """Linear-Gaussian check: y = b0 + a·z + e. Drawn with z ~ N(s, I), s the Tilt's shift, the part of z orthogonal to a keeps
    the untilted N(0, I − â âᵀ) (mean and covariance within sampling error) and y centres on ln level; a shift off a's
    direction moves the orthogonal part (the check can fail)."""
    rng = np.random.default_rng(11)
    slope = np.array([0.4, -0.2, 0.1, 0.3])
    tilt = _stripe_pools.Tilt(-1.0, tuple(slope))
    unit = slope / np.linalg.norm(slope)
    orthogonal = np.eye(4) - np.outer(unit, unit)
    n = 40_000
    for level, along in ((2.5, True), (2.5, False)):
        shift = np.array(tilt.shift(level)) if along else np.array(tilt.shift(level))[::-1]
        z = rng.standard_normal((n, 4)) + shift
        y = -1.0 + z @ slope + 0.2 * rng.standard_normal(n)
        rest = z @ orthogonal
        within = bool(np.all(np.abs(rest.mean(axis=0)) < 5.0 / math.sqrt(n)))
        assert within == along
        if along:
            np.testing.assert_allclose(np.cov(rest.T), orthogonal, atol=0.03)
            assert abs(y.mean() - math.log(level)) < 5.0 * math.sqrt(slope @ slope + 0.04) / math.sqrt(n)




def test_the_tilted_pool_s_definition_and_tables(tilted_experiment):
    """The definition says tilted; every stripe's simulated motions have their own seed and a shift of every parameter normal,
    larger toward the higher level."""
    setting = tilted_experiment.intensity.selection.simulated
    assert setting.entry()["sampling"] == "tilted" and setting.count == 12
    selection = tilted_experiment.selection
    assert any(selection.simulated)  # the test below regenerates one
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(_stripe_pools, "TILT_PILOT", 48)
        tables = [_stripe_pools.tilted_sources(setting, stripe, SCENARIO, level, {}, "psa", 0.5, G)
                  for stripe, level in enumerate([0.2, 0.6])]
    first = [next(iter(t.values())).motion for t in tables]
    assert first[0]["seed"] != first[1]["seed"] and all(len(t["normal_shift"]) == NORMALS for t in first)
    tilt = np.array(first[1]["normal_shift"]) - np.array(first[0]["normal_shift"])
    assert float(tilt @ np.array(first[1]["normal_shift"])) > 0.0  # the higher level is shifted farther along the same direction
    for label, source in selection.simulated.items():
        stripe = int(label.split()[1].split(".")[0]) - 1
        assert source.motion == {**first[stripe], "realization": source.motion["realization"]}


def test_a_chosen_tilted_motion_is_regenerated_bit_for_bit_from_its_table_alone(tilted_experiment):
    """A chosen simulated motion: its table as a scene's [motion] (how a case runs it) gives the very bytes of its row of the
    pool's generation (every motion of the table, chunk by chunk)."""
    label, source = next(iter(tilted_experiment.selection.simulated.items()))
    table = source.motion
    building = {"name": "B1", "mass": [1.0e5], "stiffness": [1.5e7], "damping_ratio": 0.05}
    alone = scene_from_dict({"building": [building], "motion": dict(table)}).motion.values
    rows = {int(i): row for chunk_rows, accelerations, _ in _stripe_pools.table_chunks(table, "psa", 0.5, G)
            for i, row in zip(chunk_rows, accelerations)}
    assert alone.tobytes() == rows[table["realization"]].tobytes()


def test_the_tilt_is_the_same_whatever_the_threads(monkeypatch):
    setting = SimulatedMotions(8, "hazard_compatible", site_model_provenance(), 3, 0.01, "tilted")
    monkeypatch.setattr(_stripe_pools, "TILT_PILOT", 24)
    tilts = []
    for threads in (1, 2):
        monkeypatch.setattr(_site_model, "motion_threads", lambda threads=threads: threads)
        tilts.append(_stripe_pools.tilt_pilot(setting, SCENARIO, "psa", 0.5, G))
    assert tilts[0] == tilts[1]


def test_a_tilted_pool_centres_its_stripe_s_measure_on_the_level(monkeypatch):
    """64 tilted motions at a level of ε ≈ 2: their mean ln IM* lies within 3 standard errors of ln level, the untilted
    scenario's 4 or more below it (the check can fail)."""
    setting = SimulatedMotions(64, "hazard_compatible", site_model_provenance(), 5, 0.01, "tilted")
    monkeypatch.setattr(_stripe_pools, "TILT_PILOT", 64)
    pilot = _stripe_pools.scenario_table(setting, SCENARIO, 64, 5)
    untilted = np.log(np.concatenate([i for _, _, i in _stripe_pools.table_chunks(pilot, "psa", 0.5, G)]))
    level = math.exp(untilted.mean() + 2.0 * untilted.std())
    table = next(iter(_stripe_pools.tilted_sources(setting, 0, SCENARIO, level, {}, "psa", 0.5, G).values())).motion
    tilted = np.log(np.concatenate([i for _, _, i in _stripe_pools.table_chunks(table, "psa", 0.5, G)]))
    error = tilted.std(ddof=1) / math.sqrt(tilted.size)
    assert abs(tilted.mean() - math.log(level)) < 3.0 * error
    assert math.log(level) - untilted.mean() > 4.0 * untilted.std(ddof=1) / math.sqrt(untilted.size)


def test_the_default_sampling_adds_nothing_to_the_definition(tmp_path):
    """Without simulated_sampling, or with "scenario", the definition (so the identity) is the one without the key."""
    plain = parse_experiment(tomllib.loads(_text(SIMULATED_SITE)), tmp_path)
    assert "sampling" not in plain["intensity"]["simulated_motions"]
    assert parse_experiment(tomllib.loads(_text(SIMULATED_SITE + 'simulated_sampling = "scenario"\n')), tmp_path) == plain
    assert SimulatedMotions.from_entry(plain["intensity"]["simulated_motions"]).sampling == "scenario"


@pytest.mark.parametrize(
    "site, message",
    [
        (SIMULATED_SITE + 'simulated_sampling = "wide"\n', r"^site\.simulated_sampling: must be one of scenario, tilted, got 'wide'$"),
        (SIMULATED_SITE + "simulated_sampling = 1\n", r"^site\.simulated_sampling: must be a non-empty string, got 1$"),
        (SIMULATED_SITE.replace("simulated_motions = 12\n", 'simulated_sampling = "tilted"\n'), r"^site\.simulated_sampling: only with site\.simulated_motions"),
        ('[site]\nruptures = "one.csv"\nsimulated_motions = 4\nsimulated_sampling = "tilted"\n',
         r'^site\.simulated_sampling: "tilted" takes a given or fitted scenario, not a site of ruptures'),
    ],
)
def test_bad_sampling_is_one_line_naming_the_field(tmp_path, site, message):
    (tmp_path / "one.csv").write_text("# vs30: 400\nname,magnitude,distance_rup_km,distance_jb_km,distance_x_km,ztor_km,dip,mechanism,rate\n"
                                      "big,7.0,20.0,20.0,-20.0,0.0,90,strike_slip,0.01\n")
    with pytest.raises(ExperimentError, match=message) as error:
        parse_experiment(tomllib.loads(_text(site)), tmp_path)
    assert "\n" not in str(error.value)


def test_the_reports_words_say_a_tilted_pool_is_each_stripe_s_own():
    """The pool as the report and the risk summary describe it: a tilted pool's motions are each stripe's own, drawn toward its
    level; the scenario's are not said to be."""
    plain = SimulatedMotions(2000, "hazard_compatible", "any", 1, 0.01)
    tilted = SimulatedMotions(4000, "hazard_compatible", "any", 1, 0.01, "tilted")
    assert plain.pool_words == "2000 simulated motions of each stripe's scenario"
    assert tilted.pool_words == "4000 simulated motions of each stripe's scenario (each stripe's own, importance-sampled toward its level)"
