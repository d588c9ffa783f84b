"""The sufficiency test of a stripe store's measure: the demand's trend with M, ln R and ε within the stripes (issue 44, item 5)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from stochpound.analysis import stripe_regression

STRIPES, EVENTS, RECORDS = 5, 30, 2
"""A synthetic stripe store: every record of every event at every stripe, as a stripe store reuses its records."""


def _synthetic(rng: np.random.Generator, slopes: dict[str, float]) -> dict[str, np.ndarray]:
    """ln D = α_stripe + Σ b x + an event's term + a record's term + the run's own noise, with the covariates of each record."""
    magnitude = np.repeat(rng.uniform(6.0, 7.8, EVENTS), RECORDS)
    log_r = np.log(rng.uniform(10.0, 80.0, EVENTS * RECORDS))
    epsilon = rng.normal(0.0, 1.0, EVENTS * RECORDS)
    shared = np.repeat(rng.normal(0.0, 0.3, EVENTS), RECORDS) + rng.normal(0.0, 0.2, EVENTS * RECORDS)  # one earthquake's, one record's
    stripe = np.repeat(np.arange(STRIPES), EVENTS * RECORDS)
    x = {"M": np.tile(magnitude, STRIPES), "ln R": np.tile(log_r, STRIPES), "ε": np.tile(epsilon, STRIPES)}
    y = (np.log([0.01, 0.02, 0.04, 0.07, 0.1])[stripe] + sum(slopes[k] * x[k] for k in x) + np.tile(shared, STRIPES)
         + rng.normal(0.0, 0.15, stripe.size))
    return {"y": y, "stripe": stripe, "event": np.tile(np.repeat(np.arange(EVENTS), RECORDS), STRIPES), **x}


def test_the_slopes_and_textbook_errors_are_least_squares_with_one_intercept_a_stripe():
    data = _synthetic(np.random.default_rng(4), {"M": 0.4, "ln R": 0.0, "ε": -0.3})
    data["y"][7] = np.nan  # a run without a finite demand is left out
    fit = stripe_regression(data["y"], data["stripe"], {k: data[k] for k in ("M", "ln R", "ε")}, level=0.05, confidence=0.9)
    keep = np.isfinite(data["y"])
    dummies = (data["stripe"][keep, None] == np.arange(STRIPES)).astype(float)  # the fixed effects written out, not taken out by means
    z = np.column_stack([dummies, data["M"][keep], data["ln R"][keep], data["ε"][keep]])
    coefficients, *_ = np.linalg.lstsq(z, data["y"][keep], rcond=None)
    dof = keep.sum() - STRIPES - 3
    sigma2 = np.sum((data["y"][keep] - z @ coefficients) ** 2) / dof
    errors = np.sqrt(sigma2 * np.diag(np.linalg.inv(z.T @ z)))[STRIPES:]
    fit_textbook = stripe_regression(data["y"], data["stripe"], {k: data[k] for k in ("M", "ln R", "ε")}, confidence=0.9)
    assert fit.clustered is False and fit.runs == keep.sum() == STRIPES * EVENTS * RECORDS - 1 and fit.stripes == STRIPES
    np.testing.assert_allclose(fit.slope, coefficients[STRIPES:], rtol=1e-10)
    np.testing.assert_allclose(fit.standard_error, errors, rtol=1e-10)
    t = np.array(fit.slope) / errors
    np.testing.assert_allclose(fit.p_value, 2 * stats.t.sf(np.abs(t), dof), rtol=1e-8)
    np.testing.assert_allclose(np.array(fit.upper) - np.array(fit.slope), stats.t.ppf(0.95, dof) * errors, rtol=1e-10)
    assert fit_textbook == fit and fit.degrees_of_freedom == dof
    assert fit.residual_sigma == pytest.approx(math.sqrt(sigma2), rel=1e-12)


def test_the_clustered_errors_are_the_sandwich_over_the_earthquakes():
    data = _synthetic(np.random.default_rng(5), {"M": 0.0, "ln R": 0.0, "ε": 0.0})
    x = np.column_stack([data[k] for k in ("M", "ln R", "ε")])
    fit = stripe_regression(data["y"], data["stripe"], {k: data[k] for k in ("M", "ln R", "ε")}, cluster=data["event"])
    dummies = (data["stripe"][:, None] == np.arange(STRIPES)).astype(float)
    z = np.column_stack([dummies, x])
    bread = np.linalg.inv(z.T @ z)
    residual = data["y"] - z @ (bread @ z.T @ data["y"])
    meat = sum(np.outer(z[data["event"] == g].T @ residual[data["event"] == g], z[data["event"] == g].T @ residual[data["event"] == g])
               for g in range(EVENTS))
    n, k = z.shape
    factor = EVENTS / (EVENTS - 1) * (n - 1) / (n - k)  # Cameron & Miller (2015), CR1 with the stripe intercepts among the k
    errors = np.sqrt(np.diag(factor * bread @ meat @ bread))[STRIPES:]
    np.testing.assert_allclose(fit.standard_error, errors, rtol=1e-8)
    assert fit.clustered and fit.clusters == EVENTS and fit.degrees_of_freedom == EVENTS - 1


def test_a_planted_slope_is_recovered_within_its_interval_and_a_null_one_is_flagged_at_about_the_level():
    repeats, covered, found, flagged, flagged_textbook = 300, 0, 0, 0, 0
    rng = np.random.default_rng(11)
    for _ in range(repeats):
        data = _synthetic(rng, {"M": 0.6, "ln R": 0.0, "ε": 0.0})
        covariates = {k: data[k] for k in ("M", "ln R", "ε")}
        fit = stripe_regression(data["y"], data["stripe"], covariates, cluster=data["event"])
        covered += fit.lower[0] <= 0.6 <= fit.upper[0]
        found += "M" in fit.insufficient
        flagged += "ln R" in fit.insufficient
        flagged_textbook += "ln R" in stripe_regression(data["y"], data["stripe"], covariates).insufficient
    # binomial(300, 0.95): mean 285, sd 3.8; binomial(300, 0.05): mean 15, sd 3.8 — bounds at about 3 sd
    assert 273 <= covered <= 297, covered
    assert found >= 285, found  # 0.6 a unit of M: about 5.7 standard errors (0.3 of event noise over M's spread 0.52 and 30 events)
    assert flagged <= 27, flagged
    # the textbook errors count each record five times (one a stripe) and call the null trend far more often than the level
    assert flagged_textbook > 2 * flagged and flagged_textbook > 40, (flagged_textbook, flagged)


def test_the_reason_names_the_significant_covariates_with_n():
    data = _synthetic(np.random.default_rng(2), {"M": 0.8, "ln R": 0.0, "ε": 0.0})
    fit = stripe_regression(data["y"], data["stripe"], {k: data[k] for k in ("M", "ln R", "ε")}, cluster=data["event"])
    assert fit.insufficient == ("M",)
    assert fit.reason().startswith("insufficient with respect to M: ln D rises by ") and f"(n {fit.runs})" in fit.reason()
    assert fit.frame().loc["M", "significant"] and not fit.frame().loc["ln R", "significant"]
    assert "n 300 runs in 5 stripes, one intercept a stripe, errors clustered by earthquake (30 clusters)" in fit.conditions()
    null = stripe_regression(data["y"] - 0.8 * data["M"], data["stripe"], {"M": data["M"]}, cluster=data["event"], level=1e-6)
    assert null.reason() == "no residual trend with M within the stripes at the 0.0001 % level (n 300): not insufficient by this test"


@pytest.mark.parametrize(("arguments", "message"), [
    ({"covariates": {}}, "covariates: must name one or more"),
    ({"level": 1.0}, "level: must be in (0, 1), got 1.0"),
    ({"stripe": [0, 1]}, "stripe: must have one value a run (6), got 2"),
    ({"covariates": {"M": [6.0, 6.0, 7.0, 7.0, 6.5, 6.5]}, "stripe": [0, 1, 0, 1, 0, 1], "cluster": [1] * 6},
     "cluster: the runs fall in 1 cluster, clustered errors of 1 slope need more than 1"),
    ({"covariates": {"M": [6.0, 6.0, 6.0, 7.0, 7.0, 7.0]}}, "covariates['M']: does not vary within the stripes"),
    ({"covariates": {"M": [6.0, 6.5, 7.0, 6.0, 6.5, 7.0], "ε": [0, 1, 2, 0, 1, 3], "ln R": [1, 2, 3, 4, 5, 6], "x": [1, 0, 0, 1, 0, 0]}},
     "log_demand: 6 runs with finite values in 2 stripes are too few for 4 slopes (need more than 6)"),
])
def test_bad_input_is_one_line_naming_the_argument(arguments, message):
    given = {"log_demand": np.log([1.0, 2.0, 3.0, 1.5, 2.5, 3.5]), "stripe": [0, 0, 0, 1, 1, 1], "covariates": {"M": [6.0, 6.5, 7.0, 6.0, 6.5, 7.5]}}
    with pytest.raises(ValueError, match=f"^{__import__('re').escape(message)}"):
        stripe_regression(**{**given, **arguments})


@pytest.mark.slow
def test_a_small_stripe_store_is_tested_on_each_motions_own_earthquake(tmp_path):
    from stochpound import open_store
    from stochpound.analysis import store_sufficiency
    from stochpound.experiment._runner import load_experiment, run_experiment
    from stochpound.motions import scenario_distribution
    from stochpound.motions.records import load_suite_member
    from stochpound.risk import contact_free_closure
    from tests.helpers import SITE_SCENE, write_experiment

    records = "".join(f'\n[[records]]\nrecord = "fema_p695_far_field/{i:02d}{c}"\nduration = 5.0\n' for i in range(1, 7) for c in "ab")
    text = (f'[experiment]\nname = "site"\n{SITE_SCENE}\n[grid]\ngap = ["inf"]\n{records}\n[intensity]\nmeasure = "psa"\nperiod = 0.5\n'
            'levels = [0.4, 0.2]\nselection = "conditional_spectrum"\nmotions = 4\nmax_scale_factor = 5.0\nseed = 2\n'
            '[site]\nvs30 = 400.0\nmagnitude = [7.0, 6.6]\ndistance_km = 20.0\nmechanism = "strike_slip"\n[solver]\nmethod = "exact"\n')
    store = open_store(run_experiment(load_experiment(write_experiment(tmp_path, text, "site.toml")), workers=0, progress=False).store).load()
    result = store_sufficiency(store, cluster=False)  # 4 motions a stripe from few earthquakes: too few clusters for 3 slopes
    (fit,) = result.results
    assert result.measure == store.pound.intensity.measure.label and result.configurations == ((),) and fit.runs == 2 * 4
    closure = contact_free_closure(store).transpose("intensity", "record")
    chosen = np.isfinite(closure.values)
    stripe = np.broadcast_to(np.arange(2)[:, None], chosen.shape)[chosen]
    members = [load_suite_member(str(name)).metadata for name in store.record.values]
    motion = store["motion_intensity"].max(["gap", "intensity", "realization"]).values  # the unscaled PSA(0.5 s), g
    epsilon = []
    for meta, value in zip(members, motion):  # each record's ε in its own earthquake, the stripe scenario's mechanism
        median, sigma = scenario_distribution("psa", 0.5, magnitude=meta["magnitude"], distance_km=meta["distance"], vs30=meta["vs30"],
                                              mechanism="strike_slip")
        epsilon.append((math.log(value) - math.log(median)) / sigma)
    records = np.broadcast_to(np.arange(len(members))[None, :], chosen.shape)[chosen]
    events = np.array([meta["event"] for meta in members])[records]
    expected = stripe_regression(np.log(closure.values[chosen]), stripe,
                                 {"M": np.array([m["magnitude"] for m in members])[records],
                                  "ln R": np.log([m["distance"] for m in members])[records], "ε": np.array(epsilon)[records]},
                                 )
    assert fit == expected and not fit.clustered
    assert len(set(events)) == 2  # the chosen motions come from two earthquakes: clustered errors of 3 slopes are refused
    with pytest.raises(ValueError, match=r"^cluster: the runs fall in 2 clusters, clustered errors of 3 slopes need more than 3"):
        store_sufficiency(store)
    assert result.frame().index.names == ["configuration", "covariate"] and len(result.frame()) == 3
