"""Risk answers an engineer can sign (docs/risk.md): the intervals of return periods and probabilities, the gap to design to,
degenerate fits named as steps with their effect on λ, the wall-free D_TM against the moat, and the false forms that must not return.

Each check compares with an independent computation (the Poisson formulas, the hazard table itself, a hand-made chain).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import pandas as pd
import xarray as xr

from stochpound.report.sections._risk import design_summary_text, design_value_text, moat_text
from stochpound.risk import HazardCurve, StoreDemands, StoreRisk, degenerate_text, mean_annual_frequency, rate_intervals
from stochpound.risk._fragility import ALWAYS, FIT, NEVER, Fragility
from stochpound.motions import Measure
from stochpound.store import Intensity, Selection

HAZARD = HazardCurve([0.05, 0.2, 0.5, 1.0, 2.0], [0.0333, 8e-3, 2e-3, 5e-4, 8e-5], units="g", measure="PGA")


def test_return_period_and_probability_intervals_map_the_maf_interval():
    maf = xr.DataArray([1e-3, 4e-4], dims="gap")
    result = rate_intervals(xr.Dataset({"maf": maf, "maf_lower": maf / 2, "maf_upper": maf * 3}), years=50.0)
    np.testing.assert_allclose(result["return_period_lower"], [1 / 3e-3, 1 / 1.2e-3])  # the shortest period: the highest rate
    np.testing.assert_allclose(result["return_period_upper"], [2000.0, 5000.0])
    np.testing.assert_allclose(result["probability_lower"], [1 - math.exp(-0.5e-3 * 50), 1 - math.exp(-2e-4 * 50)])
    np.testing.assert_allclose(result["probability_upper"], [1 - math.exp(-3e-3 * 50), 1 - math.exp(-1.2e-3 * 50)])
    assert "return_period_lower" not in rate_intervals(xr.Dataset({"maf": maf}), years=50.0)  # no interval invented without one


def test_a_degenerate_fit_is_named_a_step_with_the_rate_it_actually_gives():
    status = np.array([FIT, ALWAYS, ALWAYS, NEVER])
    text = degenerate_text(status, HAZARD)
    plateau = mean_annual_frequency(Fragility(0.0, 0.0, ALWAYS, "stripes"), HAZARD)  # what the chain integrates for 'always'
    assert math.isclose(plateau, 0.0333)  # the hazard's rate at the lowest intensity of its table
    assert f"{plateau:.3g} /yr" in text and "2 of 4 gaps: a step 'always'" in text and "1 of 4 gaps: a step 'never'" in text
    assert "plateau set by the hazard table" in text
    assert "lognormal fitted" not in text and "the lognormal" not in text
    assert degenerate_text(np.array([FIT, FIT]), HAZARD) == ""


def test_a_decreasing_fit_has_the_rate_of_its_flat_fit_stated_not_a_dash():
    """19, 19 and 19 of 20 at three stripes: the probit's slope is not positive; the fit among fragilities that do not fall with
    intensity is flat at 57/60, so λ = 0.95 × the hazard's rate at its table's lowest intensity, in the chain and in the words."""
    from stochpound.risk import code_rules_risk, flat_fit_maf, stripe_fragility
    from stochpound.risk._fragility import DECREASING
    from stochpound.risk._chain import fit_name

    levels = np.array([0.2, 0.5, 1.0])
    events = np.ones((3, 20))
    events[0, 3] = events[1, 11] = events[2, 17] = 0.0  # 19 of 20 at every stripe, the misses at different motions
    fragility = stripe_fragility(xr.DataArray(events, dims=("intensity", "record"), coords={"intensity": levels}), bootstrap=0)
    assert int(fragility["status"]) == DECREASING and np.isnan(float(fragility["theta"]))
    rate = float(mean_annual_frequency(fragility, HAZARD))
    assert math.isclose(rate, 57 / 60 * 0.0333, rel_tol=1e-12)  # p̄ λ(lo), by hand
    assert math.isclose(float(flat_fit_maf([19, 19, 19], [20, 20, 20], HAZARD)), rate, rel_tol=1e-12)
    text = degenerate_text(np.array([FIT, DECREASING]), HAZARD)
    assert "1 of 2 gaps: a flat fit 'decreasing'" in text and "p̄ × 0.0333 /yr" in text and "upper bound" in text
    assert "a step 'decreasing'" not in text and "NaN" not in text
    assert fit_name(DECREASING) == "flat: decreasing (F ≡ fraction of runs that pounded)"
    # the band: a resample whose fit is decreasing too has its flat fit's rate, not NaN (left out of the interval)
    from stochpound.risk import risk_curve

    sampled = stripe_fragility(xr.DataArray(events, dims=("intensity", "record"), coords={"intensity": levels}), bootstrap=60, seed=3)
    curve = risk_curve(sampled, HAZARD)
    flat = sampled["flat_bootstrap"]
    assert int(flat.notnull().sum()) > 0 and bool(np.isfinite(curve["maf_bootstrap"]).all())
    np.testing.assert_allclose(curve["maf_bootstrap"].where(flat.notnull()).dropna("bootstrap"), (flat * 0.0333).dropna("bootstrap"), rtol=1e-12)
    assert float(curve["maf_lower"]) <= rate <= float(curve["maf_upper"])
    # a code rule whose gap pounds 19 of 20 at every stripe: the rules table gets the flat fit's rate, not NaN ("–")
    closure = xr.DataArray(np.where(events > 0, 0.30, 0.01)[..., None], dims=("intensity", "record", "contact"),
                           coords={"intensity": levels, "contact": [0]})
    demands = xr.Dataset({"peak_closure": closure, "peak_displacement_left": closure * 0 + 0.05, "peak_displacement_right": closure * 0 + 0.05,
                          "correlation": closure * 0.0})
    rules = code_rules_risk(demands, HAZARD, bootstrap=0)
    assert (rules["status"] == DECREASING).all()
    np.testing.assert_allclose(rules["maf"], 57 / 60 * 0.0333, rtol=1e-12)


def _risk(rules: xr.Dataset | None = None) -> StoreRisk:
    """A hand-made chain: g* 0.20 m [0.15, 0.31] for 10 %/50 yr and 0.40 m [0.30, 0.62] for 2 %/50 yr, one configuration."""
    target = xr.DataArray([0.10, 0.02], dims="target", name="target")
    separation = xr.Dataset({"separation": ("target", [0.20, 0.40]), "lower": ("target", [0.15, 0.30]), "upper": ("target", [0.31, 0.62])},
                            coords={"target": target})
    fragility = xr.Dataset({"status": ("gap", np.array([FIT, ALWAYS], dtype=np.int8))}, coords={"gap": [0.1, 0.5]})
    return StoreRisk(fragility, xr.Dataset(), separation, rules, "", HAZARD, motions=22, method="stripes", years=50.0, confidence=0.95)


def test_the_gap_to_design_to_is_the_upper_bound_of_g_star_stated_as_such():
    risk = _risk()
    frame = risk.design_frame()
    assert list(frame["design"]) == [0.31, 0.62]
    assert set(frame["basis"]) == {"97.5 % one-sided upper bound of g*"}
    text = design_value_text(risk)
    assert "0.310 m for 10 % in 50 yr; 0.620 m for 2 % in 50 yr" in text and "upper bound of g*, not g* itself" in text
    unbounded = _risk()
    unbounded.separation = unbounded.separation.drop_vars(["lower", "upper"])
    assert list(unbounded.design_frame()["design"]) == [0.20, 0.40] and "no bootstrap" in design_value_text(unbounded)
    assert "g* is a central estimate from 22 motions and" in text
    selected = _risk()
    selected.setting = Intensity(Measure("pga"), "g", (0.1,), "stripes", "stripes", "", selection=Selection("conditional_spectrum", 22, 4.0, 1, ()))  # motions chosen per stripe
    assert "g* is a central estimate from 22 motions per stripe and" in design_value_text(selected)


def test_the_wall_free_d_tm_is_compared_with_the_moat_and_the_wall_governs_a_target_it_is_hit_more_often_than():
    rules = xr.Dataset({"gap": (("design_level", "rule"), [[0.45, 0.1], [0.92, 0.2]])},
                       coords={"design_level": [0.10, 0.02], "rule": ["dtm", "abs"]})
    moat = xr.Dataset({"maf": (("mu", "level"), [[1 / 918], [1 / 2000]])}, coords={"level": [0.60], "mu": [0.05, 0.12]})
    moat = rate_intervals(moat.assign(maf_lower=moat["maf"] / 2, maf_upper=moat["maf"] * 2), 50.0)
    text = moat_text(_risk(rules), StoreDemands({}, {}, moat))
    assert "at 10 %/50 yr is 0.45 m and is within the moat clearance 0.6 m" in text
    assert "at 2 %/50 yr is 0.92 m and exceeds the moat clearance 0.6 m" in text  # one value over the configurations: no "largest"
    varied = xr.Dataset({"gap": (("design_level", "rule", "mu"), [[[0.45, 0.40], [0.1, 0.1]], [[0.92, 0.70], [0.2, 0.2]]])},
                        coords={"design_level": [0.10, 0.02], "rule": ["dtm", "abs"], "mu": [0.05, 0.12]})
    assert "at 2 %/50 yr (the largest over the configurations) is 0.92 m" in moat_text(_risk(varied), StoreDemands({}, {}, moat))
    # 1/918 and 1/2000 /yr against 10 %/50 yr (once in 475 yr) and 2 %/50 yr (once in 2475 yr): the clearance limits only the rarer target
    assert ("The base reaches the moat wall at its 0.6 m clearance once in 918 [459, 1.84e+03] yr in its worst configuration with the "
            "wall; less often than 10 % in 50 yr allows (once in 475 yr) in every configuration with the wall: it does not limit the "
            "separation for this target.") in text
    assert ("more often than 2 % in 50 yr allows (once in 2.47e+03 yr) in every configuration: there the wall, not the gap, "
            "limits the separation for this target.") in text
    summary = design_summary_text(_risk(), StoreDemands({}, {}, moat))
    assert ("Limit state judged (no structural limit state with an objective, so none is ranked against it; at g*, what limits the "
            "separation): pounding between the buildings for 10 % in 50 yr; for 2 % in 50 yr, the base reaching the moat wall at its 0.6 m "
            "clearance more often than the target allows in every configuration, once in 918 [459, 1.84e+03] yr at worst.") in summary
    assert ("Limit state judged (no structural limit state with an objective, so none is ranked against it; at g*, what limits the "
            "separation): pounding between the buildings for 10 % in 50 yr; pounding between the buildings for 2 %") in design_summary_text(_risk(), None)
    # the flagship's summary said the wall governed 2 %/50 yr "in the other configurations" from its worst configuration's rate,
    # also where the base reached it less often than that target allows: each configuration is judged on its own rate
    once = rate_intervals(xr.Dataset({"maf": (("mu", "level"), [[1 / 918], [1 / 3000]])}, coords={"level": [0.60], "mu": [0.05, 0.12]}), 50.0)
    summary = design_summary_text(_risk(), StoreDemands({}, {}, once))
    assert ("for 2 % in 50 yr, the base reaching the moat wall at its 0.6 m clearance more often than the target allows in 1 of 2 "
            "configurations (μ 0.05), once in 918 yr at worst, and pounding between the buildings in the other configurations.") in summary
    assert "in 1 of 2 configurations (μ 0.05): there the wall, not the gap, limits" in moat_text(_risk(rules), StoreDemands({}, {}, once))
    # issue 45: the flagship's configurations without a moat were said to reach 'the 0.6 m moat clearance (the bearing's stop)', a
    # stop no run has: only the configurations with the wall are judged by it, and the others' rows say what they are
    both = rate_intervals(xr.Dataset({"maf": (("moat", "mu", "level"), [[[1 / 918], [1 / 3000]], [[1 / 918], [1 / 3000]]])},
                                     coords={"level": [0.60], "moat": ["none", "wall"], "mu": [0.05, 0.12]}), 50.0)
    walls = xr.DataArray([False, True], dims="moat", coords={"moat": ["none", "wall"]})
    demands = StoreDemands({}, {}, both, walled=walls)
    assert [row[2] for row in demands.wall_exceedances([0.02], 50.0)] == [[{"moat": "wall", "mu": 0.05}]]
    summary = design_summary_text(_risk(), demands)
    assert ("the base reaching the moat wall at its 0.6 m clearance more often than the target allows in 1 of 2 configurations with the "
            "wall (moat wall, μ 0.05), once in 918 yr at worst, and pounding between the buildings in the other configurations") in summary
    assert "bearing's stop" not in summary and "moat none" not in summary and ") (" not in summary
    text = moat_text(_risk(rules), demands)
    assert "In the configurations without the wall no stop is modelled at the base" in text
    frame = demands.moat_frame()
    assert list(frame["what it is"]) == ["no wall: base passes the walled twin's clearance (no stop modelled)"] * 2 + ["base reaches the wall"] * 2
    # a scene without walls: their stiffness is no choice the answer rests on
    assert "the moat wall's stiffness" not in design_summary_text(_risk(), None)
    walled = _risk()
    walled.assumptions = {"moat walls": "B1 at the base, clearance 0.6 m"}
    assert "the conditioning measure, the moat wall's stiffness: the sensitivity table" in design_value_text(walled)
    single = StoreDemands({}, {}, moat.isel(mu=0, drop=True)).moat_frame()  # one configuration: a plain index
    assert single.index.name == "moat clearance (m)" and math.isclose(single["once in, upper (yr)"].iloc[0], 2 * 918)
    assert moat_text(_risk(rules), None) == "" and moat_text(_risk(rules.sel(rule=["abs"])), StoreDemands({}, {}, moat)) == ""


def test_the_suite_mean_rules_are_not_named_as_the_codes_own():
    from stochpound.risk._chain import RULE_NAMES

    for key in ("srss", "srss_reduced", "dtm"):
        assert "suite-mean" in RULE_NAMES[key], RULE_NAMES[key]
    assert "SRSS (ASCE 7 δ_MT)" not in RULE_NAMES.values() and "0.7 SRSS (Eurocode 8)" not in RULE_NAMES.values()


def test_the_rules_table_gives_each_return_period_with_its_interval_and_each_fit_its_kind():
    dims = ("design_level", "rule", "contact")
    shape = (1, 1, 1)
    rules = xr.Dataset({"gap": (dims, np.full(shape, 0.3)), "status": (("design_level", "rule"), np.array([[ALWAYS]], dtype=np.int8))},
                       coords={"design_level": [0.02], "rule": ["srss"], "contact": [0], "code_intensity": ("design_level", [0.8]),
                               "stripe_intensity": ("design_level", [0.8])})
    maf = xr.DataArray([[1e-3]], dims=dims[:2])
    rules = rate_intervals(rules.assign(maf=maf, maf_lower=maf / 2, maf_upper=maf * 2, return_period=1 / maf,
                                        probability=1 - np.exp(-50 * maf)), 50.0)
    frame = _risk(rules).rules_frame()
    row = frame.iloc[0]
    assert (row["once in, lower (yr)"], row["once in (yr)"], row["once in, upper (yr)"]) == (500.0, 1000.0, 2000.0)
    assert row["P lower"] < row["P in 50 yr"] < row["P upper"]
    assert row["fit"] == "step: always"
    # 2 %/50 yr allows −ln(0.98)/50 = 4.04e-4 /yr; λ_P = 1e-3 does not meet it
    assert not row["meets its level"] and not row["meets, upper bound"]
    met = _risk(rules.assign(maf=rules["maf"] / 10, maf_lower=rules["maf_lower"] / 10, maf_upper=rules["maf_upper"] / 10)).rules_frame().iloc[0]
    assert met["meets its level"] and met["meets, upper bound"]  # 1e-4 and 2e-4 /yr
    assert isinstance(frame, pd.DataFrame) and "SRSS of suite-mean peaks" in frame.index.get_level_values("rule")[0]


WALLS = "".join(f'\n[[scene.wall]]\nbuilding = "B1"\nside = "{side}"\nlevel = 0\ngap = 0.1\nstiffness = 3283500000.0\nrestitution = 0.5\n'
                for side in ("left", "right"))


def test_the_rules_paragraph_says_which_rules_its_range_covers_and_the_g_star_table_how_it_resampled():
    """Read as the owner would: 'Over the rules ... the return periods range from 339' while a design-analysis row said 58.7 yr;
    'each rule means pounding ASCE 7 ...' garbled; Table 1 said 'the motions resampled' of a cluster bootstrap over events."""
    from stochpound.report.sections._risk import _rules_blocks, _separation_table

    dims = ("design_level", "rule", "contact")
    rules = xr.Dataset({"gap": (dims, np.full((1, 1, 1), 0.3)), "status": (dims[:2], np.array([[FIT]], dtype=np.int8))},
                       coords={"design_level": [0.02], "rule": ["srss"], "contact": [0], "code_intensity": ("design_level", [0.8]),
                               "stripe_intensity": ("design_level", [0.8])})
    maf = xr.DataArray([[1e-3]], dims=dims[:2])
    rules = rules.assign(maf=maf, return_period=1 / maf, probability=1 - np.exp(-50 * maf))
    risk = _risk(rules)
    risk.design_rules = xr.Dataset({"gap": (("rule", "contact"), [[0.05]]), "maf": ("rule", [1 / 60.0]), "return_period": ("rule", [60.0]),
                                    "probability": ("rule", [1 - math.exp(-50 / 60.0)]), "status": ("rule", np.array([FIT], dtype=np.int8))},
                                   coords={"rule": ["asce7_delta_mt"], "contact": [0], "design_level": ("rule", [0.02])})
    text = _rules_blocks("pair", risk)[0].text
    assert "Over the suite-mean rules, levels and configurations, the return periods range from 1e+03 to 1e+03 years" in text
    assert "Over the rules," not in text and "each rule means pounding" not in text
    assert "here: ASCE 7 §12.12.3 δ_MT of the design analysis, pounding once in 60 years." in text
    risk.separation["lower"].attrs["method"] = "BCa cluster bootstrap over events (3 clusters of the 22 motions that ran)"
    risk.curve = xr.Dataset(coords={"gap": [0.1, 0.5]})
    caption = _separation_table("pair", risk).caption
    assert caption.endswith("with its 95 % interval (BCa cluster bootstrap over events (3 clusters of the 22 motions that ran))")
    assert "the motions resampled" not in caption


def test_d_tm_where_the_base_never_slides_is_left_out_and_said_why_not_a_dash():
    """μ ∈ {∞, 0.05}: on the fixed base D_TM has nothing to size; its rows go, and the text says where and why."""
    dims = ("design_level", "rule", "mu", "contact")
    gap = np.full((1, 2, 2, 1), 0.3)
    gap[0, 1, 0, 0] = np.nan  # dtm at μ = ∞
    maf = xr.DataArray(np.where(np.isnan(gap[..., 0]), np.nan, 1e-3), dims=dims[:3])
    rules = xr.Dataset({"gap": (dims, gap), "status": (dims[:3], np.where(np.isnan(gap[..., 0]), 5, FIT).astype(np.int8))},
                       coords={"design_level": [0.02], "rule": ["abs", "dtm"], "mu": [np.inf, 0.05], "contact": [0],
                               "code_intensity": ("design_level", [0.8]), "stripe_intensity": ("design_level", [0.8])})
    rules = rate_intervals(rules.assign(maf=maf, maf_lower=maf / 2, maf_upper=maf * 2, return_period=1 / maf, probability=1 - np.exp(-50 * maf)), 50.0)
    risk = _risk(rules)
    frame = risk.rules_frame()
    dtm = frame.xs("suite-mean peak base displacement (ASCE 7 D_M form: no torsion)", level="rule")
    assert list(dtm.index.get_level_values("mu")) == [0.05] and frame["λ_P (1/yr)"].notna().all()  # no row of dashes
    text = risk.dtm_text()
    assert "left out where the studied building's base never slid in any run (mu ∞)" in text and "fixed base (μ = ∞)" in text
    assert _risk(rules.sel(mu=[0.05])).dtm_text() == ""
    assert "base slides in no run of this store" in _risk(rules.sel(rule=["abs"])).dtm_text()
    # issue 45: the suite-mean base displacement is the D_M form, never called D_TM (only eq. 17.5-3's value is)
    for said in (text, _risk(rules.sel(rule=["abs"])).dtm_text()):
        assert "D_TM" not in said.replace("not D_TM", "")


def test_d_tm_names_only_the_value_of_eq_17_5_3():
    """Issue 45: 'D_TM by eq. 17.5-1' was D_M. Of every rule the tables name, only chapter 17's row says D_TM, with eq. 17.5-3."""
    from stochpound.risk._chain import RULE_NAMES

    named = {key for key, name in RULE_NAMES.items() if "D_TM" in name}
    assert named == {"asce7_isolated"} and "D_TM (eq. 17.5-3)" in RULE_NAMES["asce7_isolated"]
    assert "17.5-1" not in RULE_NAMES["asce7_isolated"] and "D_M form: no torsion" in RULE_NAMES["dtm"]


def test_d_tm_is_not_taken_from_runs_a_moat_wall_capped(tmp_path):
    from stochpound import open_store
    from stochpound.risk import store_demands, store_risk
    from tests.helpers import ISOLATED, risk_text, run_in_process

    text = risk_text(ISOLATED + WALLS, "gap = [0.05, inf]", 'measure = "psa"\nperiod = 1.0\nlevels = [0.3, 0.8, 1.5]')
    store = open_store(run_in_process(tmp_path, "capped", text))  # walls in every run: no wall-free case
    risk = store_risk(store, bootstrap=0)
    assert "dtm" not in risk.rules["rule"].values and risk.dtm_note.startswith("the store has no wall-free runs")
    assert moat_text(risk, store_demands(store, bootstrap=0)) == ""


@pytest.fixture(scope="module")
def moat_variant_store(tmp_path_factory):
    """The flagship's layout in small: B1 on a friction pendulum, its moat a variant axis {none, wall} (0.1 m walls), gap = ∞."""
    from stochpound import open_store
    from tests.helpers import ISOLATED, risk_text, run_in_process

    variants = "\n[variants.moat.none]\n" + WALLS.replace("[[scene.wall]]", "[[variants.moat.wall.scene.wall]]")
    text = risk_text(ISOLATED + variants, "gap = [inf]", 'measure = "psa"\nperiod = 1.0\nlevels = [0.3, 0.8, 1.5]')
    return open_store(run_in_process(tmp_path_factory.mktemp("moat"), "moat_variant", text))


def test_d_tm_of_a_moat_variant_is_its_wall_free_twins_and_is_compared_with_the_moat(moat_variant_store):
    """The flagship's moat is a variant axis {none, wall}: the report said 'the store has no wall-free runs' and left D_TM and its
    comparison with the moat out. Each configuration's D_TM is now the suite-mean base displacement of its wall-free twin."""
    from stochpound.risk import store_demands, store_risk

    store = moat_variant_store
    risk = store_risk(store, bootstrap=0)
    assert risk.dtm_note == "" and "dtm" in risk.rules["rule"].values
    dtm = risk.rules["gap"].sel(rule="dtm")
    np.testing.assert_array_equal(dtm.sel(moat="wall").values, dtm.sel(moat="none").values)  # the wall's twin's displacement
    slid = store["peak_sliding_displacement"].sel(building="B1", moat="none", gap=np.inf).squeeze(drop=True)
    stripe = float(risk.rules["stripe_intensity"].sel(design_level=0.02))
    by_hand = float(slid.sel(intensity=stripe).mean())  # the suite mean of the wall-free runs at the rule's stripe
    np.testing.assert_allclose(dtm.sel(design_level=0.02, moat="wall").values, by_hand, rtol=1e-12)
    moat = moat_text(risk, store_demands(store, bootstrap=0))
    assert "The wall-free suite-mean peak base displacement (the D_M form, no torsion) at 2 %/50 yr is" in moat and "moat clearance 0.1 m" in moat
    assert "D_TM (suite-mean" not in moat  # issue 45: a planar run's base displacement is no D_TM


def test_the_stripes_table_does_not_call_wall_hits_pounding(moat_variant_store):
    """At gap = ∞ the contacts never close: every impact of a run with the moat wall is a wall hit. The stripes table said
    'pounded' and 'P(pounding)' for them; it now says impacts, and counts the wall hits apart."""
    from stochpound.report.sections._intensity import intensity_section

    store = moat_variant_store
    table = next(b for b in intensity_section("moat", store).blocks if getattr(b, "key", "").startswith("intensity-stripes"))
    frame = table.frame
    assert "pounded" not in frame.columns and "P(pounding)" not in frame.columns and "pounding" not in table.caption
    hits = ((store["peak_wall_penetration"] > 0) & (store["case_status"] == 1)).sum(("record", "realization")).sel(moat="wall")
    assert int(hits.sum()) > 0  # the small store does hit its 0.1 m walls
    np.testing.assert_array_equal(frame["wall hit"].xs("wall", level="moat").to_numpy(), hits.values.ravel())
    np.testing.assert_array_equal(frame["impacted"].xs("wall", level="moat").to_numpy(), hits.values.ravel())  # gap = ∞: only walls


def test_the_design_rows_say_why_there_is_no_eurocode_8_row():
    """The Los Angeles flagship's [design] is ASCE 7's: EC8's row was left out silently; now the text says why and how to add it."""
    def design(rules: list[str]) -> xr.Dataset:
        shape = (len(rules), 1)
        return xr.Dataset({"gap": (("rule", "contact"), np.full(shape, 0.1)), "return_period": ("rule", np.full(len(rules), 500.0))},
                          coords={"rule": rules, "contact": [0]})

    risk = _risk()
    risk.design_rules = design(["asce7_delta_mt"])
    text = risk.design_rules_text()
    assert "here: ASCE 7 §12.12.3 δ_MT of the design analysis, pounding once in 500 years." in text
    assert "(ASCE 7-16 §12.12.3: δ_M = C_d δ_max / I_e, SRSS of the two buildings, for contacts of fixed-base buildings), not from the runs" in text  # only the rules it has
    assert "There is no Eurocode 8 §4.4.2.7 row: the store's [design] has no ec8 entry" in text and "give [design] an ec8 = { ag, ground, q }" in text
    risk.design_rules = design(["asce7_delta_mt", "ec8_ds"])
    assert "no Eurocode 8" not in risk.design_rules_text()


def test_the_assumptions_say_the_base_the_grid_leaves():
    """A building with a base that the grid's μ = ∞ fixes is on a fixed base (the flagship's fixed pair was said to be on a
    sliding base); the scenario's words: tests/test_fitted_scenarios.py."""
    from stochpound.model.scene_tables import SceneTables
    from stochpound.risk._inputs import _base_words
    from stochpound.store import MuAxis

    building, fixed = SceneTables.of({"building": [{"name": "B1", "base": {"mu": 0.05}}, {"name": "B2"}]}).buildings
    assert _base_words(MuAxis((float("inf"),), ("B1",)), building) == "a fixed base (μ = ∞ on the grid)"
    assert _base_words(MuAxis((0.05, 0.08), ("B1",)), building) == "a sliding base (μ 0.05, 0.08 on the grid)"
    assert _base_words(MuAxis((0.05, float("inf")), None), building) == "a sliding base (μ 0.05 on the grid) or a fixed base"
    assert _base_words(None, fixed) == "a fixed base"


def test_the_chain_reads_its_store_once_and_answers_from_the_inputs_alone(moat_variant_store, tmp_path):
    """``read_risk_inputs`` reads what ``store_risk`` needs once; the chain then answers from the frozen inputs with the store
    closed (no step goes back to it), and its answer is the one ``store_risk`` gives from the store itself."""
    import dataclasses

    from stochpound import open_store
    from stochpound.risk import RiskInputError, RiskInputs, read_risk_inputs, store_risk

    path = tmp_path / "copy.nc"
    path.write_bytes(open(moat_variant_store.encoding["source"], "rb").read())
    store = open_store(path)
    inputs = read_risk_inputs(store)
    store.close()
    assert isinstance(inputs, RiskInputs) and inputs.method == "stripes" and inputs.studied == "B1"
    with pytest.raises(dataclasses.FrozenInstanceError):
        inputs.motions = 1  # type: ignore[misc]
    from_inputs = store_risk(inputs, bootstrap=0)
    from_store = store_risk(moat_variant_store, bootstrap=0)
    xr.testing.assert_identical(from_inputs.separation, from_store.separation)
    xr.testing.assert_identical(from_inputs.rules, from_store.rules)
    assert (from_inputs.setting, from_inputs.motions, from_inputs.assumptions) == (from_store.setting, from_store.motions, from_store.assumptions)
    with pytest.raises(RiskInputError, match="read with the inputs"):
        store_risk(inputs, studied="B2")
