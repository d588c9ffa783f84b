"""Scenes of the benchmarks: the reference study's pairs and synthetic rows for the scaling runs.

The study scenes are built with :func:`stochpound.studies.agarwal2004.study_scene`
(the study's buildings and contacts, El Centro as the study used it, g = 9.814):

(a) Building 1 isolated (μ = 0.2) next to the flexible fixed-base Building 2,
    gap 2 cm at both levels: the main scene;
(b) both fixed, flexible Building 2, gap 2 cm;
(c) both isolated (μ = 0.1), stiff Building 2, gap 1 cm: also the scene of
    the ensemble runs.
"""

from __future__ import annotations

import copy
import dataclasses
from dataclasses import dataclass
from typing import Any

import numpy as np
import xarray as xr

import stochpound
from stochpound import motions
from stochpound.motions.ground import SampledMotion
from stochpound.model.scene import Scene
from stochpound.studies.agarwal2004 import IMPACT_FREQUENCY, REFERENCE_MASS, REFERENCE_STIFFNESS, study_scene

STUDY_RECORD = "el_centro_1940_study"
KANAI_TAJIMI = {**motions.soil_preset("firm").kanai_tajimi(), "pga": 0.34 * 9.814, "envelope": "jennings", "seed": 2004}
"""The synthetic motions of the ensemble and scaling runs: firm soil, El Centro's peak (0.34 g), Jennings envelope."""


PAIR_MOTION = {"type": "kanai_tajimi", "omega_g": 15.0, "zeta_g": 0.6, "pga": 2.0, "envelope": "jennings", "method": "filter", "duration": 10.0, "dt": 0.02}
"""The rare-event benchmarks' pounding pair's ground motion (a synthetic ensemble's fields)."""

@dataclass(frozen=True)
class StudyScene:
    """One of the study's configurations.

    Attributes
    ----------
    key : str
        ``a``, ``b`` or ``c``.
    title : str
        What it is, in words.
    mu1, mu2 : float or None
        Friction coefficients of the bases (None: fixed base).
    factor : float
        Mass factor of Building 2 (2 flexible, 0.5 stiff).
    gap : float
        Gap at both levels, m.
    """

    key: str
    title: str
    mu1: float | None
    mu2: float | None
    factor: float
    gap: float

    def scene(self, duration: float | None = None, interpolation: str = "linear", study_compat: bool = False) -> Scene:
        """The scene under El Centro (the first ``duration`` seconds when given)."""
        motion: dict[str, Any] = {"record": STUDY_RECORD, "interpolation": interpolation}
        if duration is not None:
            motion["duration"] = duration
        data = study_scene(self.mu1, self.mu2, self.factor, self.gap, motion=motion)
        data["study_compat"] = study_compat
        return stochpound.scene_from_dict(data, source=f"benchmark scene ({self.key})")


STUDY_SCENES = (
    StudyScene("a", "B1 isolated (μ = 0.2), B2 flexible and fixed, gap 2 cm", 0.2, None, 2.0, 0.02),
    StudyScene("b", "both fixed, B2 flexible, gap 2 cm", None, None, 2.0, 0.02),
    StudyScene("c", "both isolated (μ = 0.1), B2 stiff, gap 1 cm", 0.1, 0.1, 0.5, 0.01),
)
MAIN_SCENE = STUDY_SCENES[0]


def with_motion(scene: Scene, values: np.ndarray, dt: float, description: str = "") -> Scene:
    """``scene`` under another sampled ground motion (m/s², linear interpolation)."""
    return dataclasses.replace(scene, motion=SampledMotion(dt, np.asarray(values, float), "linear", description))


def kanai_tajimi_motions(n_realizations: int, duration: float, dt: float, start: int = 0, **overrides: Any) -> xr.DataArray:
    """Realizations ``start``.. of the benchmark's Kanai–Tajimi motion (:data:`KANAI_TAJIMI` updated by ``overrides``), m/s²."""
    return motions.kanai_tajimi(n_realizations, duration, dt, start=start, **{**KANAI_TAJIMI, **overrides})


def kanai_tajimi_values(n_realizations: int, duration: float, dt: float, start: int) -> np.ndarray:
    """The samples of :func:`kanai_tajimi_motions` (realization × time), m/s²."""
    return np.asarray(kanai_tajimi_motions(n_realizations, duration, dt, start).values)


def lazy_kanai_tajimi_motions(n_realizations: int, duration: float, dt: float, chunk: int = 64) -> xr.DataArray:
    """:func:`kanai_tajimi_motions` as a dask-backed array, generated ``chunk`` realizations at a time on demand."""
    import dask
    import dask.array as da

    n_times = int(round(duration / dt)) + 1
    blocks = [
        da.from_delayed(dask.delayed(kanai_tajimi_values)(min(chunk, n_realizations - s), duration, dt, s), (min(chunk, n_realizations - s), n_times), float)
        for s in range(0, n_realizations, chunk)
    ]
    values = da.concatenate(blocks, axis=0)
    return xr.DataArray(values, dims=("realization", "time"), coords={"realization": np.arange(n_realizations), "time": np.arange(n_times) * dt})


def building_row(n_buildings: int, n_floors: int, gap: float = 0.02, duration: float | None = None) -> Scene:
    """A row of ``n_buildings`` shear buildings of ``n_floors`` floors each, under El Centro.

    Floors are the study's reference floors (the lower ones like its floor 1,
    the top one like its floor 2), masses scaled by 1, 2, 0.5, 1, 2, ... from
    left to right; the odd-numbered buildings (B1, B3, ...) stand on sliding
    bases with μ = 0.2 and half a floor's mass; neighbours can collide at
    every floor, with the study's impact elements and ``gap``.
    """
    factors = [(1.0, 2.0, 0.5)[j % 3] for j in range(n_buildings)]
    buildings = [_row_building(f"B{j + 1}", n_floors, factor, isolated=j % 2 == 0) for j, factor in enumerate(factors)]
    contacts = [
        _row_contact(left, right, floor, gap)
        for left, right in zip(buildings[:-1], buildings[1:])
        for floor in range(1, n_floors + 1)
    ]
    motion: dict[str, Any] = {"record": STUDY_RECORD}
    if duration is not None:
        motion["duration"] = duration
    data = {"g": 9.814, "building": buildings, "contact": contacts, "motion": motion}
    return stochpound.scene_from_dict(copy.deepcopy(data), source=f"benchmark row {n_buildings}x{n_floors}")


def _row_building(name: str, n_floors: int, factor: float, isolated: bool) -> dict[str, Any]:
    lower, top = REFERENCE_MASS
    mass = [lower * factor] * (n_floors - 1) + [top * factor]
    stiffness = [REFERENCE_STIFFNESS[0]] * (n_floors - 1) + [REFERENCE_STIFFNESS[1]]
    building: dict[str, Any] = {"name": name, "mass": mass, "stiffness": stiffness, "damping_ratio": 0.01}
    if isolated:
        building["base"] = {"mass": 0.5 * mass[0], "mu": 0.2}
    return building


def _row_contact(left: dict[str, Any], right: dict[str, Any], floor: int, gap: float) -> dict[str, Any]:
    m1, m2 = left["mass"][floor - 1], right["mass"][floor - 1]
    stiffness = IMPACT_FREQUENCY**2 * m1 * m2 / (m1 + m2)
    return {"between": [[left["name"], floor], [right["name"], floor]], "gap": gap, "stiffness": stiffness, "restitution": 0.5}
