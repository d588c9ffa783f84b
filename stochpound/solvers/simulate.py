"""The ``simulate`` entry point: one scene, one solver, one result dataset."""

from __future__ import annotations

import xarray as xr

from stochpound.results.dataset import build_dataset
from stochpound.model.scene import Scene
from stochpound.solvers.exact import run_exact
from stochpound.solvers.ivp import INTEGRATORS, run_ivp

METHODS = ("exact", "ivp")
"""Available solvers: ``exact`` (matrix-exponential propagation; the default for piecewise-linear laws) and
``ivp`` (scipy integrators with exact event location)."""


def simulate(
    scene: Scene,
    method: str | None = None,
    *,
    integrator: str = "DOP853",
    rtol: float = 1e-10,
    atol: float = 1e-12,
    demands: bool = False,
) -> xr.Dataset:
    """Simulate a scene and return the result dataset (the names of docs/scene-files.md).

    Parameters
    ----------
    scene : Scene
        From :func:`stochpound.load_scene` or built in Python.
    method : {"exact", "ivp"} or None
        The solver. ``exact``: every mode advanced exactly by matrix
        exponentials; it needs piecewise-linear laws. ``ivp``: scipy's
        ``solve_ivp`` integrators. None (default): ``exact`` when every law of
        the scene is piecewise linear, else ``ivp`` (the result's ``solver``
        and ``solver_choice`` attributes say which and why).
    integrator : str
        For ``ivp``: ``DOP853`` (default), ``RK45``, ``RK23``, ``Radau``, ``BDF`` or ``LSODA``.
    rtol, atol : float
        For ``ivp``: integrator tolerances (``atol`` in m and m/s).
    demands : bool
        Also give the demand parameters (``total_acceleration``,
        ``storey_drift``, ``storey_shear``, ``base_shear``) and their peaks over
        the run, located on the solution (monitoring them makes a run slower).

    Returns
    -------
    xarray.Dataset
        Time histories at the motion's samples, the impact table, the energy
        balance, and attributes naming the solver and its settings.
    """
    nonlinear = scene.nonlinear_laws()
    choice = "asked" if method is not None else ("nonlinear laws: " + "; ".join(nonlinear) if nonlinear else "piecewise-linear laws")
    method = method if method is not None else ("ivp" if nonlinear else "exact")
    if method not in METHODS:
        raise ValueError(f"method must be one of {', '.join(METHODS)}, got {method!r}")
    if method == "exact" and nonlinear:
        raise ValueError(f"method='exact' needs piecewise-linear laws, and {'; '.join(nonlinear)} is not: use method='ivp' (or leave method unset)")
    if integrator not in INTEGRATORS:
        raise ValueError(f"integrator must be one of {', '.join(INTEGRATORS)}, got {integrator!r}")
    for name, value in (("rtol", rtol), ("atol", atol)):
        if not (value > 0.0):
            raise ValueError(f"{name} must be > 0, got {value}")
    if method == "exact":
        recorder, counters, library = run_exact(scene, demands=demands)
        attrs = {"solver": method, "solver_choice": choice, "modes_visited": len(library)}
    else:
        recorder, counters, library = run_ivp(scene, integrator, rtol, atol, demands)
        attrs = {"solver": method, "solver_choice": choice, "integrator": integrator, "rtol": rtol, "atol": atol, "modes_visited": len(library)}
    return build_dataset(scene, library.system, recorder, counters, attrs)
