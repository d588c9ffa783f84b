"""The done-when check of conditional-spectrum selection, reduced: the same buildings at the same site get about the same g*
whichever measure their stripes are conditioned on.

The experiments of benchmarks/site_consistency.py (the elastic fixed pair beside a stiff or a flexible neighbour, and
the elastic Building 1 on a friction pendulum, mu 0.05, no moat wall, stiff neighbour; stripes at return periods 10-5000 years, 20 motions per
stripe from the 100 FEMA P695 motions, factor <= 5, the scenario fitted to the site's four curves), conditioned on each of the site's four
measures, g* from a lognormal demand per stripe (stochpound.risk.stripe_demand_rate; the counts' fits add their sampling spread: docs/intensity.md).

The same check at a site of one scenario (benchmarks.site_consistency's ``--site scenario``: M 7.5 at 10 km, strike-slip, 0.01 per
year), whose four curves come from the conditional spectrum's own models: hazard-consistent by construction, so the measures must
agree there unless the pool or the stripes fail to carry the site's shaking (docs/intensity.md, finding 8).

The four experiments' tests carry the ``benchmark`` marker: the suite skips them unless pytest is given ``--benchmarks`` (they are
the benchmark's experiments, not checks of one code path, and took 75 s of the suite's 10 minutes on 2 cores; docs/contributing.md).
Run: ``pytest --benchmarks tests/test_benchmark_site_consistency.py -s`` (prints the g* tables; about 2 minutes on 2 cores). A configuration
whose spread is beyond the limit after some measures stops there (more measures can only widen it): its table has those measures only.
"""

from __future__ import annotations

import pytest
import xarray as xr

from benchmarks.site_consistency import FOX_PLAZA, SCENARIO, Site, g_star, scenario_site

#: The measures, the two furthest apart in period first: where g* depends on the measure, they part most (docs/intensity.md's
#: table: PGA and PSA(3 s) bound the isolated building's g*), so a spread beyond :data:`LIMIT` shows soonest (:func:`_spread`).
MEASURES = ("PGA", "PSA(3 s)", "PSA(1 s)", "PSA(2 s)")
LIMIT = 1.3  # the largest max/min of g* over the measures that passes


@pytest.mark.slow
@pytest.mark.benchmark
@pytest.mark.parametrize("configuration", [
    "fixed pair",
    pytest.param("isolated", marks=pytest.mark.xfail(strict=True, reason=(
        "not yet within x1.3: measured x1.46 / x1.57 (the scaled suite gave x1.9-2.1), the same with other seeds of the selection, and "
        "x1.61 / x2.30 over five measures and five seeds with 40 motions a stripe from the records and 2000 simulated motions tilted to "
        "each stripe (benchmarks.measure_seeds, where the fixed pair is within x1.26; x1.35 / x1.40 on the risk chain's own fits to the "
        "same stores, PSA(3 s) the highest at 2 %, measure_seeds table --estimator fragility): "
        "the stripes of PGA and PSA(1 s) carry the site's hazard at the isolated period poorly, and no population of earthquakes under the "
        "models and the assumed site gives the site's long- and short-period curves together (docs/intensity.md, findings 4 and 7), and "
        "even at a site consistent by construction the measures part for this building where its g* comes from the rare tail of a "
        "spectrum weak at long periods (finding 8), where the lognormal demand per stripe this check reads misses the right-skewed tail "
        "of the closure on a short-period measure (docs/intensity.md, 'The short-period measures part by their stripes' lognormal'); "
        "strict: it fails the day it passes, to be un-marked"))),
])  # fmt: skip
def test_g_star_hardly_depends_on_the_conditioning_measure(tmp_path, configuration: str) -> None:
    assert _spread(tmp_path, configuration) <= LIMIT


@pytest.mark.slow
@pytest.mark.benchmark
@pytest.mark.parametrize("configuration", ["fixed pair", "isolated"])
def test_at_a_site_of_one_scenario_g_star_hardly_depends_on_the_conditioning_measure(tmp_path, configuration: str) -> None:
    assert _spread(tmp_path, configuration, scenario_site(*SCENARIO)) <= LIMIT


def _spread(folder, configuration: str, site: Site = FOX_PLAZA) -> float:
    """The largest max/min over the measures of the lognormal-demand g* (both targets, every neighbour), the table printed.

    The measures run one after the other, and the next only while the spread is within :data:`LIMIT`: a spread over
    more measures is never smaller (a max/min over more values), so one already beyond it fails the check whatever the
    measures left would give, and they are not run (the benchmark prints every measure's g*).
    """
    runs = []
    for measure in MEASURES:
        runs.append(g_star(folder, measure, configuration, site))
        separations = xr.concat(runs, dim="measure")
        ratio = separations.max("measure") / separations.min("measure")
        if float(ratio.max()) > LIMIT:
            break
    done = list(MEASURES[: len(runs)])
    print(f"\n{configuration} at the site {site.name}: g* (m) by conditioning measure {', '.join(done)}, and max/min:")
    print(separations.assign_coords(measure=done).to_dataframe()["separation"].to_string())
    print("max/min", ratio.to_pandas().to_string(), "" if len(runs) == len(MEASURES) else f"(beyond {LIMIT} after {len(runs)} measures: the rest not run)")
    return float(ratio.max())


def test_the_selection_benchmarks_lognormal_recomputation_agrees_with_the_counts_where_they_resolve_the_rate() -> None:
    """benchmarks.site_selection's hazard from a lognormal ln Sa(T') per stripe: with 4000 lognormal motions per stripe it is the
    counts' (``hazard_consistency``) where they resolve the rate, and it still gives a rate beyond the largest motion."""
    import numpy as np

    from benchmarks.site_selection import _lognormal_recomputed
    from stochpound.analysis import HazardCurve, hazard_consistency

    hazard = HazardCurve.power_law(1.0e-3, 2.0)
    y = np.geomspace(0.02, 20.0, 40)
    other = HazardCurve(y, 5.0e-4 * y**-2.5)
    rng = np.random.default_rng(7)
    means, stds = np.log([0.1, 0.3]), np.array([0.5, 0.7])
    values = np.exp(means[:, None] + stds[:, None] * rng.standard_normal((2, 4000)))
    values[0, :100] = np.nan  # motions that did not run in a stripe
    scaled = xr.DataArray(values, dims=("intensity", "record"), coords={"intensity": [0.2, 0.5]})
    counted = hazard_consistency(scaled, hazard, other)["recomputed"].values
    lognormal = _lognormal_recomputed(scaled, hazard, other)
    resolved = counted > 0.05 * counted.max()
    assert resolved.sum() >= 5
    np.testing.assert_allclose(lognormal[resolved], counted[resolved], rtol=0.05)
    beyond = other.im > np.nanmax(values)
    assert beyond.any() and np.all(counted[beyond] == 0) and np.all(lognormal[beyond] > 0)


@pytest.mark.parametrize(("scenario", "message"), [
    (["7.5", "x", "strike_slip", "0.01"], "--scenario: M, R_KM and RATE must be numbers, got 7.5 x strike_slip 0.01"),
    (["7.5", "10", "sideways", "0.01"], "--scenario: mechanism: must be one of strike_slip, reverse, normal, got 'sideways'"),
    (["7.5", "10", "strike_slip", "0"], "--scenario: rate: must be a finite annual rate > 0 (1/yr), got 0.0"),
])  # fmt: skip
def test_a_bad_scenario_is_a_one_line_usage_error(capsys, scenario: list[str], message: str) -> None:
    from benchmarks.site_consistency import main

    with pytest.raises(SystemExit) as stopped:
        main(["--site", "scenario", "--scenario", *scenario])
    assert stopped.value.code == 2 and capsys.readouterr().err.strip().splitlines()[-1].endswith(f"error: {message}")


def test_the_extended_pool_and_the_building_s_own_period_are_in_the_experiment_file() -> None:
    """``--motions``, ``--simulated-motions`` and ``--max-per-earthquake`` reach the experiment file; PSA(T1)'s scenario is fitted to
    the four curves and its own, and its stripes stop where its curve does."""
    import tomllib

    from benchmarks.site_consistency import CURVES, T1_CURVE, T1_MEASURE, Pool, experiment_text
    from stochpound.analysis import HazardCurve

    table = tomllib.loads(experiment_text(T1_MEASURE, "fixed pair", 2, pool=Pool(40, 1000, 3)))
    intensity, site = table["intensity"], table["site"]
    assert (intensity["motions"], intensity["max_per_earthquake"], intensity["seed"], site["simulated_motions"]) == (40, 3, 2, 1000)
    assert site["curves"] == [*CURVES, T1_CURVE] and intensity["period"] == 0.3
    assert intensity["levels"][-1] == pytest.approx(float(HazardCurve.bundled(T1_CURVE).im.max()), rel=1e-4)
    records_only = tomllib.loads(experiment_text("PSA(1 s)", "fixed pair"))
    assert records_only["intensity"]["motions"] == 20 and "max_per_earthquake" not in records_only["intensity"]
    assert "simulated_motions" not in records_only["site"] and records_only["site"]["curves"] == CURVES
