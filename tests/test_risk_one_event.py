"""Results for one earthquake (issue 48): the risk answer and the report come, their intervals stated as not estimable.

The bootstrap resamples the motions, by earthquake where the store knows them (docs/risk.md, "Intervals"):
with one motion, or with every motion from one earthquake, every resample is the sample itself, so no
interval is estimable. ``stochpound risk`` and ``stochpound report build`` once stopped there ("clusters:
the bootstrap needs at least 2 clusters (events), got 1"); they now give the estimates, which do not depend
on the bootstrap, and say why there is no interval.
"""

from __future__ import annotations

import re

import numpy as np
import pytest
import xarray as xr

from stochpound.hazard import HazardCurve, rate_from_probability
from stochpound.risk import code_rules_risk, risk_curve, risk_targeted_separation, stripe_fragility, store_risk
from stochpound.stats import bootstrap_weights, jackknife_weights, resampling_obstacle
from stochpound.store import open_store
from tests.helpers import ISOLATED, invoke, report_page_text, risk_text, run_in_process

STRIPES = 'measure = "psa"\nperiod = 1.0\nlevels = [0.3, 0.8, 1.5]'
ONE_MOTION = "only one motion, and a single record has no record-to-record variability to resample"
ONE_EARTHQUAKE = "both motions come from one earthquake (Northridge 1994)"
HAZARD = HazardCurve.power_law_through((0.4, rate_from_probability(0.10)), (0.8, rate_from_probability(0.02)))


def test_the_obstacle_names_one_motion_or_one_earthquake_and_the_resamplers_refuse_with_it():
    assert resampling_obstacle(1) == ONE_MOTION
    assert resampling_obstacle(2, ["event Northridge 1994"] * 2).startswith(ONE_EARTHQUAKE)
    assert "one station (MUL, earthquake unknown)" in resampling_obstacle(3, ["station MUL"] * 3)
    assert resampling_obstacle(2) == resampling_obstacle(2, ["event Kobe 1995", "event Northridge 1994"]) == ""
    with pytest.raises(ValueError, match=re.escape(f"clusters: the bootstrap needs at least 2 clusters (events), got 1: {ONE_EARTHQUAKE}")):
        bootstrap_weights(2, 10, 0, clusters=["event Northridge 1994"] * 2)
    with pytest.raises(ValueError, match=re.escape(f"record: the bootstrap needs at least 2 motions, got 1: {ONE_MOTION}")):
        jackknife_weights(1)


def _demands(events: list[str], seed: int = 5) -> xr.Dataset:
    """Contact-free demands at five stripes of motions from ``events`` (one per motion): closures rising with the intensity."""
    rng = np.random.default_rng(seed)
    levels = np.array([0.2, 0.4, 0.6, 0.8, 1.0])
    records = len(events)
    u1 = levels[:, None, None] * np.exp(rng.normal(np.log(0.05), 0.4, (1, records, 2)))
    u2 = levels[:, None, None] * np.exp(rng.normal(np.log(0.08), 0.4, (1, records, 2)))
    closure = np.sqrt(u1**2 + u2**2) * np.exp(rng.normal(0.0, 0.3, u1.shape))
    dims = ("intensity", "record", "contact")
    return xr.Dataset({"peak_displacement_left": (dims, u1), "peak_displacement_right": (dims, u2),
                       "correlation": (dims, np.zeros(u1.shape)), "peak_closure": (dims, closure)},
                      coords={"intensity": levels, "record_event": ("record", events)})


@pytest.mark.parametrize("events", [["Kobe 1995"] * 8, ["Kobe 1995"]])
def test_one_earthquake_gives_the_estimates_without_intervals_and_says_why(events):
    demands = _demands(events)
    events_at = (demands["peak_closure"].max("contact") >= xr.DataArray([0.04, 0.08], dims="gap", coords={"gap": [0.04, 0.08]})).astype(float)
    fragility = stripe_fragility(events_at, bootstrap=200)
    separation = risk_targeted_separation(risk_curve(fragility, HAZARD), dim="gap")
    plain = risk_targeted_separation(risk_curve(stripe_fragility(events_at, bootstrap=0), HAZARD), dim="gap")
    expected = "all 8 motions come from one earthquake (Kobe 1995)" if len(events) > 1 else ONE_MOTION
    for result in (fragility, separation):
        assert result.attrs["no_interval"].startswith(expected)
        assert not {"theta_lower", "theta_bootstrap", "lower", "upper"} & set(result.variables)
    xr.testing.assert_identical(separation["separation"], plain["separation"])  # the estimate does not depend on the bootstrap
    if len(events) > 1:  # the code rules take 7 motions or more
        rules = code_rules_risk(demands, HAZARD, bootstrap=200)
        assert rules.attrs["no_interval"].startswith(expected) and "maf_lower" not in rules
        np.testing.assert_array_equal(rules["maf"].values, code_rules_risk(demands, HAZARD, bootstrap=0)["maf"].values)


def test_two_earthquakes_still_give_intervals():
    demands = _demands(["Kobe 1995"] * 4 + ["Northridge 1994"] * 4)
    events_at = (demands["peak_closure"].max("contact") >= 0.06).astype(float)
    fragility = stripe_fragility(events_at, bootstrap=200)
    assert "no_interval" not in fragility.attrs and "theta_lower" in fragility
    assert "2 clusters of the 8 motions" in fragility["theta_lower"].attrs["method"]


# ---------------------------------------------------------------- end to end: one record, and two components of one earthquake


def _records(names: list[str]) -> str:
    return "".join(f'\n[[records]]\nrecord = "fema_p695_far_field/{name}"\nduration = 5.0\n' for name in names)


@pytest.fixture(scope="module")
def one_event_stores(tmp_path_factory):
    """Two small stripes stores of the flagship's scene, contact-free only: one record (01a), and the two components of one
    station of the Northridge earthquake (01a, 01b)."""
    folder = tmp_path_factory.mktemp("one_event")
    full = risk_text(ISOLATED, "gap = [inf]", STRIPES)
    stores = {}
    for name, records in (("one_record", ["01a"]), ("one_earthquake", ["01a", "01b"])):
        start = full.index("\n[[records]]")
        text = full[:start] + _records(records) + full[full.index("\n[intensity]"):]
        stores[name] = run_in_process(folder, name, text)
    return folder, stores


WHY = {"one_record": ONE_MOTION, "one_earthquake": ONE_EARTHQUAKE}


@pytest.mark.parametrize("name", ["one_record", "one_earthquake"])
def test_risk_of_one_earthquake_answers_with_the_interval_not_estimable(one_event_stores, name):
    _, stores = one_event_stores
    result = invoke("risk", str(stores[name]))
    assert result.exit_code == 0, result.output
    assert "Risk-targeted separation g* (m; no interval: not estimable;" in result.output
    assert f"note: no interval is estimable for g*, the rates or the code rules: {WHY[name]}" in result.output
    assert "Design to (m; g* (no bound: the interval is not estimable)):" in result.output
    separation = store_risk(open_store(stores[name]), bootstrap=0).separation["separation"].values
    for value in separation:  # the g* printed is the estimate without a bootstrap
        assert f"{value:.3f}" in result.output
    assert "Traceback" not in result.output and "Error" not in result.output


@pytest.mark.parametrize("name", ["one_record", pytest.param("one_earthquake", marks=pytest.mark.slow)])  # a report build: ~10 s each
def test_the_report_of_one_earthquake_is_built_with_the_interval_not_estimable(one_event_stores, name):
    folder, stores = one_event_stores
    out = folder / f"report_{name}"
    result = invoke("report", "build", str(stores[name]), "--out", str(out), "--format", "html")
    assert result.exit_code == 0, result.output
    text = report_page_text(out, folder)
    motions = "1 motion " if name == "one_record" else "2 motions "
    assert f"from {motions}(3 stripes of PSA(T = 1 s, 5 % damping) in g) at the site of its hazard curve, without intervals (not estimable: {WHY[name]}" in text
    assert "There is no upper bound of g* to design to (its interval is not estimable)" in text
    assert f"per configuration and target, without an interval (not estimable: {WHY[name]}" in text
    assert text.count("without a band (not estimable:") == 2  # the risk curve and the fragility curves
    assert "bootstrap band" not in text and "nan m" not in text.lower()
    if name == "one_record":  # issue 47: "1 motions" in the Intensity and record-suite texts; issue 48: a "most efficient" measure from round-off
        assert "1 motions" not in text and "1 motion, each scaled to every level" in text and "the most efficient is" not in text
    for section in ("Risk: experiment", "Intensity measure", "Hazard curve of", "Design summary."):  # the rest as usual
        assert section in text
