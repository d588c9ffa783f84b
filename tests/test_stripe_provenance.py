"""Provenance and counts a report can be held to (issue 45 items 5 and 6).

One earthquake is one earthquake across suites in the selection pool and in the report's per-stripe counts
("Northridge 1994" of the FEMA P695 far-field set and "Northridge-01 1994" of the near-field set); the stripe
table says per stripe its earthquakes, the largest share of one earthquake, the pulse records and the motions
shared with the stripe below; the motion table lists what ran, not the pool; the sources never name as a
store's definition a file that is not at the path it gives, or whose text is not the one the store ran.
"""

from __future__ import annotations

import hashlib

import numpy as np
import xarray as xr

from stochpound.motions import selection_pool
from stochpound.motions.records import load_suite_member
from stochpound.report.sections import definition_source
from stochpound.store import ran_motions, stripe_holdings

#: Four motions over two stripes: the far-field set's Northridge and the near-field set's Northridge-01 (one earthquake, M 6.7),
#: a Landers record and a simulated motion (no event: its own earthquake). Pulses: 1, 0, unknown, unknown.
RECORDS = ["fema_p695_far_field/01a", "fema_p695_near_field/09a", "fema_p695_far_field/11a", "simulated 1.0"]
EVENTS = ["Northridge 1994", "Northridge-01 1994", "Landers 1992", ""]


def _store(ran: list[list[bool]]) -> xr.Dataset:
    status = np.where(np.array(ran)[:, :, None, None], 1, 0) * np.ones((1, 1, 2, 1))  # two gaps, one realization
    return xr.Dataset(
        {"case_status": (("intensity", "record", "gap", "realization"), status)},
        coords={"intensity": [0.2, 0.6], "record": RECORDS, "gap": [0.05, np.inf], "realization": [0],
                "record_event": ("record", np.array(EVENTS, dtype=object)), "record_magnitude": ("record", [6.7, 6.7, 7.3, 7.0]),
                "record_pulse": ("record", [np.nan, 1.0, np.nan, np.nan])},
    )


def test_the_selection_pool_names_one_earthquake_once_across_suites():
    records = [load_suite_member(name) for name in RECORDS[:3]]
    assert [r.metadata["event"] for r in records] == EVENTS[:3]
    pool = selection_pool(records, [0.5, 1.0], "psa", 1.0)
    assert list(pool["earthquake"].values) == ["Northridge-01 1994", "Northridge-01 1994", "Landers 1992"]
    assert list(pool["pulse"].values) == [False, True, False]


def test_the_stripe_table_counts_earthquakes_shares_pulses_and_overlap():
    store = _store([[True, True, True, False], [False, True, True, True]])
    np.testing.assert_array_equal(ran_motions(store).values, [[True, True, True, False], [False, True, True, True]])
    table = stripe_holdings(store)
    assert list(table["motions"]) == [3, 3]
    assert list(table["earthquakes"]) == [2, 3]  # Northridge twice is one earthquake; the simulated motion is its own
    assert list(table["largest share of one earthquake"]) == ["2 of 3 (Northridge-01 1994)", "1 of 3 (each motion its own earthquake)"]
    assert list(table["pulse records"]) == ["1 of 1 classified", "1 of 1 classified"]
    assert list(table["shared with the stripe below"]) == ["–", 2]
    unclassified = stripe_holdings(store.drop_vars("record_pulse"))
    assert list(unclassified["pulse records"]) == ["unknown", "unknown"]
    tied = stripe_holdings(_store([[True, True, True, True], [True, True, True, True]]).assign_coords(
        record_event=("record", np.array(["A 2000", "A 2000", "B 2001", "B 2001"], dtype=object))))
    assert list(tied["largest share of one earthquake"]) == ["2 of 4 (A 2000 and 1 more)"] * 2
    assert list(tied["shared with the stripe below"]) == ["–", 4]


def test_the_sources_name_the_experiment_file_only_where_it_is_the_stores(tmp_path):
    text = "[experiment]\nname = 'x'\n"
    path = tmp_path / "x.toml"
    path.write_text(text)
    store = xr.Dataset(attrs={"experiment_file": str(path), "experiment_sha256": hashlib.sha256(text.encode()).hexdigest()})
    assert definition_source(store) == str(path)
    path.write_text(text + "# edited\n")
    assert definition_source(store) == (f"the experiment text recorded in the store (its file {path} has changed since the run, "
                                        f"text sha256 {store.attrs['experiment_sha256'][:16]}…)")
    path.unlink()
    assert definition_source(store).startswith(f"the experiment text recorded in the store (its file {path} is not at that path")
    assert definition_source(xr.Dataset(attrs={"experiment_file": "iso_fitted.toml"})) == (
        "the experiment text recorded in the store (its file iso_fitted.toml is not at that path)")


def test_the_simulated_motions_that_ran_are_read_off_the_store():
    """The definition lists the records only; the simulated motions some stripe chose are the store's, by their record_kind."""
    import xarray as xr

    from stochpound.store import simulated_that_ran

    status = xr.DataArray([[1, 0, 1, 0]], dims=("intensity", "record"), coords={
        "record": ["r1", "r2", "simulated 1.0", "simulated 1.1"], "record_kind": ("record", ["record", "record", "simulated", "simulated"])})
    assert simulated_that_ran(xr.Dataset({"case_status": status})) == ["simulated 1.0"]
    assert simulated_that_ran(xr.Dataset({"case_status": status.drop_vars("record_kind")})) == []
