"""Statistics of the analysis layer against scipy.stats, in memory and on chunked (dask) data."""

import numpy as np
import pytest
import xarray as xr
from scipy import stats

from stochpound.analysis import correlation, impact_statistics, moments, normal_histogram, pounding_probability, peak_response


@pytest.fixture
def sample():
    rng = np.random.default_rng(7)
    values = rng.gamma(2.0, 1.5, size=(3, 4000))  # skewed, heavy-ish tail
    return xr.DataArray(values, dims=("case", "time"), attrs={"units": "m"})


def test_moments_match_scipy(sample):
    result = moments(sample, "time")
    values = sample.values
    np.testing.assert_allclose(result["mean"], values.mean(axis=1), rtol=1e-12)
    np.testing.assert_allclose(result["variance"], values.var(axis=1), rtol=1e-12)
    np.testing.assert_allclose(result["std"], values.std(axis=1), rtol=1e-12)
    np.testing.assert_allclose(result["skewness"], stats.skew(values, axis=1), rtol=1e-10)
    np.testing.assert_allclose(result["excess"], stats.kurtosis(values, axis=1, fisher=True), rtol=1e-10)
    assert result["std"].attrs["units"] == "m" and result["excess"].attrs["units"] == "1"


def test_moments_on_dask_chunks_equal_in_memory(sample):
    lazy = moments(sample.chunk({"time": 333}), "time")
    assert lazy["skewness"].chunks is not None  # still lazy
    eager = moments(sample, "time")
    for name in eager:
        np.testing.assert_allclose(lazy[name].compute(), eager[name], rtol=1e-12)


def test_moments_over_an_ensemble_dimension(sample):
    across = moments(sample.rename(case="realization"), "realization")
    np.testing.assert_allclose(across["excess"], stats.kurtosis(sample.values, axis=0), rtol=1e-9)


def test_correlation_matches_numpy_and_is_lazy(sample):
    reference = sample.isel(case=0, drop=True)
    response = 0.3 * reference + sample.isel(case=1, drop=True)
    expected = np.corrcoef(response.values, reference.values)[0, 1]
    assert float(correlation(response, reference)) == pytest.approx(expected, rel=1e-12)
    lazy = correlation(response.chunk({"time": 500}), reference.chunk({"time": 500}))
    assert float(lazy.compute()) == pytest.approx(expected, rel=1e-12)


def test_histogram_is_a_density_with_the_fitted_normal(sample):
    histogram = normal_histogram(sample.isel(case=0), bins=30)
    widths = np.diff(histogram["edges"].values)
    assert float((histogram["density"] * widths).sum()) == pytest.approx(1.0)
    assert histogram.attrs["std"] == pytest.approx(sample.isel(case=0).values.std())
    centre = histogram["bin"].values[12]
    expected = stats.norm.pdf(centre, histogram.attrs["mean"], histogram.attrs["std"])
    assert float(histogram["normal_density"][12]) == pytest.approx(expected)


def constructed_impacts() -> xr.Dataset:
    """Three impacts: onset velocities of the two floors decide in/out of phase; durations and forces known."""
    left_velocity = np.array([0.30, 0.20, -0.05])
    right_velocity = np.array([0.10, -0.15, -0.25])  # same way, towards each other, same way (both left)
    start = np.array([1.0, 2.0, 3.0])
    end = np.array([1.05, 2.02, 3.08])
    from stochpound.analysis._impacts import in_phase

    return xr.Dataset(
        {
            "impact_in_phase": ("impact", in_phase(left_velocity, right_velocity)),
            "impact_peak_force": ("impact", [1e5, 3e5, 2e5]),
            "impact_duration": ("impact", end - start),
            "impact_impulse": ("impact", [100.0, 200.0, 50.0]),
        }
    )


def test_in_phase_and_out_of_phase_counts_and_durations():
    table = constructed_impacts()
    np.testing.assert_array_equal(table["impact_in_phase"], [True, False, True])
    result = impact_statistics(table)
    assert int(result["impacts"]) == 3
    assert int(result["impacts_in_phase"]) == 2
    assert int(result["impacts_out_of_phase"]) == 1
    assert float(result["peak_impact_force"]) == 3e5
    assert float(result["longest_impact"]) == pytest.approx(0.08)
    assert float(result["total_impulse"]) == pytest.approx(350.0)


def test_no_impacts_gives_zeros():
    empty = constructed_impacts().isel(impact=slice(0, 0))
    result = impact_statistics(empty)
    assert int(result["impacts"]) == 0 and float(result["peak_impact_force"]) == 0.0 and float(result["longest_impact"]) == 0.0


def padded_impacts() -> tuple[xr.Dataset, list[xr.Dataset]]:
    """Three realizations' tables (3, 0 and 2 impacts) and their (realization, impact) table padded with NaN."""
    table = constructed_impacts()
    tables = [table, table.isel(impact=slice(0, 0)), table.isel(impact=[2, 0])]
    tables = [t.assign_coords(impact=np.arange(t.sizes["impact"])) for t in tables]
    padded = xr.concat(tables, dim="realization", join="outer")
    return padded, tables


def test_padded_table_gives_each_realizations_statistics():
    padded, tables = padded_impacts()
    assert padded["impact_in_phase"].dtype != bool and padded["impact_in_phase"].isnull().any()  # NaN padding
    result = impact_statistics(padded)
    explicit = impact_statistics(padded, valid=padded["impact_duration"].notnull())
    for r, table in enumerate(tables):
        single = impact_statistics(table)
        for name in single.data_vars:
            assert result[name].values[r] == single[name].values, name
            assert explicit[name].values[r] == single[name].values, name
    np.testing.assert_array_equal(result["impacts"], [3, 0, 2])
    np.testing.assert_array_equal(result["impacts_in_phase"], [2, 0, 2])


def test_padded_table_statistics_are_lazy_on_dask_chunks():
    padded, _ = padded_impacts()
    lazy = impact_statistics(padded.chunk({"realization": 1}))
    eager = impact_statistics(padded)
    for name in eager.data_vars:
        assert lazy[name].chunks is not None, name  # still lazy
        np.testing.assert_array_equal(lazy[name].compute(), eager[name], err_msg=name)


def test_pounding_probability_matches_the_exact_binomial_interval():
    rng = np.random.default_rng(3)
    counts = xr.DataArray(rng.poisson([[0.2], [1.5], [0.0]], size=(3, 200)), dims=("gap", "realization"), coords={"gap": [0.08, 0.02, 0.5]})
    result = pounding_probability(counts)
    for i in range(3):
        k = int((counts[i] > 0).sum())
        interval = stats.binomtest(k, 200).proportion_ci(confidence_level=0.95, method="exact")
        assert float(result["probability"][i]) == pytest.approx(k / 200)
        assert float(result["lower"][i]) == pytest.approx(interval.low, abs=1e-12)
        assert float(result["upper"][i]) == pytest.approx(interval.high, abs=1e-12)


def test_peak_response_and_residual_sliding():
    time = np.linspace(0.0, 1.0, 5)
    total = np.array([[[0.0, 0.01, -0.03, 0.02, 0.01], [0.0, 0.02, -0.01, 0.04, 0.02]]])
    sliding = np.array([[0.0, 0.005, -0.01, 0.002, 0.002]])
    run = xr.Dataset(
        {
            "total_displacement": (("building", "floor", "time"), total),
            "relative_displacement": (("building", "floor", "time"), total - sliding[:, None, :]),
            "sliding_displacement": (("building", "time"), sliding),
        },
        coords={"building": ["B1"], "floor": [1, 2], "time": time},
    )
    peaks = peak_response(run).sel(building="B1")
    assert float(peaks["peak_total_displacement"]) == 0.04
    assert float(peaks["peak_sliding_displacement"]) == 0.01
    assert float(peaks["residual_sliding"]) == 0.002
    assert float(peaks["peak_relative_displacement"]) == pytest.approx(0.038)
