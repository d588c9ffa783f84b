"""The simulated motions of the stripes' pools (``[site] simulated_motions``; :mod:`stochpound.experiment._site` chooses among them).

A pool's simulated motions are a table (:func:`scenario_table`: the scenario,
the model and calibration, ``n``, ``seed``, ``dt``, and for a tilted pool
its ``normal_shift``) and a realization each (:func:`table_sources`): they
are regenerated from it bit for bit, never stored. The pool's spectra are
computed :data:`SIMULATED_CHUNK` motions at a time (:func:`simulated_pool`);
a scenario's pool of more than :data:`SCREEN_BASE` motions is pre-screened
(:func:`screen_level`); a tilted stripe's motions are shifted along its
scenario's :class:`Tilt` (:func:`tilted_sources`); at a site of ruptures a
stripe's motions are shared out among its causal ruptures
(:func:`rupture_allotment`, :func:`rupture_sources`).
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import xarray as xr

from stochpound.motions import MODEL_DAMPING, Scenario
from stochpound.store import SIMULATED, SIMULATED_FIELD, MotionSource, SimulatedMotions

SITE_FIELDS = ("vs30", "magnitude", "distance_km", "mechanism")
"""The ``[site]`` fields of a scenario (and of a simulated motions' table)."""
SIMULATED_CHUNK = 256
"""Simulated motions generated at once while their spectra are computed."""
SCREEN_BASE = 2000
"""The pre-screen of a larger pool of a scenario's simulated motions: its first SCREEN_BASE motions all join it ... (:func:`screen_level`)."""
SCREEN_MARGIN = 1.0
"""... and the others whose own ε at the conditioning measure is at least the top stripe's ε minus SCREEN_MARGIN."""
SIMULATED_WINDOW_LIMIT = 600.0
"""Longest window (s) :func:`~stochpound.motions.site_motions` takes given; a longer default one is found again per chunk."""
SIMULATED_STREAM = 44
"""Entropy word of the stripes' pools of simulated motions of a site's ruptures (:func:`rupture_seed`)."""
SimulatedValue = float | int | str | list[float]
"""A value of a simulated motions' table (its ``normal_shift`` the one list)."""
TILT_PILOT = 2000
"""Motions of the scenario (untilted, the selection's seed) whose conditioning measure gives the tilt's direction (:func:`tilt_pilot`)."""
TILTED_STREAM = 45
"""Entropy word of the stripes' tilted pools (:func:`tilted_seed`)."""


def simulated_sources(setting: SimulatedMotions | None, stripe: int, scenario: Scenario) -> dict[str, MotionSource]:
    """The simulated motions of a stripe's pool as motion sources, by label (``simulated <stripe>.<i>``, from 1); {} without them.

    A source's ``motion`` table holds what regenerates it: the scenario, the
    model and its calibration, ``n``, ``seed``, ``dt`` and its ``realization``.
    """
    if setting is None:
        return {}
    return table_sources(scenario_table(setting, scenario, setting.count, setting.seed), stripe)


def scenario_table(setting: SimulatedMotions, scenario: Scenario, n: int, seed: int) -> dict[str, SimulatedValue]:
    """The table of ``n`` simulated motions of a scenario and seed (no realization): what regenerates them with one."""
    return {"type": "site_motions", **{key: getattr(scenario, key) for key in SITE_FIELDS}, "n": n, "seed": seed, "dt": setting.dt,
            "model": setting.model, "calibration": setting.calibration}


def table_sources(table: Mapping[str, SimulatedValue], stripe: int) -> dict[str, MotionSource]:
    """The motions of a table as a stripe's motion sources, by label (``simulated <stripe>.<i>``, from 1)."""
    count = int(table["n"])
    labels = [f"simulated {stripe + 1}.{i:0{len(str(count - 1))}d}" for i in range(count)]
    return {label: MotionSource(label, SIMULATED, SIMULATED_FIELD, {**table, "realization": i}) for i, label in enumerate(labels)}


@dataclass(frozen=True)
class Tilt:
    """The least-squares line of a scenario's ln conditioning measure on its motions' parameter normals z (:func:`tilt_pilot`).

    ln IM* ≈ ``intercept`` + ``slope`` · z (IM* in g; ``slope``: one per parameter normal of the model).
    """

    intercept: float
    slope: tuple[float, ...]

    @classmethod
    def fit(cls, normals: np.ndarray, response: np.ndarray) -> Tilt:
        """The least-squares line of ``response`` [n] on ``normals`` [n, k], its normal equations summed exactly (math.fsum: the
        tilt does not depend on how a BLAS splits its sums) and solved."""
        design = np.column_stack([np.ones(len(response)), normals])
        columns = range(design.shape[1])
        gram = np.array([[math.fsum(design[:, i] * design[:, j]) for j in columns] for i in columns])
        moment = np.array([math.fsum(design[:, i] * response) for i in columns])
        coefficients = np.linalg.solve(gram, moment)
        return cls(float(coefficients[0]), tuple(float(value) for value in coefficients[1:]))

    def shift(self, level: float) -> list[float]:
        """The shift of the parameter normals that centres ln IM* on ln ``level`` (g): t a, t = (ln level − b0)/|a|² (a the slope)."""
        slope = np.array(self.slope)
        t = (math.log(level) - self.intercept) / math.fsum(slope * slope)
        return [float(value) for value in t * slope]


def tilt_pilot(setting: SimulatedMotions, scenario: Scenario, measure: str, period: Any, g: float) -> Tilt:
    """The tilt of a scenario: ln IM* (g) of its first :data:`TILT_PILOT` motions (untilted, seed ``setting.seed``: the untilted
    pool's first ones) regressed on their parameter normals (:meth:`Tilt.fit`)."""
    from stochpound.motions import parameter_normals

    table = scenario_table(setting, scenario, TILT_PILOT, setting.seed)
    response = np.log(np.concatenate([intensity for _, _, intensity in table_chunks(table, measure, period, g)]))
    return Tilt.fit(parameter_normals(setting.seed, range(TILT_PILOT), setting.model), response)


def tilted_seed(seed: int, stripe: int) -> int:
    """The seed of stripe ``stripe``'s tilted motions (a stream apart from the scenario's and the ruptures')."""
    return int(np.random.SeedSequence([seed, TILTED_STREAM, stripe]).generate_state(1)[0])


def tilted_sources(setting: SimulatedMotions, stripe: int, scenario: Scenario, level: float, tilts: dict[Scenario, Tilt], measure: str,
                   period: Any, g: float) -> dict[str, MotionSource]:
    """The tilted simulated motions of a stripe's pool (``[site] simulated_sampling = "tilted"``), by label (``simulated <stripe>.<i>``).

    The stripe's ``count`` motions of its scenario, seed :func:`tilted_seed`, their parameter normals drawn N(s, I) instead of
    N(0, I), s = the scenario's :class:`Tilt` (its pilot, :func:`tilt_pilot`, computed once in ``tilts``) shifted to the level:
    a shift along the regression's direction, which leaves the normals' distribution given their projection on it unchanged
    (docs/intensity.md, "A pool tilted to each stripe"). The table's ``normal_shift`` (the s) regenerates a motion bit for bit.
    """
    if scenario not in tilts:
        tilts[scenario] = tilt_pilot(setting, scenario, measure, period, g)
    table = {**scenario_table(setting, scenario, setting.count, tilted_seed(setting.seed, stripe)), "normal_shift": tilts[scenario].shift(level)}
    return table_sources(table, stripe)


def rupture_allotment(site: Any, measure: str, period: Any, levels: list[float], count: int) -> np.ndarray:
    """How many of a stripe's ``count`` simulated motions each rupture gives (int, level × rupture; levels ascending).

    Rupture r's share at level x is its weight in the exact conditional spectrum, P(r | IM* = x)
    (:meth:`~stochpound.analysis.RuptureSite.disaggregation`'s ``density_share``); ``count`` is apportioned by the largest
    remainders: each rupture gets the whole part of ``count`` × its share, the motions left go one each to the largest
    fractional parts (ties to the earlier rupture). Every level's row sums to ``count``.
    """
    shares = site.disaggregation(measure, period, levels=levels)["density_share"].values
    return np.array([largest_remainders(count, row) for row in shares], dtype=np.int64)


def largest_remainders(count: int, shares: np.ndarray) -> np.ndarray:
    """``count`` apportioned by ``shares`` (≥ 0, summing to 1) by the largest remainders, ties to the earlier entry."""
    exact = count * np.asarray(shares, dtype=float) / float(np.sum(shares))
    whole = np.floor(exact).astype(np.int64)
    order = np.lexsort((np.arange(exact.size), -(exact - whole)))  # the largest fractional part first, then the entry's order
    whole[order[: count - int(whole.sum())]] += 1
    return whole


def rupture_seed(seed: int, index: int) -> int:
    """The seed of rupture ``index``'s simulated motions in the stripes' pools (a stream apart from the measure-free answer's)."""
    return int(np.random.SeedSequence([seed, SIMULATED_STREAM, index]).generate_state(1)[0])


def rupture_sources(setting: SimulatedMotions, stripe: int, site: Any, allotment: np.ndarray) -> list[dict[str, MotionSource]]:
    """The simulated motions of a stripe's pool at a site of ruptures, one mapping per rupture (label ``simulated <stripe>.<rupture>.<i>``,
    from 1; empty where the rupture has none at the stripe).

    Rupture r's table is the same at every stripe: its scenario (geometry included), its name (``rupture``), ``n`` the most it gives any
    stripe, the seed :func:`rupture_seed`; stripe j takes its first ``allotment[j, r]`` realizations, so its motions are generated once.
    """
    groups = []
    width = len(str(len(site)))
    for index, count in enumerate(allotment[stripe]):
        n = int(allotment[:, index].max())
        scenario = site.scenario(index)
        table = {"type": "site_motions", **scenario.loose(), **scenario.geometry, "rupture": site.names[index], "n": n,
                 "seed": rupture_seed(setting.seed, index), "dt": setting.dt, "model": setting.model, "calibration": setting.calibration}
        labels = [f"simulated {stripe + 1}.{index + 1:0{width}d}.{i:0{len(str(max(n - 1, 0)))}d}" for i in range(int(count))]
        groups.append({label: MotionSource(label, SIMULATED, SIMULATED_FIELD, {**table, "realization": i}) for i, label in enumerate(labels)})
    return groups


def table_scenario(table: Mapping[str, float | str]) -> Scenario:
    """The scenario of a simulated motion's table: magnitude, R_rup, Vs30, mechanism, and the geometry it gives (a rupture's)."""
    from stochpound.motions import GEOMETRY_FIELDS

    return Scenario(**{key: table[key] for key in (*SITE_FIELDS, *GEOMETRY_FIELDS) if key in table})


def simulated_motions(sources: Sequence[MotionSource], duration: float | None = None) -> list[Any]:
    """The motions (m/s², :class:`~stochpound.motions.ground.SampledMotion`) of simulated sources of one table, regenerated from it bit for bit."""
    from stochpound.motions.ground import SampledMotion

    table = sources[0].motion
    return [SampledMotion(table["dt"], values, "linear", f"{source.label} ({table['model']}, seed {table['seed']})")
            for source, values in zip(sources, simulated_accelerations(sources, duration))]


def simulated_accelerations(sources: Sequence[MotionSource], duration: float | None = None) -> np.ndarray:
    """The ground accelerations (m/s², one row per source) of simulated sources of one table, regenerated from it bit for bit.

    ``duration`` (s), the window of the table's ``n`` motions when known (:func:`simulated_pool`), spares drawing the
    parameters of all ``n`` to find it (the window-given path of :func:`~stochpound.motions.site_motions`); the rows are the same.
    """
    return table_accelerations(sources[0].motion, [source.motion["realization"] for source in sources], duration)


def table_accelerations(table: Mapping[str, float | str], realizations: Sequence[int], duration: float | None = None) -> np.ndarray:
    """The ground accelerations (m/s², one row per realization) of a simulated motions' table (:func:`simulated_accelerations`).

    Raises
    ------
    SiteError
        The table names a calibration other than its model's here (a store written with another calibration): its motions
        cannot be regenerated, and other motions are not given in their place.
    """
    from stochpound.motions import site_motions, stated_calibration

    stated_calibration(str(table["model"]), table["calibration"] if "calibration" in table else None)
    generated = site_motions(scenario=table_scenario(table), n=table["n"], seed=table["seed"], dt=table["dt"], model=table["model"],
                             realizations=list(realizations), duration=duration, normal_shift=table["normal_shift"] if "normal_shift" in table else None)
    return generated["acceleration"].values


def simulated_pool(table: Mapping[str, float | str], periods: np.ndarray, measure: str, period: Any, g: float, screen: float | None = None) -> xr.Dataset:
    """:func:`~stochpound.motions.selection_pool` of every motion of a simulated motions' table (over ``motion``: its realization,
    ``"0"`` … ``"n-1"``), generated :data:`SIMULATED_CHUNK` at a time.

    The first chunk finds the window of the table's ``n`` motions (their default one, :func:`~stochpound.motions.site_motions`);
    the others are drawn with it given, each motion from its own generator alone: the same motions, bit for bit. Each chunk's
    spectra come from one compiled call per batch (``stochpound.motions._selection.array_pool``). With ``screen`` (g; the
    pre-screen, :func:`screen_level`), a realization from :data:`SCREEN_BASE` on joins the pool only if its own conditioning
    measure reaches ``screen``: that measure is computed for every motion, the whole spectrum for those that join alone.
    """
    from stochpound.motions import array_pool

    dt = float(table["dt"])
    parts = []
    for rows, accelerations, intensity in table_chunks(table, measure, period, g):
        kept = np.flatnonzero((rows < SCREEN_BASE) | (intensity >= screen)) if screen is not None else np.arange(rows.size)
        if kept.size:
            parts.append(array_pool(accelerations[kept], dt, [str(i) for i in rows[kept]], periods, measure, period, MODEL_DAMPING, g,
                                    intensity=intensity[kept], magnitude=table["magnitude"], distance_km=table["distance_km"], vs30=table["vs30"]))
    return xr.concat(parts, "motion")


def table_chunks(table: Mapping[str, SimulatedValue], measure: str, period: Any, g: float) -> Iterator[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Every motion of a simulated motions' table, :data:`SIMULATED_CHUNK` at a time: the realizations, their accelerations (m/s²)
    and conditioning measure (g; :func:`~stochpound.motions.pool_intensity`).

    The first chunk finds the window of the table's ``n`` motions; the others are drawn with it given (:func:`simulated_pool`).
    """
    from stochpound.motions import pool_intensity

    n, dt = int(table["n"]), float(table["dt"])
    duration = None
    for start in range(0, n, SIMULATED_CHUNK):
        rows = np.arange(start, min(start + SIMULATED_CHUNK, n))
        accelerations = table_accelerations(table, rows.tolist(), duration)
        window = (accelerations.shape[1] - 1) * dt  # n_time = round(window / dt) + 1 again
        duration = window if window <= SIMULATED_WINDOW_LIMIT else None
        yield rows, accelerations, pool_intensity(accelerations, dt, measure, period, MODEL_DAMPING, g)


def screen_level(setting: SimulatedMotions | None, stripe: int, scenarios: Sequence[Scenario], targets: Sequence[xr.Dataset], measure: str,
                 period: Any) -> float | None:
    """The pre-screen of a stripe's pool of simulated motions of its scenario (g; None: every motion's spectrum is computed).

    A pool of more than :data:`SCREEN_BASE` motions keeps its first :data:`SCREEN_BASE` and, of the others, those whose own ε at
    the conditioning measure in the scenario (:func:`~stochpound.motions.scenario_distribution`) is at least ε_top −
    :data:`SCREEN_MARGIN`, ε_top the largest ε of the stripes of the same scenario (which share the pool): the level
    median · exp(σ (ε_top − :data:`SCREEN_MARGIN`)).
    """
    from stochpound.motions import scenario_distribution

    if setting is None or setting.count <= SCREEN_BASE:
        return None
    scenario = scenarios[stripe]
    top = max(float(target.attrs["epsilon"]) for other, target in zip(scenarios, targets) if other == scenario)
    median, sigma = scenario_distribution(measure, period, scenario=scenario)
    return float(median * np.exp(sigma * (top - SCREEN_MARGIN)))


def shared_simulated_pool(sources: Mapping[str, MotionSource], periods: np.ndarray, measure: str, period: Any, g: float,
                          generated: dict[str, xr.Dataset], screen: float | None = None) -> xr.Dataset:
    """:func:`simulated_pool` of a stripe's sources (pre-screened by ``screen``, g), reusing ``generated`` (the pools of the tables
    met so far, by table and screen).

    Stripes of one scenario (a fitted scenario, one given for every level) have the same table and so the same motions:
    they are generated once and relabelled (a motion's label, earthquake and recording are its stripe's label). A source the
    pre-screen left out is not in the stripe's pool.
    """
    from stochpound.store import canonical_json

    table = next(iter(sources.values())).motion
    key = canonical_json({**{name: value for name, value in table.items() if name != "realization"}, "screen": screen})
    if key not in generated:  # every motion of the table (a stripe may take only the first ones)
        generated[key] = simulated_pool(table, periods, measure, period, g, screen)
    pool = generated[key]
    wanted = {source.motion["realization"]: label for label, source in sources.items()}
    rows = [j for j, realization in enumerate(pool["motion"].values.astype(int)) if realization in wanted]
    labels = np.array([wanted[int(pool["motion"].values[j])] for j in rows], dtype=object)
    return pool.isel(motion=rows).assign_coords(motion=labels).assign(earthquake=("motion", labels), recording=("motion", labels))
