"""Subset simulation (model §13) certified against importance sampling with elementary events on Au & Beck's oscillator.

The reference is independent of the package: the oscillator's displacement at
the samples is written here as a linear map X = A u of the white noise's
standard normals (the exact discretisation of ẍ + 2ζωẋ + ω²x = −a_g for
an acceleration linear between the samples, by one matrix exponential), and
P(max_k |X_k| > b) is estimated by importance sampling with elementary events
(ISEE, Au & Beck 2001), which is unbiased with a coefficient of variation of a
few per cent from a thousand samples at any level.
"""

from __future__ import annotations

import math
import tomllib
import warnings
from dataclasses import replace

import numpy as np
import pytest
from scipy.special import ndtr

import stochpound
import stochpound.model
from stochpound.analysis import SubsetSampler, subset_simulation
from stochpound.analysis._subset_simulation import INITIAL_SCALE, TARGET_ACCEPTANCE, SubsetLevel, au_beck_cov, genealogy_cov
from stochpound.motions import normal_motion
from stochpound.motions.ground import SampledMotion
from tests.au_beck_oscillator import DT, DURATION, N_TIME, OMEGA, S, ZETA
from tests.au_beck_oscillator import displacements as _displacements
from tests.au_beck_oscillator import isee as _isee
from tests.au_beck_oscillator import peak as _peak

def test_the_reference_oscillator_has_its_closed_form_variance():
    """The map's stationary standard deviation is √(π S / (2 ζ ω³)) (within the discretisation)."""
    sigma = np.linalg.norm(_displacements(np.eye(N_TIME)).T[-1])
    assert sigma == pytest.approx(math.sqrt(math.pi * S / (2.0 * ZETA * OMEGA**3)), rel=0.01)


@pytest.mark.parametrize("proposal", ["mma", "acs"])
def test_one_run_agrees_with_importance_sampling_at_every_threshold(proposal):
    """One subset run gives the curve at 1.6 and 2.1 (P ≈ 8e-3 and 3e-5), each within 3 of its CoV of the reference."""
    result = subset_simulation(_peak, thresholds=[1.6, 2.1], samples_per_level=500, p0=0.1, seed=3, dimension=N_TIME, proposal=proposal)
    for b, probability, cov in zip(result.threshold.values, result.probability.values, result.cov.values):
        reference, reference_cov = _isee(b, 600, seed=1)
        assert reference_cov < 0.05
        assert abs(probability - reference) < 3.0 * math.hypot(cov, reference_cov) * reference
    assert result.attrs["target_reached"] == 1 and result.attrs["levels"] >= 4


def test_same_seed_same_estimate_and_the_runs_counted():
    first = subset_simulation(_peak, thresholds=[1.2], samples_per_level=100, p0=0.1, seed=7, dimension=N_TIME)
    again = subset_simulation(_peak, thresholds=[1.2], samples_per_level=100, p0=0.1, seed=7, dimension=N_TIME)
    assert first.identical(again)
    calls = []
    counted = subset_simulation(lambda u: calls.append(len(u)) or _peak(u), thresholds=[1.2], samples_per_level=100, p0=0.1, seed=7, dimension=N_TIME)
    assert counted.attrs["runs"] == sum(calls)


@pytest.mark.parametrize(("proposal", "p0"), [("mma", 0.1), ("acs", 0.1), ("acs", 0.25)])
def test_a_half_space_has_its_exact_probability(proposal, p0):
    """g(u) = u_1 in 50 dimensions: P(g > b) = Φ(−b) exactly, down to 1e-6, within 3 reported CoV."""
    b = np.array([1.0, 2.5, 4.0, 4.75])
    result = subset_simulation(lambda u: u[:, 0], thresholds=b, samples_per_level=1000, p0=p0, seed=2, dimension=50, proposal=proposal)
    exact = ndtr(-b)
    assert np.all(np.abs(result.probability.values / exact - 1.0) < 3.0 * result.cov.values)
    assert np.all(result.cov.values < 0.5)


def test_the_genealogy_cov_is_au_beck_s_on_the_first_two_levels():
    """Down to level 1 the genealogy's δ² = Σ_i s_i² − 1/N is Au & Beck's δ² exactly: (1 − p)/(pN) on level 0 and, on
    level 1, (1 − p0)/(p0 N) + (1 − p)/(p N_1)(1 + γ) with γ from the chains (every chain there has an ancestor of its own);
    from level 2 on it counts the chains' common ancestors, which Au & Beck's δ leaves out."""
    result = subset_simulation(_peak, target_probability=1e-3, samples_per_level=200, p0=0.1, seed=5, dimension=N_TIME)
    below = result.threshold.values < result.attrs["level_thresholds"][1]
    assert below.sum() > 20 and (~below).sum() > 5 and result.attrs["levels"] == 3
    np.testing.assert_allclose(result.cov.values[below], result.cov_au_beck.values[below], rtol=1e-12)
    assert not np.allclose(result.cov.values[~below], result.cov_au_beck.values[~below], rtol=1e-3)


def test_the_genealogy_cov_is_the_ancestors_shares():
    """A hand-made genealogy (N = 10, p0 = 0.2: two chains of five a level): level 1's chains descend from level-0
    samples 7 and 2, level 2's from level 1's third state of each chain (so from 7 and 2 again). Above 9.5 (level 1)
    3 samples descend from 7 and 2 from 2: δ² = (3/5)² + (2/5)² − 1/10; above 11.5 (level 2) 3 and 1: (3/4)² + (1/4)² − 1/10;
    above 12.5 one each: 1/2 − 1/10. Beyond every sample the CoV is NaN; a level without its seeds is refused."""
    level0 = SubsetLevel(-np.inf, np.arange(10.0)[:, None], 1.0)
    level1 = SubsetLevel(7.5, np.array([[10.0, 10.0, 12.0, 8.0, 9.0], [9.0, 11.0, 11.0, 8.0, 8.0]]), 0.5, np.array([7, 2]))
    level2 = SubsetLevel(10.0, np.array([[12.0, 12.0, 14.0, 10.0, 10.0], [13.0, 11.0, 11.0, 11.0, 11.0]]), 0.5, np.array([2, 7]))
    levels = [level0, level1, level2]
    cov = genealogy_cov(levels, np.array([9.5, 11.5, 12.5, 20.0]))
    np.testing.assert_allclose(cov[:3], np.sqrt([13 / 25 - 0.1, 10 / 16 - 0.1, 1 / 2 - 0.1]), rtol=1e-12)
    assert np.isnan(cov[3]) and np.isfinite(au_beck_cov(levels, np.array([11.5]))[0])
    with pytest.raises(ValueError, match="^seeds: level 2 must name the previous level's sample that seeded each of its 2 chains"):
        genealogy_cov([level0, level1, replace(level2, seeds=None)], np.array([12.5]))


def test_adaptive_conditional_sampling_leaves_the_standard_normal_invariant():
    """Without a threshold every aCS candidate is accepted: the chains are Gaussian AR(1) processes u' = ρ u + σ z,
    ρ = √(1 − σ²), whose states stay standard normal and whose lag-1 correlation is ρ (each to 5 of its standard errors)."""
    spread = np.array([0.1, 0.5, 0.9, 1.0, 0.3])
    chains = 4000
    sampler = SubsetSampler(lambda u: np.zeros(len(u)), 5, 10 * chains, 0.1, seed=4, proposal="acs")
    u = np.random.default_rng(0).standard_normal((chains, 5))
    run = sampler.advance(1, u, np.zeros(chains), -np.inf, range(chains), spread)
    assert run.states.shape == (chains, 10, 5) and run.accepted == chains * 9
    last = run.states[:, -1, :]
    assert np.all(np.abs(last.mean(axis=0)) < 5.0 / math.sqrt(chains))
    assert np.all(np.abs(last.var(axis=0) - 1.0) < 5.0 * math.sqrt(2.0 / chains))
    lag = np.mean(run.states[:, 1:, :] * run.states[:, :-1, :], axis=(0, 1))
    assert np.all(np.abs(lag - np.sqrt(1.0 - spread**2)) < 5.0 / math.sqrt(chains))


def test_adaptive_conditional_sampling_adapts_its_spread_to_the_target_acceptance():
    """On a half-space the groups' spread scale λ, from 0.6, rises over level 1 (whose candidates are accepted more often than
    44 %), falls over level 2 (which starts with level 1's λ, too wide for a deeper level: fewer than 44 % accepted) and
    settles where about 44 % are accepted at the levels after it, its groups covering each level's chains."""
    result = subset_simulation(lambda u: u[:, 0], thresholds=[4.75], samples_per_level=1000, p0=0.1, seed=2, dimension=50, proposal="acs")
    assert result.attrs["acceptance"][0] > TARGET_ACCEPTANCE and result.attrs["scale"][0] > INITIAL_SCALE
    assert result.attrs["acceptance"][1] < TARGET_ACCEPTANCE and result.attrs["scale"][1] < result.attrs["scale"][0]
    assert np.all(np.abs(result.attrs["acceptance"][2:] - TARGET_ACCEPTANCE) < 0.05)
    assert result.attrs["proposal"] == "acs" and len(result.attrs["scale"]) == result.attrs["levels"] - 1
    sampler = SubsetSampler(_peak, N_TIME, 1000, 0.1, seed=0, proposal="acs")
    groups = sampler.groups(104)  # 100 chains and 4 that tie
    assert [len(g) for g in groups] == [10] * 9 + [14] and groups[0].start == 0 and groups[-1].stop == 104


def test_adaptive_conditional_sampling_does_not_draw_its_spread_from_the_seeds():
    """A chain's proposal must not depend on the level's seeds, its own among them: a spread of λ × the seeds' standard
    deviations did, and biased the oscillator's first passage low (×0.4 at 5e-7). Changing the last group's seed leaves
    every other chain of the level as it was (a group's λ depends only on the earlier groups' acceptance)."""
    sampler = SubsetSampler(lambda u: u[:, 0], 8, 100, 0.1, seed=5, proposal="acs")
    seeds = np.random.default_rng(1).standard_normal((sampler.chains, 8))
    seeds[:, 0] = 1.0 + np.abs(seeds[:, 0])
    other = seeds.copy()
    other[-1] = [4.0, 3.0, -3.0, 2.5, -2.5, 3.5, -3.5, 2.0]
    first, _ = sampler.run_level(1, seeds, seeds[:, 0], 1.0, INITIAL_SCALE)
    second, _ = sampler.run_level(1, other, other[:, 0], 1.0, INITIAL_SCALE)
    assert len(sampler.groups(sampler.chains)[-1]) == 1 and first.accepted > 0
    assert np.array_equal(first.states[:-1], second.states[:-1]) and not np.array_equal(first.states[-1], second.states[-1])
    assert np.array_equal(sampler.spread(0.3), np.full(8, 0.3)) and np.array_equal(sampler.spread(2.0), np.ones(8))


@pytest.mark.slow
def test_repeated_runs_scatter_as_their_reported_cov():
    """20 runs at 2.1 and 2.4 (P ≈ 3e-5 and 6e-7): every estimate within 3 reported CoV of the reference on the log scale of the
    report's intervals p·exp(±z δ) (|ln(estimate / reference)| ≤ 3δ, δ combined with the reference's CoV), and the mean reported
    CoV (the genealogy's) within 25 % of the empirical one (the root mean square relative error from the reference; about 1.1 and
    1.0 here)."""
    thresholds = [2.1, 2.4]
    references = [_isee(b, 2000, seed=5) for b in thresholds]
    runs = [subset_simulation(_peak, thresholds=thresholds, samples_per_level=1000, p0=0.1, seed=seed, dimension=N_TIME) for seed in range(20)]
    for column, (reference, reference_cov) in enumerate(references):
        estimates = np.array([r.probability.values[column] for r in runs])
        reported = np.array([r.cov.values[column] for r in runs])
        assert np.all(np.abs(np.log(estimates / reference)) <= 3.0 * np.hypot(reported, reference_cov))
        empirical = math.sqrt(np.mean((estimates - reference) ** 2)) / reference
        assert abs(reported.mean() / empirical - 1.0) < 0.25


def test_the_scene_runs_the_oscillator_of_the_reference():
    """The scene's runs under the white noise of u give the reference's response: the solver's peak (located between the
    samples) is the map's peak at the samples or at most 1 % above (the oscillator's period holds 40 samples)."""
    mass = 1.0e5
    scene = stochpound.scene_from_dict({
        "building": [{"name": "B1", "mass": [mass], "stiffness": [mass * OMEGA**2], "damping_ratio": ZETA}],
        "motion": {"type": "constant", "acceleration": 0.0, "duration": 1.0, "dt": 0.5},
    })
    motion = {"type": "white_noise", "S0": S, "duration": DURATION, "dt": DT}
    u = np.random.default_rng(4).standard_normal((2, N_TIME))
    result = subset_simulation(scene, motion=motion, response="peak_storey_drift", building="B1", floor=1,
                               thresholds=[0.2], samples_per_level=20, p0=0.5, seed=1)
    assert result.attrs["runs"] == 20 and result.threshold.attrs["units"] == "m"
    for a, sample_peak in zip(normal_motion(motion)(u), _peak(u)):
        run = stochpound.simulate(replace(scene, motion=SampledMotion(DT, a)), demands=True)
        peak = float(run["peak_storey_drift"].sel(building="B1", floor=1))
        assert sample_peak * (1.0 - 1e-9) <= peak <= sample_peak * 1.01


def test_adaptive_conditional_sampling_warns_on_a_scene_only():
    """aCS's reported CoV is too small on peaks over time (docs/rare-events.md): on a scene's response it warns, on a
    function of the normals it does not, and the modified Metropolis never does."""
    scene = stochpound.scene_from_dict({
        "building": [{"name": "B1", "mass": [1.0e5], "stiffness": [1.0e5 * OMEGA**2], "damping_ratio": ZETA}],
        "motion": {"type": "constant", "acceleration": 0.0, "duration": 1.0, "dt": 0.5},
    })
    settings = {"motion": {"type": "white_noise", "S0": S, "duration": 1.0, "dt": 0.02}, "response": "peak_storey_drift", "building": "B1", "floor": 1,
                "thresholds": [0.0], "samples_per_level": 10, "p0": 0.5}
    with pytest.warns(UserWarning, match="proposal: adaptive conditional sampling is not certified on a run's peaks over time"):
        subset_simulation(scene, proposal="acs", **settings)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        subset_simulation(scene, proposal="mma", **settings)
        subset_simulation(lambda u: u[:, 0], thresholds=[1.0], samples_per_level=100, p0=0.1, seed=0, dimension=3, proposal="acs")


@pytest.mark.parametrize(("arguments", "message"), [
    ({"p0": 0.7}, r"p0: must be a number in \(0, 0.5\]"),
    ({"samples_per_level": 105}, "samples_per_level: p0 × samples_per_level must be an integer that divides it"),
    ({"thresholds": []}, "thresholds: must be one or more finite numbers"),
    ({"seed": -1}, "seed: must be an integer >= 0"),
    ({"dimension": None}, "dimension: must be an integer >= 1"),
    ({"proposal": "gibbs"}, "proposal: must be one of mma, acs, got 'gibbs'"),
])
def test_bad_arguments_are_named(arguments, message):
    settings = {"thresholds": [1.0], "samples_per_level": 100, "p0": 0.1, "seed": 0, "dimension": 3, **arguments}
    with pytest.raises(ValueError, match=message):
        subset_simulation(lambda u: u[:, 0], **settings)


def test_a_response_that_stops_varying_is_refused():
    """An impact force that is 0 in most runs ties at the level's threshold: refused, naming the response."""
    with pytest.raises(ValueError, match="response: ties at level 1's threshold"):
        subset_simulation(lambda u: np.maximum(u[:, 0] - 2.0, 0.0), thresholds=[3.0], samples_per_level=100, p0=0.1, seed=0, dimension=2)


@pytest.mark.slow
def test_a_pounding_pair_agrees_with_crude_monte_carlo():
    """The closure of a contact-free pair (P(pounding) at gap b, by the gap identity) under a Kanai–Tajimi motion: one subset run
    against 600 seeded runs at P ≈ 0.1 and 0.02, within 3 combined CoV."""
    table = tomllib.loads(stochpound.model.bundled_scene_path("elastic_pair").read_text())
    table["building"][1]["mass"] = [2.0 * m for m in table["building"][1]["mass"]]
    for element in table["contact"]:
        element["gap"] = math.inf
    table["motion"] = {"type": "constant", "acceleration": 0.0, "duration": 1.0, "dt": 0.5}
    scene = stochpound.scene_from_dict(table)
    motion = {"type": "kanai_tajimi", "omega_g": 15.0, "zeta_g": 0.6, "pga": 2.0, "envelope": "jennings", "method": "filter", "duration": 10.0, "dt": 0.02}
    ensemble = stochpound.motions.kanai_tajimi(600, seed=11, **{k: v for k, v in motion.items() if k != "type"})
    closures = np.array([float(stochpound.simulate(replace(scene, motion=SampledMotion(0.02, a)))["peak_contact_closure"].values[1]) for a in ensemble.values])
    thresholds = np.quantile(closures, [0.9, 0.98])
    result = subset_simulation(scene, motion=motion, response="closure", contact=1, thresholds=thresholds, samples_per_level=200, p0=0.1, seed=2)
    for b, probability, cov in zip(thresholds, result.probability.values, result.cov.values):
        crude = np.mean(closures > b)
        combined = math.hypot(cov * probability, math.sqrt(crude * (1.0 - crude) / closures.size))
        assert abs(probability - crude) < 3.0 * combined


@pytest.mark.parametrize(("arguments", "message"), [
    ({"response": "speed"}, "response: must be one of closure, peak_storey_drift, base_displacement, impact_force"),
    ({"building": "B9"}, "building: must be one of B1, got 'B9'"),
    ({"floor": 2}, r"floor: must be a storey of 'B1', 1 .. 1, got 2"),
    ({"response": "closure"}, "contact: the scene has no contact"),
    ({"response": "base_displacement"}, "building: 'B1' has a fixed base"),
    ({"motion": {"type": "white_noise", "duration": 3.0, "dt": 0.02}}, "give exactly one of S0, rms"),
])
def test_a_scene_s_bad_response_is_named_before_any_run(arguments, message):
    scene = stochpound.scene_from_dict({
        "building": [{"name": "B1", "mass": [1.0e5], "stiffness": [1.0e5 * OMEGA**2], "damping_ratio": ZETA}],
        "motion": {"type": "constant", "acceleration": 0.0, "duration": 1.0, "dt": 0.5},
    })
    settings = {"motion": {"type": "white_noise", "S0": S, "duration": 3.0, "dt": 0.02}, "response": "peak_storey_drift", "building": "B1", "floor": 1,
                "thresholds": [0.1], "samples_per_level": 10, **arguments}
    with pytest.raises(ValueError, match=message):
        subset_simulation(scene, **settings)
