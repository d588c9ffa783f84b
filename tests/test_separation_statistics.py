"""Pounding curve, required separation and separation rules on constructed data: hand-computed values and scipy's intervals."""

import math

import numpy as np
import pytest
import xarray as xr
from scipy import stats

from stochpound.analysis import contact_demands, pounding_curve, required_separation, rule_exceedance, separation_rules
from stochpound.codes._separation_rules import abs_rule, cqc_coefficient, ddc_rule, fixed_base_cqc, fundamental_mode, srss_rule
from stochpound.model.building import fixed_base_frequencies
from stochpound.model.scene_file import scene_from_dict
from stochpound.studies.agarwal2004 import study_scene


def closures(*rows) -> xr.DataArray:
    """Peak closures (m), one row per realization, one column per contact."""
    return xr.DataArray(np.array(rows, float), dims=("realization", "contact"), attrs={"units": "m"})


# ---------------------------------------------------------------- pounding curve


def test_pounding_curve_counts_the_runs_whose_largest_closure_reaches_the_gap():
    peak = closures([0.03, 0.05], [0.06, 0.01], [0.02, 0.02], [0.04, np.nan])  # the last run is missing (NaN)
    curve = pounding_curve(peak, [0.0, 0.02, 0.04, 0.05, 0.07])
    # largest closures of the three complete runs: 0.05, 0.06, 0.02; a closure equal to the gap pounds
    np.testing.assert_array_equal(curve["probability"], [1.0, 1.0, 2 / 3, 2 / 3, 0.0])
    np.testing.assert_array_equal(curve["realizations"], 3)
    assert curve["gap"].attrs["units"] == "m"


def test_contacts_with_their_own_gaps_pound_when_one_closure_reaches_its_gap():
    peak = closures([0.03, 0.05], [0.06, 0.01], [0.02, 0.02])
    offsets = xr.DataArray([0.0, 0.02], dims="contact")  # contact 1's gap is 2 cm wider
    curve = pounding_curve(peak, [0.03, 0.04], gap_offsets=offsets)
    # max_c (D_c - offset_c) = 0.03, 0.06, 0.02
    np.testing.assert_array_equal(curve["probability"], [2 / 3, 1 / 3])
    per_contact = pounding_curve(peak, [0.03], contact_dim=None)
    np.testing.assert_array_equal(per_contact["probability"].squeeze("gap"), [2 / 3, 1 / 3])


@pytest.mark.parametrize("confidence", [0.9, 0.95, 0.99])
def test_pounding_curve_interval_is_scipys_exact_binomial_interval(confidence):
    rng = np.random.default_rng(11)
    peak = xr.DataArray(rng.lognormal(-3.0, 0.5, size=(57, 2)), dims=("realization", "contact"))
    gaps = np.concatenate([[0.0], np.quantile(peak.max("contact"), [0.1, 0.5, 0.9]), [1.0]])  # k = n, ..., 0
    curve = pounding_curve(peak, gaps, confidence=confidence)
    largest = peak.values.max(axis=1)
    for i, gap in enumerate(gaps):
        k = int(np.sum(largest >= gap))
        interval = stats.binomtest(k, 57).proportion_ci(confidence_level=confidence, method="exact")
        assert float(curve["probability"][i]) == k / 57
        assert float(curve["lower"][i]) == pytest.approx(interval.low, abs=1e-10)
        assert float(curve["upper"][i]) == pytest.approx(interval.high, abs=1e-10)
    assert curve["probability"][0] == 1.0 and curve["probability"][-1] == 0.0


def test_rule_exceedance_judges_each_rules_gap_per_run():
    peak = closures([0.03, 0.05], [0.06, 0.01], [0.02, 0.02], [0.01, 0.04])
    rule_gap = xr.DataArray(
        [
            [[0.04, 0.05], [0.07, 0.02], [0.03, 0.03], [0.02, 0.05]],  # reached in run 0 only (contact 1, a tie)
            [[0.01, 0.10], [0.10, 0.10], [0.10, 0.10], [0.10, 0.03]],  # reached in runs 0 (contact 0) and 3 (contact 1)
            [[np.nan, 0.1], [0.1, 0.1], [0.1, 0.1], [0.1, 0.1]],  # run 0 left out: not reached in 3 runs
            np.full((4, 2), np.nan),  # no gap: no run counted
        ],
        dims=("rule", "realization", "contact"), coords={"rule": ["a", "b", "c", "d"]},
    )
    result = rule_exceedance(peak, rule_gap)
    np.testing.assert_array_equal(result["probability"], [1 / 4, 2 / 4, 0 / 3, np.nan])
    np.testing.assert_array_equal(result["realizations"], [4, 4, 3, 0])
    assert result[["lower", "upper"]].sel(rule="d").isnull().all()
    interval = stats.binomtest(2, 4).proportion_ci(confidence_level=0.95, method="exact")
    assert float(result["lower"].sel(rule="b")) == pytest.approx(interval.low, abs=1e-10)
    assert float(result["upper"].sel(rule="b")) == pytest.approx(interval.high, abs=1e-10)
    assert "gap" not in result.dims


# ---------------------------------------------------------------- required separation


@pytest.mark.parametrize("n", [5, 6, 21, 22, 40, 71, 72, 367, 368, 1000])
@pytest.mark.parametrize("confidence", [0.9, 0.95])
def test_required_separation_is_the_quantile_with_scipys_order_statistic_interval(n, confidence):
    rng = np.random.default_rng(n)
    sample = rng.gamma(3.0, 0.01, size=n)
    targets = (0.5, 0.16, 0.05, 0.01)
    result = required_separation(xr.DataArray(sample, dims="realization"), targets, confidence=confidence)
    for p in targets:
        row = result.sel(probability=p)
        assert float(row["separation"]) == np.quantile(sample, 1.0 - p, method="inverted_cdf")
        interval = stats.quantile_test(sample, q=0.0, p=1.0 - p).confidence_interval(confidence)
        np.testing.assert_array_equal([float(row["lower"]), float(row["upper"])], [interval.low, interval.high], err_msg=f"p = {p}")
    assert int(result["realizations"]) == n


def test_required_separation_leaves_a_run_out_of_reach_by_less_than_the_target():
    sample = np.arange(1.0, 101.0) / 1000.0  # 1 mm ... 100 mm
    result = required_separation(xr.DataArray(sample, dims="realization"), [0.5, 0.05])
    np.testing.assert_array_equal(result["separation"], [0.05, 0.095])  # 50 resp. 5 of 100 runs reach more


@pytest.mark.parametrize("p, smallest", [(0.5, 6), (0.16, 22), (0.05, 72), (0.01, 368)])
def test_an_upper_bound_needs_the_documented_number_of_realizations(p, smallest):
    """(1 − p)^n ≤ 0.025 from n = ``smallest`` on (95 %); below it the bound is NaN."""
    assert (1 - p) ** smallest <= 0.025 < (1 - p) ** (smallest - 1)
    for n, missing in ((smallest - 1, True), (smallest, False)):
        sample = xr.DataArray(np.linspace(0.01, 0.1, n), dims="realization")
        upper = float(required_separation(sample, [p])["upper"][0])
        assert math.isnan(upper) == missing, n


def test_required_separation_ignores_missing_runs_and_takes_the_largest_contact():
    rng = np.random.default_rng(5)
    values = rng.gamma(3.0, 0.01, size=(30, 2))
    peak = xr.DataArray(np.vstack([values, [[np.nan, 0.2]]]), dims=("realization", "contact"))
    result = required_separation(peak, [0.5, 0.16])
    expected = required_separation(xr.DataArray(values.max(axis=1), dims="realization"), [0.5, 0.16])
    xr.testing.assert_identical(result.drop_attrs(), expected.drop_attrs())


def test_curves_are_lazy_on_dask_and_carry_other_dimensions():
    rng = np.random.default_rng(2)
    peak = xr.DataArray(rng.gamma(3.0, 0.01, size=(3, 80, 2)), dims=("case", "realization", "contact"), coords={"case": ["a", "b", "c"]})
    peak[1, 5, 0] = np.nan
    lazy_peak = peak.chunk({"case": 1, "realization": 20})
    for function, argument in ((pounding_curve, [0.02, 0.05]), (required_separation, [0.5, 0.05])):
        lazy, eager = function(lazy_peak, argument), function(peak, argument)
        assert all(lazy[name].chunks is not None for name in lazy.data_vars)
        xr.testing.assert_identical(lazy.compute(), eager)
        single = function(peak.sel(case="b", drop=True), argument)
        xr.testing.assert_identical(eager.sel(case="b", drop=True), single)


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda peak: pounding_curve(peak, [0.01], confidence=1.0), r"^confidence: must be in \(0, 1\)"),
        (lambda peak: pounding_curve(peak, [[0.01]]), r"^gaps: must be a 1-D sequence"),
        (lambda peak: pounding_curve(peak, [np.nan]), r"^gaps: must be a 1-D sequence"),
        (lambda peak: pounding_curve(peak, [0.01], dim="run"), r"^dim: 'run' is not a dimension of peak_closure"),
        (lambda peak: required_separation(peak, [0.0, 0.5]), r"^probabilities: must be a 1-D sequence of probabilities in \(0, 1\)"),
        (lambda peak: required_separation(peak.isel(realization=slice(0, 0))), r"^peak_closure: no realizations along 'realization'"),
        (lambda peak: separation_rules(contact_demands_of_harmonics(), reduction=0.0), r"^reduction: must be in \(0, 1\]"),
    ],
)
def test_bad_arguments_are_named(call, message):
    with pytest.raises(ValueError, match=message):
        call(closures([0.03, 0.05], [0.06, 0.01]))


# ---------------------------------------------------------------- rules


def test_rules_against_hand_computed_values():
    u1, u2 = xr.DataArray(0.03), xr.DataArray(0.04)
    assert float(abs_rule(u1, u2)) == pytest.approx(0.07, rel=1e-15)
    assert float(srss_rule(u1, u2)) == pytest.approx(0.05, rel=1e-15)
    assert float(ddc_rule(u1, u2, 0.5)) == pytest.approx(math.sqrt(0.0013), rel=1e-14)  # 0.0009 + 0.0016 - 0.0012
    assert float(ddc_rule(u1, u2, -1.0)) == pytest.approx(0.07, rel=1e-14)  # opposite motion: ABS
    assert float(ddc_rule(u1, u2, 0.0)) == pytest.approx(0.05, rel=1e-14)  # uncorrelated: SRSS
    assert float(ddc_rule(xr.DataArray(0.1 + 0.2), xr.DataArray(0.3), 1.0)) == pytest.approx(0.0, abs=1e-16)  # no negative rounding, no NaN


HARMONICS = {  # contact: left (building, floor, amplitude m, phase rad), right (...)
    0: (("B1", 1, 0.03, 0.0), ("B2", 1, 0.04, math.pi / 3)),
    1: (("B1", 2, 0.05, math.pi / 6), ("B2", 2, 0.02, math.pi / 6 + math.pi / 2)),
    2: (("B1", 2, 0.05, math.pi / 6), ("B2", 1, 0.04, math.pi / 3)),
}


def contact_demands_of_harmonics() -> xr.Dataset:
    """contact_demands of a constructed run: floors moving as y = a sin(ωt + phase), 1200 samples a period, 2 periods (the located peaks |y| are the amplitudes)."""
    omega, time = 2.0 * math.pi, np.arange(2400) / 1200.0
    floors = {(left[:2]): left[2:] for left, _ in HARMONICS.values()} | {right[:2]: right[2:] for _, right in HARMONICS.values()}
    total = np.full((2, 2, time.size), np.nan)
    for (building, floor), (amplitude, phase) in floors.items():
        total[["B1", "B2"].index(building), floor - 1] = amplitude * np.sin(omega * time + phase)
    contacts = list(HARMONICS.values())
    run = xr.Dataset(
        {
            "total_displacement": (("building", "floor", "time"), total, {"units": "m"}),
            "contact_left": ("contact", [left[0] for left, _ in contacts]),
            "contact_left_floor": ("contact", [left[1] for left, _ in contacts]),
            "contact_right": ("contact", [right[0] for _, right in contacts]),
            "contact_right_floor": ("contact", [right[1] for _, right in contacts]),
            "peak_contact_closure": ("contact", [0.036, 0.054, 0.05], {"units": "m"}),
            # the located peaks of |y| of a harmonic floor motion: its amplitude
            "peak_contact_displacement_left": ("contact", [left[2] for left, _ in contacts], {"units": "m"}),
            "peak_contact_displacement_right": ("contact", [right[2] for _, right in contacts], {"units": "m"}),
        },
        coords={"building": ["B1", "B2"], "floor": [1, 2], "time": time, "contact": [0, 1, 2]},
    )
    return contact_demands(run)


def test_contact_demands_and_rules_of_harmonic_floor_motions():
    """u1, u2 are the amplitudes, ρ the cosine of the phase difference, and DDC the exact peak of y_left − y_right."""
    demands = contact_demands_of_harmonics()
    for c, ((_, _, a1, phase1), (_, _, a2, phase2)) in HARMONICS.items():
        row = demands.sel(contact=c)
        assert float(row["peak_displacement_left"]) == pytest.approx(a1, rel=1e-12)
        assert float(row["peak_displacement_right"]) == pytest.approx(a2, rel=1e-12)
        assert float(row["correlation"]) == pytest.approx(math.cos(phase2 - phase1), abs=1e-12)
    np.testing.assert_array_equal(demands["peak_closure"], [0.036, 0.054, 0.05])
    rules = separation_rules(demands, cqc=xr.DataArray([0.0, np.nan, 1.0], dims="contact"))
    assert list(rules["rule"].values) == ["abs", "srss", "srss_reduced", "ddc", "ddc_cqc"] and rules.attrs["units"] == "m"
    # contact 0: 3 and 4 cm at 60 degrees; contact 1: 5 and 2 cm at 90 degrees
    np.testing.assert_allclose(rules.sel(contact=0), [0.07, 0.05, 0.035, math.sqrt(0.0013), 0.05], rtol=1e-12)
    np.testing.assert_allclose(rules.sel(contact=1).values[:4], [0.07, math.sqrt(0.0029), 0.7 * math.sqrt(0.0029), math.sqrt(0.0029)], rtol=1e-12)
    assert math.isnan(rules.sel(contact=1, rule="ddc_cqc")) and float(rules.sel(contact=2, rule="ddc_cqc")) == pytest.approx(0.01, rel=1e-12)
    # the DDC of two histories of one frequency is the largest |y_left - y_right| they reach
    theta = np.linspace(0.0, 2.0 * math.pi, 200001)
    for c, ((_, _, a1, phase1), (_, _, a2, phase2)) in HARMONICS.items():
        exact = np.max(np.abs(a1 * np.sin(theta + phase1) - a2 * np.sin(theta + phase2)))
        assert float(rules.sel(contact=c, rule="ddc")) == pytest.approx(exact, rel=1e-9)


def test_cqc_coefficient_against_hand_computed_values():
    # equal damping 5 %: 8 ζ² (1 + r) r^1.5 / [(1 − r²)² + 4 ζ² r (1 + r)²]
    # r = 0.5: 8·0.0025·1.5·0.5^1.5 / (0.75² + 4·0.0025·0.5·1.5²) = 0.03·0.353553390593 / 0.57375
    assert cqc_coefficient(10.0, 0.05, 5.0, 0.05) == pytest.approx(0.03 * 0.353553390593 / 0.57375, rel=1e-11)
    # r = 0.9: 8·0.0025·1.9·0.9^1.5 / (0.19² + 4·0.0025·0.9·1.9²) = 0.038·0.853814968245 / 0.06859
    assert cqc_coefficient(10.0, 0.05, 9.0, 0.05) == pytest.approx(0.038 * 0.853814968245 / 0.06859, rel=1e-11)
    # equal frequencies 10 rad/s, ζ = 2 % and 5 %: 8·sqrt(0.001·100)·(0.2 + 0.5)·100 / (4·0.001·100·200 + 4·0.0029·10⁴)
    assert cqc_coefficient(10.0, 0.02, 10.0, 0.05) == pytest.approx(8 * math.sqrt(0.1) * 70.0 / 196.0, rel=1e-14)
    assert cqc_coefficient(7.0, 0.03, 7.0, 0.03) == pytest.approx(1.0, rel=1e-15)
    assert cqc_coefficient(3.0, 0.02, 11.0, 0.07) == cqc_coefficient(11.0, 0.07, 3.0, 0.02)


def test_fixed_base_cqc_of_the_study_pair_from_the_two_storey_closed_form():
    scene = scene_from_dict(study_scene(mu1=None, mu2=None, factor=2.0, gap=math.inf))
    modes = []
    for building in scene.buildings:
        (m1, m2), (k1, k2) = building.mass, building.stiffness
        # mode 1 of a two-storey shear building: the smaller root of m1 m2 λ² − (m1 k2 + m2 (k1 + k2)) λ + k1 k2 = 0
        b = m1 * k2 + m2 * (k1 + k2)
        omega = math.sqrt((b - math.sqrt(b * b - 4.0 * m1 * m2 * k1 * k2)) / (2.0 * m1 * m2))
        assert omega == pytest.approx(fixed_base_frequencies(np.array(building.mass), np.array(building.stiffness))[0], rel=1e-12)
        zeta = building.damping_ratio if building.damping_ratio is not None else building.damping[0] / building.stiffness[0] * omega / 2.0
        modes.append((omega, zeta))
        assert fundamental_mode(building) == pytest.approx((omega, zeta), rel=1e-6)  # B1's dashpots are a1 K to 6 digits
    (omega_i, zeta_i), (omega_j, zeta_j) = modes
    r = omega_j / omega_i  # the textbook form of the coefficient
    expected = 8 * math.sqrt(zeta_i * zeta_j) * (zeta_i + r * zeta_j) * r**1.5 / (
        (1 - r * r) ** 2 + 4 * zeta_i * zeta_j * r * (1 + r * r) + 4 * (zeta_i**2 + zeta_j**2) * r * r
    )
    np.testing.assert_allclose(fixed_base_cqc(scene), [expected, expected], rtol=1e-6)
    isolated = scene_from_dict(study_scene(mu1=0.2, factor=2.0, gap=math.inf))
    assert np.isnan(fixed_base_cqc(isolated)).all()
