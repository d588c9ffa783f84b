"""benchmarks.measure_seeds: the study's tables from its kept results, and a run that resumes without redoing a result."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from benchmarks import measure_seeds
from benchmarks.site_consistency import Pool

GAPS = np.linspace(0.01, 1.0, 100)


def _result(scale: float, decay: float, separation: list[list[float]], gaps: np.ndarray = GAPS) -> xr.Dataset:
    """A result of two neighbours: the rate scale·exp(−gap/decay) (1/yr) over ``gaps`` (m), the g* given (neighbour × target)."""
    rate = xr.DataArray(np.outer(scale * np.exp(-gaps / decay), [1.0, 1.0]), dims=("gap", "neighbour"),
                        coords={"gap": gaps, "neighbour": ["stiff", "flexible"]})
    g = xr.DataArray(separation, dims=("neighbour", "target"), coords={"neighbour": ["stiff", "flexible"], "target": [0.1, 0.02]})
    return xr.Dataset({"rate": rate, "separation": g})


def test_the_spread_table_gives_the_medians_and_the_spreads_over_measures_seeds_and_rates() -> None:
    scales = {"PGA": [1.0, 2.0, 1.5], "PSA(1 s)": [1.0, 1.0, 1.0]}
    g = {"PGA": [0.10, 0.12, 0.11], "PSA(1 s)": [0.13, 0.13, 0.14]}
    separation = xr.concat([xr.concat([_result(scales[m][k], 0.1, [[g[m][k], 2 * g[m][k]], [g[m][k], 2 * g[m][k]]])["separation"]
                                       for k in range(3)], dim="seed") for m in scales], dim="measure")
    # each result on its own gap grid, as the risk chain's grids differ from store to store (joined, NaN at the others' gaps)
    rate = xr.concat([xr.concat([_result(scales[m][k], 0.1, [[0, 0], [0, 0]], GAPS * (1 + 0.003 * (3 * j + k)))["rate"] for k in range(3)], dim="seed",
                                join="outer") for j, m in enumerate(scales)], dim="measure", join="outer")
    coords = {"measure": list(scales), "seed": [1, 2, 3]}
    rows = measure_seeds.spread_rows("fixed pair", separation.assign_coords(coords), rate.assign_coords(coords))
    assert len(rows) == 4  # two neighbours × two targets
    first = rows[0]
    assert first[0] == "fixed pair, stiff neighbour, 10% in 50 yr"
    assert first[1] == "0.110 (0.100–0.120)" and first[2] == "0.130 (0.130–0.140)"
    assert first[3] == f"×{0.13 / 0.11:.2f}"  # over the measures' medians
    assert first[4] == f"×{0.14 / 0.10:.2f}"  # over every measure and seed
    assert first[5] == f"×{0.12 / 0.10:.2f} (PGA)"
    assert first[6] == "×2.00 (PGA)"  # the rates differ by their scale alone, wherever they are read


def test_a_run_keeps_each_result_and_does_not_redo_it(tmp_path, monkeypatch) -> None:
    done = []

    def fake(folder, configuration, measure, seed, pool, site):
        done.append((configuration, measure, seed))
        return _result(1.0, 0.1, [[0.1, 0.2], [0.1, 0.2]]).assign_attrs(seconds=1.0)

    monkeypatch.setattr(measure_seeds, "run_one", fake)
    pool = Pool(40, 10, 3, "tilted")
    measure_seeds.run(tmp_path, ["fixed pair"], ["PGA", "PSA(1 s)"], [1, 2], pool)
    assert len(done) == 4
    measure_seeds.run(tmp_path, ["fixed pair", "isolated"], ["PGA", "PSA(1 s)"], [1, 2], pool)
    assert done[4:] == [("isolated", m, s) for s in (1, 2) for m in ("PGA", "PSA(1 s)")]
    assert measure_seeds.result_path(tmp_path, "fixed pair", "PSA(T1 = 0.3 s)", 3).name == "psat1_0p3s-seed3.nc"
    with pytest.raises(SystemExit, match=r"--motions: .*ran 40 motions a stripe, not 120"):  # a folder holds one number of motions
        measure_seeds.run(tmp_path, ["fixed pair"], ["PGA"], [1], Pool(120, 10, 3, "tilted"))
    assert len(done) == 8


@pytest.mark.parametrize("sampling, line", [("tilted", 'simulated_sampling = "tilted"\n'), ("scenario", "")])
def test_the_pool_writes_its_sampling_only_when_tilted(sampling: str, line: str) -> None:
    assert Pool(40, 2000, 3, sampling).site_lines() == "simulated_motions = 2000\n" + line


@pytest.mark.slow
def test_consistency_reads_the_kept_stores_and_gives_each_curve_at_the_targets_over_the_seeds(tmp_path) -> None:
    """``consistency`` on a store kept where ``run`` keeps it: the ratios of stochpound.risk's own check, one row per conditioning
    measure with the median and range over the seeds; a store not run is named."""
    from stochpound import open_store
    from stochpound.experiment import load_experiment, run_experiment
    from stochpound.risk import consistency_at_targets, site_consistency
    from benchmarks.site_consistency import FOX_PLAZA, experiment_file
    from tests.helpers import stripes_site_text, write_experiment

    work = measure_seeds.work_folder(tmp_path, "isolated", 1)
    work.mkdir(parents=True)
    text = stripes_site_text('[hazard]\nbundled = "fox_plaza_los_angeles_sa1p0s"\n')
    report = run_experiment(load_experiment(write_experiment(work, text, experiment_file(work, "PSA(1 s)").name)), workers=0, progress=False)
    assert report.store == experiment_file(work, "PSA(1 s)").with_suffix(".nc")
    ratios = measure_seeds.consistency(tmp_path, "isolated", ["PSA(1 s)"], [1], FOX_PLAZA)
    assert list(ratios["checked"].values) == list(FOX_PLAZA.measures)
    with open_store(report.store) as store:
        expected = {name: consistency_at_targets(site_consistency(store)[name]) for name in ("PGA", "PSA(2 s)")}
    for name, values in expected.items():
        np.testing.assert_allclose(ratios.sel(measure="PSA(1 s)", checked=name, seed=1).values, values, rtol=1e-12, equal_nan=True)
    pga = expected["PGA"]
    assert np.all(np.isfinite(pga)) and np.all(np.isnan(expected["PSA(2 s)"]))  # two stripes of 4 motions reach PGA's targets, not PSA(2 s)'s
    row = dict(zip(["conditioning", *FOX_PLAZA.measures], measure_seeds.consistency_rows("isolated", ratios)[0]))
    assert row["conditioning"] == "isolated, PSA(1 s)" and row["PSA(2 s)"] == "– / –"
    assert row["PGA"] == f"{pga[0]:.2f} ({pga[0]:.2f}–{pga[0]:.2f}) / {pga[1]:.2f} ({pga[1]:.2f}–{pga[1]:.2f})"
    with pytest.raises(FileNotFoundError, match="psa2.nc of isolated, seed 1: not in work/"):
        measure_seeds.consistency(tmp_path, "isolated", ["PSA(2 s)"], [1], FOX_PLAZA)


def test_the_model_s_own_curves_are_its_motions_counted_at_the_site_s_levels(monkeypatch) -> None:
    """``model_curves`` at a site of one scenario (ν = 0.1 /yr): with motions whose PGA is known, the model's rate at the site's level
    of each target is ν × the share of motions beyond it, and the model's level at the target's rate is the motion at which ν × the
    share beyond first passes it."""
    import stochpound.motions
    from benchmarks.site_consistency import scenario_site

    site = scenario_site(7.0, 20.0, "strike_slip", 0.1)
    n = 5000
    pga = np.linspace(0.001, 2.0, n)[::-1]  # g; motion i a single sample of that acceleration

    def motions(*, scenario, n, seed, realizations):
        return xr.Dataset({"acceleration": (("realization", "time"), pga[realizations, None] * stochpound.motions.DEFAULT_G)},
                          attrs={"dt": 0.01})

    monkeypatch.setattr(stochpound.motions, "site_motions", motions)
    curves = measure_seeds.model_curves(site, ["PGA"], n)
    for probability in (0.1, 0.02):
        target = -np.log1p(-probability) / 50.0
        row = curves.loc[(probability, "PGA")]
        level = float(site.hazard("PGA").intensity_at(target))
        assert row["site level"] == pytest.approx(level, rel=1e-12)
        assert row["model rate / site rate"] == pytest.approx(0.1 * np.mean(pga > level) / target, rel=1e-12)
        passed = int(np.ceil(target / 0.1 * n - 1e-9))  # the motions (from the strongest) whose weights 0.1/n first reach the rate
        assert row["model level / site level"] == pytest.approx(pga[passed - 1] / level, rel=1e-12)


def test_the_measure_free_comparison_at_fox_plaza_takes_ruptures_fitted_to_its_curves(capsys) -> None:
    """Fox Plaza gives no ruptures: the answer without a measure runs on the ones fitted to its 17 curves at the assumed Vs30, within
    the site-motion model's range (M 5.5-8, R_rup 5-100 km); at 300 m/s six, their curves within 0.20 rms in ln rate (docs quote it)."""
    from stochpound.motions import SITE_MOTION_LIMITS

    with pytest.raises(SystemExit):
        measure_seeds.main(["measure_free", "folder", "--vs30", "300", "--runs", "1"])
    printed = capsys.readouterr()
    assert "--runs: must be at least 12 (two runs of each of the site's ruptures), got 1" in printed.err
    assert "fitted to its 17 curves at Vs30 300 m/s (rms of ln(recomputed / site) 0.20, largest 0.63)" in printed.out
    site = measure_seeds.fitted_ruptures(300.0)
    for field in ("magnitude", "distance_km"):
        low, high = SITE_MOTION_LIMITS[field]
        assert all(low <= getattr(scenario, field) <= high for scenario, _ in site)
    assert site.vs30 == 300.0 and min(site.rate) > 0
    with pytest.raises(SystemExit):
        measure_seeds.main(["measure_free", "folder", "--site", "scenario", "--runs", "1"])
    assert "--runs: must be at least 2 (two runs of each of the site's ruptures), got 1" in capsys.readouterr().err


def test_the_fragility_estimator_reads_the_risk_chain_s_g_star_of_each_measure_and_seed_s_store(monkeypatch, tmp_path) -> None:
    """``fragility_separation`` opens the store ``run`` kept for each measure and seed and keeps ``store_risk``'s g* (10 % and
    2 % in 50 years) under that measure and seed."""
    import contextlib

    import stochpound
    import stochpound.risk
    from benchmarks.site_consistency import experiment_file, scenario_site

    site = scenario_site(7.0, 20.0, "strike_slip", 0.1)
    opened = []

    @contextlib.contextmanager
    def open_store(path):
        opened.append(path)
        yield xr.Dataset(attrs={"path": str(path)})

    def store_risk(store, hazard, targets):
        value = 0.1 * len(opened)  # the n-th store opened gives g* = 0.1 n (10 %), 0.2 n (2 %), λ_P = n / g on its grid
        separation = xr.DataArray([[value, 2 * value]], dims=("neighbour", "target"), coords={"neighbour": ["stiff"], "target": list(targets)})
        gaps = [value, 1.0]  # each store its own grid
        maf = xr.DataArray([[len(opened) / g for g in gaps]], dims=("neighbour", "gap"), coords={"neighbour": ["stiff"], "gap": gaps})
        return type("Risk", (), {"separation": xr.Dataset({"separation": separation}).assign_coords(target_rate=("target", [0.0, 0.0])),
                                 "non_increasing_maf": lambda self: maf.assign_coords(years=50.0)})()

    for seed in (1, 3):
        for measure in ("PGA", "PSA(2 s)"):
            path = experiment_file(measure_seeds.work_folder(tmp_path, "isolated", seed), measure).with_suffix(".nc")
            path.parent.mkdir(parents=True, exist_ok=True)
            path.touch()
    monkeypatch.setattr(stochpound, "open_store", open_store)
    monkeypatch.setattr(stochpound.risk, "store_risk", store_risk)
    g, rate = measure_seeds.fragility_separation(tmp_path, "isolated", ["PGA", "PSA(2 s)"], [1, 3], site)
    assert opened == [experiment_file(measure_seeds.work_folder(tmp_path, "isolated", s), m).with_suffix(".nc")
                      for m in ("PGA", "PSA(2 s)") for s in (1, 3)]
    assert g.sel(measure="PSA(2 s)", seed=1, neighbour="stiff", target=0.1) == pytest.approx(0.3)
    assert g.sel(measure="PGA", seed=3, neighbour="stiff", target=0.02) == pytest.approx(0.4)
    assert "target_rate" not in g.coords and "years" not in rate.coords
    own = rate.sel(measure="PSA(2 s)", seed=3, neighbour="stiff").dropna("gap")  # the 4th store: its own two gaps, NaN at the others'
    assert own["gap"].values.tolist() == pytest.approx([0.4, 1.0]) and own.values.tolist() == pytest.approx([10.0, 4.0])
    assert rate.sizes["gap"] == 5


def test_the_fragility_estimator_names_a_store_run_has_not_made(tmp_path) -> None:
    from benchmarks.site_consistency import scenario_site

    with pytest.raises(FileNotFoundError, match=r"pga\.nc of isolated, seed 2: not in work/ \(run it first\)"):
        measure_seeds.fragility_separation(tmp_path, "isolated", ["PGA"], [2], scenario_site(7.0, 20.0, "strike_slip", 0.1))


def test_the_table_of_the_fragility_estimator_is_printed_not_written(capsys) -> None:
    with pytest.raises(SystemExit):
        measure_seeds.main(["table", "folder", "--estimator", "fragility", "--write"])
    assert "--write: the section is the lognormal demand's; print the fragility estimator's tables without it" in capsys.readouterr().err


@pytest.mark.parametrize("estimator", ["lognormal", "fragility"])
def test_the_tables_take_g_star_and_the_rate_from_the_estimator_asked_for(monkeypatch, estimator: str) -> None:
    """``table --estimator fragility`` reads g* and λ_P from the risk chain's fits, the selections still from the kept results."""
    kept = {"lognormal": ("lognormal g*", "lognormal rate"), "fragility": ("fragility g*", "fragility rate")}
    result = type("Result", (), {"attrs": {"seconds": 1.0}})()
    monkeypatch.setattr(measure_seeds, "load", lambda folder, configuration, measures, seeds: (*kept["lognormal"], {"PGA": [result]}))
    monkeypatch.setattr(measure_seeds, "fragility_separation", lambda folder, configuration, measures, seeds, site: kept["fragility"])
    monkeypatch.setattr(measure_seeds, "spread_rows", lambda configuration, separation, rate: [[separation, rate]])
    monkeypatch.setattr(measure_seeds, "selection_rows", lambda configuration, selections: [[configuration, len(selections)]])
    spreads, selected, seconds, _ = measure_seeds.tables(Path("folder"), ["isolated"], ["PGA"], [1], estimator)
    assert spreads == [list(kept[estimator])] and selected == [["isolated", 1]] and seconds == [1.0]


def test_fox_plaza_at_another_vs30_is_its_own_site_and_only_fox_plaza_takes_one(capsys) -> None:
    """``--vs30`` fits Fox Plaza's scenarios at another Vs30 (its ``[site]`` table's, under its own name, so that its stores do not
    mix with the 400 m/s study's); 400 m/s is the site itself; the site of one scenario refuses it, and ``--write`` refuses any other."""
    from benchmarks.site_consistency import FOX_PLAZA, fox_plaza_site

    assert fox_plaza_site() is FOX_PLAZA and fox_plaza_site(400.0) is FOX_PLAZA
    soft = fox_plaza_site(300.0)
    assert "vs30 = 300.0" in soft.table and "vs30 = 400.0" not in soft.table and soft.name != FOX_PLAZA.name
    assert soft.table.replace("vs30 = 300.0", "vs30 = 400.0") == FOX_PLAZA.table
    for argv, message in ((["table", "x", "--site", "scenario", "--vs30", "300"], "--vs30: Fox Plaza's assumed Vs30"),
                          (["table", "x", "--vs30", "300", "--write"], "--write: the section is Fox Plaza's study at Vs30 400 m/s")):
        with pytest.raises(SystemExit):
            measure_seeds.main(argv)
        assert message in capsys.readouterr().err


def test_fox_plaza_at_another_vs30_fits_a_measure_of_its_own_curve_to_it_too() -> None:
    """PSA(T1)'s experiment at 300 m/s fits its scenario to the four curves and its own, as at 400 m/s."""
    from benchmarks.site_consistency import FOX_PLAZA, MEASURES, experiment_text, fox_plaza_site

    measure = next(m for m in MEASURES if "T1" in m)
    assert f'"{MEASURES[measure]}"]' in experiment_text(measure, "isolated", site=fox_plaza_site(300.0))
    assert f'"{MEASURES[measure]}"]' in experiment_text(measure, "isolated", site=FOX_PLAZA)


@pytest.mark.parametrize(("vs30", "message"), [("50", "--vs30: must be within 180-1000 (the NGA-West2 models' range), got 50.0"),
                                              ("190", "--vs30: must be within 200-1100 (the site-motion model's range), got 190.0")])
def test_fox_plaza_s_vs30_outside_the_models_is_a_one_line_usage_error(capsys, vs30: str, message: str) -> None:
    for action in ("run", "measure_free"):
        with pytest.raises(SystemExit):
            measure_seeds.main([action, "folder", "--vs30", vs30])
        assert message in capsys.readouterr().err


def test_fox_plaza_s_sa_avg_is_fitted_to_its_derived_curve_read_from_a_file_beside_the_experiment(tmp_path) -> None:
    """Fox Plaza publishes no Sa_avg curve: the study's is the fitted ruptures' (its file says DERIVED), written beside the
    experiment and given to ``[site] curves`` as a file stating its measure; the experiment fits its scenario to it and the four
    curves, at the site's own Vs30 (300 m/s: the curve of that Vs30's ruptures, not 400's)."""
    import tomllib

    from benchmarks.site_consistency import FOX_PLAZA, SA_AVG, experiment_text, fox_plaza_site
    from stochpound.analysis import HazardCurve
    from stochpound.experiment._spec import parse_experiment

    soft = fox_plaza_site(300.0)
    assert SA_AVG in FOX_PLAZA.measures and SA_AVG in soft.derived
    assert not (soft.hazard(SA_AVG).rate == FOX_PLAZA.hazard(SA_AVG).rate).all()
    name = soft.derived_curve_file(SA_AVG)
    soft.hazard(SA_AVG).to_csv(tmp_path / name)
    text = experiment_text(SA_AVG, "isolated", 1, site=soft)
    assert f'file = "{name}", measure = "sa_avg"' in text
    definition = parse_experiment(tomllib.loads(text), tmp_path)
    assert name in definition["site"]["curves"] and "DERIVED" in (tmp_path / name).read_text()
    assert {scenario["vs30"] for scenario in definition["intensity"]["site"]} == {300.0}
    read = HazardCurve.from_file(tmp_path / name)
    np.testing.assert_array_equal(read.rate, soft.hazard(SA_AVG).rate)  # the file holds the curve's numbers exactly


def test_fox_plaza_s_stand_in_ruptures_are_a_site_of_ruptures_whose_table_reads_back_as_the_same_site(tmp_path, capsys) -> None:
    """``--site fox_plaza_ruptures``: the ruptures fitted to Fox Plaza's curves, written as a rupture table beside the experiment,
    read back as the very site (the targets' exact conditional spectra and the answer without a measure are of the same ruptures);
    its stripes' simulated motions come from their causal ruptures, so a tilted pool is refused before anything runs."""
    import tomllib

    from benchmarks.site_consistency import Pool, experiment_text, fox_plaza_ruptures_site
    from stochpound.analysis import RuptureSite
    from stochpound.experiment._spec import parse_experiment

    site = fox_plaza_ruptures_site(400.0)
    (name, text), = site.companion_files("PSA(2 s)").items()
    (tmp_path / name).write_text(text)
    assert RuptureSite.from_file(tmp_path / name) == site.ruptures and "vs30: 400.0" in text
    definition = parse_experiment(tomllib.loads(experiment_text("PSA(2 s)", "isolated", 1, site=site, pool=Pool(40, 200, 3))), tmp_path)
    assert definition["site"] == {"scenario": "ruptures", "ruptures": name}
    with pytest.raises(SystemExit):
        measure_seeds.main(["run", str(tmp_path), "--site", "fox_plaza_ruptures"])
    assert "--sampling: a site of ruptures draws" in capsys.readouterr().err


def test_too_few_motions_a_stripe_are_refused_before_the_folder_is_made(tmp_path, capsys) -> None:
    with pytest.raises(SystemExit):
        measure_seeds.main(["run", str(tmp_path / "study"), "--motions", "1"])
    assert "--motions: must be at least 2 motions a stripe, got 1" in capsys.readouterr().err
    assert not (tmp_path / "study").exists()
