"""stochpound: stochastic analysis of earthquake pounding between adjacent buildings.

The main entry points are :func:`load_scene` (read and validate a scene file)
and :func:`simulate` (run one scene and return an :class:`xarray.Dataset`).
"""

__version__ = "0.1.0"

import importlib as _importlib

from stochpound._errors import ExperimentError, RecordError, SceneError, SiteError, StochpoundError

_LAZY = {
    "load_scene": "stochpound.model.scene_file",
    "scene_from_dict": "stochpound.model.scene_file",
    "simulate": "stochpound.solvers.simulate",
    "open_store": "stochpound.store",
    "simulate_ensemble": "stochpound.experiment._ensemble",
}
"""The public names whose modules are imported on first use.

``import stochpound`` stays light (numba, xarray and dask load with the first
of these), so that the command line answers ``--help`` quickly and a Ctrl-C
while it starts is caught by it (exit 130, no traceback)."""
_SUBPACKAGES = ("analysis", "experiment", "model", "motions", "report", "results", "risk", "solvers", "store", "studies", "cli")


def __getattr__(name: str) -> object:
    """The lazily imported public names and subpackages (PEP 562)."""
    if name in _LAZY:
        value = getattr(_importlib.import_module(_LAZY[name]), name)
        globals()[name] = value
        return value
    if name in _SUBPACKAGES:
        return _importlib.import_module(f"stochpound.{name}")
    raise AttributeError(f"module 'stochpound' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted({*globals(), *_LAZY, *_SUBPACKAGES})


__all__ = ["__version__", "load_scene", "scene_from_dict", "simulate", "simulate_ensemble", "open_store", "ExperimentError", "SceneError", "RecordError", "SiteError", "StochpoundError"]
