"""The physical model: buildings, the laws of their bases and contacts, the scene, and the system and modes they make.

One module per concept: :mod:`~stochpound.model.building` (shear buildings),
:mod:`~stochpound.model.friction` (sliding bases), :mod:`~stochpound.model.contact`
(impact elements), :mod:`~stochpound.model.laws` (the law registry: the contract
and one module per contact or friction law), :mod:`~stochpound.model.scene` and
:mod:`~stochpound.model.scene_file` (a scene and its TOML file),
:mod:`~stochpound.model.system` (global matrices), :mod:`~stochpound.model.modes`
(the linear modes of the hybrid system and their guards),
:mod:`~stochpound.model.guards` (event kinds) and
:mod:`~stochpound.model.modal_solution` (a closed-form reference),
:mod:`~stochpound.model.yielding` (bilinear yielding storeys) and
:func:`design_yield_shears` (a code-designed building's yield shears);
:func:`bundled_scenes` and :func:`bundled_scene_path` find the scenes shipped with stochpound;
:func:`building_periods`, :func:`scene_periods` and :func:`scene_warnings` say what a scene's numbers mean at a glance.
"""

import importlib
import sys

from stochpound.model._design import design_yield_shears
from stochpound.model.building import Building, InitialState
from stochpound.model.contact import Contact, ImpactElement
from stochpound.model.friction import Base
from stochpound.model.scene import Scene
from stochpound.model.modal_solution import building_periods, scene_periods
from stochpound.model.scene_file import bundled_scene_path, bundled_scenes, scene_warnings
from stochpound.model.wall import Wall

__all__ = ["Scene", "Building", "InitialState", "Base", "Contact", "Wall", "ImpactElement", "design_yield_shears", "bundled_scenes", "bundled_scene_path",
           "building_periods", "scene_periods", "scene_warnings"]

_MOVED_LAWS = {"law": "contract", **{name: name for name in ("kelvin", "hertz", "hertz_damp_ye", "hertz_damp_exact", "jankowski", "coulomb",
                                                             "velocity_friction")}}
"""The law modules' paths before they moved into :mod:`stochpound.model.laws` (old name: new name): each old path is the same module."""
for _old, _new in _MOVED_LAWS.items():
    sys.modules[f"{__name__}.{_old}"] = importlib.import_module(f"{__name__}.laws.{_new}")
