"""Site-based stochastic ground motions of a scenario (Rezaeian & Der Kiureghian 2010, made hazard-compatible).

:func:`site_motions` draws any number of motions of a scenario (magnitude,
rupture distance, Vs30, mechanism) from a seed; :func:`site_motions_from_normals`
is the same map from an explicit array of independent standard normals, one
row per motion (its first 7 give the motion's parameters, the next 11 its
spectral-shape gains with the hazard-compatible model, the others the white
noise at each sample: the model is in ``stochpound.motions._site_model``).
Motion i of a seed uses the generator of realization i
(:func:`~stochpound.motions.realization_rng`): its 7 parameter normals, its
shape layer's 11 (the hazard-compatible model only), then its noise.
``site_motions(..., normal_shift=s)`` adds s to every motion's parameter
normals (importance sampling: the experiments' pools tilted to each stripe).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import xarray as xr

from stochpound._errors import SiteError
from stochpound.motions._scenario import Scenario, given_scenario
from stochpound.motions._seeding import check_seed, realization_rng
from stochpound.motions._site_model import (
    MODELS, SHAPE_PERIODS, UNITS, gamma_shape, load_site_model, motion_parameters, motions_from_noise_rows, motions_from_normals,
)  # fmt: skip

#: The scenarios the hazard-compatible calibration covers; outside them the model is not offered.
SITE_MOTION_LIMITS: dict[str, tuple[float, float]] = {"magnitude": (5.5, 8.0), "distance_km": (5.0, 100.0), "vs30": (200.0, 1100.0)}
#: The default window ends when every motion's modulation has delivered this fraction of its Arias intensity ...
WINDOW_FRACTION = 0.999
#: ... plus this many periods of the post-filter's corner (its transient), rounded up to whole WINDOW_ROUND seconds.
WINDOW_TAIL_PERIODS, WINDOW_ROUND = 2.0, 5.0


def _checked(scenario: Scenario | None, loose: tuple, dt: float, model: str) -> Scenario:
    """The scenario given (:func:`~stochpound.motions._scenario.given_scenario`), checked against the calibrated range, after ``dt`` and ``model``."""
    checked = given_scenario(scenario, *loose, limits=SITE_MOTION_LIMITS, source="the site-motion model's calibrated range")
    if checked.geometry and model == "rezaeian_2010":
        raise SiteError(f"scenario: the published model takes magnitude, distance_km, vs30 and mechanism only, not a geometry "
                        f"({', '.join(checked.geometry)}): give the scenario without it, or model='hazard_compatible'")
    if isinstance(dt, bool) or not isinstance(dt, (int, float)) or not 0.0 < dt <= 0.02:
        raise SiteError(f"dt: must be within 0-0.02 s (the model's filter reaches 25 Hz and more), got {dt!r}")
    if model not in MODELS:
        raise SiteError(f"model: must be one of {', '.join(MODELS)}, got {model!r}")
    return checked


def _window(parameters: dict[str, np.ndarray]) -> float:
    """The default duration (s): every motion's WINDOW_FRACTION of intensity and the post-filter's tail, rounded up."""
    from scipy import special

    k, rate = gamma_shape(parameters["t_mid"], parameters["d5_95"])
    end = special.gammaincinv(k, WINDOW_FRACTION) / rate + WINDOW_TAIL_PERIODS / parameters["f_corner"]
    return WINDOW_ROUND * math.ceil(float(np.max(end)) / WINDOW_ROUND)


def _dataset(acceleration: np.ndarray, parameters: dict[str, np.ndarray], dt: float, attrs: dict) -> xr.Dataset:
    n, n_time = acceleration.shape
    variables = {"acceleration": (("realization", "time"), acceleration, {"units": "m/s2", "long_name": "ground acceleration"})}
    for name, values in parameters.items():
        variables[name] = (("realization", "shape_period") if values.ndim == 2 else "realization", values, {"units": UNITS[name]})
    coords = {"realization": np.arange(n), "time": ("time", np.arange(n_time) * dt, {"units": "s"})}
    if "spectral_shape" in parameters:
        coords["shape_period"] = ("shape_period", np.array(SHAPE_PERIODS), {"units": "s"})
    return xr.Dataset(variables, coords=coords, attrs={**attrs, "dt": float(dt)})


def _attrs(scenario: Scenario, model: str) -> dict:
    return {**scenario.loose(), **scenario.geometry, "model": model, "model_provenance": load_site_model(model).provenance}


def site_motions_from_normals(normals: np.ndarray, *, magnitude: float | None = None, distance_km: float | None = None, vs30: float | None = None,
                              mechanism: str | None = None, dt: float = 0.01, model: str = "hazard_compatible",
                              scenario: Scenario | None = None) -> xr.Dataset:
    """Motions of a scenario as a deterministic function of independent standard normals.

    Parameters
    ----------
    normals : array_like, shape (n, 7 + K + n_time)
        Row i: motion i's normals; the first 6 give its parameters (the
        predictive equations' residuals, correlated through the model's
        covariance), the 7th its post-filter's corner, the next K its
        spectral-shape gains (``hazard_compatible``: K = 12, one per period of
        the shape layer; ``rezaeian_2010``: K = 0), the next n_time the
        white noise at t = 0, dt, ….
    magnitude, distance_km, vs30 : float
        Moment magnitude (5.5–8), rupture distance (5–100 km), Vs30 (200–1100 m/s).
    mechanism : {"strike_slip", "reverse", "normal"}
        Faulting mechanism.
    dt : float
        Time step, s (≤ 0.02).
    model : {"hazard_compatible", "rezaeian_2010"}
        The calibrated equations (default) or the published ones.
    scenario : Scenario, optional
        The scenario as one value, instead of ``magnitude``, ``distance_km``, ``vs30`` and ``mechanism``.

    Returns
    -------
    xarray.Dataset
        As :func:`~stochpound.motions.site_motions`.
    """
    scenario = _checked(scenario, (magnitude, distance_km, vs30, mechanism), dt, model)
    normals = np.asarray(normals, dtype=float)
    count = load_site_model(model).normals
    if normals.ndim != 2 or normals.shape[1] < count + 3 or not np.all(np.isfinite(normals)):
        raise SiteError(f"normals: must be a finite array of shape (n, {count} + n_time) with n_time >= 3 (model {model}), got shape {normals.shape}")
    acceleration, parameters = motions_from_normals(load_site_model(model), scenario, normals, dt)
    return _dataset(acceleration, parameters, dt, _attrs(scenario, model))


def site_motions(magnitude: float | None = None, distance_km: float | None = None, vs30: float | None = None, mechanism: str | None = None,
                 n: int | None = None, seed: int | None = None, dt: float = 0.01, *, duration: float | None = None, model: str = "hazard_compatible",
                 realizations: Sequence[int] | None = None, scenario: Scenario | None = None,
                 normal_shift: Sequence[float] | None = None) -> xr.Dataset:
    """Stochastic ground motions of a site's scenario (Rezaeian & Der Kiureghian 2010, hazard-compatible; model §11).

    Parameters
    ----------
    magnitude : float
        Moment magnitude, 5.5–8.
    distance_km : float
        Rupture distance, 5–100 km.
    vs30 : float
        Time-averaged shear-wave velocity of the top 30 m, 200–1100 m/s.
    mechanism : {"strike_slip", "reverse", "normal"}
        Faulting mechanism.
    n : int
        Number of motions (≥ 1).
    seed : int
        Seed (≥ 0): motion i depends on (seed, i) and the window alone.
    dt : float
        Time step, s (≤ 0.02).
    duration : float, optional
        Length of the window, s; default: long enough for every motion's
        modulation to deliver 99.9 % of its Arias intensity plus two periods of
        the post-filter's corner, rounded up to 5 s.
    model : {"hazard_compatible", "rezaeian_2010"}
        The calibrated model (default; docs/site-motions.md) or the published equations.
    realizations : list of int, optional
        Only these motions of the ``n`` (each in 0 … n − 1), in this order:
        bit for bit the same rows as of the full set (the window is still the
        full set's), at the memory of these alone (and, with ``duration``
        given, at the cost of these alone). Default: all ``n``.
    scenario : Scenario, optional
        The scenario as one value, instead of ``magnitude``, ``distance_km``, ``vs30`` and ``mechanism``
        (``site_motions(n=100, seed=1, scenario=Scenario(7.0, 10.0, 760.0, "strike_slip"))``); with the
        hazard-compatible model it may carry a geometry (R_JB, R_x, Z_tor, dip, basin depths), which the
        NGA-West2 medians and σ its spectral-shape layer follows take (a hanging-wall site, say).
    normal_shift : list of float, optional
        Added to every motion's parameter normals (its first 7, and its 12
        shape normals with the hazard-compatible model: one value each) before
        they give its parameters; the noise is unchanged. The motions are then
        drawn with those normals N(shift, I) instead of N(0, I): importance
        sampling toward a part of the scenario (docs/intensity.md, "A pool
        tilted to each stripe"). Default: no shift.

    Returns
    -------
    xarray.Dataset
        ``acceleration`` (realization, time; m/s², zero velocity and
        displacement at the end), and per realization its parameters:
        ``arias_intensity`` (m/s, the expected value of the modulation),
        ``d5_95`` and ``t_mid`` (s), ``f_mid`` (Hz), ``f_slope`` (Hz/s),
        ``zeta_f`` and ``f_corner`` (Hz); with the hazard-compatible model
        ``spectral_shape`` (realization, shape_period): the ln gains of its
        spectral-shape layer (docs/site-motions.md). Attributes: the scenario (its geometry too, if given), ``model``,
        ``model_provenance``, ``seed``, ``n``, ``dt``; ``realization`` numbers
        the motions among the n.

    Raises
    ------
    SiteError
        Naming the field: a scenario outside the calibrated range, an unknown
        mechanism or model, a bad ``n``, ``dt``, ``duration`` or ``normal_shift``.
    """
    scenario = _checked(scenario, (magnitude, distance_km, vs30, mechanism), dt, model)
    site_model = load_site_model(model)
    shift = _shift(normal_shift, site_model.normals, model)
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise SiteError(f"n: must be an integer >= 1, got {n!r}")
    try:
        seed = check_seed(seed)
    except ValueError as error:
        raise SiteError(str(error)) from None
    rows = _rows(realizations, int(n))
    if duration is not None and (isinstance(duration, bool) or not isinstance(duration, (int, float)) or not 10.0 * dt <= duration <= 600.0):
        raise SiteError(f"duration: must be within {10 * dt:g}-600 s, got {duration!r}")
    drawn = range(int(n)) if duration is None else rows  # the default window is the whole set's; a given one needs the rows asked for alone
    rngs = [realization_rng(seed, i) for i in drawn]
    first = np.array([rng.standard_normal(site_model.normals) for rng in rngs])
    if normal_shift is not None:
        first = first + shift
    parameters = motion_parameters(site_model, scenario, first)  # each motion's parameters are its own row's
    if duration is None:
        duration = _window(parameters)
        parameters = {name: values[rows] for name, values in parameters.items()}
        rngs = [_after_parameters(seed, i, site_model.normals) for i in rows]  # a generator per row: a realization asked twice is drawn twice alike
    n_time = int(round(duration / dt)) + 1
    acceleration = motions_from_noise_rows(parameters, lambda batch: np.array([rng.standard_normal(n_time) for rng in rngs[batch]]), n_time, dt)
    dataset = _dataset(acceleration, parameters, dt, _attrs(scenario, model))
    dataset = dataset.assign_coords(realization=np.asarray(rows, dtype=int))
    dataset.attrs.update(seed=seed, n=int(n))
    return dataset


def parameter_normals(seed: int, realizations: Sequence[int], model: str = "hazard_compatible") -> np.ndarray:
    """The parameter normals [len(realizations), 7 + K] that :func:`site_motions` of ``seed`` draws for these motions (before any ``normal_shift``)."""
    count = load_site_model(model).normals
    return np.array([realization_rng(seed, int(i)).standard_normal(count) for i in realizations]).reshape(-1, count)


def _shift(normal_shift: Sequence[float] | None, count: int, model: str) -> np.ndarray:
    """The shift of every motion's parameter normals (zeros without one), checked: ``count`` finite numbers."""
    if normal_shift is None:
        return np.zeros(count)
    shift = np.asarray(normal_shift, dtype=float) if _numbers(normal_shift) else np.array([])
    if shift.shape != (count,) or not np.all(np.isfinite(shift)):
        raise SiteError(f"normal_shift: {count} finite numbers (one per parameter normal of model {model}), got {normal_shift!r}")
    return shift


def _numbers(values: object) -> bool:
    """Whether ``values`` is a sequence of real numbers (not booleans)."""
    return (isinstance(values, (list, tuple, np.ndarray)) and
            all(isinstance(v, (int, float, np.integer, np.floating)) and not isinstance(v, (bool, np.bool_)) for v in values))


def _after_parameters(seed: int, realization: int, normals: int) -> np.random.Generator:
    """Realization ``realization``'s generator past its ``normals`` parameter normals, where its noise starts."""
    rng = realization_rng(seed, realization)
    rng.standard_normal(normals)
    return rng


def _rows(realizations: Sequence[int] | None, n: int) -> list[int]:
    """The motions asked for (all ``n`` by default), checked to be integers in 0 … n − 1."""
    if realizations is None:
        return list(range(n))
    rows = list(realizations)
    if not rows or any(isinstance(i, bool) or not isinstance(i, (int, np.integer)) or not 0 <= i < n for i in rows):
        raise SiteError(f"realizations: must be one or more integers within 0-{n - 1} (the motions of the n = {n}), got {rows!r}")
    return [int(i) for i in rows]


def site_model_provenance(model: str = "hazard_compatible") -> str:
    """The names of a site-motion model's published equations and calibration, e.g. ``"rezaeian_der_kiureghian_2010 + nga_west2_calibration_1"``.

    Parameters
    ----------
    model : {"hazard_compatible", "rezaeian_2010"}
        The model, as :func:`~stochpound.motions.site_motions` takes it.

    Raises
    ------
    SiteError
        An unknown model.
    """
    if model not in MODELS:
        raise SiteError(f"model: must be one of {', '.join(MODELS)}, got {model!r}")
    return load_site_model(model).provenance


def stated_calibration(model: str, stated: str | None) -> str:
    """The calibration of ``model`` here (:func:`site_model_provenance`), refusing another one ``stated`` by a table or a store.

    Raises
    ------
    SiteError
        An unknown model, or ``stated`` (when not None) not this model's calibration: motions written with another
        calibration cannot be regenerated, and this one's are not given in their place.
    """
    calibration = site_model_provenance(model)
    if stated is not None and stated != calibration:
        raise SiteError(f"calibration: {stated!r} is not the calibration of model {model!r} here ({calibration!r}): the motions cannot be "
                        "regenerated (run again with this stochpound, or use the one that wrote them)")
    return calibration
