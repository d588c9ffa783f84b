"""Yielding buildings in an experiment store and limit states beyond first contact through the risk chain (docs/risk.md, "Limit states").

The risk flagship's pair (Building 1 on a friction pendulum beside a fixed
Building 2) with yielding storeys and storey heights, under eight far-field
motions at three stripes, contact-free and at a 5 cm gap.
"""

from __future__ import annotations

import tomllib

import numpy as np
import pandas as pd
import pytest

import stochpound
from stochpound.risk import (LIMIT_STATE_KINDS, LimitState, RiskInputError, gap_cost_frame, limit_state_risk, limit_states_from_table,
                             site_hazard)
from stochpound.store import open_store
from tests.helpers import ISOLATED, risk_text, run_in_process

STRIPES = 'measure = "psa"\nperiod = 1.0\nlevels = [0.3, 0.8, 1.5]'
YIELDING = ('damping_ratio = 0.05\nyield_force = [1.0e5, 0.7e5]\nhardening = 0.05\nstorey_height = [3.5, 3.0]\n')
#: The flagship's scene with both buildings' storeys yielding (B1's about a quarter of its weight at the base).
YIELDING_SCENE = ISOLATED.replace("damping_ratio = 0.05\n", YIELDING)


@pytest.fixture(scope="module")
def store_path(tmp_path_factory):
    """The yielding pair's store file, demands kept (8 motions × 3 stripes × gaps 5 cm and inf)."""
    assert YIELDING_SCENE.count("yield_force") == 2
    text = risk_text(YIELDING_SCENE, "gap = [0.05, inf]", STRIPES) + "demands = true\n"
    return run_in_process(tmp_path_factory.mktemp("yielding"), "yielding", text)


@pytest.fixture(scope="module")
def store(store_path):
    return open_store(store_path).load()


def test_a_store_keeps_each_cases_storey_summaries(store):
    """The store's storey summaries are those of the case's own run, recomputed here with simulate()."""
    assert {"peak_drift_ratio", "peak_ductility", "residual_drift", "residual_drift_ratio"} <= set(store.data_vars)
    assert store["peak_ductility"].attrs["units"] == "1" and store["residual_drift"].attrs["units"] == "m"
    assert float(store["peak_ductility"].max()) > 2.0 and float(store["residual_drift"].max()) > 1e-3  # they yield
    case = store.isel(intensity=2, record=3, realization=0).sel(gap=0.05)
    scene = store.pound.scene(intensity=float(case["intensity"]), record=str(case["record"].values), realization=0, gap=0.05)
    run = stochpound.simulate(scene, demands=True)
    assert int(case["impacts"]) == run.sizes["impact"]
    for name, source in (("peak_drift_ratio", "peak_storey_drift_ratio"), ("peak_ductility", "peak_storey_ductility"),
                         ("residual_drift", "residual_storey_drift"), ("residual_drift_ratio", "residual_storey_drift_ratio")):
        np.testing.assert_allclose(case[name].values, np.abs(run[source]).max("floor").values, rtol=1e-12, err_msg=name)


def test_the_gap_identity_holds_in_a_yielding_store(store):
    free = store["peak_contact_closure"].sel(gap=np.inf).max("contact")
    pounded = store["impacts"].sel(gap=0.05) > 0
    assert bool(pounded.any()) and not bool(pounded.all())
    assert bool(((free >= 0.05) == pounded).all())


# ---------------------------------------------------------------- limit states beyond first contact


LIMIT_STATES_TOML = """
[limit_states]
drift_ratio = [0.005, 0.02]
ductility = { B2 = 2.0 }
residual_drift_ratio = [0.001]
floor_acceleration = [1.0]
impact_force = [1.0e5]
isolator_displacement = { B1 = 0.1 }
"""
LIMIT_STATES = tomllib.loads(LIMIT_STATES_TOML)["limit_states"]


@pytest.fixture(scope="module")
def risk(store):
    return limit_state_risk(store, limit_states_from_table(LIMIT_STATES))


def test_every_limit_state_is_a_direct_count_of_the_runs_demands(store, risk):
    """The fragility's per-stripe counts are those of the stored summaries, at every gap (the contact-free twins included)."""
    states = limit_states_from_table(LIMIT_STATES)
    assert [s.label for s in states] == list(risk["limit_state"].values)
    assert "peak floor acceleration ≥ 1 g" in risk["limit_state"].values and "peak base displacement of B1 ≥ 0.1 m" in risk["limit_state"].values
    g = store.pound.definition.to_dict()["scene"]["g"]
    for state in states:
        variable = LIMIT_STATE_KINDS[state.kind].variable
        demand = store[variable].sel(building=state.building) if state.building else store[variable]
        if "building" in demand.dims:
            demand = demand.max("building")
        demand = demand / g if state.kind == "floor_acceleration" else demand
        counted = (demand >= state.capacity).sum(["record", "realization"])
        np.testing.assert_array_equal(risk["exceeded"].sel(limit_state=state.label).transpose(*counted.dims).values, counted.values, err_msg=state.label)
    assert int(risk["runs"].min()) == int(risk["runs"].max()) == 8


def test_the_gap_costs_what_pounding_adds_to_each_limit_states_rate(risk):
    """maf − maf of the contact-free twins, per limit state; the twins' own cost is 0; an impact force is reached only with a gap."""
    free, finite = risk.sel(gap=np.inf), risk.sel(gap=0.05)
    np.testing.assert_array_equal(free["gap_cost"].values, 0.0)
    np.testing.assert_array_equal(finite["maf_contact_free"].values, free["maf"].values)
    np.testing.assert_allclose(finite["gap_cost"].values, finite["maf"].values - free["maf"].values, rtol=0, atol=0)
    impact = "peak impact force ≥ 100000 N"
    assert float(free["maf"].sel(limit_state=impact)) == 0.0 and int(free["exceeded"].sel(limit_state=impact).sum()) == 0
    assert float(finite["gap_cost"].sel(limit_state=impact)) > 0.0
    table = gap_cost_frame(risk)
    assert list(table.index) == [(label, 0.05) for label in risk["limit_state"].values] and "P in 50 yr" in table  # finite gaps only
    assert table.loc[(impact, 0.05), "Δλ (1/yr)"] == pytest.approx(float(finite["gap_cost"].sel(limit_state=impact)), rel=1e-15)


def test_a_limit_states_rate_is_its_fragility_integrated_over_the_hazard(store, risk):
    """λ = ∫ F(x) |dλ(x)|, here by a sum over 20 000 intensities of the hazard's table (independent of the chain's quadrature)."""
    from scipy.stats import norm

    hz = site_hazard(store)
    lo, hi = hz.support
    x = np.geomspace(lo, hi, 20001)
    mid = np.sqrt(x[1:] * x[:-1])
    cases = risk[["theta", "beta", "maf", "status"]].stack(case=("limit_state", "gap"))
    fitted = cases.isel(case=np.flatnonzero(cases["status"].values == 0))
    assert fitted.sizes["case"] >= 3
    for theta, beta, maf in zip(fitted["theta"].values, fitted["beta"].values, fitted["maf"].values):
        fragility = norm.cdf(np.log(mid / theta) / beta)
        direct = np.sum(fragility * -np.diff(hz(x))) + norm.cdf(np.log(hi / theta) / beta) * float(hz(hi))
        assert maf == pytest.approx(direct, rel=1e-3)


@pytest.mark.parametrize(
    "table, message",
    [
        ({"drift": [0.01]}, "limit_states.drift: not a limit state; one of drift_ratio"),
        ({"drift_ratio": [0.0]}, "limit_states.drift_ratio: a capacity must be a number > 0 (1), got 0.0"),
        ({"floor_acceleration": "1 g"}, "limit_states.floor_acceleration: a capacity must be a number > 0 (g), got '1 g'"),
        ({"impact_force": {"B1": 1e5}}, "limit_states.impact_force: has no building"),
        ({"ductility": True}, "limit_states.ductility: a capacity must be a number > 0 (1), got True"),
        ({}, "limit_states: must be a table of drift_ratio"),
    ],
)
def test_a_bad_limit_state_is_named(table, message):
    with pytest.raises(RiskInputError, match="^" + message.replace("(", r"\(").replace(")", r"\)")):
        limit_states_from_table(table)


def test_a_store_without_a_limit_states_demand_or_building_is_named(store):
    with pytest.raises(RiskInputError, match=r"^store: has no 'peak_floor_acceleration' \(it needs \[output\] demands = true\)$"):
        limit_state_risk(store.drop_vars("peak_floor_acceleration"), [LimitState("floor_acceleration", 1.0)])
    with pytest.raises(RiskInputError, match=r"^limit_states: building 'B3' is not one of the store's \(B1, B2\)$"):
        limit_state_risk(store, [LimitState("ductility", 2.0, "B3")])


def test_the_risk_command_prints_and_writes_the_limit_states(store_path, risk, tmp_path):
    from click.testing import CliRunner

    from stochpound.cli import main

    (tmp_path / "states.toml").write_text(LIMIT_STATES_TOML)
    result = CliRunner().invoke(main, ["risk", str(store_path), "--bootstrap", "0", "--limit-states", str(tmp_path / "states.toml"),
                                       "--csv", str(tmp_path / "tables")])
    assert result.exit_code == 0, result.output
    assert "Limit states beyond first contact" in result.output and "peak impact force ≥ 100000 N" in result.output
    written = pd.read_csv(tmp_path / "tables" / "limit_states.csv")
    assert list(written["limit_state"]) == list(risk["limit_state"].values)
    np.testing.assert_allclose(written["Δλ (1/yr)"], risk["gap_cost"].sel(gap=0.05).values, rtol=1e-12)
    (tmp_path / "bad.toml").write_text("[limit_states]\ndrift_ratio = [-1.0]\n")
    bad = CliRunner().invoke(main, ["risk", str(store_path), "--bootstrap", "0", "--limit-states", str(tmp_path / "bad.toml")])
    assert bad.exit_code == 1 and "Error: limit_states.drift_ratio: a capacity must be a number > 0 (1), got -1.0" in bad.output


def test_the_gap_cost_table_gives_the_runs_bounds_where_they_do_not_pin_the_fit(risk):
    """Issue 45: a fit the runs do not pin gives λ as its extrapolation; the table gives beside it the bounds the stripes give."""
    from stochpound.risk import limit_state_bounds, limit_state_pinned

    table = gap_cost_frame(risk)
    pinned = limit_state_pinned(risk).sel(gap=0.05)
    lower, upper = (bound.sel(gap=0.05) for bound in limit_state_bounds(risk))
    for label in risk["limit_state"].values:
        row = table.loc[(label, 0.05)]
        if bool(pinned.sel(limit_state=label)):
            assert np.isnan(row["λ⁻ if not pinned (1/yr)"]) and np.isnan(row["λ⁺ if not pinned (1/yr)"])
        else:
            assert row["λ⁻ if not pinned (1/yr)"] == float(lower.sel(limit_state=label))
            assert row["λ⁺ if not pinned (1/yr)"] == float(upper.sel(limit_state=label))
    assert not bool(pinned.all())  # the store has a fit its runs do not pin
