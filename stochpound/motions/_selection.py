"""Selection and scaling of recorded motions to a conditional spectrum (Jayaram, Lin & Baker 2011).

For one stripe (the conditioning measure IM* at a level x, and the target
of :func:`~stochpound.motions.conditional_spectrum` over a period range):

1. every motion of the pool is scaled by s = x / IM*, its own measure
   unscaled; only motions with s ≤ ``max_scale_factor`` are candidates;
2. a set of ``motions`` target spectra is simulated from the conditional
   multivariate normal of ln Sa (mean ln median, covariance
   σ_i σ_j ρ_ij from the target's ``sigma_ln`` and ``correlation``);
3. to each simulated spectrum, in turn, the nearest unused candidate (sum
   over periods of the squared difference of ln Sa in units of the target's
   σ);
4. greedy swaps: each chosen motion in turn is replaced by the candidate
   that most lowers the misfit Σ_T (d_m² + d_s²) + 100 Σ_T (d_m⁴ + d_s⁴),
   d_m and d_s the differences of the set's mean and sample standard
   deviation (n − 1) of ln Sa from the target's, until a full pass changes
   nothing (the quartic term, as large as the quadratic one at a difference
   of 0.1, holds the worst period down);
5. steps 2–4 are repeated for 20 simulated sets;
6. one more start: the linear programme below, its weights' heaviest
   candidates (the rules kept), then step 4; of the 21 sets the one of least
   misfit is kept.

The programme: weights w ∈ [0, 1] of the candidates, Σ w = ``motions``, at
most 1 over the motions of one recording and ``max_per_earthquake`` over
those of one earthquake, whose weighted mean of the scaled ln Sa lies within
t of the target's mean at every period, t the least it can be. Every set
the rules allow is such a w, so **no set of the pool comes closer to the
target's mean than t at its worst period** (``mean_bound``). A second
programme asks for the mean within :data:`TARGET_TOLERANCE` and, at every
period, for the weighted sum of squares about the target's mean to allow
a standard deviation within the tolerance of the target's (a set's variance
is that sum, over n − 1, less n / (n − 1) times its mean's squared miss).
(It runs only where the chosen set misses: a set that meets the target
proves it reachable.) Where either fails (``target_reachable`` 0) no set of the pool meets the
target within the tolerance: a miss is the pool's, its motions lack the
target's shape, not the search's. Where both succeed a set may still miss
(the weights need not be whole); the first programme's heaviest candidates
are then a start near the target's mean for the swaps, which the simulated
sets, drawn about the target, may not reach at high ε.

With ``tolerance_first``, a stripe whose set of least misfit misses the
target (and whose first programme does not rule the tolerance out) is
chosen again with the tolerance first: any set within it before any set
outside. An integer programme (scipy's ``milp``, HiGHS) over whole
weights, with the rules, asks for the set's mean of ln Sa within
:data:`TARGET_TOLERANCE` of the target's at every period, its σ at most the
tolerance above the target's (a sufficient condition: the sum of squares
about the target's mean at most (σ + tolerance)² (n − 1)), the condition
that it be at most the tolerance below (convex in the weights) relaxed by
its tangents at misses of the mean of −0.1 to 0.1, and the least sum over
the periods of the mean's misses (so that the set stays close where it can,
not at the tolerance's edge everywhere). It runs over
:data:`TOLERANCE_CANDIDATES` candidates: those of its linear relaxation's
solution, then those of least reduced cost, and stops at its first node (no
clock: the same pool gives the same set). A set it finds is checked exactly;
one that misses on σ adds a tangent at its misses and the programme runs again (at
most :data:`_TOLERANCE_ROUNDS` times). A set found within the tolerance is
then improved by swaps of least misfit that keep it within, and replaces
the set of least misfit; where none is found that set stays, and misses
(``chosen_by`` says which rule chose the set). Measured on the isolated risk
flagship's top stripe (ε 3.5, 7926 candidates, selection seeds 1–5;
docs/intensity.md, "The tolerance first"): a set within the tolerance in
every seed, where the set of least misfit missed by 0.11–0.13 at 0.043 s.

Rules of the field: a set never holds the same recording twice (a motion
is known by its PEER record sequence number and component where the
metadata give them, else by its name); with ``max_per_earthquake`` it holds
at most that many motions of an earthquake (the metadata's ``event``, one name across suites; a
motion without one, such as a simulated motion, is its own earthquake); with
``exclude_pulses`` the records the metadata mark as pulses (``pulse``: the
FEMA P695 near-field pulse subset, or a PEER search report's pulse period) are no candidates. Steps 3 and 4 only
ever take a candidate the rules allow.

Everything random comes from ``numpy.random.default_rng(seed)``: the same
pool, target and seed give the same selection.

The period range covers the structure: :func:`selection_periods` spaces
periods logarithmically from 0.2 times its shortest to 3 times its longest
period of interest (each building's first-mode period and the isolated
period), within the models' 0.01–10 s, the conditioning period added.

:func:`array_pool` is :func:`selection_pool` of motions of one step given
as rows (simulated motions), bit for bit, at the cost of their spectra alone;
:func:`pool_intensity` their conditioning measure alone (a pool's pre-screen).

A process computes a pool motion's spectrum at a period once (the cache of
:func:`~stochpound.motions.response_spectrum`): the experiments of one
process that share a pool (stripes conditioned on other measures, other
seeds) reuse it.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import xarray as xr

from scipy import sparse
from scipy.optimize import Bounds, LinearConstraint, linprog, milp

from stochpound._errors import SiteError
from stochpound.stats import earthquake_identities
from stochpound.motions._conditional import PERIOD_RANGE
from stochpound.motions._measures import peak_ground_motion
from stochpound.motions._spectrum import DEFAULT_G, pseudo_spectra, response_spectrum

#: Simulated sets of target spectra, each a start of the greedy selection.
SIMULATED_SETS = 20
#: Periods of a selection range, log-spaced.
RANGE_PERIODS = 20
#: The range of a selection: from this fraction of the shortest period of interest ...
RANGE_LOW = 0.2
#: ... to this multiple of the longest.
RANGE_HIGH = 3.0
#: Fault types of the FEMA P695 metadata and mechanisms of PEER NGA-West2 search reports as scenario mechanisms.
FAULT_TYPES = {"Strike-slip": "strike_slip", "Thrust": "reverse", "Reverse": "reverse", "Reverse-Oblique": "reverse", "Normal": "normal",
               "strike slip": "strike_slip", "Reverse Oblique": "reverse", "Normal Oblique": "normal"}
#: A stripe's selection misses its target where its mean or standard deviation of ln Sa is farther than this from the target's at a period.
TARGET_TOLERANCE = 0.1
#: Weight of the quartic term of the misfit.
QUARTIC_WEIGHT = 100.0
_MAX_PASSES = 50
#: Candidates of the integer programme of ``tolerance_first``: the linear relaxation's own, then those of least reduced cost.
TOLERANCE_CANDIDATES = 3000
#: Misses of the set's mean (the same at every period) at whose tangents the σ floor of ``tolerance_first`` is relaxed, before any cut.
_TANGENTS = (-TARGET_TOLERANCE, -TARGET_TOLERANCE / 2, 0.0, TARGET_TOLERANCE / 2, TARGET_TOLERANCE)
#: Rounds of the integer programme, each with a cut at the mean's misses of the set the one before found that misses on σ.
_TOLERANCE_ROUNDS = 3
#: Attributes of a pool's metadata variables.
_METADATA_UNITS: dict[str, dict[str, str]] = {"magnitude": {}, "distance_km": {"units": "km"}, "vs30": {"units": "m/s"}, "mechanism": {}, "earthquake": {},
                                              "recording": {}, "pulse": {}}


def selection_periods(structure_periods: Sequence[float], conditioning: Sequence[float] = (), count: int = RANGE_PERIODS) -> np.ndarray:
    """Periods (s) of a selection: ``count`` log-spaced over 0.2 T_min – 3 T_max of ``structure_periods`` (within 0.01–10 s), ``conditioning`` added.

    Parameters
    ----------
    structure_periods : list of float
        The structure's periods of interest, s (first modes, the isolated period).
    conditioning : list of float
        The conditioning measure's period(s), s (none for PGA).
    count : int
        Periods in the range.
    """
    values = np.asarray(structure_periods, dtype=float)
    if not values.size or not np.all(values > 0):
        raise SiteError(f"structure_periods: must be one or more periods > 0 s, got {list(structure_periods)!r}")
    low = max(PERIOD_RANGE[0], RANGE_LOW * float(values.min()))
    high = min(PERIOD_RANGE[1], RANGE_HIGH * float(values.max()))
    return np.unique(np.concatenate([np.geomspace(low, high, count), np.asarray(conditioning, dtype=float)]))


def selection_pool(
    records: Sequence,
    periods: Sequence[float],
    measure: str,
    period: float | Sequence[float] | None = None,
    damping: float = 0.05,
    g: float = DEFAULT_G,
) -> xr.Dataset:
    """Unscaled spectra and conditioning measures of a pool of records.

    Parameters
    ----------
    records : list of Record
        The pool (:class:`~stochpound.motions.records.Record`, e.g. from
        :func:`~stochpound.motions.records.load_suite`).
    periods : list of float
        Periods of the target, s.
    measure : {"pga", "psa", "sa_avg"}
        The conditioning measure; ``period`` its T* (psa) or averaging periods (sa_avg), s.
    damping : float
        Damping ratio of the spectra.
    g : float
        m/s², to convert records stored in g.

    Returns
    -------
    xarray.Dataset
        Over ``motion`` (the records' names): ``psa`` (``motion``, ``period``; g),
        ``intensity`` (g), ``magnitude``, ``distance_km``, ``vs30`` (NaN where
        unknown), ``mechanism`` ("" where unknown), ``earthquake`` (the
        metadata's ``event`` normalised across suites, :func:`~stochpound.motions.records.earthquake_identities`, else the motion's name), ``recording`` (PEER
        record sequence number and component, else the name) and ``pulse``
        (the metadata's ``pulse``, False where unknown).
    """
    psa, intensity = [], []
    conditioning = _conditioning_periods(measure, period)
    grid = np.asarray(periods, dtype=float)
    for record in records:
        a = record.acceleration(g)
        spectrum = response_spectrum(a, record.dt, np.concatenate([grid, conditioning]), damping).psa.values / g
        psa.append(spectrum[: grid.size])
        intensity.append(peak_ground_motion(a, record.dt)[0] / g if measure == "pga" else float(_spectral_measure(spectrum[grid.size :])))
    meta = [record.metadata or {} for record in records]
    # one earthquake, one name across suites ("Northridge 1994" and "Northridge-01 1994" of one magnitude); a motion without one is its own
    earthquakes = earthquake_identities([str(m.get("event") or "") for m in meta], [float(m.get("magnitude", np.nan)) for m in meta])
    names = [record.name for record in records]
    return _pool_dataset(names, grid, np.array(psa), np.array(intensity), measure, damping, {
        "magnitude": np.array([float(m.get("magnitude", np.nan)) for m in meta]),
        "distance_km": np.array([float(m.get("distance", np.nan)) for m in meta]),
        "vs30": np.array([float(m.get("vs30", np.nan)) for m in meta]),
        "mechanism": np.array([FAULT_TYPES.get(str(m.get("fault_type", "")), "") for m in meta], dtype=object),
        "earthquake": np.array([identity or name for identity, name in zip(earthquakes, names)], dtype=object),
        "recording": np.array([_recording(m, name) for m, name in zip(meta, names)], dtype=object),
        "pulse": np.array([bool(m.get("pulse", False)) for m in meta]),
    })


def _conditioning_periods(measure: str, period: float | Sequence[float] | None) -> list[float]:
    """The periods (s) of the conditioning measure's spectral values: none for PGA."""
    return [] if measure == "pga" else list(np.atleast_1d(np.asarray(period, dtype=float)))


def _spectral_measure(psa: np.ndarray) -> np.ndarray:
    """The conditioning measure from the PSA at its periods (g, over the last axis): PSA itself at one period, Sa_avg (their
    geometric mean) at several."""
    return np.exp(np.mean(np.log(psa), axis=-1))


def _pool_dataset(names: Sequence[str], grid: np.ndarray, psa: np.ndarray, intensity: np.ndarray, measure: str, damping: float,
                  metadata: dict[str, np.ndarray]) -> xr.Dataset:
    """:func:`selection_pool`'s dataset of the pool's spectra (g), measures (g) and metadata (one array per variable, over ``motion``)."""
    return xr.Dataset(
        {
            "psa": (("motion", "period"), psa, {"units": "g", "long_name": "pseudo-spectral acceleration of the unscaled motion"}),
            "intensity": ("motion", intensity, {"units": "g", "long_name": f"the unscaled motion's {measure}"}),
            **{name: ("motion", values, _METADATA_UNITS[name]) for name, values in metadata.items()},
        },
        coords={"motion": list(names), "period": ("period", grid, {"units": "s"})},
        attrs={"damping": float(damping), "measure": measure},
    )


def pool_intensity(accelerations: np.ndarray, dt: float, measure: str, period: float | Sequence[float] | None = None, damping: float = 0.05,
                   g: float = DEFAULT_G) -> np.ndarray:
    """The conditioning measure (g) of motions of one step (rows, m/s²): :func:`selection_pool`'s ``intensity``, bit for bit.

    Parameters
    ----------
    accelerations : array_like, shape (n, n_time)
        The motions, m/s², at ``dt`` (s).
    dt : float
        Step, s.
    measure : {"pga", "psa", "sa_avg"}
        The conditioning measure; ``period`` its T* (psa) or averaging periods (sa_avg), s.
    damping : float
        Damping ratio of the spectra.
    g : float
        m/s².
    """
    a = np.asarray(accelerations, dtype=float)
    if measure == "pga":
        return np.max(np.abs(a), axis=1) / g
    return _spectral_measure(pseudo_spectra(a, dt, np.array(_conditioning_periods(measure, period)), damping) / g)


def array_pool(accelerations: np.ndarray, dt: float, names: Sequence[str], periods: Sequence[float], measure: str,
               period: float | Sequence[float] | None = None, damping: float = 0.05, g: float = DEFAULT_G, *,
               intensity: np.ndarray | None = None, magnitude: float = np.nan, distance_km: float = np.nan, vs30: float = np.nan) -> xr.Dataset:
    """:func:`selection_pool` of motions of one step given as rows, every spectrum in one compiled call per batch
    (``stochpound.motions._spectrum.pseudo_spectra``): the same dataset, bit for bit, as of the motions as records whose
    metadata are ``magnitude``, ``distance_km`` and ``vs30`` and whose earthquake and recording are their names.

    Parameters
    ----------
    accelerations : array_like, shape (n, n_time)
        The motions, m/s², at ``dt`` (s).
    names : list of str
        Their names (n).
    periods, measure, period, damping, g
        As :func:`selection_pool`.
    intensity : array, optional
        Their conditioning measure (g) when already known (:func:`pool_intensity`), else computed.
    magnitude, distance_km, vs30 : float, optional
        Moment magnitude, rupture distance (km) and Vs30 (m/s) shared by the motions (NaN: unknown).
    """
    grid = np.asarray(periods, dtype=float)
    a = np.asarray(accelerations, dtype=float)
    psa = pseudo_spectra(a, dt, grid, damping) / g
    if intensity is None:
        intensity = pool_intensity(a, dt, measure, period, damping, g)
    n, labels = a.shape[0], np.array(list(names), dtype=object)
    return _pool_dataset(list(names), grid, psa, np.asarray(intensity, dtype=float), measure, damping, {
        "magnitude": np.full(n, float(magnitude)),
        "distance_km": np.full(n, float(distance_km)),
        "vs30": np.full(n, float(vs30)),
        "mechanism": np.full(n, "", dtype=object),
        "earthquake": labels,
        "recording": labels.copy(),
        "pulse": np.zeros(n, dtype=bool),
    })


def _recording(metadata: dict, name: str) -> str:
    """A motion's recording: ``RSN <n> <component>`` where the metadata give them, else its name."""
    rsn = metadata.get("rsn")
    return f"RSN {int(rsn)} {metadata.get('component', '')}" if rsn is not None and np.isfinite(rsn) else str(name)


def select_motions(pool: xr.Dataset, target: xr.Dataset, motions: int, max_scale_factor: float, seed: int = 0, *,
                   max_per_earthquake: int | None = None, exclude_pulses: bool = False, tolerance_first: bool = False) -> xr.Dataset:
    """Choose and scale ``motions`` motions of ``pool`` to match ``target`` (module docstring).

    Parameters
    ----------
    pool : xarray.Dataset
        From :func:`selection_pool`, over the target's periods.
    target : xarray.Dataset
        From :func:`~stochpound.motions.conditional_spectrum`; its ``level`` is the stripe's.
    motions : int
        Motions to choose (≥ 2).
    max_scale_factor : float
        Largest scale factor allowed (≥ 1).
    seed : int
        Seed of the simulated target spectra.
    max_per_earthquake : int, optional
        Most motions of one earthquake in the set (≥ 1; default: no limit).
    exclude_pulses : bool
        Leave out the records the metadata mark as pulses.
    tolerance_first : bool
        Where the set of least misfit misses the target, a set within :data:`TARGET_TOLERANCE` found by the integer
        programme instead (module docstring).

    Returns
    -------
    xarray.Dataset
        Over ``selected``: ``motion`` (names), ``scale_factor``, ``earthquake``; over
        ``period``: the set's ``mean_ln`` and ``std_ln`` (sample, n − 1) of
        the scaled ln Sa, the target's ``median`` and ``sigma_ln``. Attributes:
        ``level``, ``max_scale_factor``, ``seed``, ``pool`` (its motions),
        ``candidates`` (those within ``max_scale_factor`` and the rules),
        ``mean_bound`` (no set of the candidates has its mean of ln Sa closer
        to the target's than this at its worst period: the module docstring's
        programme) and ``target_reachable`` (0 where no set of the candidates
        can meet the target's mean and σ within :data:`TARGET_TOLERANCE`, 1
        where the programmes do not rule it out), ``chosen_by`` (``misfit``, or
        ``tolerance`` where ``tolerance_first`` replaced a set that missed).

    Raises
    ------
    SiteError
        Naming the field: ``motions`` < 2 or more than the pool's motions within
        ``max_scale_factor`` of the level, ``max_scale_factor`` < 1, periods
        of pool and target that differ, candidates that cannot make
        ``motions`` distinct motions under ``max_per_earthquake``.
    """
    if isinstance(motions, bool) or not isinstance(motions, (int, np.integer)) or motions < 2:
        raise SiteError(f"motions: must be an integer >= 2, got {motions!r}")
    if isinstance(max_scale_factor, bool) or not isinstance(max_scale_factor, (int, float)) or not max_scale_factor >= 1.0:
        raise SiteError(f"max_scale_factor: must be >= 1, got {max_scale_factor!r}")
    if pool.period.size != target.period.size or not np.allclose(pool.period.values, target.period.values, rtol=1e-9):
        raise SiteError("periods: the pool's spectra and the target are over different periods")
    if max_per_earthquake is not None and (isinstance(max_per_earthquake, bool) or not isinstance(max_per_earthquake, (int, np.integer))
                                           or max_per_earthquake < 1):
        raise SiteError(f"max_per_earthquake: must be an integer >= 1, got {max_per_earthquake!r}")
    level = float(target.attrs["level"])
    scale = level / pool["intensity"].values
    names = pool["motion"].values
    kept = ~pool["pulse"].values if exclude_pulses and "pulse" in pool else np.ones(scale.size, dtype=bool)
    eligible = np.flatnonzero((scale <= max_scale_factor * (1 + 1e-12)) & kept)
    pulses = " and not pulses (exclude_pulses)" if exclude_pulses else ""
    if eligible.size < motions:
        raise SiteError(
            f"motions: only {eligible.size} of the pool's {scale.size} motions reach the level {level:g} g within max_scale_factor = "
            f"{max_scale_factor:g}{pulses}, fewer than motions = {motions} (add records or raise max_scale_factor)"
        )
    earthquakes = pool["earthquake"].values if "earthquake" in pool else names
    rules = _Rules(earthquakes[eligible], (pool["recording"].values if "recording" in pool else names)[eligible], max_per_earthquake)
    if rules.capacity < motions:
        limit = f"at most max_per_earthquake = {max_per_earthquake} of an earthquake" if max_per_earthquake is not None else "no recording twice"
        raise SiteError(
            f"motions: the {eligible.size} motions of the pool within max_scale_factor = {max_scale_factor:g} of the level {level:g} g{pulses} make "
            f"only {rules.capacity} distinct motions with {limit}, fewer than motions = {motions} "
            "(add records or simulated_motions, or raise max_scale_factor or max_per_earthquake)"
        )
    ln_sa = np.log(pool["psa"].values[eligible]) + np.log(scale[eligible])[:, None]
    mean = np.log(target["median"].values)
    sigma = target["sigma_ln"].values
    covariance = target["correlation"].values * np.outer(sigma, sigma)
    rng = np.random.default_rng(seed)
    weights = 1.0 / np.where(sigma > 0, sigma, 1.0)
    best: tuple[float, list[int]] | None = None
    for _ in range(SIMULATED_SETS):
        chosen: list[int] = []
        for spectrum in rng.multivariate_normal(mean, covariance, size=motions, method="eigh"):
            distance = np.sum(((ln_sa - spectrum) * weights) ** 2, axis=1)
            distance[~rules.allowed(chosen)] = np.inf
            chosen.append(int(np.argmin(distance)))
        chosen = _swap(ln_sa, chosen, mean, sigma, rules)
        misfit = _set_misfit(ln_sa[chosen], mean, sigma)
        if best is None or misfit < best[0]:
            best = (misfit, chosen)
    bound, programme_weights = _programme(ln_sa, mean, sigma, motions, rules)
    chosen = _swap(ln_sa, _heaviest_allowed(programme_weights, motions, rules), mean, sigma, rules)
    if _set_misfit(ln_sa[chosen], mean, sigma) >= best[0]:
        chosen = best[1]
    met = not misses_target(ln_sa[chosen].mean(axis=0), ln_sa[chosen].std(axis=0, ddof=1), target["median"].values, sigma)
    # a set that meets the target proves it reachable
    reachable = met or (bound <= TARGET_TOLERANCE and _programme(ln_sa, mean, sigma, motions, rules, TARGET_TOLERANCE) is not None)
    within = _tolerance_set(ln_sa, target["median"].values, sigma, motions, rules) if tolerance_first and not met and reachable else None
    chosen = chosen if within is None else within
    spectra = ln_sa[chosen]
    set_mean, set_std = spectra.mean(axis=0), spectra.std(axis=0, ddof=1)
    picked = eligible[chosen]
    return xr.Dataset(
        {
            "motion": ("selected", pool["motion"].values[picked]),
            "scale_factor": ("selected", scale[picked], {"units": "1"}),
            "earthquake": ("selected", earthquakes[picked]),
            "mean_ln": ("period", set_mean, {"units": "1", "long_name": "mean ln Sa (g) of the scaled set"}),
            "std_ln": ("period", set_std, {"units": "1", "long_name": "standard deviation of ln Sa of the scaled set"}),
            "median": target["median"],
            "sigma_ln": target["sigma_ln"],
        },
        coords={"period": target.period},
        attrs={"level": level, "max_scale_factor": float(max_scale_factor), "seed": int(seed), "pool": int(scale.size), "candidates": int(eligible.size),
               "mean_bound": bound, "target_reachable": int(reachable), "chosen_by": "misfit" if within is None else "tolerance"},
    )


def _programme(ln_sa: np.ndarray, mean: np.ndarray, sigma: np.ndarray, motions: int, rules: _Rules,
               tolerance: float | None = None) -> tuple[float, np.ndarray] | None:
    """The least t, and its weights w ∈ [0, 1] of the candidates (rows of ``ln_sa``, scaled ln Sa), Σ w = ``motions``, within
    the ``rules`` (Σ w ≤ 1 over a recording's rows, ≤ the cap over an earthquake's), such that the weighted mean of ln Sa is
    within t of ``mean`` at every period (module docstring).

    With ``tolerance``, t may not exceed it, and at every period the weighted sum of squares about the target's mean,
    S = Σ w (ln Sa − mean)² / (motions − 1), must lie within [(σ − tolerance)², (σ + tolerance)² + motions tolerance² /
    (motions − 1)]: a set within ``tolerance`` of the target's mean and σ satisfies both (its variance is S less
    motions / (motions − 1) times its mean's squared miss). None where no weights do.
    """
    n, periods = ln_sa.shape
    rows = [sparse.hstack([sparse.csr_matrix(np.vstack([ln_sa.T, -ln_sa.T]) / motions), sparse.csr_matrix(-np.ones((2 * periods, 1)))])]
    bounds = [np.concatenate([mean, -mean])]
    if tolerance is not None:
        squares = ((ln_sa - mean) ** 2).T / (motions - 1)
        rows.append(sparse.hstack([sparse.csr_matrix(np.vstack([squares, -squares])), sparse.csr_matrix((2 * periods, 1))]))
        bounds.append(np.concatenate([(sigma + tolerance) ** 2 + motions * tolerance**2 / (motions - 1), -np.maximum(sigma - tolerance, 0.0) ** 2]))
    for row, cap in rules.rows(n + 1):
        rows.append(row)
        bounds.append(cap)
    objective = np.zeros(n + 1)
    objective[-1] = 1.0
    result = linprog(objective, A_ub=sparse.vstack(rows).tocsr(), b_ub=np.concatenate(bounds), A_eq=np.append(np.ones(n), 0.0)[None, :],
                     b_eq=[float(motions)], bounds=[(0.0, 1.0)] * n + [(0.0, tolerance)], method="highs")
    if result.status == 2 and tolerance is not None:
        return None
    if result.status != 0:  # without a tolerance a set, hence a solution, exists: the rules' capacity was checked
        raise RuntimeError(f"the selection's programme for the target stopped without an answer: {result.message}")
    return float(result.x[-1]), result.x[:-1]


def _tolerance_set(ln_sa: np.ndarray, median: np.ndarray, sigma: np.ndarray, motions: int, rules: _Rules) -> list[int] | None:
    """A set of ``motions`` rows of ``ln_sa`` (scaled ln Sa of the candidates) within :data:`TARGET_TOLERANCE` of the target's mean
    (``median``, g) and σ at every period, under the ``rules``, by the integer programme of ``tolerance_first`` (module docstring),
    improved by swaps that keep it within; None where the programme finds none."""
    mean = np.log(median)
    tangents = [np.full(mean.size, miss) for miss in _TANGENTS]
    n, periods = ln_sa.shape
    matrix, lower, upper = _tolerance_system(ln_sa, mean, sigma, motions, rules, tangents)
    rows = np.isfinite(upper), np.isfinite(lower)
    cost = np.concatenate([np.zeros(n), np.ones(periods)])  # the weights cost nothing, the mean's misses u ≥ |miss| one each
    relaxed = linprog(cost, A_ub=sparse.vstack([matrix[rows[0]], -matrix[rows[1]]]), b_ub=np.concatenate([upper[rows[0]], -lower[rows[1]]]),
                      bounds=[(0.0, 1.0)] * n + [(0.0, None)] * periods, method="highs")
    if relaxed.status != 0:
        return None
    order = np.lexsort((relaxed.lower.marginals[:n], relaxed.x[:n] <= 1e-9))  # the relaxation's own candidates, then the least reduced cost
    kept = np.sort(order[:TOLERANCE_CANDIDATES])
    part, part_rules = ln_sa[kept], rules.subset(kept)
    cost = np.concatenate([np.zeros(kept.size), np.ones(periods)])
    bounds = Bounds(np.zeros(cost.size), np.concatenate([np.ones(kept.size), np.full(periods, np.inf)]))
    for _ in range(_TOLERANCE_ROUNDS):
        found = milp(cost, integrality=1.0 - cost, bounds=bounds, options={"node_limit": 1},  # whole weights, the misses continuous
                     constraints=LinearConstraint(*_tolerance_system(part, mean, sigma, motions, part_rules, tangents)))
        if found.x is None:
            return None
        chosen = list(np.flatnonzero(found.x[: kept.size] > 0.5))
        spectra = part[chosen]
        if not misses_target(spectra.mean(axis=0), spectra.std(axis=0, ddof=1), median, sigma):
            return [int(kept[row]) for row in _swap(part, chosen, mean, sigma, part_rules, within=median)]
        tangents.append(spectra.mean(axis=0) - mean)
    return None


def _tolerance_system(ln_sa: np.ndarray, mean: np.ndarray, sigma: np.ndarray, motions: int, rules: _Rules,
                      tangents: list[np.ndarray]) -> tuple[sparse.csr_matrix, np.ndarray, np.ndarray]:
    """The constraints of ``tolerance_first``'s programme (module docstring) over the rows of ``ln_sa``: its matrix and row bounds
    over the candidates' weights, then the mean's misses u ≥ |miss| per period (the objective's)."""
    n, periods = ln_sa.shape
    tolerance = TARGET_TOLERANCE
    mean_rows = sparse.csr_matrix(ln_sa.T / motions)
    squares = sparse.csr_matrix(((ln_sa - mean) ** 2).T / (motions - 1))
    ratio = motions / (motions - 1)
    floor = np.maximum(sigma - tolerance, 0.0) ** 2
    blocks = [  # (weights' rows, misses' rows, lower, upper)
        (np.ones((1, n)), np.zeros((1, periods)), [motions], [motions]),
        (mean_rows, np.zeros((periods, periods)), mean - tolerance, mean + tolerance),
        (mean_rows, -np.eye(periods), np.full(periods, -np.inf), mean),
        (mean_rows, np.eye(periods), mean, np.full(periods, np.inf)),
        (squares, np.zeros((periods, periods)), np.full(periods, -np.inf), (sigma + tolerance) ** 2),
        *[(squares - sparse.diags(2.0 * ratio * miss) @ mean_rows, np.zeros((periods, periods)),
           floor - 2.0 * ratio * miss * mean - ratio * miss**2, np.full(periods, np.inf)) for miss in tangents],
        *[(row, np.zeros((row.shape[0], periods)), np.full(row.shape[0], -np.inf), cap) for row, cap in rules.rows(n)],
    ]
    matrix = sparse.vstack([sparse.hstack([sparse.csr_matrix(a), sparse.csr_matrix(b)]) for a, b, _, _ in blocks]).tocsr()
    lower, upper = (np.concatenate([np.asarray(block[k], dtype=float) for block in blocks]) for k in (2, 3))
    return matrix, lower, upper


def _heaviest_allowed(weights: np.ndarray, motions: int, rules: _Rules) -> list[int]:
    """``motions`` candidates, the heaviest first (ties to the earlier row), each allowed by the rules beside those before it."""
    order = np.lexsort((np.arange(weights.size), -weights))
    chosen: list[int] = []
    while len(chosen) < motions:
        allowed = rules.allowed(chosen)
        chosen.append(int(next(i for i in order if allowed[i])))
    return chosen


def misses_target(mean_ln: np.ndarray, std_ln: np.ndarray, median: np.ndarray, sigma_ln: np.ndarray) -> np.ndarray:
    """Whether a selection misses its target: its mean or standard deviation of ln Sa farther than ``TARGET_TOLERANCE`` (0.1) from the target's at any period.

    Parameters
    ----------
    mean_ln, std_ln : array
        The scaled set's mean and standard deviation of ln Sa (Sa in g), over periods (last axis; stripes before it).
    median : array
        The target's median Sa, g.
    sigma_ln : array
        The target's standard deviation of ln Sa.

    Returns
    -------
    numpy.ndarray of bool
        One per stripe (the leading axes).
    """
    mean_off = np.abs(np.asarray(mean_ln) - np.log(np.asarray(median)))
    std_off = np.abs(np.asarray(std_ln) - np.asarray(sigma_ln))
    return np.any((mean_off > TARGET_TOLERANCE) | (std_off > TARGET_TOLERANCE), axis=-1)


def _misfit(set_mean: np.ndarray, set_std: np.ndarray, mean: np.ndarray, sigma: np.ndarray) -> np.ndarray:
    """Σ_T (d_m² + d_s²) + w Σ_T (d_m⁴ + d_s⁴) over the last axis (module docstring)."""
    dm2, ds2 = (set_mean - mean) ** 2, (set_std - sigma) ** 2
    return np.sum(dm2 + ds2, axis=-1) + QUARTIC_WEIGHT * np.sum(dm2 * dm2 + ds2 * ds2, axis=-1)


def _set_misfit(spectra: np.ndarray, mean: np.ndarray, sigma: np.ndarray) -> float:
    """:func:`_misfit` of a set of ln spectra (rows)."""
    return float(_misfit(spectra.mean(axis=0), spectra.std(axis=0, ddof=1), mean, sigma))


class _Rules:
    """Which candidates a set may still take: no recording twice, at most ``cap`` motions of an earthquake (module docstring)."""

    def __init__(self, earthquakes: np.ndarray, recordings: np.ndarray, cap: int | None) -> None:
        self.earthquake = np.unique(earthquakes.astype(str), return_inverse=True)[1]
        self.recording = np.unique(recordings.astype(str), return_inverse=True)[1]
        self.cap = np.inf if cap is None else cap
        distinct = np.unique(np.stack([self.earthquake, self.recording]), axis=1)[0]  # one entry per recording, by its earthquake
        self.capacity = int(np.minimum(np.bincount(distinct), self.cap).sum())

    def rows(self, columns: int) -> list[tuple[sparse.csr_matrix, np.ndarray]]:
        """The rules as rows of a programme over the candidates' weights (its first columns of ``columns``) and their bounds:
        Σ w ≤ 1 over a recording's candidates, ≤ the cap over an earthquake's (a group no larger than its cap is bounded by w ≤ 1 already)."""
        groups = [(self.recording, 1.0)] + ([(self.earthquake, float(self.cap))] if np.isfinite(self.cap) else [])
        rows = []
        for labels, cap in groups:
            shared = np.flatnonzero(np.bincount(labels) > cap)
            if shared.size:
                member = np.flatnonzero(np.isin(labels, shared))
                matrix = sparse.csr_matrix((np.ones(member.size), (np.searchsorted(shared, labels[member]), member)), shape=(shared.size, columns))
                rows.append((matrix, np.full(shared.size, cap)))
        return rows

    def subset(self, rows: np.ndarray) -> _Rules:
        """The rules of the candidates ``rows`` (indices) alone."""
        return _Rules(self.earthquake[rows], self.recording[rows], None if np.isinf(self.cap) else int(self.cap))

    def allowed(self, taken: list[int]) -> np.ndarray:
        """Candidates a set holding the rows ``taken`` may add (bool, one per row)."""
        counts = np.bincount(self.earthquake[taken], minlength=self.earthquake.max() + 1)
        recorded = np.zeros(self.recording.max() + 1, dtype=bool)
        recorded[self.recording[taken]] = True
        return (counts[self.earthquake] < self.cap) & ~recorded[self.recording]


def _swap(ln_sa: np.ndarray, chosen: list[int], mean: np.ndarray, sigma: np.ndarray, rules: _Rules, within: np.ndarray | None = None) -> list[int]:
    """Greedy swaps of chosen rows of ``ln_sa`` for allowed ones while the misfit falls (each slot in turn, best replacement);
    ``within`` (the target's median, g): only swaps that keep the set within :data:`TARGET_TOLERANCE` of the target's mean and σ."""
    chosen = list(chosen)
    n = len(chosen)
    best = _set_misfit(ln_sa[chosen], mean, sigma)
    ln_sa_squared = ln_sa**2
    for _ in range(_MAX_PASSES):
        improved = False
        for slot in range(n):
            kept = chosen[:slot] + chosen[slot + 1 :]
            others = ln_sa[kept]
            total, squares = others.sum(axis=0), (others**2).sum(axis=0)
            set_mean = (total + ln_sa) / n  # every row as the slot's motion
            variance = np.maximum((squares + ln_sa_squared - n * set_mean**2) / (n - 1), 0.0)
            misfit = _misfit(set_mean, np.sqrt(variance), mean, sigma)
            misfit[~rules.allowed(kept)] = np.inf
            if within is not None:
                misfit[misses_target(set_mean, np.sqrt(variance), within, sigma)] = np.inf
            row = int(np.argmin(misfit))
            if misfit[row] < best - 1e-12:
                chosen[slot], best, improved = row, float(misfit[row]), True
        if not improved:
            break
    return chosen
