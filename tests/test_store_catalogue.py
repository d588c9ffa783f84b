"""The store's declared catalogue of variables against what a real run and its summaries return."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from stochpound.analysis._summary import top_floor_total_displacement
from stochpound.store import (CASE_SUMMARIES, CATALOGUE, IMPACT_TABLE, STOREY_SUMMARIES, WALL_SUMMARIES, REFERENCE_HISTORY, REFERENCE_SUMMARIES, TIME_HISTORIES,
                              StoreVariable)
from stochpound.experiment._spec import TIME_HISTORY_VARIABLES
from stochpound.experiment._summary import DEMAND_SUMMARIES, REFERENCE_SUMMARIES as REFERENCE_NAMES, STOREY_SOURCES, case_summary, case_values, reference_summary
from stochpound.model.scene_file import scene_from_dict
from stochpound.solvers.simulate import simulate


@pytest.fixture(scope="module")
def run() -> xr.Dataset:
    """Two two-storey buildings (the right one stiffer), the left one on a sliding base, one contact that closes; demands kept."""
    building = {"mass": [1.0, 1.0], "stiffness": [40.0, 40.0], "damping_ratio": 0.05}
    scene = scene_from_dict(
        {
            "building": [{"name": "A", **building, "base": {"mass": 1.0, "mu": 0.3}}, {"name": "B", **building, "stiffness": [400.0, 400.0]}],
            "contact": [{"between": [["A", 2], ["B", 2]], "gap": 0.01, "stiffness": 400.0, "restitution": 0.5}],
            "motion": {"type": "harmonic", "amplitude": 3.0, "omega": 5.0, "duration": 3.0, "dt": 0.01},
        },
        source="catalogue test",
    )
    result = simulate(scene, "ivp", demands=True)
    assert int(result["impact_contact"].size) > 0  # the impact table has rows
    return result


def _check(variable: StoreVariable, data: xr.DataArray) -> None:
    assert tuple(d for d in data.dims if d != "time") == variable.dims, variable.name
    assert data.dtype.kind == np.dtype(variable.dtype).kind, variable.name
    assert {k: data.attrs.get(k) for k in ("units", "long_name")} == variable.attrs, variable.name


def test_case_summaries_are_declared(run: xr.Dataset) -> None:
    """Every summary of a case, in order, with its dimensions, dtype, units and long name."""
    summary = case_summary(run, "A", top_floor_total_displacement(run, "A"))
    assert list(summary.data_vars) == [v.name for v in CASE_SUMMARIES + WALL_SUMMARIES + STOREY_SUMMARIES]
    for variable in CASE_SUMMARIES + WALL_SUMMARIES + STOREY_SUMMARIES:
        _check(variable, summary[variable.name])
    assert set(DEMAND_SUMMARIES) <= {v.name for v in CASE_SUMMARIES}


def test_reference_summaries_are_declared(run: xr.Dataset) -> None:
    """The fixed-base reference's summaries (the studied building alone)."""
    summary = reference_summary(run.isel(building=[0]), "A")
    assert list(summary.data_vars) == [v.name for v in REFERENCE_SUMMARIES] == [f"reference_{n}" for n in REFERENCE_NAMES]
    for variable in REFERENCE_SUMMARIES:
        _check(variable, summary[variable.name])


def test_time_histories_and_impacts_are_declared(run: xr.Dataset) -> None:
    """Every history an experiment can keep and every impact column, as simulate() returns them."""
    assert tuple(TIME_HISTORIES) == TIME_HISTORY_VARIABLES
    for variable in TIME_HISTORIES.values():
        assert run[variable.name].dims[-1] == "time"
        _check(variable, run[variable.name])
    for variable in IMPACT_TABLE:
        _check(variable, run[variable.name])
    assert REFERENCE_HISTORY.dims == TIME_HISTORIES["total_displacement"].dims[1:]
    assert REFERENCE_HISTORY.units == TIME_HISTORIES["total_displacement"].units


def test_the_catalogue_declares_each_variable_once_and_derived_units_agree():
    """One declaration per name; a peak, a moment or a reference has the units of the history it is taken from."""
    declared = [*CASE_SUMMARIES, *WALL_SUMMARIES, *STOREY_SUMMARIES, *REFERENCE_SUMMARIES, *TIME_HISTORIES.values(), REFERENCE_HISTORY, *IMPACT_TABLE]
    assert len(CATALOGUE) == len(declared) and all(CATALOGUE[v.name] is v for v in declared)
    taken_from = {
        "peak_total_displacement": "total_displacement", "peak_relative_displacement": "relative_displacement",
        "peak_sliding_displacement": "sliding_displacement", "residual_sliding": "sliding_displacement",
        "peak_impact_force": "impact_force", "impact_peak_force": "impact_force", "response_mean": "total_displacement",
        "response_std": "total_displacement", "reference_total_displacement": "total_displacement",
        "peak_floor_acceleration": "ground_acceleration", "peak_wall_penetration": "peak_contact_closure",
        "residual_drift": "total_displacement",
    }
    for derived, source in taken_from.items():
        assert CATALOGUE[derived].units == CATALOGUE[source].units, derived
    for variable in REFERENCE_SUMMARIES:
        own = CATALOGUE[variable.name.removeprefix("reference_")]
        assert (variable.units, variable.long_name) == (own.units, own.long_name + " (studied building alone on a fixed base)")


def test_storey_summaries_are_the_largest_over_each_buildings_storeys() -> None:
    """A yielding building with storey heights next to an elastic one: the storey summaries per building, in both paths (xarray and kernels)."""
    from stochpound.studies.agarwal2004 import study_scene

    scene = study_scene(None, None, 2.0, gap=0.01)
    scene["building"][0].update(yield_force=[1.0e5, 0.7e5], hardening=0.05, storey_height=[3.5, 3.0])
    run = simulate(scene_from_dict(scene), "exact", demands=True)
    summary = case_summary(run, "B1", top_floor_total_displacement(run, "B1"))
    values = case_values(run, "B1", top_floor_total_displacement(run, "B1").values)
    assert float(summary["peak_ductility"].sel(building="B1")) > 1.5  # it yields
    for name, source in STOREY_SOURCES.items():
        _check(CATALOGUE[name], summary[name])
        np.testing.assert_array_equal(summary[name].values, values[name])
        expected = [np.max(np.abs(run[source].sel(building="B1").values)), np.nan]  # B2 is elastic and gives no heights
        if name == "residual_drift":
            expected[1] = 0.0  # an elastic storey of a yielding run keeps no drift
        np.testing.assert_array_equal(summary[name].values, expected, err_msg=name)
    assert float(summary["residual_drift"].sel(building="B1")) > 0.0
