"""A site given by its ruptures (stochpound.analysis.RuptureSite): its hazard against a summation written here from the four
pygmm models, its disaggregation against its own curve, the exact conditional spectrum against the single-scenario one, the
mixture's moments computed here and a Monte Carlo of the site's earthquakes; the rupture table's errors; the bundled demo;
an experiment's [site] ruptures."""

from __future__ import annotations

import tomllib

import numpy as np
import pygmm
import pytest
from scipy.special import ndtr

from stochpound import SiteError
from stochpound.analysis import RUPTURE_COLUMNS, RuptureSite, bundled_rupture_sites, rate_from_probability, scenario_hazard
from stochpound.experiment._runner import load_experiment
from stochpound.experiment._spec import ExperimentError, parse_experiment
from stochpound.hazard._ruptures import bundled_rupture_path
from stochpound.motions import SITE_MOTION_LIMITS, conditional_spectrum, scenario_distribution
from stochpound.store import definition_sha256
from tests.helpers import SITE_SCENE, write_experiment

DEMO = "demo_three_sources"
DIPS = {"strike_slip": ("SS", 90.0), "reverse": ("RS", 40.0), "normal": ("NS", 50.0)}
RETURN_PERIODS = np.array([72.0, 475.0, 2475.0, 10000.0])


def _independent_moments(site: RuptureSite, period: float | None) -> tuple[np.ndarray, np.ndarray]:
    """μ_r and σ_r of ln IM from the four models called here (PGA: period None), their ln medians averaged and σ² averaged."""
    classes = (pygmm.AbrahamsonSilvaKamai2014, pygmm.BooreStewartSeyhanAtkinson2014, pygmm.CampbellBozorgnia2014, pygmm.ChiouYoungs2014)
    means, sigmas = [], []
    for i in range(len(site)):
        scenario = pygmm.Scenario(mag=site.magnitude[i], dist_rup=site.distance_rup_km[i], dist_jb=site.distance_jb_km[i],
                                  dist_x=site.distance_x_km[i], depth_tor=site.ztor_km[i], dip=site.dip[i], v_s30=site.vs30,
                                  mechanism=DIPS[site.mechanism[i]][0], region="california", vs_source="measured",
                                  on_hanging_wall=site.distance_x_km[i] >= 0)
        models = [model(scenario) for model in classes]
        if period is None:
            ln, var = [np.log(m.pga) for m in models], [m.ln_std_pga**2 for m in models]
        else:
            ln = [float(m.interp_ln_spec_accels(np.array([period]))[0]) for m in models]
            var = [float(m.interp_ln_stds(np.array([period]))[0]) ** 2 for m in models]
        means.append(np.mean(ln))
        sigmas.append(np.sqrt(np.mean(var)))
    return np.array(means), np.array(sigmas)


@pytest.fixture(scope="module")
def demo() -> RuptureSite:
    return RuptureSite.bundled(DEMO)


@pytest.mark.parametrize("period", [None, 1.0])
def test_the_demo_sites_hazard_is_the_sum_over_its_ruptures_computed_here(demo: RuptureSite, period: float | None) -> None:
    measure = "pga" if period is None else "psa"
    mean, sigma = _independent_moments(demo, period)
    rates = np.array(demo.rate)

    def summed(x: np.ndarray) -> np.ndarray:
        return np.sum(rates * ndtr(-(np.log(x)[:, None] - mean) / sigma), axis=1)

    x = demo.intensity_at(measure, period, 1.0 / RETURN_PERIODS)  # the levels of 72 to 10 000 years
    np.testing.assert_allclose(summed(x), 1.0 / RETURN_PERIODS, rtol=1e-6)  # solved exactly
    grid = np.geomspace(0.5 * x[0], 1.5 * x[-1], 23)
    np.testing.assert_allclose(demo.rate_of_exceedance(measure, period, grid), summed(grid), rtol=1e-9)
    curve = demo.hazard_curve(measure, period)  # the table, interpolated log-log
    np.testing.assert_allclose(curve(grid), summed(grid), rtol=0.01)
    assert curve.units == "g" and DEMO in curve.source


def test_the_disaggregation_sums_to_the_curve_at_every_level(demo: RuptureSite) -> None:
    levels = demo.intensity_at("psa", 1.0, 1.0 / RETURN_PERIODS)
    d = demo.disaggregation("psa", 1.0, levels=levels)
    np.testing.assert_allclose(d.contribution.sum("rupture"), demo.hazard_curve("psa", 1.0)(levels), rtol=0.01)
    np.testing.assert_allclose(d.rate, 1.0 / RETURN_PERIODS, rtol=1e-6)
    for name in ("share", "density_share"):
        np.testing.assert_allclose(d[name].sum("rupture"), 1.0, rtol=1e-12)
    np.testing.assert_allclose(d.binned_share.sum(("magnitude_bin", "distance_bin", "epsilon_bin")), 1.0, rtol=1e-12)
    mean, sigma = _independent_moments(demo, 1.0)
    epsilon = (np.log(levels)[:, None] - mean) / sigma
    share = np.array(demo.rate) * ndtr(-epsilon)
    share /= share.sum(axis=1, keepdims=True)
    np.testing.assert_allclose(d.share, share, rtol=1e-9)
    np.testing.assert_allclose(d.mean_magnitude, share @ np.array(demo.magnitude), rtol=1e-9)
    np.testing.assert_allclose(d.mean_epsilon, np.sum(share * epsilon, axis=1), rtol=1e-7, atol=1e-9)
    # the ruptures of one magnitude bin (the background's M 5.75) add up to that bin's share
    in_bin = np.array(demo.magnitude) == 5.75
    assert in_bin.sum() == 4
    np.testing.assert_allclose(d.binned_share.sel(magnitude_bin=5.5).sum(("distance_bin", "epsilon_bin")), share[:, in_bin].sum(axis=1), rtol=1e-12)
    # the demo's levels of 72 to 10 000 years: within the models' range, caused at moderate ε
    assert np.all(np.diff(d.mean_epsilon.values) > 0) and d.mean_epsilon.values[-1] < 2.5
    assert 5.0 < d.mean_magnitude.min() and d.mean_magnitude.max() < 8.0


def test_the_uniform_hazard_spectrum_is_each_periods_own_level(demo: RuptureSite) -> None:
    uhs = demo.uniform_hazard_spectrum([0.0, 1.0, 3.0], return_periods=[475.0, 2475.0])
    for j, period in enumerate([None, 1.0, 3.0]):
        measure = "pga" if period is None else "psa"
        np.testing.assert_allclose(demo.rate_of_exceedance(measure, period, uhs.psa.values[:, j]), [1 / 475.0, 1 / 2475.0], rtol=1e-6)


def _one(magnitude: float = 7.2, distance: float = 12.0, **changes: object) -> dict[str, tuple]:
    row = {"magnitude": magnitude, "distance_rup_km": distance, "distance_jb_km": distance - 2.0, "distance_x_km": 6.0, "ztor_km": 2.0,
           "dip": 45.0, "mechanism": "reverse", "rate": 0.01} | changes
    return {key: (value,) for key, value in row.items()}


def _site(*rows: dict[str, tuple], **site: object) -> RuptureSite:
    columns = {key: tuple(value for row in rows for value in row[key]) for key in RUPTURE_COLUMNS}
    return RuptureSite(**columns, **({"vs30": 450.0} | site))


PERIODS = [0.1, 0.3, 1.0, 2.0, 4.0]


@pytest.mark.parametrize("weights", ["level", "exceedance"])
def test_the_exact_spectrum_of_one_rupture_is_its_conditional_spectrum(weights: str) -> None:
    site = _site(_one(), z1p0_km=0.4, z2p5_km=1.8)
    exact = site.conditional_spectrum("psa", 1.0, level=0.6, periods=PERIODS, weights=weights)
    geometry = {"distance_jb_km": 10.0, "distance_x_km": 6.0, "ztor_km": 2.0, "dip": 45.0, "z1p0_km": 0.4, "z2p5_km": 1.8}
    single = conditional_spectrum("psa", 1.0, level=0.6, periods=PERIODS, magnitude=7.2, distance_km=12.0, vs30=450.0, mechanism="reverse",
                                  geometry=geometry)
    for name in ("median", "sigma_ln", "correlation", "unconditional_median", "unconditional_sigma_ln"):
        np.testing.assert_allclose(exact[name].values, single[name].values, rtol=1e-12, atol=1e-12)
    assert exact.attrs["epsilon"] == pytest.approx(single.attrs["epsilon"], rel=1e-12)
    assert exact.rupture_weight.values.tolist() == [1.0] and np.all(exact.between_sigma_ln.values == 0.0)
    # the geometry given is used: a footwall site of the same rupture has another spectrum
    footwall = conditional_spectrum("psa", 1.0, level=0.6, periods=PERIODS, magnitude=7.2, distance_km=12.0, vs30=450.0, mechanism="reverse")
    assert not np.allclose(footwall.unconditional_median.values, single.unconditional_median.values, rtol=1e-3)


def test_the_exact_spectrum_of_two_ruptures_is_their_mixture() -> None:
    """The mixture's moments from the two single-scenario spectra, weighted here by ν φ(ε)/σ and by ν Φc(ε)."""
    site = _site(_one(), _one(6.0, 8.0, mechanism="strike_slip", dip=90.0, distance_x_km=-8.0, distance_jb_km=7.0, rate=0.2))
    level = 0.3
    parts, moments = [], []
    for i in range(2):
        scenario = site.scenario(i)
        parts.append(conditional_spectrum("psa", 1.0, level=level, periods=PERIODS, scenario=scenario))
        moments.append(scenario_distribution("psa", 1.0, scenario=scenario))
    epsilon = np.array([part.attrs["epsilon"] for part in parts])
    sigma = np.array([m[1] for m in moments])
    np.testing.assert_allclose(epsilon, (np.log(level) - np.log([m[0] for m in moments])) / sigma, rtol=1e-12)
    for weights, p in (("level", np.array(site.rate) * np.exp(-epsilon**2 / 2) / sigma), ("exceedance", np.array(site.rate) * ndtr(-epsilon))):
        p = p / p.sum()
        exact = site.conditional_spectrum("psa", 1.0, level=level, periods=PERIODS, weights=weights)
        means = np.log([part["median"].values for part in parts])
        mean = p @ means
        variance = p @ (np.array([part["sigma_ln"].values for part in parts]) ** 2 + (means - mean) ** 2)
        np.testing.assert_allclose(exact.rupture_weight.values, p, rtol=1e-10)
        np.testing.assert_allclose(np.log(exact["median"].values), mean, rtol=1e-10, atol=1e-12)
        np.testing.assert_allclose(exact["sigma_ln"].values, np.sqrt(variance), rtol=1e-10, atol=1e-12)
        assert exact["sigma_ln"].sel(period=1.0) == pytest.approx(0.0, abs=1e-7)  # at T* the level itself
        assert exact.attrs["magnitude"] == pytest.approx(p @ np.array(site.magnitude), rel=1e-12)
    assert 0.05 < p[0] < 0.95  # both ruptures matter at this level


def test_the_exact_spectrum_is_the_site_given_the_level_by_monte_carlo() -> None:
    """Earthquakes drawn from the two ruptures by their rates, each a correlated spectrum (the models' median, σ, Baker–Jayaram ρ);
    those whose PSA(1 s) falls within ±1.5 % of the level have the mean and σ of ln Sa of the exact spectrum (weights "level")."""
    from pygmm.baker_jayaram_2008 import calc_correls

    site = _site(_one(), _one(6.0, 8.0, mechanism="strike_slip", dip=90.0, distance_x_km=-8.0, distance_jb_km=7.0, rate=0.2))
    level, periods = 0.3, [0.1, 0.3, 1.0, 3.0]
    rho = np.array([calc_correls(np.array(periods), t) for t in periods])
    rng = np.random.default_rng(7)
    n = 2_000_000
    which = rng.random(n) < site.rate[0] / sum(site.rate)
    spectra = np.empty((n, len(periods)))
    for i, chosen in enumerate((which, ~which)):
        unconditional = conditional_spectrum("psa", 1.0, level=level, periods=periods, scenario=site.scenario(i))
        s = unconditional.unconditional_sigma_ln.values
        spectra[chosen] = rng.multivariate_normal(np.log(unconditional.unconditional_median.values), rho * np.outer(s, s), size=int(chosen.sum()))
    near = np.abs(spectra[:, 2] - np.log(level)) < 0.015
    exact = site.conditional_spectrum("psa", 1.0, level=level, periods=periods)
    kept = spectra[near]
    assert kept.shape[0] > 10_000
    np.testing.assert_allclose(kept.mean(axis=0), np.log(exact["median"].values), atol=0.01)
    np.testing.assert_allclose(kept.std(axis=0), exact["sigma_ln"].values, atol=0.015)  # at T*: the bin's own width, 0.0087
    exceedance = site.conditional_spectrum("psa", 1.0, level=level, periods=periods, weights="exceedance")
    assert abs(np.log(exceedance["median"].values[-1]) - kept.mean(axis=0)[-1]) > 0.025  # the exceedance shares: another target


def test_a_one_rupture_site_is_the_scenario_hazard() -> None:
    scenario = {"magnitude": 7.0, "distance_km": 20.0, "vs30": 400.0, "mechanism": "strike_slip"}
    curve = scenario_hazard("psa", 2.0, **scenario, rate=0.05)
    site = _site(_one(7.0, 20.0, distance_jb_km=20.0, distance_x_km=-20.0, ztor_km=0.0, dip=90.0, mechanism="strike_slip", rate=0.05), vs30=400.0)
    np.testing.assert_allclose(site.rate_of_exceedance("psa", 2.0, curve.im), curve.rate, rtol=1e-12)


def _write(tmp_path, text: str, name: str = "site.csv"):
    path = tmp_path / name
    path.write_text(text)
    return path


HEADER = "name,magnitude,distance_rup_km,distance_jb_km,distance_x_km,ztor_km,dip,mechanism,rate\n"
ROW = "a,7.0,20,20,-20,0,90,strike_slip,0.01\n"


def test_a_rupture_table_is_read_with_its_site_fields(tmp_path) -> None:
    path = _write(tmp_path, "# my faults, from my model\n# vs30: 360\n# z1p0_km: 0.5\n" + HEADER + ROW + "b,6.5,10,8,5,3,45,reverse,0.002\n")
    site = RuptureSite.from_file(path)
    assert len(site) == 2 and site.vs30 == 360.0 and site.z1p0_km == 0.5 and site.z2p5_km is None
    assert site.names == ("a", "b") and site.mechanism == ("strike_slip", "reverse") and site.source == "my faults, from my model"
    assert RuptureSite.from_file(path, vs30=360.0, z2p5_km=2.0).z2p5_km == 2.0
    assert RuptureSite.from_entry(site.to_entry()) == site
    assert set(site.to_entry(identity=True)) == set(site.to_entry()) - {"name", "source"}


@pytest.mark.parametrize(
    "text, kwargs, message",
    [
        (HEADER + ROW, {}, "vs30: not stated"),
        ("# vs30: 400\n" + HEADER + ROW, {"vs30": 760.0}, "vs30: 760.0 given, but site.csv states 400"),
        ("# vs30: 400\n" + HEADER.replace(",dip", "") + ROW, {}, "site.csv, line 2: header: missing dip"),
        ("# vs30: 400\n" + HEADER.replace("rate", "rate,weight") + ROW.replace("0.01", "0.01,1"), {}, "site.csv, line 2: header: unknown weight"),
        ("# vs30: 400\n" + HEADER + ROW.replace("7.0", "9.1"), {}, "site.csv, line 3: magnitude: must be within 3.5-8.5"),
        ("# vs30: 400\n" + HEADER + ROW.replace("20,20", "20,25"), {}, "site.csv, line 3: distance_jb_km: must be within 0-20"),
        ("# vs30: 400\n" + HEADER + ROW.replace("strike_slip", "oblique"), {}, "site.csv, line 3: mechanism: must be one of"),
        ("# vs30: 400\n" + HEADER + ROW.replace("0.01", "0"), {}, "site.csv, line 3: rate: must be an annual rate of occurrence > 0"),
        ("# vs30: 400\n" + HEADER + ROW.replace(",90,", ",x,"), {}, "site.csv, line 3: dip: must be a number, got 'x'"),
        ("# vs30: 400\n" + HEADER + ROW.replace(",90,", ",10,"), {}, "site.csv, line 3: dip: must be within 15-90"),
        ("# vs30: 100\n" + HEADER + ROW, {}, "site.csv: vs30: must be within 180-1000"),
        ("# vs30: 400\n" + HEADER, {}, "site.csv: no ruptures"),
    ],
)
def test_a_bad_rupture_table_is_one_line_naming_file_line_and_field(tmp_path, text: str, kwargs: dict, message: str) -> None:
    with pytest.raises(SiteError) as error:
        RuptureSite.from_file(_write(tmp_path, text), **kwargs)
    assert str(error.value).startswith(message) and "\n" not in str(error.value)


def test_the_bundled_demo_is_made_as_its_sources_say(demo: RuptureSite) -> None:
    assert DEMO in bundled_rupture_sites() and demo.vs30 == 400.0
    background = [i for i, name in enumerate(demo.names) if name.startswith("background")]
    assert len(background) == 12
    low, high = SITE_MOTION_LIMITS["magnitude"]  # every rupture's motions can be simulated (the answer without a measure)
    assert all(low <= m <= high for m in demo.magnitude) and min(demo.magnitude[i] for i in background) - 0.25 == low
    for i in background:  # b = 1, 0.2 per year above M 5, truncated at M 7, from M 5.5 on, rings of a 100 km disc by area
        m1 = demo.magnitude[i] - 0.25
        ring = demo.names[i].split("_r")[1]
        r1, r2 = (float(v) for v in ring.split("-"))
        expected = 0.2 * (10 ** -(m1 - 5) - 10 ** -(m1 + 0.5 - 5)) / (1 - 10**-2) * (r2**2 - r1**2) / 100**2
        assert demo.rate[i] == pytest.approx(expected, rel=5e-4)
        assert demo.distance_jb_km[i] == pytest.approx(2 / 3 * (r2**3 - r1**3) / (r2**2 - r1**2), abs=0.05)
    background_rate = 0.2 * (10 ** -(low - 5) - 10**-2) / (1 - 10**-2)  # M 5.5 to 7 of the truncated law
    assert sum(demo.rate) == pytest.approx(1 / 150 + 1 / 500 + background_rate, rel=5e-4)
    reverse = demo.names.index("reverse_fault")
    assert demo.distance_rup_km[reverse] == pytest.approx(10 * np.sin(np.radians(40)) + 5 * np.cos(np.radians(40)), abs=0.05)
    assert rate_from_probability(0.5, 50) > 1 / 72.2  # 72 years: 50 % in 50 years, a level the site reaches


SELECTION = 'measure = "psa"\nperiod = 1.0\nlevels = [0.4, 0.2]\nselection = "conditional_spectrum"\nmotions = 4\nmax_scale_factor = 5.0\n'
RECORDS = "".join(f'\n[[records]]\nrecord = "fema_p695_far_field/{i:02d}a"\n' for i in range(1, 7))


def _experiment(site: str) -> str:
    return f'[experiment]\nname = "ruptures"\n{SITE_SCENE}\n[grid]\ngap = ["inf"]\n{RECORDS}\n[intensity]\n{SELECTION}\n{site}\n[solver]\nmethod = "exact"\n'


def test_an_experiments_site_of_ruptures_targets_the_exact_spectrum(tmp_path, demo: RuptureSite) -> None:
    definition = parse_experiment(tomllib.loads(_experiment(f'[site]\nruptures = "{DEMO}"\n')), tmp_path)
    entry = definition["intensity"]
    assert RuptureSite.from_entry(entry["ruptures"]) == demo and definition["site"] == {"scenario": "ruptures", "ruptures": DEMO}
    weights = demo.disaggregation("psa", 1.0, levels=[0.2, 0.4]).density_share.values
    assert [s["magnitude"] for s in entry["site"]] == pytest.approx(list(weights @ np.array(demo.magnitude)), rel=1e-12)
    # the table's values are in the identity, its comments and file name are not
    text = tmp_path / "mine.csv"
    original = bundled_rupture_path(DEMO).read_text()
    text.write_text(original)
    same = parse_experiment(tomllib.loads(_experiment('[site]\nruptures = "mine.csv"\n')), tmp_path)
    assert definition_sha256(same) == definition_sha256(definition)
    text.write_text(original.replace("# vs30: 400", "# a comment\n# vs30: 400"))
    assert definition_sha256(parse_experiment(tomllib.loads(_experiment('[site]\nruptures = "mine.csv"\n')), tmp_path)) == definition_sha256(definition)
    text.write_text(original.replace("0.006667", "0.005"))
    assert definition_sha256(parse_experiment(tomllib.loads(_experiment('[site]\nruptures = "mine.csv"\n')), tmp_path)) != definition_sha256(definition)
    # every stripe's target is the site's exact conditional spectrum at its level
    selection = load_experiment(write_experiment(tmp_path, _experiment(f'[site]\nruptures = "{DEMO}"\n'), "ruptures.toml")).selection
    for level, target in zip([0.2, 0.4], selection.targets):
        exact = demo.conditional_spectrum("psa", 1.0, level=level, periods=selection.periods)
        np.testing.assert_allclose(target["median"].values, exact["median"].values, rtol=1e-12)
        np.testing.assert_allclose(target["sigma_ln"].values, exact["sigma_ln"].values, rtol=1e-12)
    assert selection.coordinates()["site_magnitude"].values == pytest.approx([s["magnitude"] for s in entry["site"]], rel=1e-12)


@pytest.mark.parametrize(
    "site, field",
    [
        ('[site]\nruptures = "nowhere.csv"\n', "site.ruptures: 'nowhere.csv' is neither a file nor a bundled site"),
        (f'[site]\nruptures = "{DEMO}"\nvs30 = 760.0\n', f"site.vs30: 760.0 given, but {DEMO}.csv states 400"),
        (f'[site]\nruptures = "{DEMO}"\nmagnitude = 7.0\n', "site.magnitude: unknown field"),
        ('[site]\nscenario = "ruptures"\nvs30 = 400.0\n', "site.scenario:"),
        (f'[site]\nruptures = "{DEMO}"\nsimulated_motions = 0\n', "site.simulated_motions: simulated motions a stripe in its pool"),
    ],
)
def test_a_bad_site_of_ruptures_is_one_line_naming_the_field(tmp_path, site: str, field: str) -> None:
    with pytest.raises(ExperimentError) as error:
        parse_experiment(tomllib.loads(_experiment(site)), tmp_path)
    assert str(error.value).startswith(field) and "\n" not in str(error.value)


def test_an_experiments_hazard_comes_from_the_same_ruptures(tmp_path, demo: RuptureSite) -> None:
    site = f'[site]\nruptures = "{DEMO}"\n'
    definition = parse_experiment(tomllib.loads(_experiment(site + f'[hazard]\nruptures = "{DEMO}"\n')), tmp_path)
    hazard, curve = definition["hazard"], demo.hazard_curve("psa", 1.0)
    assert hazard["source"] == "ruptures" and hazard["ruptures"] == DEMO and hazard["units"] == "g"
    np.testing.assert_allclose(hazard["im"], curve.im, rtol=1e-12)
    np.testing.assert_allclose(hazard["rate"], curve.rate, rtol=1e-12)
    scaled = 'measure = "psa"\nperiod = 1.0\nlevels = [3.0, 6.0]\nunits = "m/s2"\n'  # levels in m/s²: the intensities converted with g
    text = f'[experiment]\nname = "r"\n{SITE_SCENE}\n[grid]\ngap = ["inf"]\n{RECORDS}\n[intensity]\n{scaled}\n[hazard]\nruptures = "{DEMO}"\n'
    converted = parse_experiment(tomllib.loads(text), tmp_path)["hazard"]
    np.testing.assert_allclose(converted["im"], curve.im * 9.81, rtol=1e-12)
    for table, field in ((f'[hazard]\nruptures = "{DEMO}"\nvs30 = 300.0\n', "hazard.vs30: 300.0 given"),
                         ('[hazard]\npower_law = { k0 = 1e-4, k = 2.0 }\nvs30 = 300.0\n', "hazard.vs30: only with ruptures"),
                         ('[hazard]\nruptures = "nowhere"\n', "hazard.ruptures: 'nowhere' is neither")):
        with pytest.raises(ExperimentError) as error:
            parse_experiment(tomllib.loads(_experiment(site + table)), tmp_path)
        assert str(error.value).startswith(field) and "\n" not in str(error.value)


def test_the_command_prints_the_hazard_and_disaggregation(demo: RuptureSite) -> None:
    from tests.helpers import invoke

    result = invoke("site", DEMO, "--measure", "psa", "--period", "1.0", "--return-periods", "475,2475")
    assert result.exit_code == 0, result.output
    levels = demo.intensity_at("psa", 1.0, [1 / 475.0, 1 / 2475.0])
    d = demo.disaggregation("psa", 1.0, levels=levels)
    rows = [line.split() for line in result.output.splitlines() if line.split() and line.split()[0] in ("475", "2475")]
    for row, level, magnitude in zip(rows, levels, d.mean_magnitude.values):
        assert float(row[2]) == pytest.approx(level, rel=1e-3) and float(row[3]) == pytest.approx(magnitude, abs=0.006)
    assert "reverse_fault" in rows[1][6]  # the largest share at 2475 years
    for args, message in ((("nowhere",), "Error: TABLE|NAME: 'nowhere' is neither"), ((DEMO, "--return-periods", "3"), "Error: --return-periods:"),
                          ((DEMO, "--measure", "psa"), "Error: --period: psa needs one period")):
        failed = invoke("site", *args)
        assert failed.exit_code == 1 and failed.output.strip().startswith(message) and len(failed.output.strip().splitlines()) == 1


@pytest.mark.slow  # a run and its store (about 50 s on a busy machine)
def test_a_run_of_a_site_of_ruptures_stores_and_reports_the_mixture(tmp_path, demo: RuptureSite) -> None:
    from stochpound import open_store
    from stochpound.experiment._runner import run_experiment
    from stochpound.report.render import Paragraph
    from stochpound.report.sections._intensity import intensity_section
    from stochpound.store import scenario_kind

    records = "".join(f'\n[[records]]\nrecord = "fema_p695_far_field/{i:02d}{c}"\nduration = 5.0\n' for i in range(1, 7) for c in "ab")
    selection = SELECTION.replace("levels = [0.4, 0.2]", "levels = [0.1, 0.2]").replace("motions = 4", "motions = 3")
    text = (f'[experiment]\nname = "ruptures"\n{SITE_SCENE}\n[grid]\ngap = ["inf"]\n{records}\n[intensity]\n{selection}\n'
            f'[site]\nruptures = "{DEMO}"\n[hazard]\nruptures = "{DEMO}"\n[solver]\nmethod = "exact"\n')
    experiment = load_experiment(write_experiment(tmp_path, text, "ruptures.toml"))
    report = run_experiment(experiment, workers=0, progress=False)
    store = open_store(report.store).load()
    assert report.complete and scenario_kind(store) == "ruptures"
    weights = demo.disaggregation("psa", 1.0, levels=[0.1, 0.2]).density_share.values
    np.testing.assert_allclose(store.site_magnitude.values, weights @ np.array(demo.magnitude), rtol=1e-12)
    exact = demo.conditional_spectra("psa", 1.0, levels=[0.1, 0.2], periods=store.selection_period.values)
    np.testing.assert_allclose(store.target_median.values, [cs["median"].values for cs in exact], rtol=1e-12)
    np.testing.assert_allclose(store.target_epsilon.values, [cs.attrs["epsilon"] for cs in exact], rtol=1e-12)
    assert store.pound.hazard.source == "ruptures"
    words = " ".join(block.text for block in intensity_section("ruptures", store).blocks if isinstance(block, Paragraph))
    assert f"0.2 g: the ruptures' mean M {store.site_magnitude.values[1]:.3g} at {store.site_distance_km.values[1]:.3g} km" in words


def test_a_site_written_as_a_rupture_table_reads_back_as_the_same_site(tmp_path):
    """RuptureSite.to_csv writes what from_file reads: the same ruptures (every column, exactly), names, site fields and source."""
    site = RuptureSite.bundled("demo_three_sources", vs30=400.0)
    path = tmp_path / "again.csv"
    assert site.to_csv(path) is None and path.read_text() == site.to_csv()
    again = RuptureSite.from_file(path, name=site.name)
    assert again.to_entry() == site.to_entry()
    assert again.hazard_curve("psa", 1.0).rate.tolist() == site.hazard_curve("psa", 1.0).rate.tolist()
