"""Site-based stochastic motions of a scenario as a synthetic ensemble: :func:`scenario_motions`, and its map from standard normals.

:func:`~stochpound.motions.site_motions` draws n motions of a scenario, their
window (duration) the n motions' own. :func:`scenario_motions` is the same
model in the synthetic generators' convention (those of
:func:`~stochpound.motions.kanai_tajimi`): the window is given, so that
realization i depends on (seed, i) and the window alone, whatever the other
realizations, the batch or the worker that draws it. Realization i is
f(u_i), u_i the first K + n_time standard normals (K the model's, 7 for the published one) of realization i's
generator (:class:`ScenarioNormalMotion`, the map of
:func:`~stochpound.motions.site_motions_from_normals`), hence motion i of
``site_motions(..., n, seed, dt, duration=duration)`` for any n > i, bit for bit.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import xarray as xr

from stochpound._errors import SiteError
from stochpound.motions._scenario import Scenario, given_scenario
from stochpound.motions._seeding import check_seed
from stochpound.motions._site_model import load_site_model
from stochpound.motions._site_motions import SITE_MOTION_LIMITS, site_model_provenance, site_motions, site_motions_from_normals

SCENARIO_TYPE = "scenario_motions"
"""The synthetic type (a ``[motion] type``, a ``[synthetic.<name>] type``) of :func:`scenario_motions`."""
#: Per-realization parameters of the motions, kept as coordinates of the ensemble.
PARAMETERS = ("arias_intensity", "d5_95", "t_mid", "f_mid", "f_slope", "zeta_f", "f_corner")


@dataclass(frozen=True)
class ScenarioNormalMotion:
    """A site-based motion of a scenario as a function a = f(u) of n = K + n_time independent standard normals (K: the model's).

    The interface of :class:`~stochpound.motions.NormalMotion` (``dt``,
    ``n_time``, ``time``, ``dimension``, calling it on normals, ``sample``),
    for the site model: :func:`~stochpound.motions.normal_motion` of a
    ``type = "scenario_motions"`` table.

    Parameters
    ----------
    scenario : Scenario
        Magnitude, rupture distance, Vs30 and mechanism (checked against the model's range).
    n_time : int
        Samples, at t = 0, dt, ..., (n_time − 1)·dt.
    dt : float
        Step, s.
    model : str
        The site-motion model (``hazard_compatible`` or ``rezaeian_2010``).
    attrs : dict[str, float | str]
        The motion's parameters, as :func:`scenario_motions` results carry them.
    """

    scenario: Scenario
    n_time: int
    dt: float
    model: str
    attrs: dict[str, float | str] = field(default_factory=dict, compare=False)

    @property
    def time(self) -> np.ndarray:
        """Sample times, s."""
        return np.arange(self.n_time) * self.dt

    @property
    def dimension(self) -> int:
        """n, the number of standard normals a motion takes: its model's for the parameters (and spectral shape), one per sample for its noise."""
        return load_site_model(self.model).normals + self.n_time

    def motions(self, u: np.ndarray) -> xr.Dataset:
        """The motions of the rows of ``u`` (m, n) with their parameters (:func:`~stochpound.motions.site_motions_from_normals`)."""
        return site_motions_from_normals(u, scenario=self.scenario, dt=self.dt, model=self.model)

    def __call__(self, u: np.ndarray) -> np.ndarray:
        """The ground acceleration of the normals ``u`` ((n,) or (m, n)), m/s² ((n_time,) or (m, n_time))."""
        u = np.asarray(u, dtype=float)
        if u.ndim not in (1, 2) or u.shape[-1] != self.dimension:
            raise ValueError(f"u: must have shape (n,) or (m, n) with n = {self.dimension}, got {u.shape}")
        values = self.motions(u.reshape(-1, self.dimension))["acceleration"].values
        return values[0] if u.ndim == 1 else values

    def sample(self, rngs: list[np.random.Generator]) -> np.ndarray:
        """One motion per generator, each of its generator's first n standard normals, m/s² (len(rngs), n_time)."""
        return self(np.array([rng.standard_normal(self.dimension) for rng in rngs]).reshape(len(rngs), self.dimension))


def scenario_normal_motion(duration: float, dt: float, magnitude: float, distance_km: float, vs30: float, mechanism: str, *,
                           model: str = "hazard_compatible", calibration: str | None = None) -> ScenarioNormalMotion:
    """The :class:`ScenarioNormalMotion` of a scenario ensemble's fields, checked (arguments as :func:`scenario_motions`).

    Raises
    ------
    SiteError
        Naming the field: a scenario outside the model's calibrated range,
        an unknown model, a ``calibration`` that is not the model's, a bad
        ``dt`` (≤ 0.02 s) or ``duration`` (10 dt – 600 s).
    """
    provenance = site_model_provenance(model)  # an unknown model: the message naming the models
    if calibration is not None and calibration != provenance:
        raise SiteError(f"calibration: {calibration!r} is not the calibration of model {model!r} here ({provenance!r}): "
                        "the motions cannot be regenerated")
    scenario = given_scenario(None, magnitude, distance_km, vs30, mechanism, limits=SITE_MOTION_LIMITS, source="the site-motion model's calibrated range")
    if isinstance(dt, bool) or not isinstance(dt, (int, float)) or not 0.0 < dt <= 0.02:
        raise SiteError(f"dt: must be within 0-0.02 s (the model's filter reaches 25 Hz and more), got {dt!r}")
    if isinstance(duration, bool) or not isinstance(duration, (int, float)) or not 10.0 * dt <= duration <= 600.0:
        raise SiteError(f"duration: must be within {10 * dt:g}-600 s, got {duration!r}")
    n_time = int(round(duration / dt)) + 1
    attrs = {"long_name": "ground acceleration", "units": "m/s2", **scenario.loose(), "model": model, "model_provenance": provenance,
             "dt": float(dt), "duration": float((n_time - 1) * dt)}
    return ScenarioNormalMotion(scenario, n_time, float(dt), model, attrs)


def scenario_motions(n_realizations: int, duration: float, dt: float, magnitude: float, distance_km: float, vs30: float, mechanism: str,
                     seed: int = 0, *, start: int = 0, model: str = "hazard_compatible", calibration: str | None = None) -> xr.DataArray:
    """Realizations of site-based stochastic motions of a scenario (Rezaeian & Der Kiureghian 2010, hazard-compatible; model §11).

    The synthetic generators' convention for :func:`~stochpound.motions.site_motions`:
    realization i depends on (seed, i) and the window alone (module docstring).

    Parameters
    ----------
    n_realizations : int
        Number of realizations (≥ 0).
    duration : float
        Length of the window, s (10 dt – 600 s); samples at t = 0, dt, ..., round(duration/dt)·dt.
    dt : float
        Step, s (≤ 0.02).
    magnitude, distance_km, vs30 : float
        Moment magnitude (5.5–8), rupture distance (5–100 km), Vs30 (200–1100 m/s).
    mechanism : {"strike_slip", "reverse", "normal"}
        Faulting mechanism.
    seed : int
        Seed (≥ 0).
    start : int
        Index of the first realization: realizations start .. start + n_realizations − 1.
    model : {"hazard_compatible", "rezaeian_2010"}
        The calibrated equations (default) or the published ones.
    calibration : str, optional
        The model's calibration (:func:`~stochpound.motions.site_model_provenance`),
        checked when given: a table written with another cannot regenerate its motions.

    Returns
    -------
    xarray.DataArray
        Ground acceleration, m/s², dims ``(realization, time)``, each
        motion's parameters (``arias_intensity``, ``d5_95``, ``t_mid``,
        ``f_mid``, ``f_slope``, ``zeta_f``, ``f_corner``) as coordinates on
        ``realization``; the scenario, model, calibration, seed, dt and duration in ``attrs``.

    Raises
    ------
    SiteError
        Naming the field: a scenario outside the model's calibrated range, an
        unknown model, a ``calibration`` that is not the model's, a bad ``dt``
        (≤ 0.02 s), ``duration`` (10 dt – 600 s), ``n_realizations``, ``start`` or ``seed``.
    """
    motion = scenario_normal_motion(duration, dt, magnitude, distance_km, vs30, mechanism, model=model, calibration=calibration)
    for name, value in (("n_realizations", n_realizations), ("start", start)):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 0:
            raise SiteError(f"{name}: must be an integer >= 0, got {value!r}")
    try:
        seed = check_seed(seed)
    except ValueError as error:
        raise SiteError(str(error)) from None
    first, count = int(start), int(n_realizations)
    generated = site_motions(scenario=motion.scenario, n=first + count, seed=seed, dt=motion.dt, duration=duration, model=model,
                             realizations=range(first, first + count)) if count else None  # f(u_i) row by row, on the batches' threads
    values = generated["acceleration"].values if generated is not None else np.empty((0, motion.n_time))
    realizations = np.arange(first, first + count)
    coords = {"realization": realizations, "time": motion.time}
    for name in PARAMETERS:
        coords[name] = ("realization", generated[name].values if generated is not None else np.empty(0), {"units": _units(generated, name)})
    attrs = {**motion.attrs, "seed": seed, "realization_streams": "numpy PCG64(SeedSequence(seed, spawn_key=(realization,)))"}
    return xr.DataArray(values, dims=("realization", "time"), coords=coords, name="ground_acceleration", attrs=attrs)


def _units(generated: xr.Dataset | None, name: str) -> str:
    return str(generated[name].attrs["units"]) if generated is not None else ""
