"""Where the risk chain's data stop, it says so instead of answering (issue 49).

* a target rarer than the stripes reach: g* is a lower bound (``≥``), not
  the largest closure seen, checked against the exact g* of a closure that
  is lognormal in the intensity (``D = a x ε``) under a power-law hazard;
* probabilities of exceedance above 1 in a hazard file are refused as per cent;
* the bootstrap's memory estimate bounds the measured peak of the chain, and
  a bootstrap beyond the limit is refused in one line;
* an unfinished store is refused unless asked, saying how many cases ran;
* the hazard errors name only options ``stochpound risk`` has;
* ``read_hazard_file`` is given by ``stochpound.risk``.
"""

from __future__ import annotations

import re
import tracemalloc

import numpy as np
import pytest
import xarray as xr

import stochpound.hazard
import stochpound.risk
from stochpound._memory import LIMIT_VARIABLE, MemoryLimitError
from stochpound.cli._risk import risk as risk_command
from stochpound.hazard import StatedMeasure, hazard_option, read_hazard_file
from stochpound.risk import HazardCurve, StoreRisk, limit_state_events, risk_curve, risk_targeted_separation, stripe_fragility
from stochpound.risk._chain import bootstrap_bytes, bound_beyond_stripes, check_bootstrap
from stochpound.risk._stripe_coverage import top_capped_maf
from stochpound.motions import Measure
from stochpound.store import Intensity, UnfinishedStoreError, check_finished

A, SIGMA = 0.1, 0.4  # closure D = A x ε (m, x in g), ln ε ~ N(0, SIGMA²): F(x; g) = Φ(ln(A x / g) / SIGMA), θ(g) = g / A
K0, K = 1e-4, 2.5  # hazard λ(x) = K0 x^-K (1/yr)
TARGETS = (0.1, 0.02, 0.001, 0.0001)


def _exact(rate: np.ndarray) -> np.ndarray:
    """g* (m) of λ_P(g) = K0 (g/A)^-K exp(K² SIGMA² / 2) = rate (the closed form of MODEL §10)."""
    return A * (K0 * np.exp(K**2 * SIGMA**2 / 2) / rate) ** (1 / K)


def _chain(levels: tuple[float, ...], motions: int = 40, bootstrap: int = 200, seed: int = 1):
    rng = np.random.default_rng(seed)
    levels = np.asarray(levels)
    closure = xr.DataArray(A * levels[:, None] * np.exp(SIGMA * rng.standard_normal(motions))[None, :], dims=("intensity", "record"),
                           coords={"intensity": levels})
    hz = HazardCurve.power_law(K0, K)
    gaps = np.geomspace(0.5 * float(closure.min()), 1.5 * float(closure.max()), 60)
    fragility = stripe_fragility(limit_state_events(closure, gaps), bootstrap=bootstrap)
    separation = risk_targeted_separation(risk_curve(fragility, hz), TARGETS)
    return closure, hz, fragility, separation


def test_a_rare_target_is_a_lower_bound_not_the_largest_closure_seen():
    closure, hz, fragility, plain = _chain((0.2, 0.4, 0.8))
    exact = _exact(plain["target_rate"].values)
    largest = float(closure.max())
    # the cliff: without the bound, the rare targets stop at the largest closure seen, far below the exact g*
    assert np.all(plain["separation"].values[2:] <= 1.5 * largest) and np.all(plain["separation"].values[2:] < 0.85 * exact[2:])
    bounded = bound_beyond_stripes(plain, fragility, hz)
    flagged = bounded["lower_bound"].values
    assert flagged.tolist() == [False, False, True, True]
    # the frequent targets, inside the runs, are unchanged and near the exact answer (40 motions)
    assert np.array_equal(bounded["separation"].values[:2], plain["separation"].values[:2])
    assert np.allclose(bounded["separation"].values[:2], exact[:2], rtol=0.15)
    # the rare ones: a lower bound of the exact g*, no wider than the widest gap the top stripe's runs close, no interval
    reach = float(bounded["reach"])
    top_closures = float(closure.sel(intensity=0.8).max())
    assert reach <= top_closures and reach > 0.5 * top_closures
    assert np.all(bounded["separation"].values[2:] <= np.minimum(exact[2:], reach))
    assert np.isnan(bounded["lower"].values[2:]).all() and np.isnan(bounded["upper"].values[2:]).all()


def test_a_target_rarer_than_the_top_stripe_is_a_lower_bound_even_inside_the_runs():
    """Stripes up to 0.4 g, whose hazard rate (1.0e-3 /yr) exceeds 2 % in 50 yr's (4.04e-4): the fitted tail beyond 0.4 g
    would carry the answer; the bound holds the fragility at its top-stripe value and stays below the exact g*."""
    _, hz, fragility, plain = _chain((0.1, 0.2, 0.4), motions=60)
    bounded = bound_beyond_stripes(plain, fragility, hz)
    assert float(hz(0.4)) > float(plain["target_rate"].sel(target=0.02))
    assert bool(bounded["lower_bound"].sel(target=0.02)) and not bool(bounded["lower_bound"].sel(target=0.1))
    exact = _exact(bounded["target_rate"].values)
    assert np.all(bounded["separation"].values[1:] <= exact[1:])
    assert np.all(bounded["separation"].values <= plain["separation"].values)


def test_the_capped_rate_is_the_rate_with_the_fragility_held_at_the_top_stripe():
    """λ⁻ against a direct quadrature of ∫ min(F(x), F(x_n)) |dλ| over the power law, written here."""
    _, hz, fragility, _ = _chain((0.2, 0.4, 0.8), bootstrap=0)
    capped = top_capped_maf(fragility, hz)
    full = stochpound.risk.mean_annual_frequency(fragility, hz)
    fits = np.flatnonzero(fragility["status"].values == 0)
    assert fits.size > 10 and np.all(capped.values <= full.values * (1 + 1e-3))
    from scipy import integrate, special
    for index in fits[:: max(1, fits.size // 5)]:
        theta, beta = float(fragility["theta"][index]), float(fragility["beta"][index])
        top = special.ndtr(np.log(0.8 / theta) / beta)

        def integrand(u: float) -> float:  # u = ln x; |dλ| = K K0 x^-K du
            return min(special.ndtr((u - np.log(theta)) / beta), top) * K * K0 * np.exp(-K * u)

        expected = integrate.quad(integrand, np.log(theta) - 10 * beta, np.log(0.8), limit=200)[0] + top * K0 * 0.8**-K
        assert float(capped[index]) == pytest.approx(expected, rel=2e-3)


def test_the_tables_give_a_bound_as_such_and_withhold_the_design_gap():
    _, hz, fragility, plain = _chain((0.2, 0.4, 0.8))
    curve = risk_curve(fragility, hz)
    risk = StoreRisk(fragility, curve, bound_beyond_stripes(plain, fragility, hz), None, "", hz, 40, "stripes",
                     setting=Intensity(Measure("pga"), "g", (0.2, 0.4, 0.8), "stripes", "stripes", ""), stripes=3)
    frame = risk.to_frame()
    assert frame["lower_bound"].tolist() == [False, False, True, True]
    table = risk.separation_frame()
    bound = float(risk.separation["separation"].sel(target=0.001))
    assert table.loc["0.1 % in 50 yr", "g* (m)"] == f"≥ {bound:.3f}" and isinstance(table.loc["10 % in 50 yr", "g* (m)"], float)
    design = risk.design_frame().set_index("target")
    assert np.isnan(design.loc[0.001, "design"]) and design.loc[0.001, "basis"] == f"withheld: g* ≥ {bound:.3f} m, beyond the stripes' runs"
    assert design.loc[0.1, "design"] == pytest.approx(float(risk.separation["upper"].sel(target=0.1)))
    text = risk.beyond_stripes_text()
    level = float(hz.intensity_at(float(risk.separation["target_rate"].sel(target=0.001)) / 10))
    assert "g* for 0.1 % in 50 yr lies beyond the stripes' runs in every configuration" in text
    assert f"add stripes above 0.8 g, up to about {level:.3g} g" in text and "10 % in 50 yr" not in text


@pytest.mark.parametrize("extrapolate", [False, True])
def test_probabilities_above_one_are_refused_as_per_cent(tmp_path, extrapolate):
    path = tmp_path / "percent.csv"
    path.write_text("# Measure: PGA in g\n# Investigation time: 50\nim,poe\n0.1,63\n0.3,10\n0.6,2\n1.0,0.5\n")
    with pytest.raises(ValueError, match=r"^percent\.csv: poe: 3 value\(s\) above 1 \(largest 63\): these look like per cent"):
        read_hazard_file(path)
    with pytest.raises(ValueError, match=r"^--hazard\.file: percent\.csv: poe: 3 value\(s\) above 1 .* look like per cent"):
        hazard_option(str(path), Measure("pga"), "g", 9.81, extrapolate=extrapolate)
    path.write_text("# Measure: PGA in g\n# Investigation time: 50\nim,poe\n0.1,0.63\n0.3,0.1\n0.6,0.02\n1.0,0.005\n")
    assert read_hazard_file(path).values.max() == 0.63


def test_the_hazard_errors_name_only_options_of_stochpound_risk(tmp_path):
    options = {name for parameter in risk_command.params for name in parameter.opts if name.startswith("--")}
    bare = tmp_path / "bare.csv"
    bare.write_text("im,poe\n0.1,0.5\n0.5,0.1\n1.0,0.02\n")
    psa = Measure("psa", 1.0, damping=0.05)
    cases = [({"measure": "psa", "units": "g"}, "--hazard-measure: not stated: bare.csv does not give its curve's period"),
             ({"measure": "psa", "period": 1.0, "units": "g"}, "--hazard-measure: not stated: bare.csv does not give its curve's damping"),
             ({"measure": "psa", "period": 2.0, "damping": 0.05, "units": "g"}, "--hazard-measure: the hazard's measure must be"),
             ({"measure": "psa", "period": 1.0, "damping": 0.05, "units": "g"}, "--investigation-time: the values are probabilities")]
    for stated, start in cases:
        with pytest.raises(ValueError) as error:
            hazard_option(str(bare), psa, "g", 9.81, stated=StatedMeasure.from_entry(stated))
        message = str(error.value)
        assert message.startswith(start), message
        assert set(re.findall(r"--[a-z-]+", message)) <= options, message
    header = tmp_path / "stated.csv"
    header.write_text("# Measure: PSA(1.0 s, 5 %) in g\nim,rate\n0.1,0.02\n0.5,0.002\n1.0,0.0004\n")
    with pytest.raises(ValueError, match=r"^--hazard-measure: period 2\.0, but stated\.csv states period = 1\.0"):
        hazard_option(str(header), Measure("psa", 2.0, damping=0.05), "g", 9.81, stated=StatedMeasure(period=2.0))


def test_read_hazard_file_is_given_by_the_risk_package():
    assert "read_hazard_file" in stochpound.risk.__all__ and stochpound.risk.read_hazard_file is stochpound.hazard.read_hazard_file


def test_the_bootstrap_estimate_bounds_the_chains_peak_within_a_factor_of_three():
    """Peak of numpy's allocations (tracemalloc) while the stripes are refitted to the resamples, integrated and g* solved."""
    _chain((0.2, 0.4), motions=10, bootstrap=10)  # warm the imports and caches
    for levels, motions, resamples in (((0.2, 0.4, 0.8), 40, 300), ((0.1, 0.2, 0.4, 0.8, 1.6), 20, 700)):
        tracemalloc.start()
        try:
            _chain(levels, motions, resamples)
            peak = tracemalloc.get_traced_memory()[1]
        finally:
            tracemalloc.stop()
        estimate = bootstrap_bytes(resamples, 60, len(levels), motions)
        assert 1.0 <= estimate / peak <= 3.0, (estimate, peak)


def test_a_bootstrap_beyond_the_limit_is_refused_before_it_runs(monkeypatch):
    monkeypatch.setenv(LIMIT_VARIABLE, "1GiB")
    check_bootstrap(1000, 60, 3, 44)
    with pytest.raises(MemoryLimitError, match=r"^bootstrap \(--bootstrap\): 100000000 resamples of 44 motions, each refitting 60 fits "
                                               r"\(gaps × configurations\) over 3 stripes; the risk chain needs about [0-9.]+ TiB, more than "
                                               rf"the memory limit of 1 GiB \({LIMIT_VARIABLE}=1GiB\)"):
        check_bootstrap(100_000_000, 60, 3, 44)


def test_an_unfinished_store_is_refused_unless_asked():
    store = xr.Dataset(attrs={"cases_done": 288, "cases_total": 704})
    with pytest.raises(UnfinishedStoreError, match=r"^far: 288/704 cases done: .* or pass --partial to answer from the 288 cases that ran$"):
        check_finished(store, "far", partial=False)
    check_finished(store, "far", partial=True)
    check_finished(xr.Dataset(attrs={"cases_done": 704, "cases_total": 704}), "far", partial=False)
    flags = xr.Dataset({"case_status": ("case", np.array([1, 1, 0, -1], dtype=np.int8))})  # a store without the attributes: its flags
    with pytest.raises(UnfinishedStoreError, match=r"^flags: 2/3 cases done"):
        check_finished(flags, "flags", partial=False)
