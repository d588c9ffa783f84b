"""Hazard curves: tables in log-log, power laws, files, the bundled site curves, Poisson helpers, validation."""

import numpy as np
import pytest

from stochpound.analysis import HazardCurve, probability_from_rate, rate_from_probability, return_period
from stochpound.hazard._curve import bundled_curves


def test_poisson_helpers_give_the_code_rates():
    assert rate_from_probability(0.02, 50) == pytest.approx(4.0405e-4, rel=1e-4)
    assert rate_from_probability(0.10, 50) == pytest.approx(2.1072e-3, rel=1e-4)
    assert probability_from_rate(rate_from_probability(0.02, 50), 50) == pytest.approx(0.02)
    assert return_period(rate_from_probability(0.10, 50)) == pytest.approx(474.56, rel=1e-4)
    assert return_period(0.0) == np.inf


def test_power_law_and_its_fit_through_two_points():
    hz = HazardCurve.power_law(k0=2e-4, k=2.2)
    assert hz([0.5, 1.0, 3.0]) == pytest.approx(2e-4 * np.array([0.5, 1.0, 3.0]) ** -2.2)
    assert hz.support == (0.0, np.inf)
    first, second = (0.35, rate_from_probability(0.10)), (0.75, rate_from_probability(0.02))
    through = HazardCurve.power_law_through(first, second)
    assert through([first[0], second[0]]) == pytest.approx([first[1], second[1]])
    assert through.intensity_at(second[1]) == pytest.approx(0.75)
    assert through.probability(0.75, 50) == pytest.approx(0.02)
    assert not through.extrapolated


def test_table_interpolates_in_log_log_and_inverts():
    im = np.array([0.1, 0.2, 0.5, 1.0])
    rate = np.array([1e-2, 3e-3, 4e-4, 5e-5])
    hz = HazardCurve(im, rate)
    assert hz(im) == pytest.approx(rate)
    x = np.sqrt(0.2 * 0.5)
    assert hz(x) == pytest.approx(np.sqrt(3e-3 * 4e-4))
    assert hz.intensity_at(np.sqrt(3e-3 * 4e-4)) == pytest.approx(x)
    assert hz.intensity_at(rate) == pytest.approx(im)
    assert hz.return_period(0.5) == pytest.approx(2500.0)


def test_outside_the_table_is_an_error_unless_extrapolation_is_asked_and_then_recorded():
    hz = HazardCurve([0.1, 0.2, 0.5], [1e-2, 3e-3, 4e-4])
    with pytest.raises(ValueError, match="^x: outside the hazard table"):
        hz(0.6)
    with pytest.raises(ValueError, match="^rate: outside"):
        hz.intensity_at(1e-5)
    extended = HazardCurve([0.1, 0.2, 0.5], [1e-2, 3e-3, 4e-4], extrapolate=True)
    assert not extended.extrapolated
    slope = np.log(4e-4 / 3e-3) / np.log(0.5 / 0.2)
    assert extended(1.0) == pytest.approx(4e-4 * 2.0**slope)
    assert extended.extrapolated
    assert extended.intensity_at(4e-4 * 2.0**slope) == pytest.approx(1.0)


def test_a_csv_file_with_comments_and_header_is_read_with_its_provenance(tmp_path):
    path = tmp_path / "site.csv"
    path.write_text("# site: somewhere\n# source: a PSHA run\nim,rate\n0.1,0.01\n0.3,1e-3\n\n1.0,2e-5\n")
    hz = HazardCurve.from_file(path)
    assert hz.im.tolist() == [0.1, 0.3, 1.0] and hz.rate.tolist() == [0.01, 1e-3, 2e-5]
    assert hz.source == "site: somewhere\nsource: a PSHA run"
    path.write_text("im,rate\n0.1,0.01\n0.3,oops\n")
    with pytest.raises(ValueError, match="site.csv:3"):
        HazardCurve.from_file(path)


def test_the_bundled_los_angeles_curves_load_with_provenance():
    names = bundled_curves()
    assert "fox_plaza_los_angeles_pga" in names and "fox_plaza_los_angeles_sa3p0s" in names
    for name in names:
        hz = HazardCurve.bundled(name)
        assert "usgs/earthquake-rtgm-calculator" in hz.source and hz.units == "g"
        assert hz.im.size == 16
    pga = HazardCurve.bundled("fox_plaza_los_angeles_pga")
    assert pga(0.01) == pytest.approx(0.5696) and pga(2.0) == pytest.approx(6.4884e-8)
    assert 0.7 < float(pga.intensity_at(rate_from_probability(0.02))) < 0.9
    with pytest.raises(ValueError, match="^name"):
        HazardCurve.bundled("nowhere")


@pytest.mark.parametrize(("im", "rate", "field"), [
    ([0.1, 0.2], [1e-2], "rate"),
    ([0.0, 0.2], [1e-2, 1e-3], "im"),
    ([0.2, 0.1], [1e-2, 1e-3], "im"),
    ([0.1, 0.2], [1e-2, 0.0], "rate"),
    ([0.1, 0.2], [1e-3, 1e-2], "rate"),
    ([0.1], [1e-2], "im"),
])
def test_bad_tables_name_the_field(im, rate, field):
    with pytest.raises(ValueError, match=f"^{field}"):
        HazardCurve(im, rate)


@pytest.mark.parametrize(("call", "field"), [
    (lambda: HazardCurve.power_law(k0=-1.0, k=2.0), "k0"),
    (lambda: HazardCurve.power_law(k0=1e-4, k=0.0), "k"),
    (lambda: HazardCurve.power_law_through((0.3, 1e-3), (0.6, 2e-3)), "points"),
    (lambda: rate_from_probability(1.2), "probability"),
    (lambda: rate_from_probability(0.1, years=0.0), "years"),
    (lambda: HazardCurve.power_law(1e-4, 2.0)(-1.0), "x"),
])
def test_bad_arguments_name_the_field(call, field):
    with pytest.raises(ValueError, match=f"^{field}"):
        call()


def test_a_curve_written_as_csv_reads_back_as_the_same_table(tmp_path):
    """HazardCurve.to_csv writes what from_file reads: the same intensities and rates to the bit, and the provenance."""
    curve = HazardCurve.bundled(bundled_curves()[0])
    path = tmp_path / "again.csv"
    assert curve.to_csv(path) is None and path.read_text() == curve.to_csv()
    again = HazardCurve.from_file(path)
    assert again.im.tolist() == curve.im.tolist() and again.rate.tolist() == curve.rate.tolist() and again.source == curve.source
    with pytest.raises(ValueError, match="^to_csv: a power law has no table"):
        HazardCurve.power_law(1e-3, 2.5).to_csv()
