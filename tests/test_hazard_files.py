"""Hazard files are read, never guessed: the three formats, what they state, conversions and refusals.

The test files (tests/data/hazard, README there) restate the bundled Fox Plaza
SA(1.0 s) curve in each format, so each reader must give back that curve.
"""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest

from stochpound.analysis import HazardCurve, bundled_measure
from stochpound.motions import Measure
from stochpound.hazard._files import (
    StatedMeasure,
    parse_units,
    read_hazard_file,
    unit_factor,
)
from stochpound.hazard._setting import hazard_curve, hazard_option
from stochpound.experiment._intensity import IntensityError
from stochpound.experiment._spec import ExperimentError, parse_experiment
from stochpound.store import Hazard
from tests.helpers import ISOLATED, risk_text as _text

DATA = Path(__file__).resolve().parent / "data" / "hazard"
OPENQUAKE = DATA / "hazard_curve-mean-SA(1.0)_42.csv"
NSHMP = DATA / "curves" / "SA1P0" / "total.csv"
POE_CM = DATA / "site_poe_cm_s2.csv"
FOX = HazardCurve.bundled("fox_plaza_los_angeles_sa1p0s")
PSA1 = Measure("psa", 1.0, damping=0.05)


def test_a_stated_measure_is_parsed_from_the_usual_spellings():
    assert StatedMeasure.parse("5 %-damped spectral acceleration at T = 1.0 s, in g") == StatedMeasure("psa", 1.0, damping=0.05, units="g")
    assert StatedMeasure.parse("peak ground acceleration (PGA), in g") == StatedMeasure("pga", units="g")
    assert StatedMeasure.parse("PSA(2.0 s, 5 %) in m/s²") == StatedMeasure("psa", 2.0, damping=0.05, units="m/s2")
    assert StatedMeasure.parse("PGA in gal") == StatedMeasure("pga", units="cm/s2")
    assert StatedMeasure.parse("SA1P0") == StatedMeasure("psa", 1.0)
    with pytest.raises(ValueError, match="^measure: 'MMI' names no measure"):
        StatedMeasure.parse("MMI")


def test_hazard_units_are_read_in_the_records_spellings():
    """Issue 48: the hazard's units took their own short list of spellings; now the records' reader's, and m/s, cm/s for PGV."""
    for written, units in [("cm/s^2", "cm/s2"), ("Gal", "cm/s2"), ("cm/sec/sec", "cm/s2"), ("m s-2", "m/s2"), ("G", "g"), ("cm / s", "cm/s")]:
        assert parse_units(written) == units, written
    assert StatedMeasure.parse("PGA in cm/s^2") == StatedMeasure("pga", units="cm/s2")
    assert StatedMeasure.parse("PSA(1.0 s, 5 %), in m s-2") == StatedMeasure("psa", 1.0, damping=0.05, units="m/s2")
    assert StatedMeasure.parse("PGA in mm/s2") == StatedMeasure("pga")  # no units it knows at the end: none stated, as before
    with pytest.raises(ValueError, match=r"^units: must be one of g, m/s2, cm/s2, m/s, cm/s \(or gal, .*got 'mm/s2'$"):
        parse_units("mm/s2")


def test_a_stated_measure_is_a_value_with_what_the_text_leaves_out_left_none():
    """The parser's one result: a frozen value whose entry() gives its stated keys back, a Measure once kind and period are stated."""
    stated = StatedMeasure.parse("PSA(2.0 s, 5 %) in m/s²")
    assert stated == StatedMeasure("psa", 2.0, damping=0.05, units="m/s2") and hash(stated) == hash(StatedMeasure.from_entry(stated.entry()))
    assert stated.entry() == {"measure": "psa", "period": 2.0, "damping": 0.05, "units": "m/s2"}
    assert stated.measure == Measure("psa", 2.0, damping=0.05)
    partial = StatedMeasure.parse("spectral acceleration")
    assert (partial.kind, partial.period, partial.units, partial.measure) == ("psa", None, None, None)
    assert StatedMeasure.parse("SA(0.2)").measure.description == "PSA(T = 0.2 s)"  # no damping stated: none described
    assert StatedMeasure.of(bundled_measure("fox_plaza_los_angeles_pga"), "g") == StatedMeasure.parse("PGA in g")


def test_bundled_curves_name_their_measure_as_a_value():
    measure = bundled_measure("fox_plaza_los_angeles_sa1p0s")
    assert measure == Measure("psa", 1.0, damping=0.05) and measure.label == "PSA(1 s)"
    assert bundled_measure("fox_plaza_los_angeles_pga") == Measure("pga")
    with pytest.raises(ValueError, match="^name: no bundled hazard curve 'nowhere_pga'"):
        bundled_measure("nowhere_pga")


def test_unit_factors():
    assert unit_factor("cm/s2", "g", 9.81) == pytest.approx(1 / 981.0, rel=1e-15)
    assert unit_factor("g", "m/s2", 9.80665) == 9.80665 and unit_factor("cm/s", "m/s", 9.81) == 0.01
    with pytest.raises(ValueError, match=r"^units: the hazard's intensities are in cm/s \(a velocity\), the store's in g"):
        unit_factor("cm/s", "g", 9.81)


def test_openquake_file_is_probabilities_in_its_investigation_time():
    read = read_hazard_file(OPENQUAKE, site=0)
    assert read.format == "openquake" and read.quantity == "poe" and read.investigation_time == 50.0
    assert read.stated == StatedMeasure("psa", 1.0, damping=0.05, units="g")
    curve = read.curve("g", 9.81)
    np.testing.assert_allclose(curve.im, FOX.im, rtol=1e-12)
    np.testing.assert_allclose(curve.rate[1:], FOX.rate[1:], rtol=1e-9)  # the first P is 1 - 1e-12: 4 digits left in 1 - P
    np.testing.assert_allclose(curve.rate[0], FOX.rate[0], rtol=1e-3)
    assert "probabilities of exceedance in 50 years converted to annual rates" in curve.source
    second = read_hazard_file(OPENQUAKE, site=1).curve("g", 9.81)
    np.testing.assert_allclose(second.rate[1:], FOX.rate[1:] / 2, rtol=1e-9)  # the second site: P = 1 - exp(-25 λ) read in 50 years
    with pytest.raises(ValueError, match=r"^hazard_curve-mean-SA\(1\.0\)_42\.csv: 2 sites: choose one"):
        read_hazard_file(OPENQUAKE)


def test_openquake_longitude_is_not_read_as_an_intensity():
    read = read_hazard_file(OPENQUAKE, site=0)
    assert read.im[0] == 0.01 and -118.413 not in read.im


def test_nshmp_file_is_rates_its_measure_the_folder_and_zeros_left_out():
    read = read_hazard_file(NSHMP, site="Fox Plaza")
    assert read.format == "nshmp-haz" and read.quantity == "rate"
    assert read.stated == StatedMeasure("psa", 1.0, damping=0.05, units="g")
    curve = read.curve("g", 9.81)
    np.testing.assert_array_equal(curve.im, FOX.im)
    np.testing.assert_array_equal(curve.rate, FOX.rate)
    assert "2 level(s) of zero exceedance above 2 g left out" in curve.source
    np.testing.assert_array_equal(read_hazard_file(NSHMP, site=1).curve("g", 9.81).rate, FOX.rate / 2)
    with pytest.raises(ValueError, match=r"site: no site named 'Nowhere' \(sites: Fox Plaza,Elsewhere\)"):
        read_hazard_file(NSHMP, site="Nowhere")


def test_stochpound_file_in_cm_s2_and_probabilities_gives_the_curve():
    curve = read_hazard_file(POE_CM).curve("g", 9.81)
    np.testing.assert_allclose(curve.im, FOX.im, rtol=1e-12)
    np.testing.assert_allclose(curve.rate[1:], FOX.rate[1:], rtol=1e-9)
    assert "intensities converted from cm/s2 to g (g = 9.81 m/s²)" in curve.source


def test_a_poe_column_needs_an_investigation_time(tmp_path):
    path = tmp_path / "poe.csv"
    path.write_text("# Measure: PGA in g\nim,poe\n0.1,0.5\n0.5,0.1\n")
    with pytest.raises(ValueError, match="^investigation_time: the values are probabilities of exceedance"):
        read_hazard_file(path).curve("g", 9.81)
    np.testing.assert_allclose(read_hazard_file(path).curve("g", 9.81, investigation_time=50.0).rate, -np.log([0.5, 0.9]) / 50.0)


def test_a_column_that_is_not_named_is_refused(tmp_path):
    path = tmp_path / "bare.csv"
    path.write_text("0.1,0.01\n0.5,0.001\n")
    with pytest.raises(ValueError, match="^bare.csv: header: name the second column 'rate'"):
        read_hazard_file(path)


def test_a_curve_that_is_not_decreasing_is_an_error(tmp_path):
    path = tmp_path / "up.csv"
    path.write_text("# Measure: PGA in g\nim,rate\n0.1,0.001\n0.5,0.01\n")
    with pytest.raises(ValueError, match="strictly decreasing"):
        read_hazard_file(path).curve("g", 9.81)


# ------------------------------------------------- the four silent wrong answers of issue 35, in [hazard] and --hazard


def _entry(tmp_path: Path, hazard: str, intensity: str = 'measure = "psa"\nperiod = 1.0\nlevels = [0.3, 0.8, 1.5]') -> dict:
    text = _text(ISOLATED, "gap = [inf]", intensity, hazard)  # the flagship's scene (g = 9.81 m/s², the default)
    return parse_experiment(tomllib.loads(text), base_dir=tmp_path)["hazard"]


def _copy(tmp_path: Path, source: Path, text: str | None = None) -> str:
    """The file (or ``text`` instead of its content) in the experiment's folder, under a name of its own."""
    name = source.name if text is None else f"edited_{len(list(tmp_path.iterdir()))}_{source.name}"
    (tmp_path / name).write_text(text if text is not None else source.read_text())
    return name


def test_a_hazard_in_cm_s2_is_converted_or_refused(tmp_path):
    name = _copy(tmp_path, POE_CM)
    curve = hazard_curve(Hazard.from_entry(_entry(tmp_path, f'file = "{name}"')))
    np.testing.assert_allclose(curve.im, FOX.im, rtol=1e-12)
    unstated = _copy(tmp_path, POE_CM, POE_CM.read_text().replace("in cm/s2", ""))
    with pytest.raises(ExperimentError, match=rf"^hazard\.units: not stated: {unstated} does not give its curve's units"):
        _entry(tmp_path, f'file = "{unstated}"')
    np.testing.assert_allclose(hazard_curve(Hazard.from_entry(_entry(tmp_path, f'file = "{unstated}"\nunits = "cm/s2"'))).im, FOX.im, rtol=1e-12)
    with pytest.raises(ExperimentError, match=rf"^hazard\.units: 'g', but {name} states units = 'cm/s2'"):
        _entry(tmp_path, f'file = "{name}"\nunits = "g"')


def test_probabilities_in_50_years_are_converted_or_refused(tmp_path):
    name = _copy(tmp_path, POE_CM)
    entry = _entry(tmp_path, f'file = "{name}"')
    np.testing.assert_allclose(entry["rate"][1:], FOX.rate[1:], rtol=1e-9)
    assert "converted to annual rates" in entry["provenance"]
    timeless = _copy(tmp_path, POE_CM, POE_CM.read_text().replace("# Investigation time: 50 years\n", ""))
    with pytest.raises(ExperimentError, match=r"^hazard\.investigation_time: the values are probabilities of exceedance"):
        _entry(tmp_path, f'file = "{timeless}"')
    np.testing.assert_allclose(_entry(tmp_path, f'file = "{timeless}"\ninvestigation_time = 50.0')["rate"][1:], FOX.rate[1:], rtol=1e-9)


def test_a_pga_curve_for_a_psa_store_is_an_error_naming_both(tmp_path):
    pga = _copy(tmp_path, Path(__file__).resolve().parent.parent / "data" / "hazard" / "fox_plaza_los_angeles_pga.csv")
    with pytest.raises(ExperimentError, match=r"^hazard\.measure: the hazard's measure must be \[intensity\]'s, PSA\(T = 1 s, 5 % damping\) "
                                              r"\(intensity\.measure = 'psa'\); the hazard's measure is 'pga'"):
        _entry(tmp_path, f'file = "{pga}"')
    with pytest.raises(IntensityError, match=r"^--hazard-measure: the hazard's measure must be"):
        hazard_option(str(tmp_path / pga), PSA1, "g")


def test_levels_in_m_s2_with_a_hazard_in_g_are_converted(tmp_path):
    intensity = 'measure = "psa"\nperiod = 1.0\nlevels = [3.0, 8.0, 15.0]\nunits = "m/s2"'
    entry = _entry(tmp_path, 'bundled = "fox_plaza_los_angeles_sa1p0s"', intensity)
    curve = hazard_curve(Hazard.from_entry(entry))
    assert entry["units"] == "m/s2" and curve.units == "m/s2"
    x = np.array([0.3, 0.8, 1.5])
    np.testing.assert_allclose(curve(x * 9.81), FOX(x), rtol=1e-12)
    law = hazard_curve(Hazard.from_entry(_entry(tmp_path, 'power_law = { k0 = 2.0e-4, k = 2.2 }\nunits = "g"', intensity)))
    np.testing.assert_allclose(law(x * 9.81), 2.0e-4 * x**-2.2, rtol=1e-12)


def test_a_curve_that_misses_the_stripes_is_an_error_or_extrapolated(tmp_path):
    (tmp_path / "short.csv").write_text("# Measure: PSA(1.0 s, 5 %) in g\nim,rate\n0.1,0.02\n0.5,0.002\n1.0,0.0004\n")
    with pytest.raises(ExperimentError, match=r"^hazard: the hazard curve covers \[0\.1, 1\] g, the stripes \(intensity\.levels\) \[0\.3, 1\.5\] g"):
        _entry(tmp_path, 'file = "short.csv"')
    assert _entry(tmp_path, 'file = "short.csv"\nextrapolate = true')["extrapolate"] is True
