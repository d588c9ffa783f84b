"""An experiment store's structural configurations as scenes, and what is computed from them to describe them.

A configuration is one combination of the values of the experiment's variant
axes; its scene is that of its first case with a finite μ (the grid's gaps and
μ are described separately). :class:`StoreScenes` reads them from the store's
grid once and computes the buildings' fixed-base modes, the code design's yield
shears and the impact elements' parameters a report describes.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np
import xarray as xr

from stochpound.model import design_yield_shears
from stochpound.model.contact import effective_mass
from stochpound.model.laws.contract import ElementParameters
from stochpound.model.modal_solution import Modes, modal_properties
from stochpound.model.scene import Building, Contact, Scene
from stochpound.model.scene_file import scene_from_dict
from stochpound.model.wall import Wall
from stochpound.store import CASE, Case, GapAxis, is_fixed_base


@dataclass(frozen=True)
class Configuration:
    """One structural configuration of an experiment: a combination of its variant axes' values.

    Attributes
    ----------
    labels : dict
        The variant axes' values (empty without variant axes).
    scene : Scene
        The scene of the configuration's first case with a finite μ (its
        gaps and μ are those of that case; the grid's values are described
        separately).
    """

    labels: dict[str, str]
    scene: Scene

    @property
    def name(self) -> str:
        """``neighbour = stiff, model = corrected``, or ``–`` without variant axes."""
        return ", ".join(f"{axis} = {value}" for axis, value in self.labels.items()) or "–"


class StoreScenes:
    """An experiment store's definition, with its configurations' scenes.

    Parameters
    ----------
    name : str
        The experiment's name.
    store : xarray.Dataset
        The store (its ``definition`` attribute is read).
    """

    def __init__(self, name: str, store: xr.Dataset) -> None:
        self.name = name
        self.store = store
        self.experiment = store.pound.grid
        self.definition = self.experiment.contract

    @cached_property
    def configurations(self) -> list[Configuration]:
        """One per combination of the variant axes, in grid order."""
        cases = [c for c in self.experiment.cases if c.kind == CASE]
        variant_axes = [v.name for v in self.experiment.variants]
        chosen: dict[tuple, Any] = {}
        for case in cases:
            labels = case.label_dict
            key = tuple(labels[axis] for axis in variant_axes)
            if key not in chosen or (not _fixed_by_mu(case) and _fixed_by_mu(chosen[key])):
                chosen[key] = case
        return [Configuration(dict(zip(variant_axes, key)), scene_from_dict(self.experiment.structure(case))) for key, case in chosen.items()]

    def takes_grid_mu(self, building: Building) -> bool:
        """Whether the grid's ``mu`` axis sets this building's friction (it must then stand on a base)."""
        mu = self.definition.mu
        return mu is not None and building.base is not None and mu.sets(building.name, has_base=True)

    @property
    def mu_values(self) -> list[float]:
        """The ``mu`` axis's values (empty without one)."""
        return list(self.definition.mu.values) if self.definition.mu is not None else []

    def gap_axis(self, contact: int) -> GapAxis | None:
        """The grid's gap axis that sets this contact's gap, if any."""
        return self.definition.contact_gap_axis(contact)

    @property
    def study_compat_cases(self) -> int:
        """How many grid cases run the study's equations (``study_compat``)."""
        return sum(1 for c in self.configurations if c.scene.study_compat) * self._cases_per_configuration

    @property
    def _cases_per_configuration(self) -> int:
        total = sum(1 for c in self.experiment.cases if c.kind == CASE)
        return total // max(len(self.configurations), 1)

    @property
    def energy_residual(self) -> float | None:
        """The largest energy residual over the stored cases, as a share of the energy input (None where the store has none)."""
        return float(self.store["energy_residual_ratio"].max()) if "energy_residual_ratio" in self.store else None

    @staticmethod
    def modes(building: Building) -> Modes:
        """The building's modes on a fixed base (:func:`stochpound.model.modal_solution.modal_properties`)."""
        return modal_properties(building)

    def design_shears(self, building: Building, g: float) -> tuple[float, np.ndarray]:
        """The building's first fixed-base period (s) and the yield shears (N) of the store's ``[design]`` at it
        (:func:`stochpound.model.design_yield_shears`; call for a building with storey heights in a store with a design)."""
        design = self.definition.design
        period = float(modal_properties(building).periods[0])
        return period, design_yield_shears(building.mass, building.storey_height, period=period, sds=design.sds, sd1=design.sd1, r=design.r,
                                           overstrength=design.omega0, importance=design.ie, long_period=design.tl, g=g)

    @staticmethod
    def contact_parameters(scene: Scene, contact: Contact) -> ElementParameters:
        """The contact's law parameters, with the effective mass of the two floors it joins."""
        left, right = scene.buildings[contact.left], scene.buildings[contact.right]
        return contact.parameters(effective_mass(left.mass[contact.left_floor - 1], right.mass[contact.right_floor - 1]))

    @staticmethod
    def wall_parameters(scene: Scene, wall: Wall) -> ElementParameters:
        """The wall's law parameters, with the mass of the level it faces (the base's at level 0)."""
        building = scene.buildings[wall.building]
        return wall.parameters(building.base.mass if wall.level == 0 and building.base is not None else building.mass[max(wall.level, 1) - 1])


def _fixed_by_mu(case: Case) -> bool:
    """Whether the grid's μ axis fixes the case's bases (μ = ∞; a case without a μ axis keeps them)."""
    return case.mu is not None and is_fixed_base(case.mu)
