"""The result of one simulation as an :class:`xarray.Dataset` (names of CONTRACT.md).

Outputs are given at the motion's sample times, t = 0 included. Every
variable carries ``units`` and ``long_name`` (CF conventions).

Every array is built with numpy first and the dataset is assembled directly
from its variables (:func:`_assemble`): xarray's usual construction converts,
aligns and merges every variable, which would cost more than a whole exact run.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import xarray as xr
from xarray.indexes import PandasIndex

from stochpound import __version__
from stochpound.atomic import replacing
from stochpound.events import EventCounters
from stochpound.recorder import ENERGY_TERMS, Recorder
from stochpound.scene import Scene
from stochpound.system import System

_ENERGY_NAMES = {
    "input": "work of the ground-acceleration load (relative-motion input energy)",
    "damping": "energy dissipated by the storey dashpots",
    "friction": "energy dissipated by base friction",
    "impact": "work absorbed by the impact elements (dissipated, plus stored while closed)",
}


def _var(dims: tuple[str, ...], data: np.ndarray, units: str, long_name: str, **attrs: Any) -> xr.Variable:
    return xr.Variable(dims, data, {"units": units, "long_name": long_name, **attrs}, fastpath=True)


def build_dataset(scene: Scene, system: System, recorder: Recorder, counters: EventCounters, solver_attrs: dict[str, Any]) -> xr.Dataset:
    """Assemble the result dataset of one run.

    Parameters
    ----------
    scene, system : the simulated scene and its assembled system.
    recorder : Recorder with the recorded outputs.
    counters : EventCounters of the run.
    solver_attrs : dict
        Solver name and settings, stored as attributes.
    """
    coords = {
        "time": _var(("time",), scene.motion.times, "s", "time"),
        "building": _var(("building",), np.array(scene.building_names, dtype=object), "1", "building name, left to right"),
        "floor": _var(("floor",), np.arange(1, scene.max_floors + 1), "1", "floor number, 1 = lowest"),
        "contact": _var(("contact",), np.arange(len(scene.contacts)), "1", "contact index"),
    }
    data_vars = {
        **_response_variables(scene, system, recorder),
        **_contact_variables(scene),
        **_impact_variables(recorder),
        **_energy_variables(recorder),
    }
    attrs = {
        "title": "stochpound simulation",
        "Conventions": "CF-1.10",
        "stochpound_version": __version__,
        "scene_source": scene.source,
        "motion": scene.motion.description,
        "g": scene.g,
        "study_compat": int(scene.study_compat),
        **solver_attrs,
        **counters.as_attrs(),
    }
    return _assemble(coords, data_vars, attrs)


def _assemble(coords: dict[str, xr.Variable], data_vars: dict[str, xr.Variable], attrs: dict[str, Any]) -> xr.Dataset:
    """The dataset of dimension coordinates ``coords`` (with default indexes) and ``data_vars``, consistent by construction.

    The same dataset as ``xr.Dataset(data_vars, coords=coords, attrs=attrs)``
    (checked by the tests), without the conversion, alignment and merge of
    every variable (the indexes are built from :class:`pandas.Index` objects,
    which also spares xarray's check for dask arrays, and its import of dask).
    """
    indexes = {name: PandasIndex(pd.Index(variable.values, dtype=variable.dtype), name, coord_dtype=variable.dtype) for name, variable in coords.items()}
    variables = {name: indexes[name].create_variables({name: variable})[name] for name, variable in coords.items()}
    variables.update(data_vars)
    dims: dict[str, int] = {}
    for variable in variables.values():
        dims.update(zip(variable.dims, variable.shape))
    return xr.Dataset._construct_direct(variables, set(coords), dims, attrs, indexes)


def _response_variables(scene: Scene, system: System, recorder: Recorder) -> dict[str, xr.Variable]:
    """Displacements, ground acceleration, contact and friction forces and base states at the samples."""
    q = recorder.states[:, : system.n_dof]
    n_times, n_buildings, n_floors = len(scene.motion.times), len(scene.buildings), scene.max_floors
    relative = np.full((n_buildings, n_floors, n_times), np.nan)
    sliding = np.zeros((n_buildings, n_times))
    for b, building in enumerate(scene.buildings):
        relative[b, : building.n_floors] = q[:, system.floor_dofs[b]].T
        if system.base_dofs[b] >= 0:
            sliding[b] = q[:, system.base_dofs[b]]
    return {
        "total_displacement": _var(("building", "floor", "time"), relative + sliding[:, None, :], "m",
                                   "floor displacement relative to the ground (y = s + u)"),
        "relative_displacement": _var(("building", "floor", "time"), relative, "m", "floor displacement relative to the building's base (u)"),
        "sliding_displacement": _var(("building", "time"), sliding, "m", "sliding displacement of the base relative to the ground (s)"),
        "ground_acceleration": _var(("time",), np.asarray(scene.motion.at_times(), float), "m s-2", "ground acceleration a_g"),
        "impact_force": _var(("contact", "time"), recorder.forces.T, "N", "contact force, positive in compression (0 while open)"),
        "base_friction_force": _var(
            ("building", "time"), recorder.friction.T, "N", "force of the foundation on the base, positive to the right (0 for a fixed base)"
        ),
        "base_state": _var(
            ("building", "time"), recorder.base_states.T, "1", "base state",
            flag_values=np.array([-1, 0, 1], dtype=np.int8), flag_meanings="slipping_left stuck_or_fixed slipping_right",
        ),
    }


def _contact_variables(scene: Scene) -> dict[str, xr.Variable]:
    names = scene.building_names
    contacts = scene.contacts
    return {
        "contact_left": _var(("contact",), np.array([names[c.left] for c in contacts], dtype=object), "1", "left building of the contact"),
        "contact_left_floor": _var(("contact",), np.array([c.left_floor for c in contacts], dtype=int), "1", "floor of the left building"),
        "contact_right": _var(("contact",), np.array([names[c.right] for c in contacts], dtype=object), "1", "right building of the contact"),
        "contact_right_floor": _var(("contact",), np.array([c.right_floor for c in contacts], dtype=int), "1", "floor of the right building"),
        "contact_gap": _var(("contact",), np.array([c.gap for c in contacts], float), "m", "at-rest gap"),
        "contact_stiffness": _var(("contact",), np.array([c.stiffness for c in contacts], float), "N m-1", "impact spring stiffness"),
        "contact_damping": _var(("contact",), np.array([c.damping for c in contacts], float), "N s m-1", "impact dashpot"),
    }


def _impact_variables(recorder: Recorder) -> dict[str, xr.Variable]:
    impacts = recorder.impacts

    def column(name, dtype=float):
        return np.array([getattr(impact, name) for impact in impacts], dtype=dtype)

    start, end = column("start"), column("end")
    dims = ("impact",)
    return {
        "impact_contact": _var(dims, column("contact", int), "1", "contact index of the impact"),
        "impact_start": _var(dims, start, "s", "time the impact began"),
        "impact_end": _var(dims, end, "s", "time the impact ended (end of the motion if still closed)"),
        "impact_duration": _var(dims, end - start, "s", "impact duration"),
        "impact_peak_force": _var(dims, column("peak_force"), "N", "largest contact force of the impact"),
        "impact_peak_time": _var(dims, column("peak_time"), "s", "time of the largest contact force"),
        "impact_impulse": _var(dims, column("impulse"), "N s", "time integral of the contact force"),
        "impact_onset_velocity": _var(dims, column("onset_velocity"), "m s-1", "approach velocity (rate of penetration) at onset"),
        "impact_in_phase": _var(dims, column("in_phase", bool), "1", "both floors moving the same way at onset"),
        "impact_complete": _var(dims, column("complete", bool), "1", "the impact ended before the end of the motion"),
    }


def _energy_variables(recorder: Recorder) -> dict[str, xr.Variable]:
    kinetic, strain = recorder.kinetic_and_strain()
    energy = recorder.energy
    variables = {f"energy_{term}": _var(("time",), energy[term], "J", _ENERGY_NAMES[term]) for term in ENERGY_TERMS}
    variables["energy_kinetic"] = _var(("time",), kinetic, "J", "kinetic energy of the motion relative to the ground")
    variables["energy_strain"] = _var(("time",), strain, "J", "strain energy of storeys and base restoring springs")
    residual = energy["input"] - (kinetic - kinetic[0]) - (strain - strain[0]) - energy["damping"] - energy["friction"] - energy["impact"]
    variables["energy_residual"] = _var(("time",), residual, "J", "input minus every other term (0 for an exact solution)")
    return variables


def write_dataset(dataset: xr.Dataset, path: str | Path) -> Path:
    """Write ``dataset`` as netCDF4/HDF5 atomically (a temporary file renamed into place).

    An interrupted write never leaves a partial file at ``path``; the file's
    permissions follow the umask (:mod:`stochpound.atomic`).
    """
    path = Path(path)
    with replacing(path) as temporary:
        dataset.to_netcdf(temporary, engine="h5netcdf", invalid_netcdf=False)
    return path
