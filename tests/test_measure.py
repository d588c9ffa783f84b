"""The intensity measure as one value (stochpound.motions.Measure): validation, names, and the canonical entry round trip."""

import pytest

from stochpound.motions import Measure


@pytest.mark.parametrize("entry", [
    {"measure": "pga"},
    {"measure": "pgv"},
    {"measure": "psa", "period": 1.0, "damping": 0.05},
    {"measure": "psa", "period": 0.2},
    {"measure": "sa_avg", "periods": [0.5, 1.0, 2.0, 4.0], "damping": 0.05},
])
def test_an_entry_is_read_and_written_back_unchanged(entry):
    measure = Measure.from_entry({**entry, "units": "g", "levels": [0.1]})
    assert measure.entry() == entry
    assert Measure.from_entry(measure.entry()) == measure
    assert hash(Measure.from_entry(entry)) == hash(measure)


def test_the_names_are_the_ones_tables_and_reports_print():
    psa = Measure("psa", 1.0, damping=0.05)
    assert (psa.label, psa.description) == ("PSA(1 s)", "PSA(T = 1 s, 5 % damping)")
    avg = Measure.of("sa_avg", [0.5, 1.0, 2.0, 4.0], 0.05)
    assert (avg.label, avg.description) == ("Sa_avg(0.5-4 s)", "Sa_avg(0.5-4 s, 4 periods, 5 % damping)")
    assert (Measure("pga").label, Measure("pgv").description, str(psa)) == ("PGA", "PGV", "PSA(1 s)")
    assert Measure.from_entry({"measure": "psa", "period": 3.0, "damping": 0.05}).description == "PSA(T = 3 s, 5 % damping)"


@pytest.mark.parametrize("entry, message", [
    ({"measure": "sd"}, "measure: must be one of pga, pgv, psa, sa_avg, got 'sd'"),
    ({"measure": "psa"}, "period: must be a period > 0 (s), got None"),
    ({"measure": "psa", "period": -1.0}, "period: must be a period > 0 (s), got -1.0"),
    ({"measure": "pga", "period": 1.0}, "period: only psa takes a period"),
    ({"measure": "sa_avg", "periods": [1.0]}, "periods: sa_avg needs at least 2 periods"),
    ({"measure": "psa", "period": 1.0, "damping": 5.0}, "damping: must be a ratio in (0, 1), got 5.0"),
    ({"measure": "pgv", "damping": 0.05}, "damping: only a spectral measure"),
    ({"period": 1.0}, "measure: missing"),
])
def test_a_wrong_measure_is_refused_naming_the_field(entry, message):
    with pytest.raises(ValueError) as error:
        Measure.from_entry(entry)
    assert str(error.value).startswith(message)


def test_matching_ignores_an_unstated_damping_but_not_a_different_one():
    stated = Measure("psa", 1.0, damping=0.05)
    assert Measure("psa", 1.0).matches(stated) and stated.matches(Measure("psa", 1.0 + 1e-12))
    assert not stated.matches(Measure("psa", 1.0, damping=0.02))
    assert not stated.matches(Measure("psa", 2.0)) and not stated.matches(Measure("pga"))
