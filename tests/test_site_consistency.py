"""The site's hazard at its other measures recomputed from a stripes store's motions as they ran (stochpound.risk.site_consistency)."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from stochpound import open_store
from stochpound.analysis import HazardCurve, bundled_site_curves, rate_from_probability, stripe_rate_weights
from stochpound.experiment._runner import load_experiment, run_experiment
from stochpound.motions import Measure
from stochpound.report.render import FigureItem, Paragraph
from stochpound.report.sections import intensity_section
from stochpound.risk import TARGETS, consistency_at_targets, site_consistency
from tests.helpers import stripes_site_text, write_experiment

SITE = "fox_plaza_los_angeles"
SITE_PERIODS = (0.03, 0.05, 0.1, 0.15, 0.2, 0.3, 0.4, 0.5, 0.6, 0.75, 1.0, 1.5, 2.0, 3.0, 4.0, 5.0)
"""The periods (s) of the bundled site's PSA curves (besides its PGA one)."""


def _store(tmp_path, hazard: str) -> xr.Dataset:
    report = run_experiment(load_experiment(write_experiment(tmp_path, stripes_site_text(hazard), "site.toml")), workers=0, progress=False)
    return open_store(report.store).load()


def test_bundled_site_curves_are_the_curves_of_one_site() -> None:
    curves = bundled_site_curves(f"{SITE}_sa2p0s")
    assert len(curves) == 17 and curves[0] == f"{SITE}_pga" and curves[-3:] == [f"{SITE}_sa3p0s", f"{SITE}_sa4p0s", f"{SITE}_sa5p0s"]
    assert curves[1:5] == [f"{SITE}_sa0p03s", f"{SITE}_sa0p05s", f"{SITE}_sa0p1s", f"{SITE}_sa0p15s"]  # by period, not by name
    with pytest.raises(ValueError, match="name: no bundled hazard curve"):
        bundled_site_curves("nowhere_pga")


def test_recomputed_from_the_motions_as_they_ran_and_shown_in_the_report(tmp_path) -> None:
    store = _store(tmp_path, f'[hazard]\nbundled = "{SITE}_sa1p0s"\n')
    result = site_consistency(store)
    assert list(result) == ["PGA", *(f"PSA({period:g} s)" for period in SITE_PERIODS if period != 1.0)]  # every other curve of the site
    # by hand: the motions that ran in each stripe, their stored PGA or PSA (log-log between the stored periods) times their scale factor
    levels = store["intensity"].values
    weights = stripe_rate_weights(levels, HazardCurve.bundled(f"{SITE}_sa1p0s"))
    log_t = np.log(store["spectrum_period"].values)
    for label, name, value in [("PGA", "pga", lambda m: float(m.motion_pga) / 9.81),
                               ("PSA(2 s)", "sa2p0s", lambda m: np.exp(np.interp(np.log(2.0), log_t, np.log(m.motion_psa.values))) / 9.81)]:
        other = HazardCurve.bundled(f"{SITE}_{name}")
        expected = np.zeros(other.im.size)
        for j in range(levels.size):
            cases = store.isel(intensity=j, realization=0).sel(gap=np.inf)
            ran = [r for r in cases.record.values if int(cases.case_status.sel(record=r)) == 1]
            assert len(ran) == 4
            spectra = np.array([value(cases.sel(record=r)) * float(cases.scale_factor.sel(record=r)) for r in ran])
            expected += weights[j] * (spectra[:, None] > np.asarray(other.im)[None, :]).mean(axis=0)
        np.testing.assert_allclose(result[label]["recomputed"].values, expected, rtol=1e-12)
        np.testing.assert_allclose(result[label]["site"].values, other.rate, rtol=1e-12)
    # the report's Intensity section: the figure, and the sentence with every measure's ratios at 10 % and 2 % in 50 years
    section = intensity_section("site", store)
    assert any(isinstance(block, FigureItem) and block.key == "intensity-consistency-site" for block in section.blocks)
    text = next(block.text for block in section.blocks if isinstance(block, Paragraph) and block.text.startswith("Hazard consistency"))
    for label, data in result.items():
        shown = "/".join("beyond the curve" if np.isnan(r) else f"{r:.2f}" for r in consistency_at_targets(data))
        assert f"{label} {shown}" in text


def test_given_curves_are_recomputed_as_the_sites_own_and_sa_avg_is_the_geometric_mean_of_the_stored_spectrum(tmp_path) -> None:
    store = _store(tmp_path, f'[hazard]\nbundled = "{SITE}_sa1p0s"\n')
    own = HazardCurve.bundled(f"{SITE}_sa1p0s")
    sa_avg = Measure("sa_avg", periods=(0.5, 1.0, 2.0))
    curves = {Measure("pga"): HazardCurve.bundled(f"{SITE}_pga"), Measure("psa", period=2.0, damping=0.05): HazardCurve.bundled(f"{SITE}_sa2p0s"),
              sa_avg: HazardCurve.bundled(f"{SITE}_sa1p0s")}
    given = site_consistency(store, curves, hazard=own)
    assert list(given) == ["PGA", "PSA(2 s)", "Sa_avg(0.5-2 s)"]
    default = site_consistency(store)
    for label in ("PGA", "PSA(2 s)"):  # the same numbers as the bundled site's own check
        xr.testing.assert_identical(given[label], default[label])
    # Sa_avg by hand: each motion that ran, the geometric mean of its stored PSA (log-log at 0.5, 1 and 2 s) times its scale factor
    levels, log_t = store["intensity"].values, np.log(store["spectrum_period"].values)
    weights = stripe_rate_weights(levels, own)
    expected = np.zeros(own.im.size)
    for j in range(levels.size):
        cases = store.isel(intensity=j, realization=0).sel(gap=np.inf)
        ran = [r for r in cases.record.values if int(cases.case_status.sel(record=r)) == 1]
        log_psa = [np.interp(np.log(sa_avg.periods), log_t, np.log(cases.motion_psa.sel(record=r).values)) for r in ran]
        spectra = np.array([np.exp(np.mean(row)) / 9.81 * float(cases.scale_factor.sel(record=r)) for row, r in zip(log_psa, ran)])
        expected += weights[j] * (spectra[:, None] > np.asarray(own.im)[None, :]).mean(axis=0)
    np.testing.assert_allclose(given["Sa_avg(0.5-2 s)"]["recomputed"].values, expected, rtol=1e-12)
    # what the stored motions do not give is refused, naming the field
    for measure, message in [(Measure("pgv"), "curves: PGV is not recomputed"), (Measure("psa", period=8.0), "curves: PSA.8 s. needs the spectrum at 8-8 s"),
                             (Measure("psa", period=1.0, damping=0.02), "curves: PSA.T = 1 s, 2 % damping. needs the spectrum at its damping")]:
        with pytest.raises(ValueError, match=message):
            site_consistency(store, {measure: own})


def test_a_store_without_a_hazard_of_its_own_is_checked_against_the_hazard_given(tmp_path) -> None:
    store = _store(tmp_path, "")
    curves = {Measure("psa", period=2.0): HazardCurve.bundled(f"{SITE}_sa2p0s")}
    assert site_consistency(store, curves) == {}  # no hazard of its stripes: nothing to weigh them with
    own = HazardCurve.bundled(f"{SITE}_sa1p0s")
    result = site_consistency(store, curves, hazard=own)["PSA(2 s)"]
    np.testing.assert_allclose(result["site"].values, curves[Measure("psa", period=2.0)].rate, rtol=1e-12)
    assert np.all(np.isfinite(result["recomputed"].values)) and result["recomputed"].values.max() > 0


def test_nothing_without_a_bundled_site(tmp_path) -> None:
    store = _store(tmp_path, "[hazard]\npower_law = {k0 = 1e-4, k = 2.5}\n")
    assert site_consistency(store) == {}
    assert not any(isinstance(block, FigureItem) and block.key == "intensity-consistency-site" for block in intensity_section("site", store).blocks)


def test_ratio_at_the_targets_interpolates_log_log_in_the_site_rate() -> None:
    y = np.geomspace(0.05, 3.0, 15)
    site = 1e-3 * y**-2.0
    ratio = 1.5 * y**0.5  # a power law of the site's rate too: ratio = 1.5 (site / 1e-3)^(-1/4), exact under log-log interpolation
    data = xr.Dataset({"site": ("im", site), "ratio": ("im", ratio), "recomputed": ("im", site * ratio)}, coords={"im": y})
    rates = rate_from_probability(np.asarray(TARGETS))
    np.testing.assert_allclose(consistency_at_targets(data), 1.5 * (rates / 1e-3) ** -0.25, rtol=1e-12)
    assert np.isnan(consistency_at_targets(data.isel(im=slice(0, 3)))).all()  # the site's curve stops before the targets' rates
