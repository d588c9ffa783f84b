"""Scenarios fitted to a site's own hazard curves (stochpound.motions.fit_scenarios) and [site] scenario = "fitted"."""

from __future__ import annotations

import json
import tomllib

import numpy as np
import pytest
import xarray as xr

from stochpound._errors import SiteError
from stochpound.analysis import HazardCurve, stripe_rate_weights
from stochpound.experiment._spec import ExperimentError, parse_experiment
from tests.helpers import SITE_SCENE
from stochpound.motions import TARGET_TOLERANCE, conditional_spectrum, fit_levels, fit_scenarios, misses_target, recomputed_hazard

KNOWN = {"magnitude": 7.0, "distance_km": 10.0, "vs30": 400.0, "mechanism": "reverse"}
IM_STAR = HazardCurve.power_law(2.0e-4, 2.2)  # PSA(1 s) in g


def _fit(levels: np.ndarray, others: list, **change) -> list[dict]:
    fine = fit_levels(levels)
    arguments = {"measure": "psa", "period": 1.0, "levels": levels, "fine_levels": fine, "fine_rates": stripe_rate_weights(fine, IM_STAR),
                 "others": others, "vs30": 400.0, "mechanism": "reverse", **change}
    return fit_scenarios(**arguments)


def _synthetic_site(scenario: dict) -> list[tuple[float | None, np.ndarray, np.ndarray]]:
    """The site's PGA and PSA(2 s) curves if the scenario caused every level of PSA(1 s): the integral over 200 fine bins."""
    fine = np.geomspace(0.02, 6.0, 200)
    weights = stripe_rate_weights(fine, IM_STAR)
    im = np.geomspace(0.05, 3.0, 30)
    shell = [(None, im, np.ones(im.size)), (2.0, im, np.ones(im.size))]
    rates = recomputed_hazard("psa", 1.0, fine, weights, [scenario] * fine.size, shell)
    return [(node, im, rate) for (node, _, _), rate in zip(shell, rates)]


def test_the_fit_reproduces_a_synthetic_site_built_from_a_known_scenario() -> None:
    others = _synthetic_site(KNOWN)
    levels = IM_STAR.intensity_at(1.0 / np.array([72.0, 224.0, 475.0, 975.0, 2475.0, 5000.0]))
    fitted = _fit(levels, others)
    assert len(fitted) == levels.size and all(s["vs30"] == 400.0 and s["mechanism"] == "reverse" for s in fitted)
    assert all(s == fitted[0] for s in fitted)  # one scenario for every level
    fine = np.geomspace(0.02, 6.0, 200)  # the fitted scenario's hazard, integrated as the synthetic site's
    recomputed = recomputed_hazard("psa", 1.0, fine, stripe_rate_weights(fine, IM_STAR), [fitted[0]] * fine.size, others)
    wrong = _synthetic_site({**KNOWN, "magnitude": 5.5, "distance_km": 80.0})
    for (_, im, site), fit, (_, _, bad) in zip(others, recomputed, wrong):
        inside = (site <= IM_STAR(levels[:1])[0]) & (site >= IM_STAR(levels[-1:])[0])  # the rates the stripes represent
        assert inside.sum() >= 5
        assert np.all(np.abs(np.log(fit[inside] / site[inside])) < 0.05)  # the fit integrates 60 levels over x_1/5 - 5 x_top, the site 200 over 0.02-6 g
        assert np.max(np.abs(np.log(bad[inside] / site[inside]))) > 0.5  # the check can fail: a wrong scenario misses the curves
    # what matters downstream: the conditional spectrum at the other periods, as the known scenario's
    for level, scenario in zip(levels, fitted):
        got = conditional_spectrum("psa", 1.0, level=level, periods=[0.2, 2.0], **scenario)
        known = conditional_spectrum("psa", 1.0, level=level, periods=[0.2, 2.0], **KNOWN)
        assert np.allclose(np.log(got["median"]), np.log(known["median"]), atol=0.15)


def test_the_fit_is_deterministic_and_kept_per_process_for_its_inputs() -> None:
    """A fit of inputs fitted before is the one kept (experiments at the same site and stripes fit once per process), and a
    fresh fit gives it again."""
    from stochpound.motions import _fitted

    others = _synthetic_site(KNOWN)
    levels = IM_STAR.intensity_at(1.0 / np.array([100.0, 1000.0, 3000.0]))
    _fitted._least_misfit.cache_clear()
    first = _fit(levels, others)
    second = _fit(list(levels), [(node, list(im), list(rate)) for node, im, rate in others])  # the same numbers, as lists
    assert _fitted._least_misfit.cache_info()[:2] == (1, 1)  # (hits, misses)
    _fitted._least_misfit.cache_clear()
    assert first == second == _fit(levels, others)


@pytest.mark.parametrize(
    "change, field",
    [
        ({"measure": "pgv"}, "measure:"),
        ({"levels": [0.3, 0.2]}, "levels:"),
        ({"others": []}, "others:"),
        ({"fine_levels": np.geomspace(0.25, 1.0, 60)}, "fine_levels:"),
        ({"fine_rates": [1e-3]}, "fine_levels:"),
        ({"vs30": 50.0}, "vs30:"),
        ({"mechanism": "oblique"}, "mechanism:"),
    ],
)
def test_bad_input_to_the_fit_is_one_line_naming_the_field(change: dict, field: str) -> None:
    with pytest.raises(SiteError) as error:
        _fit(**{"levels": np.array([0.2, 0.3]), "others": _synthetic_site(KNOWN), **change})
    assert str(error.value).startswith(field) and "\n" not in str(error.value)




def _text(intensity: str, site: str) -> str:
    return f'[experiment]\nname = "fitted"\n{SITE_SCENE}\n[grid]\ngap = ["inf"]\n[[records]]\nsuite = "fema_p695_far_field"\n[intensity]\n{intensity}\n{site}\n'


CURVES = '["fox_plaza_los_angeles_pga", "fox_plaza_los_angeles_sa1p0s", "fox_plaza_los_angeles_sa2p0s"]'
FITTED_SELECTION = 'measure = "psa"\nperiod = 1.0\nlevels = [0.9, 0.4]\nselection = "conditional_spectrum"\nmotions = 4\nmax_scale_factor = 5.0\n'
FITTED_SITE = f'[site]\nscenario = "fitted"\ncurves = {CURVES}\nvs30 = 400.0\nmechanism = "reverse"\n'


def test_a_fitted_site_stores_the_fitted_scenario_of_every_level(tmp_path) -> None:
    definition = parse_experiment(tomllib.loads(_text(FITTED_SELECTION, FITTED_SITE)), tmp_path)
    scenarios = definition["intensity"]["site"]
    assert "fitted to the site's hazard curves fox_plaza_los_angeles_pga" in definition["intensity"]["note"]
    hazard = HazardCurve.bundled("fox_plaza_los_angeles_sa1p0s")
    others = [(None, HazardCurve.bundled("fox_plaza_los_angeles_pga").im, HazardCurve.bundled("fox_plaza_los_angeles_pga").rate),
              (2.0, HazardCurve.bundled("fox_plaza_los_angeles_sa2p0s").im, HazardCurve.bundled("fox_plaza_los_angeles_sa2p0s").rate)]
    levels = np.array([0.4, 0.9])
    fine = fit_levels(levels, hazard.support[1])
    assert scenarios == fit_scenarios("psa", 1.0, levels, fine, stripe_rate_weights(fine, hazard), others, 400.0, "reverse")


def test_a_fitted_site_takes_stripes_down_to_the_start_of_the_hazard_table(tmp_path) -> None:
    """Stripes of frequent shaking (an inefficient measure needs them: weak shaking pounds often) are fitted on a fine grid that
    starts within the table instead of failing five times below the lowest stripe; the grid's first bin stays inside it."""
    hazard = HazardCurve.bundled("fox_plaza_los_angeles_sa1p0s")
    low = float(hazard.intensity_at(1.0 / 3.0))  # the 3-year level, less than 5 times the table's first intensity
    assert low / 5.0 < hazard.support[0]
    definition = parse_experiment(tomllib.loads(_text(FITTED_SELECTION.replace("[0.9, 0.4]", f"[0.9, {low:.4f}]"), FITTED_SITE)), tmp_path)
    assert len(definition["intensity"]["site"]) == 2
    fine = fit_levels([low, 0.9], hazard.support[1], hazard.support[0])
    assert fine[0] >= hazard.support[0] and fine[0] <= low
    assert np.all(np.isfinite(stripe_rate_weights(fine, hazard)))


def test_the_definition_keeps_how_the_scenario_was_obtained_as_data_outside_the_identity(tmp_path) -> None:
    """The scenario's kind is the definition's ``site`` entry (read by the risk assumptions, not guessed from the note's prose),
    and it leaves the identity as it was: a definition without the entry (a store written before it) hashes the same."""
    from stochpound.risk._inputs import _scenario_words
    from stochpound.store import definition_sha256, read_definition

    fitted = parse_experiment(tomllib.loads(_text(FITTED_SELECTION, FITTED_SITE)), tmp_path)
    given = parse_experiment(tomllib.loads(_text(FITTED_SELECTION, '[site]\nvs30 = 400.0\nmagnitude = 7.0\ndistance_km = 10.0\nmechanism = "reverse"\n')), tmp_path)
    assert fitted["site"] == {"scenario": "fitted", "curves": json.loads(CURVES)} and given["site"] == {"scenario": "given"}
    assert read_definition(fitted).site.scenario == "fitted"
    for definition in (fitted, given):
        before = {key: value for key, value in definition.items() if key != "site"}
        assert definition_sha256(definition) == definition_sha256(before) and read_definition(before).site is None
    store = xr.Dataset({"site_magnitude": ("intensity", [7.5, 8.0]), "site_distance_km": ("intensity", [30.0, 30.0]),
                        "site_vs30": ("intensity", [400.0, 400.0])})
    assert _scenario_words(store, "fitted") == "M 7.5–8, R 30 km, Vs30 400 m/s, fitted to the site's hazard curves (a calibration standing in for a disaggregation)"
    assert "an assumption unless" in _scenario_words(store, "given") and "not recorded" in _scenario_words(store, None)
    assert _scenario_words(xr.Dataset(), "given").startswith("as the [site] table gives it")


@pytest.mark.parametrize(
    "site, field",
    [
        (FITTED_SITE.replace('"fitted"', '"disaggregated"'), "site.scenario:"),
        (FITTED_SITE.replace(CURVES, '["fox_plaza_los_angeles_pga", "nowhere"]'), "site.curves[1]:"),
        (FITTED_SITE.replace(CURVES, '["fox_plaza_los_angeles_pga", "fox_plaza_los_angeles_sa2p0s"]'), "site.curves:"),
        (FITTED_SITE.replace(CURVES, '["fox_plaza_los_angeles_sa1p0s"]'), "site.curves:"),
        (FITTED_SITE + "magnitude = 7.0\n", "site.magnitude:"),
        (FITTED_SITE.replace("vs30 = 400.0\n", ""), "site.vs30:"),
        (FITTED_SITE.replace('mechanism = "reverse"', 'mechanism = ["reverse", "reverse"]'), "site.mechanism:"),
        ('[site]\ncurves = ["fox_plaza_los_angeles_pga"]\nvs30 = 400.0\nmagnitude = 7.0\ndistance_km = 10.0\nmechanism = "reverse"\n', "site.curves:"),
    ],
)
def test_bad_fitted_site_is_one_line_naming_the_field(tmp_path, site: str, field: str) -> None:
    with pytest.raises(ExperimentError) as error:
        parse_experiment(tomllib.loads(_text(FITTED_SELECTION, site)), tmp_path)
    assert str(error.value).startswith(field) and "\n" not in str(error.value)


def _write_curve(path, curve: HazardCurve, header: str) -> None:
    """``curve`` written as a user's hazard-curve file at ``path``, its numbers exactly, after ``header`` (its '#' lines)."""
    rows = "\n".join(f"{float(x)!r},{float(y)!r}" for x, y in zip(curve.im, curve.rate))
    path.write_text(f"{header}im,rate\n{rows}\n")


def _copy_curve(tmp_path, name: str, header: str) -> str:
    """A bundled curve written as a user's hazard-curve file with ``header`` (its '#' lines), in ``tmp_path``; its file name."""
    _write_curve(tmp_path / f"{name}.csv", HazardCurve.bundled(name), header)
    return f"{name}.csv"


def test_a_fitted_site_takes_hazard_curve_files_and_fits_them_as_the_same_bundled_curves(tmp_path) -> None:
    """The user's own curves (files beside the experiment, their measure stated by the header or by the entry) give the same fitted
    scenario as the same numbers bundled; the definition names each curve by its file."""
    pga = _copy_curve(tmp_path, "fox_plaza_los_angeles_pga", "# My site, from the USGS tool\n# Measure: PGA, in g\n")
    sa1 = _copy_curve(tmp_path, "fox_plaza_los_angeles_sa1p0s", "# My site\n")  # the entry states its measure
    files = f'["{pga}", {{ file = "{sa1}", measure = "psa", period = 1.0, damping = 0.05, units = "g" }}, "fox_plaza_los_angeles_sa2p0s"]'
    from_files = parse_experiment(tomllib.loads(_text(FITTED_SELECTION, FITTED_SITE.replace(CURVES, files))), tmp_path)
    bundled = parse_experiment(tomllib.loads(_text(FITTED_SELECTION, FITTED_SITE)), tmp_path)
    assert from_files["intensity"]["site"] == bundled["intensity"]["site"]
    assert from_files["site"]["curves"] == [pga, sa1, "fox_plaza_los_angeles_sa2p0s"]
    changed = FITTED_SITE.replace(CURVES, files).replace(", damping = 0.05", "")  # a PSA curve without its damping: nobody states it
    with pytest.raises(ExperimentError, match=r"^site\.curves\[1\]\.damping: not stated"):
        parse_experiment(tomllib.loads(_text(FITTED_SELECTION, changed)), tmp_path)


def test_a_fitted_site_conditions_on_sa_avg_from_a_curve_file_stating_its_periods(tmp_path) -> None:
    """Sa_avg has no bundled curve: its curve comes as a file whose entry states the measure and periods; the fit reproduces the
    PSA curves from stripes of Sa_avg, as fit_scenarios does given the same curves."""
    from stochpound.analysis import RuptureSite

    periods = (0.5, 1.0, 2.0)
    site = RuptureSite.from_scenarios([(Scenario_of(7.0, 20.0), 0.01), (Scenario_of(6.0, 10.0), 0.05)], name="two")
    curve = site.hazard_curve("sa_avg", periods)
    _write_curve(tmp_path / "sa_avg.csv", curve, "# Sa_avg of two ruptures\n")
    entry = '{ file = "sa_avg.csv", measure = "sa_avg", periods = [0.5, 1.0, 2.0], damping = 0.05, units = "g" }'
    levels = curve.intensity_at(np.array([1 / 100.0, 1 / 1000.0]))
    selection = (f'measure = "sa_avg"\nperiods = [0.5, 1.0, 2.0]\nlevels = [{levels[0]:.4f}, {levels[1]:.4f}]\n'
                 'selection = "conditional_spectrum"\nmotions = 4\nmax_scale_factor = 5.0\n')
    text = FITTED_SITE.replace(CURVES, f'[{entry}, "fox_plaza_los_angeles_sa1p0s", "fox_plaza_los_angeles_sa2p0s"]')
    scenarios = parse_experiment(tomllib.loads(_text(selection, text)), tmp_path)["intensity"]["site"]
    read = HazardCurve.from_file(tmp_path / "sa_avg.csv")
    others = [(T, HazardCurve.bundled(name).im, HazardCurve.bundled(name).rate) for T, name in ((1.0, "fox_plaza_los_angeles_sa1p0s"), (2.0, "fox_plaza_los_angeles_sa2p0s"))]
    ordered = np.array([float(f"{x:.4f}") for x in levels])
    fine = fit_levels(ordered, read.support[1], read.support[0])
    assert scenarios == fit_scenarios("sa_avg", periods, ordered, fine, stripe_rate_weights(fine, read), others, 400.0, "reverse")
    as_other = FITTED_SITE.replace(CURVES, f'["fox_plaza_los_angeles_pga", "fox_plaza_los_angeles_sa1p0s", {entry}]')  # Sa_avg is not fitted
    with pytest.raises(ExperimentError, match=r"^site\.curves\[2\]: the fit reproduces curves of PGA or PSA"):
        parse_experiment(tomllib.loads(_text(FITTED_SELECTION, as_other)), tmp_path)


def Scenario_of(magnitude: float, distance_km: float):
    from stochpound.motions import Scenario

    return Scenario.of(magnitude, distance_km, 400.0, "reverse")


@pytest.mark.parametrize(
    "entry, field",
    [
        ('"missing.csv"', "site.curves[0]: 'missing.csv' is neither a bundled hazard curve nor a file"),
        ('{ file = "bare.csv" }', "site.curves[0].measure: not stated"),
        ('{ file = "bare.csv", measure = "pga", units = "cm/s2" }', "site.curves[0].units: the fit takes curves in g"),
        ('{ file = "bare.csv", measure = "psa", period = 0.3, damping = 0.02, units = "g" }', "site.curves[0].damping: the NGA-West2 models give 5 %"),
        ('{ file = "bare.csv", measure = "pga", units = "g", bogus = 1 }', "site.curves[0].bogus: unknown field"),
        ("3", "site.curves[0]: a bundled hazard curve's name, a hazard-curve file or a table"),
        ('{ file = "rare.csv", measure = "psa", period = 0.3, damping = 0.05, units = "g" }', "site.curves: the site's PSA(0.3 s) curve has no intensity"),
    ],
)
def test_a_bad_curve_entry_is_one_line_naming_it(tmp_path, entry: str, field: str) -> None:
    (tmp_path / "bare.csv").write_text("im,rate\n0.1,0.01\n1.0,0.0001\n")
    (tmp_path / "rare.csv").write_text("im,rate\n0.1,1e-7\n1.0,1e-8\n")  # no rate within the stripes' rates
    site = FITTED_SITE.replace(CURVES, f'[{entry}, "fox_plaza_los_angeles_sa1p0s", "fox_plaza_los_angeles_sa2p0s"]')
    with pytest.raises(ExperimentError) as error:
        parse_experiment(tomllib.loads(_text(FITTED_SELECTION, site)), tmp_path)
    assert str(error.value).startswith(field) and "\n" not in str(error.value)


def test_a_selection_misses_its_target_where_its_mean_or_std_of_ln_sa_is_off_by_more_than_the_tolerance() -> None:
    median, sigma = np.array([[0.5, 0.3, 0.1]] * 3), np.array([[0.0, 0.4, 0.5]] * 3)
    mean_ln, std_ln = np.log(median), sigma.copy()
    mean_ln[1, 2] += TARGET_TOLERANCE * 1.1  # stripe 1: the mean off at one period
    std_ln[2, 1] -= TARGET_TOLERANCE * 1.1  # stripe 2: the std off
    mean_ln[0] += TARGET_TOLERANCE * 0.9  # stripe 0: within
    assert misses_target(mean_ln, std_ln, median, sigma).tolist() == [False, True, True]


@pytest.mark.parametrize("kind", ["fitted", "given", "ruptures", None])
def test_the_reports_selection_says_a_fitted_scenario_stands_in_for_a_disaggregation_and_that_its_cost_is_not_measured(monkeypatch, kind) -> None:
    """The Intensity section's selection paragraph: for a fitted scenario, what it is (a calibration standing in for a disaggregation)
    and that the store cannot measure its cost in g*; nothing for a scenario given, from ruptures or unrecorded."""
    from stochpound.report.sections import _intensity

    monkeypatch.setattr(_intensity, "scenario_kind", lambda store: kind)
    with_consistency, without = (_intensity._fitted_text(xr.Dataset(), shown) for shown in (True, False))
    if kind != "fitted":
        assert with_consistency == without == ""
        return
    assert "a calibration standing in for a disaggregation of the site's hazard" in with_consistency
    assert "What it costs in g* is not measured by this store" in with_consistency and "docs/measure-free.md" in with_consistency
    assert "(how closely: the hazard consistency below)" in with_consistency and "hazard consistency" not in without


def test_a_fitted_stores_report_says_so_from_its_definition(tmp_path) -> None:
    """End to end: the store of a fitted site's experiment, read back, gives the Intensity section the fitted scenario's words."""
    from stochpound import open_store
    from stochpound.experiment._runner import load_experiment, run_experiment
    from stochpound.report.render import Paragraph
    from stochpound.report.sections._intensity import intensity_section
    from tests.helpers import write_experiment

    experiment = load_experiment(write_experiment(tmp_path, _text(FITTED_SELECTION.replace("motions = 4", "motions = 2"), FITTED_SITE), "fitted.toml"))
    report = run_experiment(experiment, workers=0, progress=False)
    store = open_store(report.store).load()
    text = " ".join(block.text for block in intensity_section("fitted", store).blocks if isinstance(block, Paragraph))
    assert 'The scenario was fitted to the site\'s hazard curves ([site] scenario = "fitted"): a calibration standing in for a' in text
