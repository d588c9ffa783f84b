"""The answer without an intensity measure for a store's configurations (stochpound.analysis.store_measure_free): each
configuration's scene is the one its conditioned answer ran, its runs are measure_free_risk's on that scene, every demand is
read from the same runs, and the table gives every configuration, demand and target."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
import xarray as xr

from stochpound import open_store
from stochpound.analysis import MeasureFreeDemand, RuptureSite, measure_free_risk, store_measure_free, store_sufficiency
from stochpound.experiment._runner import load_experiment, run_experiment
from stochpound.risk import configuration_scene
from tests.helpers import ISOLATED, invoke, risk_text, write_experiment

STRIPES = 'measure = "psa"\nperiod = 1.0\nlevels = [0.3, 0.8]'
SITE = RuptureSite(magnitude=(7.0, 6.0), distance_rup_km=(20.0, 10.0), distance_jb_km=(20.0, 10.0), distance_x_km=(-20.0, -10.0),
                   ztor_km=(0.0, 0.0), dip=(90.0, 90.0), mechanism=("strike_slip", "reverse"), rate=(0.01, 0.05), vs30=400.0, name="two")


@pytest.fixture(scope="module")
def store_path(tmp_path_factory):
    """B1 on a friction pendulum (μ 0.05 and 0.08, the configurations) beside a fixed B2, contact-free, 8 motions x 2 stripes."""
    text = risk_text(ISOLATED, 'gap = [inf]\nmu = { values = [0.05, 0.08], buildings = ["B1"] }', STRIPES)
    report = run_experiment(load_experiment(write_experiment(tmp_path_factory.mktemp("store"), text, "isolated.toml")), workers=0, progress=False)
    assert report.complete
    return report.store


@pytest.fixture(scope="module")
def store(store_path):
    return open_store(store_path).load()


@pytest.fixture(scope="module")
def answer(store):
    return store_measure_free(store, SITE, runs=8, seed=3, bootstrap=100)


def test_each_configuration_runs_its_own_scene_as_measure_free_risk_would(store, answer):
    assert answer.configurations == ((("mu", 0.05),), (("mu", 0.08),))
    assert (answer.runs, answer.first_stage, answer.extra) == (8, 2, 4) and "two of 2 ruptures" in answer.site
    for labels, results in zip(answer.configurations, answer.results):
        scene = configuration_scene(store, dict(labels))
        assert all(math.isinf(contact.gap) for contact in scene.contacts) and scene.buildings[0].base.mu == dict(labels)["mu"]
        alone = measure_free_risk(scene, SITE, motions=2, extra=4, seed=3, bootstrap=100)
        closure, base, *drifts = results
        for name in ("response_value", "level", "level_lower", "level_upper", "motions"):
            np.testing.assert_array_equal(closure[name].values, alone[name].values)
        assert base.attrs["demand"] == "base displacement of B1" and [d.attrs["demand"] for d in drifts] == [
            "storey drift of B1 (largest over its storeys)", "storey drift of B2 (largest over its storeys)"]
        np.testing.assert_array_equal(base.motions.values, closure.motions.values)  # the same runs
    # the same motions for both configurations: the fixed neighbour's drift does not depend on B1's friction (no contact)
    np.testing.assert_allclose(answer.results[0][3].response_value.values, answer.results[1][3].response_value.values, rtol=1e-9)
    assert not np.allclose(answer.results[0][1].response_value.values[:, :2], answer.results[1][1].response_value.values[:, :2])


def test_the_table_has_every_configuration_demand_and_target(answer):
    frame = answer.frame()
    assert len(frame) == 2 * 4 * 2 and set(frame["target"]) == {0.10, 0.02} and set(frame["mu"]) == {0.05, 0.08}
    row = frame[(frame["mu"] == 0.08) & (frame["demand"] == "closure (largest over the contacts)") & (frame["target"] == 0.02)].iloc[0]
    closure = answer.results[1][0]
    assert row["level"] == float(closure.level.sel(target=0.02)) and row["lower"] <= row["level"] <= row["upper"] and row["runs"] == 8
    assert "8 runs a configuration (2 runs of each rupture, then 4 shared out by Neyman allocation" in answer.conditions()


def test_a_budget_below_two_runs_a_rupture_is_one_line(store):
    with pytest.raises(ValueError, match=r"^runs: must be an integer >= 4 \(two runs of each of the site's 2 ruptures\), got 3$"):
        store_measure_free(store, SITE, runs=3)


@pytest.mark.slow
def test_the_answer_does_not_depend_on_the_workers(store, answer):
    again = store_measure_free(store, SITE, runs=8, seed=3, bootstrap=100, workers=2)
    assert again.frame().equals(answer.frame())


def test_the_demands_of_a_scene_put_the_closure_first(store):
    from stochpound.analysis._measure_free_store import scene_demands

    assert scene_demands(configuration_scene(store, {"mu": 0.05})) == [
        MeasureFreeDemand("closure"), MeasureFreeDemand("base_displacement", "B1"), MeasureFreeDemand("peak_storey_drift", "B1"),
        MeasureFreeDemand("peak_storey_drift", "B2")]


TABLE = ("# vs30: 400\nname,magnitude,distance_rup_km,distance_jb_km,distance_x_km,ztor_km,dip,mechanism,rate\n"
         "r1,7.0,20,20,-20,0,90,strike_slip,0.01\nr2,6.0,10,10,-10,0,90,reverse,0.05\n")


def test_the_risk_command_prints_it_beside_the_conditioned_answer_with_its_site_and_conditions(store_path, store, tmp_path):
    table = tmp_path / "two.csv"
    table.write_text(TABLE)
    result = invoke("risk", str(store_path), "--ruptures", str(table), "--ruptures-runs", "8", "--seed", "3", "--bootstrap", "0")
    assert result.exit_code == 0, result.output
    site = RuptureSite.from_file(table)
    expected = store_measure_free(store, site, runs=8, seed=3)
    text = result.output
    assert "Without an intensity measure (docs/measure-free.md): at the site of ruptures " + site.describe() in text
    assert expected.conditions() in text and "The answers above are at the hazard's site (" in text
    assert expected.display_frame().to_string() in text
    assert text.index("Risk-targeted separation g*") < text.index("Without an intensity measure") < text.index("Design to")


def test_the_risk_commands_ruptures_errors_are_one_line(store_path):
    for args, message in ((["--ruptures", "nowhere"], "Invalid value for --ruptures: 'nowhere' is neither a file nor a bundled site"),
                          (["--ruptures", "demo_three_sources", "--ruptures-runs", "20"],
                           "Invalid value for --ruptures-runs: must be an integer >= 28 (two runs of each of the site's 14 ruptures), got 20")):
        result = invoke("risk", str(store_path), *args)
        assert result.exit_code == 2 and message in result.output, result.output
        assert len([line for line in result.output.splitlines() if line.startswith("Error")]) == 1
    result = invoke("report", "build", str(store_path), "--out", str(store_path.parent / "report"), "--ruptures", "nowhere")
    assert result.exit_code == 2 and "Error: Invalid value for --ruptures: 'nowhere' is neither a file" in result.output
    assert not (store_path.parent / "report").exists()


def test_the_report_section_formats_the_answer_and_names_both_sites(answer):
    from stochpound.report.render import Paragraph, Table
    from stochpound.report.sections import measure_free_section

    section = measure_free_section("isolated", answer, "the hazard curve of somewhere")
    assert section.title == "Without an intensity measure: experiment isolated" and section.key == "measure-free-isolated"
    words = " ".join(block.text for block in section.blocks if isinstance(block, Paragraph))
    assert f"at the site of ruptures {answer.site}" in words and answer.conditions() in words
    assert "conditioned on the hazard of its site (the hazard curve of somewhere)" in words
    (table,) = [block for block in section.blocks if isinstance(block, Table)]
    assert table.frame.equals(answer.display_frame()) and table.caption.endswith("at two")


@pytest.mark.slow
def test_the_report_gets_the_section_after_the_risk_section_when_given_ruptures(store_path, answer):
    from stochpound.report.assemble import assemble_report

    report = assemble_report([store_path], ruptures=SITE, ruptures_runs=8)
    keys = [section.key.rsplit("-", 1)[0] for section in report.sections]
    assert keys.index("measure-free") == keys.index("risk") + 1
    section = report.sections[keys.index("measure-free")]
    (table,) = [block for block in section.blocks if str(getattr(block, "key", "")).startswith("table-measure-free-")]
    assert table.frame.equals(store_measure_free(open_store(store_path).load(), SITE, runs=8).display_frame())
    try:  # the store's own measure tested, or why not, as the section says
        tested = store_sufficiency(open_store(store_path).load())
        expected = tested.verdict() in section.blocks[-2].text and section.blocks[-1].frame.equals(tested.display_frame())
    except ValueError as error:
        expected = section.blocks[-1].text == f"The sufficiency of the store's measure was not tested: {error}."
    assert expected


def test_the_comparison_puts_each_measures_seeds_beside_the_measure_free_g_star(answer):
    from stochpound.analysis import compare_measures

    free = {labels[0][1]: results[0].level for labels, results in zip(answer.configurations, answer.results)}  # over target, per μ

    def g_star(factor: float) -> xr.DataArray:  # g* over (target, mu): the measure-free one times a factor
        return xr.concat([free[mu] * factor for mu in (0.05, 0.08)], dim=pd.Index([0.05, 0.08], name="mu"))

    table = compare_measures({"PGA": [g_star(1.1), g_star(1.5), g_star(1.3)], "PSA(1 s)": [g_star(0.9)]}, answer)
    assert len(table) == 2 * 2 * 2
    row = table.loc[("mu 0.08", "PGA", 0.02)]
    reference = float(free[0.08].sel(target=0.02))
    assert row["measure-free"] == reference and row["median"] == pytest.approx(1.3 * reference, rel=1e-12)
    assert row["seed spread"] == pytest.approx(1.5 / 1.1, rel=1e-12) and row["seeds"] == 3
    assert row["ratio"] == pytest.approx(1.3, rel=1e-12) and not row["agrees"]
    assert table.loc[("mu 0.05", "PSA(1 s)", 0.1)]["agrees"] and table.loc[("mu 0.05", "PSA(1 s)", 0.1)]["seed spread"] == 1.0
    with pytest.raises(ValueError, match=r"^conditioned\['PGA'\]: g\* has no dimension 'mu'"):
        compare_measures({"PGA": [free[0.05]]}, answer)
    with pytest.raises(ValueError, match=r"^tolerance: must be a ratio > 1"):
        compare_measures({"PGA": [g_star(1.0)]}, answer, tolerance=0.8)


def test_the_comparison_names_a_missing_measures_measured_reason(answer):
    from stochpound.analysis import StoreSufficiency, compare_measures, stripe_regression

    free = {labels[0][1]: results[0].level for labels, results in zip(answer.configurations, answer.results)}
    g_star = xr.concat([free[mu] * 1.5 for mu in (0.05, 0.08)], dim=pd.Index([0.05, 0.08], name="mu"))  # misses by ×1.5 everywhere
    rng = np.random.default_rng(3)
    stripe, magnitude = np.repeat([0, 1, 2], 20), rng.uniform(6.0, 7.8, 60)
    trend = stripe_regression(0.7 * magnitude + rng.normal(0.0, 0.1, 60), stripe, {"M": magnitude})  # a demand rising with M
    flat = stripe_regression(rng.normal(0.0, 0.1, 60), stripe, {"M": magnitude})
    tests = StoreSufficiency("PGA", "closure", ((("mu", 0.05),), (("mu", 0.08),)), (trend, flat))
    table = compare_measures({"PGA": [g_star], "PSA(1 s)": [g_star / 1.5]}, answer, sufficiency={"PGA": tests})
    assert table.loc[("mu 0.05", "PGA", 0.02), "reason"] == trend.reason() and trend.reason().startswith("insufficient with respect to M")
    assert table.loc[("mu 0.05", "PGA", 0.02), "insufficient"] == "M" and table.loc[("mu 0.08", "PGA", 0.1), "insufficient"] == ""
    assert table.loc[("mu 0.08", "PGA", 0.1), "reason"] == flat.reason() and flat.reason().startswith("no residual trend with M")
    assert table.loc[("mu 0.05", "PSA(1 s)", 0.1), "reason"] == "" and table.loc[("mu 0.05", "PSA(1 s)", 0.1), "agrees"]
    with pytest.raises(ValueError, match=r"^sufficiency: 'PGV' is not one of the measures compared \(PGA, PSA\(1 s\)\)"):
        compare_measures({"PGA": [g_star], "PSA(1 s)": [g_star]}, answer, sufficiency={"PGV": tests})


def test_the_report_section_says_the_measures_sufficiency_from_the_data(answer):
    from stochpound.analysis import StoreSufficiency, stripe_regression
    from stochpound.report.render import Paragraph, Table
    from stochpound.report.sections import measure_free_section

    rng = np.random.default_rng(3)
    stripe, magnitude = np.repeat([0, 1], 20), rng.uniform(6.0, 7.8, 40)
    fits = tuple(stripe_regression(slope * magnitude + rng.normal(0.0, 0.1, 40), stripe, {"M": magnitude}) for slope in (0.7, 0.0))
    tests = StoreSufficiency("PSA(1 s)", "closure", ((("mu", 0.05),), (("mu", 0.08),)), fits)
    section = measure_free_section("isolated", answer, "somewhere", tests)
    words = " ".join(block.text for block in section.blocks if isinstance(block, Paragraph))
    assert f"mu 0.05: {fits[0].reason()}; mu 0.08: {fits[1].reason()}." in words and fits[0].conditions() in words
    assert "n 40 runs in 2 stripes" in words and "Is PSA(1 s) sufficient for the contact-free closure?" in words
    tables = [block for block in section.blocks if isinstance(block, Table)]
    assert tables[-1].key == "table-sufficiency-isolated" and tables[-1].frame.equals(tests.display_frame())
    untested = measure_free_section("isolated", answer, "somewhere", untested="store: has no 'record_magnitude' (...)")
    assert untested.blocks[-1].text == "The sufficiency of the store's measure was not tested: store: has no 'record_magnitude' (...)."


def test_the_sufficiency_test_runs_each_configuration_of_the_store_and_says_what_a_store_lacks(store, answer):
    from stochpound.analysis import stripe_regression
    from stochpound.risk import contact_free_closure

    tested = store_sufficiency(store, cluster=False)
    assert tested.configurations == answer.configurations and tested.measure == "PSA(1 s)"
    closure = contact_free_closure(store).sel(mu=0.08).transpose("intensity", "record")
    stripe = np.repeat(np.arange(closure.sizes["intensity"]), closure.sizes["record"])
    magnitude = np.tile(store["record_magnitude"].values, closure.sizes["intensity"])
    alone = store_sufficiency(store.drop_vars("motion_intensity"), cluster=False)  # no unscaled measure: M and ln R only
    expected = stripe_regression(np.log(closure.values.ravel()), stripe,
                                 {"M": magnitude, "ln R": np.log(np.tile(store["record_distance"].values, closure.sizes["intensity"]))})
    assert alone.result((("mu", 0.08),)) == expected and tested.result((("mu", 0.08),)).covariates == ("M", "ln R", "ε")
    with pytest.raises(ValueError, match=r"^store: has no 'record_magnitude' \(the motions' earthquakes"):
        store_sufficiency(store.drop_vars("record_magnitude"))
    with pytest.raises(ValueError, match=r"^labels: no configuration \(\('mu', 0.5\),\) in the sufficiency test of PSA\(1 s\)"):
        tested.result((("mu", 0.5),))
