"""Bundled records: registry, statistics against SOURCES.md and the study's Table 3.2, CLI."""

from __future__ import annotations

import importlib.resources
import shutil
from decimal import Decimal

import numpy as np
import pytest

from stochpound._data_files import bundled_data_dir
import scipy.stats

from stochpound._errors import RecordError
from stochpound.motions.records import (
    Record,
    arias_intensity,
    list_records,
    load_record,
    moments,
    record_statistics,
    records_dir,
    registry_entries,
)
from stochpound.motions.records import _registry as registry_module
from stochpound.motions.records._readers import sha256_of
from stochpound.studies.agarwal2004 import STUDY_G, study_table_3_2

# Values exactly as printed in data/records/SOURCES.md (section in the comment).
# Each is compared to half a unit of its last printed digit. SOURCES.md computes
# every statistic on a = value_in_g x 9.814 (its "Statistics convention"); for
# the Northridge file (m/s²) it first divides by 9.81 ("converted with 9.81").
SOURCES = [
    # name, samples (None = all), {statistic: printed value}
    ("el_centro_1940", None, dict(npts="2688", peak_g="0.3487", mean="0.00048175", std="0.4605", skewness="0.4644", excess="8.8124")),  # §1
    ("el_centro_1940", 2500, dict(peak_g="0.3487", mean="0.00060444", std="0.4772", skewness="0.4479", excess="8.0147")),  # §1
    ("el_centro_1940_study", None, dict(npts="2500", peak_g="0.342", mean="0.000593", std="0.4679")),  # §1, "std 0.4772/1.0197 = 0.4679, mean 0.000593, peak 0.342"
    ("el_centro_1940_peknold", None, dict(npts="1559", peak_g="0.3188", mean="0.0000217", std="0.6010", skewness="-0.0460", excess="3.967")),  # §2
    ("el_centro_1940_ngaw2_rsn6", None, dict(npts="5372", peak_g="0.2808", mean="5.8e-07", std="0.4255", skewness="-0.2447", excess="7.578")),  # §3
    ("el_centro_1940_ngaw2_rsn6", 5000, dict(std="0.4410", skewness="-0.236", excess="6.85")),  # §3 "First 50 s"
    ("mexico_city_1985_sct", None, dict(npts="8171", peak_g="0.0995", mean="-4.9e-06", std="0.2236", skewness="+0.3650", excess="4.0633")),  # §4
    ("mexico_city_1985_study", None, dict(npts="8171", peak_g="0.0995", mean="+4.9e-06", std="0.2236", skewness="-0.3650", excess="4.0633")),  # §4
    ("mexico_city_1985_sct_ew", None, dict(peak_g="0.1712")),  # §4
    ("loma_prieta_1989_corralitos_090", None, dict(npts="7999", peak_g="0.4828", mean="8.5e-07", std="0.6314", skewness="+0.4591", excess="11.72")),  # §5
    ("loma_prieta_1989_corralitos_000", None, dict(npts="7997", peak_g="0.6447", mean="8.5e-07", std="0.7125", skewness="-0.0579", excess="20.17")),  # §5
    ("loma_prieta_1989_substitute", None, dict(npts="7999", peak_g="0.4828", std="0.6314", skewness="+0.4591", excess="11.72")),  # §5
    ("northridge_1994_sylmar_hospital_360", None, dict(npts="3000", peak_g="0.8428", mean="-4.6e-05", std="0.7224", skewness="+1.989", excess="39.26")),  # §6
    ("northridge_1994_sylmar_hospital_360", 1202, dict(std="1.140", skewness="+1.263", excess="14.02")),  # §6
    ("northridge_1994_substitute", None, dict(npts="3000", peak_g="0.8428", std="0.7224", skewness="+1.989", excess="39.26")),  # §6
]


def _sources_statistics(record: Record, samples: int | None) -> dict[str, float]:
    """Statistics in SOURCES.md's convention (see the comment above SOURCES)."""
    in_g = record.values if record.units == "g" else record.acceleration() / 9.81
    a = in_g[:samples] * STUDY_G
    mean, std, skewness, excess = moments(a)
    return dict(npts=a.size, peak_g=float(np.max(np.abs(in_g[:samples]))), mean=mean, std=std, skewness=skewness, excess=excess)


def _half_unit(printed: str) -> float:
    exponent = Decimal(printed).as_tuple().exponent
    return 0.5 * 10.0**exponent


@pytest.mark.parametrize("name,samples,expected", SOURCES, ids=[f"{n}-{s or 'all'}" for n, s, _ in SOURCES])
def test_statistics_equal_sources_md(name, samples, expected):
    ours = _sources_statistics(load_record(name), samples)
    for key, printed in expected.items():
        assert abs(ours[key] - float(printed)) <= _half_unit(printed) * (1 + 1e-9), (key, ours[key], printed)


def test_expected_values_are_quoted_from_sources_md():
    text = (records_dir() / "SOURCES.md").read_text()
    for _, _, expected in SOURCES:
        for printed in expected.values():
            assert printed.lstrip("+") in text, printed


def test_mexico_padding_diagnostic_of_sources_md():
    """§4: the S00E series zero-padded to the study's 9004 samples (diagnostic, no file)."""
    record = load_record("mexico_city_1985_study")
    padded = np.concatenate([record.acceleration(STUDY_G), np.zeros(9004 - record.npts)])
    mean, std, skewness, excess = moments(padded)
    for ours, printed in ((mean, "4.5e-06"), (std, "0.2130"), (skewness, "-0.3832"), (excess, "4.7833")):
        assert abs(ours - float(printed)) <= _half_unit(printed)


def test_study_reconstruction_matches_table_3_2():
    """el_centro_1940_study reproduces the study's std, skewness and excess to 0.1 %."""
    table = study_table_3_2("el_centro")
    stats = record_statistics(load_record("el_centro_1940_study"), g=STUDY_G)
    assert stats.npts == table["npts"] and stats.dt == table["dt"]
    for key in ("std", "skewness", "excess"):
        assert stats.as_dict()[key] == pytest.approx(table[key], rel=1e-3), key
    mexico = record_statistics(load_record("mexico_city_1985_study"), g=STUDY_G)
    assert np.sign(mexico.skewness) == np.sign(study_table_3_2("mexico_city")["skewness"])


def test_every_name_loads_with_verified_hash():
    assert list_records() == list(registry_entries())
    for name in list_records():
        record = load_record(name)
        assert record.npts > 0 and record.dt > 0 and np.all(np.isfinite(record.values))
        assert "sha256" in record.provenance
    for entry in registry_entries().values():
        if not entry.is_variant:
            assert sha256_of(records_dir() / entry.file) == entry.sha256


def test_variants_are_transformations_of_their_base():
    base = load_record("el_centro_1940")
    study = load_record("el_centro_1940_study")
    np.testing.assert_array_equal(study.values, base.values[:2500] / 1.0197)
    assert study.duration == pytest.approx(49.98)
    np.testing.assert_array_equal(load_record("mexico_city_1985_study").values, -load_record("mexico_city_1985_sct").values)


def test_substitutes_are_labelled():
    for name in ("loma_prieta_1989_substitute", "northridge_1994_substitute"):
        record = load_record(name)
        assert record.provenance.startswith("SUBSTITUTE for the study's")
        assert record.description.startswith("SUBSTITUTE")
    assert "Corralitos" in load_record("loma_prieta_1989_substitute").description
    assert "Sylmar" in load_record("northridge_1994_substitute").description


def test_sha_mismatch_is_an_error(tmp_path, monkeypatch):
    folder = tmp_path / "records"
    shutil.copytree(records_dir(), folder)
    target = folder / "elcentro1940_S00E_dt0.02_2688.txt"
    target.write_text(target.read_text().replace("-1.1012760e-002", "-1.1012761e-002", 1))
    monkeypatch.setattr(registry_module, "records_dir", lambda: folder)
    with pytest.raises(RecordError, match="el_centro_1940: bundled file data/records/elcentro1940_S00E_dt0.02_2688.txt has sha256"):
        load_record("el_centro_1940")


def test_packaged_copy_is_preferred(tmp_path, monkeypatch):
    """A wheel puts the records at stochpound/_data/records: they are looked up there first."""
    package = tmp_path / "stochpound"
    shutil.copytree(records_dir(), package / "_data" / "records")
    monkeypatch.setattr(importlib.resources, "files", lambda name: package)
    bundled_data_dir.cache_clear()
    try:
        assert records_dir() == package / "_data" / "records"
    finally:
        bundled_data_dir.cache_clear()
    assert (records_dir() / "registry.toml").is_file()


def test_dt_and_units_must_agree_for_bundled_records():
    assert load_record("el_centro_1940", dt=0.02, units="g").npts == 2688
    with pytest.raises(RecordError, match="dt=0.01 s was given but the bundled record has dt=0.02 s"):
        load_record("el_centro_1940", dt=0.01)
    with pytest.raises(RecordError, match="bundled record is in m/s2"):
        load_record("northridge_1994_substitute", units="g")


def test_unknown_name_lists_known_names():
    with pytest.raises(RecordError) as info:
        load_record("el_centro_1941")
    message = str(info.value)
    assert message.startswith("el_centro_1941: no bundled record")
    for name in list_records():
        assert name in message


def test_acceleration_units():
    values = np.array([0.5, -1.0])
    np.testing.assert_allclose(Record("x", 0.01, values, "g").acceleration(g=9.814), values * 9.814)
    np.testing.assert_allclose(Record("x", 0.01, values, "m/s2").acceleration(g=1.0), values)
    np.testing.assert_allclose(Record("x", 0.01, values, "gal").acceleration(), values / 100)
    with pytest.raises(ValueError, match="units must be one of"):
        Record("x", 0.01, values, "ft/s2")


def test_moments_agree_with_scipy():
    a = load_record("el_centro_1940_peknold").acceleration(STUDY_G)
    mean, std, skewness, excess = moments(a)
    assert mean == pytest.approx(np.mean(a)) and std == pytest.approx(np.std(a, ddof=0))
    assert skewness == pytest.approx(scipy.stats.skew(a, bias=True), rel=1e-12)
    assert excess == pytest.approx(scipy.stats.kurtosis(a, fisher=True, bias=True), rel=1e-12)


def test_arias_intensity_of_a_sine():
    """π/(2g) ∫ (A sin ωt)² dt over whole periods is π A² T / (4 g); linear interpolation converges as dt²."""
    amplitude, omega, g = 3.0, 2.0 * np.pi, 9.81
    exact = np.pi * amplitude**2 * 10.0 / (4.0 * g)
    errors = []
    for dt in (0.01, 0.005):
        t = np.arange(int(round(10.0 / dt)) + 1) * dt
        errors.append(abs(arias_intensity(amplitude * np.sin(omega * t), dt, g) - exact) / exact)
    assert errors[0] < 1e-3 and errors[1] < errors[0] / 3.5


# ---------------------------------------------------------------- command line


def _cli(*args):
    from click.testing import CliRunner

    from stochpound.cli._records import records

    return CliRunner().invoke(records, list(args))


def test_cli_list():
    result = _cli("list")
    assert result.exit_code == 0, result.output
    for name in list_records():
        assert name in result.output
    assert result.output.count("[SUBSTITUTE]") == 2


def test_cli_show_study_record_with_table_3_2(tmp_path):
    plot = tmp_path / "ec.png"
    result = _cli("show", "el_centro_1940_study", "--plot", str(plot), "--g", str(STUDY_G))
    assert result.exit_code == 0, result.output
    stats = record_statistics(load_record("el_centro_1940_study"), g=STUDY_G)
    table = study_table_3_2("el_centro")
    for text in (f"{stats.std:.4f}", f"{stats.excess:.4f}", f"{table['excess']:.4f}", f"{table['skewness']:.4f}", "study Table 3.2", "Arias"):
        assert text in result.output, text
    assert plot.stat().st_size > 10_000 and plot.read_bytes()[:4] == b"\x89PNG"


def test_cli_g_defaults_are_one_value():
    """Every --g of the records commands defaults to the scenes' g (9.81 m/s²), not one 9.814 and another 9.81."""
    from stochpound.cli._records import records
    from stochpound.model.scene import Scene

    defaults = {name: next(p.default for p in command.params if p.name == "g") for name, command in records.commands.items()
                if any(p.name == "g" for p in command.params)}
    assert len(defaults) >= 2 and set(defaults.values()) == {Scene.__dataclass_fields__["g"].default}, defaults


def test_cli_show_substitute_and_file(tmp_path):
    result = _cli("show", "northridge_1994_substitute")
    assert result.exit_code == 0 and "SUBSTITUTE" in result.output and "1.6829" in result.output
    path = tmp_path / "one.txt"
    path.write_text("0.1\n-0.2\n0.05\n")
    result = _cli("show", str(path), "--dt", "0.02")
    assert result.exit_code == 0 and "0.2000" in result.output  # peak in g
    result = _cli("show", str(path))
    assert result.exit_code != 0 and "missing dt" in result.output


def test_cli_units_take_the_readers_spellings(tmp_path):
    """Issue 48: --units took only g, m/s2 and cm/s2; now every spelling the reader knows, and an unknown one is a one-line error."""
    path = tmp_path / "one.txt"
    path.write_text("98.1\n-196.2\n49.05\n")
    outputs = {units: _cli("show", str(path), "--dt", "0.02", "--units", units) for units in ("cm/s2", "gal", "cm/s²", "cm/s/s")}
    assert all(result.exit_code == 0 for result in outputs.values()), [result.output for result in outputs.values()]
    assert len({result.output for result in outputs.values()}) == 1 and "0.2000" in outputs["gal"].output  # peak in g
    result = _cli("spectrum", str(path), "--dt", "0.02", "--units", "mm/s2")
    error = [line for line in result.output.splitlines() if line.startswith("Error")]
    assert result.exit_code == 2 and len(error) == 1, result.output
    assert "'--units'" in error[0] and "units must be one of g, m/s2, cm/s2 (or gal," in error[0] and "'mm/s2'" in error[0]


def test_cli_is_registered():
    from stochpound.cli import main

    assert "records" in main.commands
