"""stochpound: stochastic analysis of earthquake pounding between adjacent buildings.

The main entry points are :func:`load_scene` (read and validate a scene file)
and :func:`simulate` (run one scene and return an :class:`xarray.Dataset`).
"""

__version__ = "0.1.0"

from stochpound._errors import RecordError, SceneError, SiteError, StochpoundError  # noqa: E402
from stochpound.model.scene_file import load_scene, scene_from_dict  # noqa: E402
from stochpound.solvers.simulate import simulate  # noqa: E402
from stochpound.experiment._store import open_store  # noqa: E402
from stochpound.experiment._ensemble import simulate_ensemble  # noqa: E402
from stochpound.experiment._spec import ExperimentError  # noqa: E402

__all__ = ["__version__", "load_scene", "scene_from_dict", "simulate", "simulate_ensemble", "open_store", "ExperimentError", "SceneError", "RecordError", "SiteError", "StochpoundError"]
