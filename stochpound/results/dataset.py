"""The result of one simulation as an :class:`xarray.Dataset` (the names of docs/scene-files.md).

Outputs are given at the motion's sample times, t = 0 included. Every
variable carries ``units`` and ``long_name`` (CF conventions); those of the
time histories a store can keep are the store's catalogue's
(``stochpound.store.TIME_HISTORIES``), declared once there.
"""

from __future__ import annotations

import functools
from pathlib import Path
from typing import Any, Sequence

import numpy as np
import xarray as xr

from stochpound import __version__
from stochpound._atomic import replacing
from stochpound.results.record import ENERGY_TERMS, EventCounters, Recorder
from stochpound.model.contact import ImpactElement
from stochpound.model import laws, yielding
from stochpound.model.scene import Scene
from stochpound.model.system import System
from stochpound.store import TIME_HISTORIES


def _history(name: str, data: np.ndarray, **attrs: Any) -> tuple:
    """A time history of the store's catalogue: its dimensions then ``time``, its ``units`` and ``long_name``."""
    variable = TIME_HISTORIES[name]
    return (*variable.dims, "time"), data, {**variable.attrs, **attrs}


def _var(dims: tuple[str, ...], data: np.ndarray, units: str, long_name: str, **attrs: Any) -> tuple:
    """A variable (dims, data, attrs) with its CF ``units`` and ``long_name``."""
    return dims, data, {"units": units, "long_name": long_name, **attrs}


def build_dataset(scene: Scene, system: System, recorder: Recorder, counters: EventCounters, solver_attrs: dict[str, float | str]) -> xr.Dataset:
    """Assemble the result dataset of one run.

    Parameters
    ----------
    scene, system : the simulated scene and its assembled system.
    recorder : Recorder with the recorded outputs.
    counters : EventCounters of the run.
    solver_attrs : dict[str, float | str]
        Solver name and settings (``solver``, ``rtol``...), stored as attributes.
    """
    data_vars = {
        **_response_variables(scene, system, recorder),
        **scene_parameters(scene),
        **(_wall_variables(scene, recorder) if scene.walls else {}),
        **_closure_variables(recorder, system.n_contacts, "contact"),
        **_contact_displacement_variables(recorder),
        **(_closure_variables(recorder, system.n_contacts, "wall") if scene.walls else {}),
        **_impact_variables(recorder, system.n_contacts, bool(scene.walls)),
        **(_demand_variables(scene, recorder) if recorder.demands else {}),
        **(_yielding_variables(scene, recorder) if system.storeys else {}),
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
    coordinates = _coordinates(np.asarray(scene.motion.times, float).tobytes(), tuple(scene.building_names), scene.max_floors,
                               len(scene.contacts), len(scene.walls))
    return xr.Dataset(data_vars, coords=coordinates, attrs=attrs)


@functools.lru_cache(maxsize=16)
def _coordinates(times: bytes, building_names: tuple[str, ...], max_floors: int, n_contacts: int, n_walls: int) -> xr.Coordinates:
    """The dimension coordinates of a result: time (``times``, float64 bytes, s), building, floor, contact and wall.

    Built once per layout and output times and shared by the datasets of
    every run with them (an ensemble's): their indexes are immutable and
    each dataset copies the variables it takes, so a result changed in
    place changes no other. Building them costs about as much as the rest
    of the dataset (docs/benchmarks.md, "Against an earlier revision").
    """
    coords = {
        "time": _var(("time",), np.frombuffer(times, float), "s", "time"),
        "building": _var(("building",), np.array(building_names, dtype=str), "1", "building name, left to right"),
        "floor": _var(("floor",), np.arange(1, max_floors + 1), "1", "floor number, 1 = lowest"),
        "contact": _var(("contact",), np.arange(n_contacts), "1", "contact index"),
        **({"wall": _var(("wall",), np.arange(n_walls), "1", "wall index")} if n_walls else {}),
    }
    return xr.Coordinates(coords)


def _response_variables(scene: Scene, system: System, recorder: Recorder) -> dict[str, tuple]:
    """Displacements, ground acceleration, contact and friction forces and base states at the samples."""
    relative, sliding = recorder.displacements()
    return {
        "total_displacement": _history("total_displacement", relative + sliding[:, None, :]),
        "relative_displacement": _history("relative_displacement", relative),
        "sliding_displacement": _history("sliding_displacement", sliding),
        "ground_acceleration": _history("ground_acceleration", np.asarray(scene.motion.at_times(), float)),
        "impact_force": _history("impact_force", recorder.forces[:, : system.n_contacts].T),
        "base_friction_force": _history("base_friction_force", recorder.by_building(recorder.friction)),
        "base_state": _history(
            "base_state", recorder.by_building(recorder.base_states),
            flag_values=np.array([-1, 0, 1], dtype=np.int8), flag_meanings="slipping_left stuck_or_fixed slipping_right",
        ),
    }


def _closure_variables(recorder: Recorder, n_contacts: int, kind: str) -> dict[str, tuple]:
    """The closure over time of each contact (``kind`` "contact", the first ``n_contacts`` elements) or wall, and its peak over the run, located on the solution."""
    rows = slice(0, n_contacts) if kind == "contact" else slice(n_contacts, recorder.system.n_elements)  # the other monitors follow the elements
    toward = "y_left - y_right of the contact's floors" if kind == "contact" else "the level's displacement toward the wall"
    return {
        f"{kind}_closure": _var((kind, "time"), recorder.closure()[rows], "m", f"closure {toward} (the gap is closed where it reaches the gap)"),
        f"peak_{kind}_closure": _var((kind,), recorder.peaks[0, rows], "m", "largest closure over the run: the separation this run needed"),
        f"peak_{kind}_closure_time": _var((kind,), recorder.peaks[1, rows], "s", "time of the largest closure"),
    }


def _contact_displacement_variables(recorder: Recorder) -> dict[str, tuple]:
    """The largest abs(y) of each contact's two floors over the run and when, located on the solution: the separation rules' u1, u2.

    NaN for a contact with a finite gap (:meth:`~stochpound.results.record.Recorder.contact_displacement_peaks`).
    """
    variables = {}
    for side, (value, when) in zip(("left", "right"), recorder.contact_displacement_peaks()):
        variables[f"peak_contact_displacement_{side}"] = _var(("contact",), value, "m",
                                                              f"largest |y| of the contact's {side} floor over the run (y = s + u; NaN for a finite gap)")
        variables[f"peak_contact_displacement_{side}_time"] = _var(("contact",), when, "s", f"time of the largest |y| of the contact's {side} floor")
    return variables


_DEMAND_NAMES = {
    "total_acceleration": ("m s-2", "total floor acceleration (relative acceleration of the floor and its base, plus the ground's)"),
    "storey_drift": ("m", "storey drift u_i - u_(i-1) (u_0 = 0, the base)"),
    "storey_shear": ("N", "storey shear k_i d_i + c_i d'_i of the storey below the floor"),
}


def _demand_variables(scene: Scene, recorder: Recorder) -> dict[str, tuple]:
    """The demand parameters at the samples and their peaks (absolute values) over the run, located on the solution."""
    variables = {}
    peaks = recorder.demand_peaks()
    for name, (units, long_name) in _DEMAND_NAMES.items():
        variables[name] = _var(("building", "floor", "time"), recorder.by_floor(recorder.demands[name]), units, long_name)
        peak, when = peaks[name]
        variables[f"peak_{name}"] = _var(("building", "floor"), recorder.by_floor(peak), units, f"largest absolute {name.replace('_', ' ')} over the run")
        variables[f"peak_{name}_time"] = _var(("building", "floor"), recorder.by_floor(when), "s", f"time of the largest absolute {name.replace('_', ' ')}")
    shear, peak_shear, when = variables["storey_shear"][1], variables["peak_storey_shear"][1], variables["peak_storey_shear_time"][1]
    variables["base_shear"] = _var(("building", "time"), shear[:, 0], "N", "base shear: the shear of the first storey")
    variables["peak_base_shear"] = _var(("building",), peak_shear[:, 0], "N", "largest absolute base shear over the run")
    variables["peak_base_shear_time"] = _var(("building",), when[:, 0], "s", "time of the largest absolute base shear")
    height = _storey_heights(scene)
    if height is not None:
        drift = variables["storey_drift"][1]
        variables["storey_drift_ratio"] = _var(("building", "floor", "time"), drift / height[:, :, None], "1", "storey drift over the storey height")
        variables["peak_storey_drift_ratio"] = _var(("building", "floor"), variables["peak_storey_drift"][1] / height, "1",
                                                    "largest absolute storey drift ratio over the run")
    return variables


def _yielding_variables(scene: Scene, recorder: Recorder) -> dict[str, tuple]:
    """The yielding storeys' plastic drifts over time, their peak ductility (located on the solution) and residual drifts (0 or NaN for elastic storeys)."""
    system = recorder.system
    shape = (len(scene.buildings), scene.max_floors)
    plastic_drift, _ = recorder.plastic_drifts()
    plastic = recorder.by_floor(np.zeros((len(system.total_displacement), len(recorder.motion.times))))
    ductility, residual = np.full(shape, np.nan), recorder.by_floor(np.zeros(len(system.total_displacement)))
    peaks = recorder.storey_drift_peaks()
    for j, storey in enumerate(system.storeys):
        plastic[storey.building, storey.storey] = plastic_drift[j]
        ductility[storey.building, storey.storey] = peaks[0, j] / storey.yield_drift
        residual[storey.building, storey.storey] = yielding.residual_drift(storey, plastic_drift[j, -1])
    variables = {
        "storey_plastic_drift": _var(("building", "floor", "time"), plastic, "m", "plastic drift z of the storey below the floor (0 for an elastic storey)"),
        "peak_storey_ductility": _var(("building", "floor"), ductility, "1", "largest absolute storey drift over its yield drift F_y / k (NaN for an elastic storey)"),
        "residual_storey_drift": _var(("building", "floor"), residual, "m", "drift the storey keeps at rest after the run: (1 - alpha) z at the end"),
    }
    height = _storey_heights(scene)
    if height is not None:
        variables["residual_storey_drift_ratio"] = _var(("building", "floor"), residual / height, "1", "residual storey drift over the storey height")
    return variables


def _storey_heights(scene: Scene) -> np.ndarray | None:
    """Each storey's height (building × floor, m; NaN where a building gives none or above its top floor), or None when no building gives ``storey_height``."""
    heights = [b.storey_height for b in scene.buildings]
    if all(h is None for h in heights):
        return None
    height = np.full((len(heights), scene.max_floors), np.nan)
    for b, h in enumerate(heights):
        if h is not None:
            height[b, : len(h)] = h
    return height


def _wall_variables(scene: Scene, recorder: Recorder) -> dict[str, tuple]:
    """Each wall's force over time."""
    n_contacts = len(scene.contacts)
    return {"wall_force": _var(("wall", "time"), recorder.forces[:, n_contacts:].T, "N", "force of the wall's impact element, positive in compression (0 while open)")}


def _wall_parameters(scene: Scene) -> dict[str, tuple]:
    """What each wall is: its building, side, level, gap, stiffness and damping."""
    names, walls = scene.building_names, scene.walls
    return {
        "wall_building": _var(("wall",), np.array([names[w.building] for w in walls], dtype=str), "1", "building beside the wall"),
        "wall_side": _var(("wall",), np.array([w.side_name for w in walls], dtype=str), "1", "side of the building the wall is on"),
        "wall_level": _var(("wall",), np.array([w.level for w in walls], dtype=int), "1", "level the wall faces: 0 the base, else the floor"),
        "wall_gap": _var(("wall",), np.array([w.gap for w in walls], float), "m", "at-rest gap"),
        "wall_stiffness": _var(("wall",), np.array([w.stiffness for w in walls], float), "N m-1", "impact spring stiffness"),
        "wall_damping": _var(("wall",), np.array([w.damping for w in walls], float), "N s m-1", "impact dashpot"),
    }


def scene_parameters(scene: Scene) -> dict[str, tuple]:
    """What a scene runs with: each building's base, each contact and wall with its law's parameters.

    Returns
    -------
    dict
        ``base_*`` (dimension ``building``), ``contact_*`` (``contact``) and
        ``wall_*`` (``wall``, with walls): name -> (dims, values, attrs), as
        the variables of a result (and the coordinates of an experiment store).
    """
    return {
        **_base_variables(scene),
        **_contact_variables(scene),
        **_element_variables("contact", scene.contacts),
        **(_wall_parameters(scene) if scene.walls else {}),
        **(_element_variables("wall", scene.walls) if scene.walls else {}),
    }


def _base_variables(scene: Scene) -> dict[str, tuple]:
    """Each building's base as run: its friction law's parameters (:data:`~stochpound.model.laws.FRICTION_VARIABLES`; μ = ∞ for a fixed base), its mass and restoring force."""
    bases = [b.base for b in scene.buildings]

    def column(field: str, fixed: float = np.nan) -> np.ndarray:
        return np.array([fixed if base is None else np.nan if getattr(base, field) is None else getattr(base, field) for base in bases], float)

    restoring = [np.nan if b.base is None else b.base.restoring(scene.g * (b.base.mass + sum(b.mass))) for b in scene.buildings]
    friction = {v.name: _var(("building",), column(v.field, v.missing), v.units, v.long_name) for v in laws.FRICTION_VARIABLES}
    return {
        **friction,
        "base_mass": _var(("building",), column("mass"), "kg", "base mass (nan: a fixed base)"),
        "base_restoring_stiffness": _var(("building",), np.array(restoring, float), "N m-1",
                                         "restoring stiffness of the base (W/R for a friction pendulum; nan: a fixed base)"),
        "base_radius": _var(("building",), column("radius"), "m", "radius of the friction pendulum (nan: a flat slider or a fixed base)"),
    }


def _element_variables(kind: str, elements: Sequence[ImpactElement]) -> dict[str, tuple]:
    """The law of each impact element of ``kind`` (``contact`` or ``wall``) as run, beside its gap, stiffness and damping."""
    return {
        f"{kind}_law": _var((kind,), np.array([e.law for e in elements], dtype=str), "1", "contact law of the impact element"),
        f"{kind}_restitution": _var((kind,), np.array([np.nan if e.restitution is None else e.restitution for e in elements], float), "1",
                                    "coefficient of restitution the damping was derived from (nan: damping given)"),
        f"{kind}_tensile": _var((kind,), np.array([e.tensile for e in elements], dtype=bool), "1",
                                "the element separates when the penetration returns to 0 (false: when its force does)"),
    }


def _contact_variables(scene: Scene) -> dict[str, tuple]:
    names = scene.building_names
    contacts = scene.contacts
    return {
        "contact_left": _var(("contact",), np.array([names[c.left] for c in contacts], dtype=str), "1", "left building of the contact"),
        "contact_left_floor": _var(("contact",), np.array([c.left_floor for c in contacts], dtype=int), "1", "floor of the left building"),
        "contact_right": _var(("contact",), np.array([names[c.right] for c in contacts], dtype=str), "1", "right building of the contact"),
        "contact_right_floor": _var(("contact",), np.array([c.right_floor for c in contacts], dtype=int), "1", "floor of the right building"),
        "contact_gap": _var(("contact",), np.array([c.gap for c in contacts], float), "m", "at-rest gap"),
        "contact_stiffness": _var(("contact",), np.array([c.stiffness for c in contacts], float), "N m-1", "impact spring stiffness"),
        "contact_damping": _var(("contact",), np.array([c.damping for c in contacts], float), "N s m-1", "impact dashpot"),
    }


def _impact_variables(recorder: Recorder, n_contacts: int, walls: bool) -> dict[str, tuple]:
    """One row per impact; with ``walls``, ``impact_wall`` names the wall of a wall impact (``impact_contact`` is then −1)."""
    impacts = recorder.impacts

    def column(name, dtype=float):
        return np.array([getattr(impact, name) for impact in impacts], dtype=dtype)

    start, end, element = column("start"), column("end"), column("contact", int)
    dims = ("impact",)
    wall = {"impact_wall": _var(dims, np.where(element >= n_contacts, element - n_contacts, -1), "1", "wall index of the impact (-1: a contact)")}
    return {
        "impact_contact": _var(dims, np.where(element < n_contacts, element, -1), "1", "contact index of the impact (-1: a wall)"),
        **(wall if walls else {}),
        "impact_start": _var(dims, start, "s", "time the impact began"),
        "impact_end": _var(dims, end, "s", "time the impact ended (end of the motion if still closed)"),
        "impact_duration": _var(dims, end - start, "s", "impact duration"),
        "impact_peak_force": _var(dims, column("peak_force"), "N", "largest contact force of the impact"),
        "impact_peak_time": _var(dims, column("peak_time"), "s", "time of the largest contact force"),
        "impact_impulse": _var(dims, column("impulse"), "N s", "time integral of the contact force"),
        "impact_onset_velocity": _var(dims, column("onset_velocity"), "m s-1", "approach velocity (rate of penetration) at onset"),
        "impact_in_phase": _var(dims, column("in_phase", bool), "1", "both floors moving the same way at onset (false at a wall, which moves with the ground)"),
        "impact_complete": _var(dims, column("complete", bool), "1", "the impact ended before the end of the motion"),
    }


def _energy_variables(recorder: Recorder) -> dict[str, tuple]:
    kinetic, strain = recorder.kinetic_and_strain()
    energy = recorder.energy
    variables = {f"energy_{term}": _history(f"energy_{term}", energy[term]) for term in ENERGY_TERMS}
    variables["energy_kinetic"] = _history("energy_kinetic", kinetic)
    variables["energy_strain"] = _history("energy_strain", strain)
    residual = energy["input"] - (kinetic - kinetic[0]) - (strain - strain[0]) - energy["damping"] - energy["friction"] - energy["impact"]
    if recorder.system.storeys:
        storeys = recorder.system.storeys
        hysteretic = np.array([storey.plastic_strength for storey in storeys]) @ recorder.plastic_drifts()[1]
        variables["energy_hysteretic"] = _var(("time",), hysteretic, "J", "energy dissipated by the yielding storeys ((1 - alpha) F_y times the accumulated plastic drift)")
        residual = residual - hysteretic
    variables["energy_residual"] = _history("energy_residual", residual)
    return variables


def write_dataset(dataset: xr.Dataset, path: str | Path) -> Path:
    """Write ``dataset`` as netCDF4/HDF5 atomically (a temporary file renamed into place).

    An interrupted write never leaves a partial file at ``path``; the file's
    permissions follow the umask (``stochpound._atomic``).
    """
    path = Path(path)
    with replacing(path) as temporary:
        dataset.to_netcdf(temporary, engine="h5netcdf", invalid_netcdf=False)
    return path
