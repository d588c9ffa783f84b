"""g* by conditioning measure and selection seed at Fox Plaza: ``python -m benchmarks measure_seeds run|table|consistency|measure_free FOLDER``.

Issue 43's measure/seed study, on a pool of records and simulated motions. For every configuration of
:mod:`benchmarks.site_consistency` (the elastic fixed pair beside its stiff or flexible neighbour; Building 1 on the friction
pendulum, μ 0.05, no moat, stiff neighbour; contact-free), every Fox Plaza measure (PGA, PSA(T1 = 0.3 s), PSA(1 s),
PSA(2 s), PSA(3 s), and Sa_avg(0.5-4 s) on its derived curve, :func:`benchmarks.site_consistency.fox_plaza_sa_avg`; each with its own
scenario fitted to the site's curves) and every selection seed: one experiment
(:func:`benchmarks.site_consistency.measure_risk`: ``--motions`` motions a stripe, 40 unless stated, at most 3 of an earthquake, scale factor ≤ 5, from
the 100 FEMA P695 records and ``--simulated`` site-based stochastic motions a stripe drawn by ``--sampling``; the selection's
seed is the motions' seed too, so another seed is another pool).

``run FOLDER`` keeps each experiment's result in ``FOLDER/<configuration>/<measure>-seed<k>.nc``: the rate of pounding over
the gap grid from a lognormal demand per stripe (:func:`stochpound.risk.stripe_demand_rate`), g* at 10 % and 2 % in 50
years from it, and the selection's diagnostics (the fitted scenario, the stripes' ε, their differences from the target). A
result already there is not run again: an interrupted study resumes, and two invocations with different
``--configurations`` run side by side (one core each).

``--site fox_plaza_ruptures`` (with ``--sampling scenario``) runs the same study at Fox Plaza's stand-in ruptures
(:func:`benchmarks.site_consistency.fox_plaza_ruptures_site`: the ruptures fitted to its 17 curves at ``--vs30``, every measure's
curve theirs, each stripe's target their exact conditional spectrum, its simulated motions their causal ruptures'): no fitted
scenario, so what still parts there is the chain's own.

``table FOLDER`` prints the study's two tables from the results and, with ``--write``, rewrites the section of
docs/benchmarks.md between its markers: per configuration and target, each measure's median g* over the seeds (their
range), the spread over the measures' medians and over measures and seeds, the largest seed-to-seed spread of one measure
in g* and in the rate of pounding at that measure's median g*; per configuration and measure, the selections' misses. With
``--estimator fragility`` g* and the rate come from the risk chain's own fits to the stores kept in ``FOLDER/work``
(:func:`fragility_separation`) instead of the results' lognormal demand (printed only: the section is the lognormal demand's).

``consistency FOLDER`` prints, per configuration and conditioning measure, the site's hazard of every measure of the site
(Sa_avg(0.5–4 s) too; at Fox Plaza over its derived curve) recomputed from the stripes' motions as they ran (the stores ``run`` keeps in
``FOLDER/work``) over the site's own curve, at 10 % and 2 % in 50 years: the median over the seeds (their range)
(:func:`stochpound.risk.site_consistency`), over the seeds whose stripes reach the target (their number when not all: the others' motions, scaled as they ran, never
reach that level, a ratio of 0). A measure whose stripes carry the site's shaking at the building's periods gives
ratios near 1 there.

``measure_free FOLDER`` prints, per configuration, each
measure's g* (the median over the seeds, their range; ``--estimator lognormal``, the default, from the results' lognormal demand
per stripe, or ``fragility`` from the risk chain's own fits to each gap's counts, :func:`fragility_separation`) beside the answer
without a measure at the site's ruptures
(:func:`stochpound.analysis.store_measure_free`, ``--runs`` runs of simulated motions of the ruptures on the configuration's scene:
a site of one scenario, ``--site scenario``, is its one rupture; Fox Plaza gives none, and stands in the ruptures fitted to its 17
curves at its Vs30 within the site-motion model's range, :func:`fitted_ruptures`),
and before them the site-motion model's own curves of every measure at the site's levels of 10 % and 2 % in 50 years
(:func:`model_curves`): the answer without a measure is the model's world, the measures' chains the site curves', and the two are
the same world only where the model's curves are the site's (at Fox Plaza they are also only as close as the fitted ruptures'
curves, which the table's first lines state).
"""

from __future__ import annotations

import argparse
import json
import os
import time
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd
import xarray as xr

from stochpound.motions import DEFAULT_G as G, Measure

from benchmarks.report import machine
from benchmarks.sections import Section
from benchmarks.site_consistency import (CONFIGURATIONS, FOX_PLAZA, MEASURE_ARGS, RETURN_PERIODS, SA_AVG, SCENARIO, Pool, Site, check_site_vs30,
                                         fox_plaza_ruptures, fox_plaza_ruptures_site,
                                         experiment_file, fox_plaza_site, lognormal_rate, measure_risk, parse_scenario_site, rate_g_star,
                                         site_measures)
from benchmarks.timing import REPOSITORY

if TYPE_CHECKING:
    from stochpound.analysis import StoreMeasureFree
    from stochpound.hazard import RuptureSite

SECTION = Section("<!-- measure seeds: start -->", "<!-- measure seeds: end -->")
#: The study's first run (untilted pools of 1000, 2026-12-02), a section of docs/benchmarks.md no command writes: kept as measured.
UNTILTED = Section("<!-- measure seeds untilted: start -->", "<!-- measure seeds untilted: end -->")
#: The selection seeds of the study.
SEEDS = (1, 2, 3, 4, 5)
#: Bullet 3's tolerance: measures agree when their g* lie within this ratio.
AGREEMENT = 1.3
#: Motions a stripe, and the most of one earthquake in it.
MOTIONS, MAX_PER_EARTHQUAKE = 40, 3
#: The diagnostics of a store's selection kept with a result.
SELECTION = ("site_magnitude", "site_distance_km", "target_epsilon", "selection_misses_target", "selection_mean_ln", "selection_std_ln",
             "target_median", "target_sigma_ln", "selection_simulated", "selection_earthquakes")


def result_path(folder: Path, configuration: str, measure: str, seed: int) -> Path:
    """Where one experiment's result is kept."""
    name = measure.replace("(", "").replace(")", "").replace(" = ", "_").replace(" ", "").replace(".", "p").lower()
    return folder / configuration.replace(" ", "_") / f"{name}-seed{seed}.nc"


def work_folder(folder: Path, configuration: str, seed: int) -> Path:
    """Where one configuration and seed's experiments run, their files and stores kept."""
    return folder / "work" / f"{configuration.replace(' ', '_')}-{seed}"


def store_path(folder: Path, configuration: str, measure: str, seed: int) -> Path:
    """Where ``run`` keeps the store of one configuration, measure and seed (in ``FOLDER/work``)."""
    return experiment_file(work_folder(folder, configuration, seed), measure).with_suffix(".nc")


def kept_store(folder: Path, configuration: str, measure: str, seed: int) -> Path:
    """The store ``run`` kept for one configuration, measure and seed (:func:`store_path`).

    Raises
    ------
    FileNotFoundError
        Naming the store, if ``run`` has not made it.
    """
    path = store_path(folder, configuration, measure, seed)
    if not path.exists():
        raise FileNotFoundError(f"{path.name} of {configuration}, seed {seed}: not in {path.parent.parent.name}/ (run it first)")
    return path


def run_one(folder: Path, configuration: str, measure: str, seed: int, pool: Pool, site: Site = FOX_PLAZA) -> xr.Dataset:
    """One experiment's result (module docstring): its pounding rate over the gap grid, g* and the selection's diagnostics."""
    work = work_folder(folder, configuration, seed)
    work.mkdir(parents=True, exist_ok=True)
    began = time.time()
    store, risk = measure_risk(work, measure, configuration, seed=seed, pool=pool, site=site)
    rate = lognormal_rate(store, risk)
    kept = store[[name for name in SELECTION if name in store]].drop_encoding().assign(rate=rate, separation=rate_g_star(rate, risk))
    kept.attrs = {"configuration": configuration, "measure": measure, "seed": seed, "motions": pool.motions, "simulated": pool.simulated,
                  "sampling": pool.sampling, "seconds": time.time() - began}
    return kept


def run(folder: Path, configurations: list[str], measures: list[str], seeds: list[int], pool: Pool, site: Site = FOX_PLAZA) -> None:
    """Every result not yet in ``folder`` (module docstring), one after the other.

    Raises
    ------
    SystemExit
        Naming ``--motions``, where a result already in ``folder`` ran another number of motions a stripe than ``pool``'s.
    """
    for configuration in configurations:
        for seed in seeds:
            for measure in measures:
                path = result_path(folder, configuration, measure, seed)
                if path.exists():
                    with xr.open_dataset(path) as kept:
                        motions = result_motions(kept.attrs)
                    if motions != pool.motions:
                        raise SystemExit(f"--motions: {path.parent.name}/{path.name} in {folder.name}/ ran {motions} motions a stripe, "
                                         f"not {pool.motions}: another number needs another folder")
                    continue
                path.parent.mkdir(parents=True, exist_ok=True)
                result = run_one(folder, configuration, measure, seed, pool, site)
                result.to_netcdf(path.with_suffix(".part"))
                os.replace(path.with_suffix(".part"), path)
                print(f"{configuration}, {measure}, seed {seed}: {result.attrs['seconds']:.0f} s", flush=True)


def _cells(values: xr.DataArray) -> list[tuple[str, dict]]:
    """The configuration cells of a result's variable (its dimensions other than gap, target, measure and seed), named."""
    others = [d for d in values.dims if d not in ("gap", "target", "measure", "seed")]
    if not others:
        return [("", {})]
    stacked = values.stack(cell=others)
    cells = []
    for cell in stacked["cell"].values:
        cell = cell if isinstance(cell, tuple) else (cell,)
        cells.append((", ".join(f"{v} {d}" for d, v in zip(others, cell)), dict(zip(others, cell))))
    return cells


def _rate_at(rate: xr.DataArray, gap: float) -> float:
    """The rate of pounding (1/yr) at ``gap`` (m), interpolated in log rate over the result's own gap grid (the results' grids
    differ: joined, each holds NaN at the others' gaps)."""
    rate = rate.dropna("gap")
    gaps, rates = rate["gap"].values, np.log(np.maximum(rate.values, 1e-300))
    return float(np.exp(np.interp(gap, gaps, rates)))


def load(folder: Path, configuration: str, measures: list[str], seeds: list[int]) -> tuple[xr.DataArray, xr.DataArray, dict]:
    """g* (measure × seed × target × cells), the rate (measure × seed × gap × cells) and the selections of a configuration."""
    separations, rates, selections = [], [], {}
    for measure in measures:
        runs = [xr.open_dataset(result_path(folder, configuration, measure, seed)).load() for seed in seeds]
        separations.append(xr.concat([r["separation"] for r in runs], dim="seed"))
        rates.append(xr.concat([r["rate"] for r in runs], dim="seed", join="outer"))  # each on its own gap grid
        selections[measure] = runs
    coords = {"measure": measures, "seed": seeds}
    return (xr.concat(separations, dim="measure").assign_coords(coords), xr.concat(rates, dim="measure", join="outer").assign_coords(coords),
            selections)


def spread_rows(configuration: str, separation: xr.DataArray, rate: xr.DataArray) -> list[list[str]]:
    """The g* table's rows of a configuration (module docstring)."""
    rows = []
    for name, cell in _cells(separation):
        for target in separation["target"].values:
            g = separation.sel(target=target, **cell)
            medians = g.median("seed")
            row = [f"{configuration}{', ' + name if name else ''}, {target:.0%} in 50 yr"]
            row += [f"{float(medians.sel(measure=m)):.3f} ({float(g.sel(measure=m).min()):.3f}–{float(g.sel(measure=m).max()):.3f})"
                    for m in g["measure"].values]
            seed_spread = g.max("seed") / g.min("seed")
            worst = str(seed_spread.idxmax("measure").values)
            lam = {m: [_rate_at(rate.sel(measure=m, seed=s, **cell), float(medians.sel(measure=m))) for s in g["seed"].values]
                   for m in g["measure"].values}
            lam_spread = {m: max(v) / min(v) for m, v in lam.items()}
            worst_lam = max(lam_spread, key=lam_spread.get)
            row += [f"×{float(medians.max() / medians.min()):.2f}", f"×{float(g.max() / g.min()):.2f}",
                    f"×{float(seed_spread.max()):.2f} ({worst})", f"×{lam_spread[worst_lam]:.2f} ({worst_lam})"]
            rows.append(row)
    return rows


def selection_rows(configuration: str, selections: dict) -> list[list[str]]:
    """The selections' table rows of a configuration: per measure, the fitted scenario (seed 1's), the stripes' ε, the stripes
    that miss their target over all seeds, the worst difference and what the stripes hold."""
    rows = []
    for measure, runs in selections.items():
        first = runs[0]
        misses = sum(int(r["selection_misses_target"].sum()) for r in runs)
        total = sum(r.sizes["intensity"] for r in runs)
        worst_mean = max(float(np.abs(r["selection_mean_ln"] - np.log(r["target_median"])).max()) for r in runs)
        worst_std = max(float(np.abs(r["selection_std_ln"] - r["target_sigma_ln"]).max()) for r in runs)
        simulated = np.concatenate([r["selection_simulated"].values for r in runs])
        earthquakes = np.concatenate([r["selection_earthquakes"].values for r in runs])
        eps = first["target_epsilon"].values
        rows.append([f"{configuration}, {measure}", f"M {float(first['site_magnitude'][0]):.2g} at {float(first['site_distance_km'][0]):.3g} km",
                     f"{eps.min():.1f} to {eps.max():.1f}", f"{misses} of {total}", f"{worst_mean:.2f} / {worst_std:.2f}",
                     f"{simulated.min()}–{simulated.max()}", f"{earthquakes.min()}–{earthquakes.max()}"])
    return rows


def consistency(folder: Path, configuration: str, measures: list[str], seeds: list[int], site: Site) -> xr.DataArray:
    """The site's hazard of every measure of ``site`` recomputed from the stripes of each conditioning measure's stores (kept by
    ``run`` in ``FOLDER/work``) over the site's own curve, at 10 % and 2 % in 50 years
    (:func:`stochpound.risk.site_consistency`, :func:`~stochpound.risk.consistency_at_targets`): conditioning × checked × seed × target.

    Raises
    ------
    FileNotFoundError
        Naming the store of a conditioning measure and seed that ``run`` has not made.
    """
    from stochpound import open_store
    from stochpound.risk import consistency_at_targets, site_consistency

    curves = {name: site.hazard(name) for name in site.measures}
    by_measure = {Measure.of(*MEASURE_ARGS[name]): curve for name, curve in curves.items()}
    ratios = np.full((len(measures), len(curves), len(seeds), 2), np.nan)
    for i, measure in enumerate(measures):
        for k, seed in enumerate(seeds):
            with open_store(kept_store(folder, configuration, measure, seed)) as store:
                checked = site_consistency(store, by_measure, hazard=curves[measure])
            for j, result in enumerate(checked.values()):
                ratios[i, j, k] = consistency_at_targets(result)
    return xr.DataArray(ratios, dims=("measure", "checked", "seed", "target"),
                        coords={"measure": measures, "checked": list(curves), "seed": seeds, "target": ["10 % in 50 yr", "2 % in 50 yr"]})


def fragility_separation(folder: Path, configuration: str, measures: list[str], seeds: list[int], site: Site) -> tuple[xr.DataArray, xr.DataArray]:
    """g* (m; measure × seed × target × cells) of the risk chain's own estimator, the lognormal fragility fitted to the counts of
    each gap (:func:`stochpound.risk.store_risk`, no bootstrap), from the stores ``run`` kept in ``FOLDER/work``, and the rate
    of pounding λ_P(g) it reads g* from (1/yr; measure × seed × gap × cells, each store on its own gap grid, NaN at the others').

    Raises
    ------
    FileNotFoundError
        Naming the store of a measure and seed that ``run`` has not made.
    """
    from stochpound import open_store
    from stochpound.risk import store_risk

    separations, rates = [], []
    for measure in measures:
        by_seed, rate_by_seed = [], []
        for seed in seeds:
            with open_store(kept_store(folder, configuration, measure, seed)) as store:
                risk = store_risk(store.load(), site.hazard(measure), targets=(0.1, 0.02))
            by_seed.append(risk.separation["separation"].reset_coords(drop=True))
            rate_by_seed.append(risk.non_increasing_maf().reset_coords(drop=True))
        separations.append(xr.concat(by_seed, dim="seed"))
        rates.append(xr.concat(rate_by_seed, dim="seed", join="outer"))
    coords = {"measure": measures, "seed": seeds}
    return (xr.concat(separations, dim="measure").assign_coords(coords),
            xr.concat(rates, dim="measure", join="outer").assign_coords(coords))


def measure_free(folder: Path, configuration: str, measures: list[str], seeds: list[int], site: Site, runs: int,
                 workers: int, estimator: str = "lognormal") -> tuple[pd.DataFrame, StoreMeasureFree]:
    """Each measure's g* (over the seeds; ``estimator`` "lognormal": the lognormal demand per stripe of ``run``'s results,
    "fragility": :func:`fragility_separation`) beside the answer without a measure
    at the site's ruptures (:func:`stochpound.analysis.store_measure_free`, ``runs`` runs, the motions' seed 1, on the configuration's
    scene as the first measure's first seed's store ran it), compared by :func:`stochpound.analysis.compare_measures` (within
    ×1.3, bullet 3's tolerance).

    Raises
    ------
    FileNotFoundError
        Naming the store that ``run`` has not made.
    """
    from stochpound import open_store
    from stochpound.analysis import compare_measures, store_measure_free

    separation = (load(folder, configuration, measures, seeds)[0] if estimator == "lognormal" else
                  fragility_separation(folder, configuration, measures, seeds, site)[0])
    with open_store(kept_store(folder, configuration, measures[0], seeds[0])) as store:
        free = store_measure_free(store.load(), site.ruptures, runs=runs, seed=1, workers=workers)
    conditioned = {m: [separation.sel(measure=m, seed=s, drop=True) for s in seeds] for m in measures}
    return compare_measures(conditioned, free, tolerance=AGREEMENT), free


def fitted_ruptures(vs30: float) -> RuptureSite:
    """Fox Plaza's stand-in ruptures at ``vs30`` (m/s): :func:`benchmarks.site_condition.fit_ruptures` on its 17 curves within the
    site-motion model's range (:func:`benchmarks.site_consistency.fox_plaza_ruptures`), printed with how closely their curves give
    back the site's and the ruptures and rates kept."""
    error, site = fox_plaza_ruptures(float(vs30))
    print(f"Fox Plaza's ruptures fitted to its 17 curves at Vs30 {vs30:g} m/s (rms of ln(recomputed / site) {np.sqrt(np.mean(error**2)):.2f}, "
          f"largest {np.abs(error).max():.2f}): " + "; ".join(f"M {scenario.magnitude:g} at {scenario.distance_km:g} km {scenario.mechanism} "
                                                            f"{rate:.3g}/yr" for scenario, rate in site) + "\n", flush=True)
    return site


def model_curves(site: Site, measures: list[str], motions: int, seed: int = 7) -> pd.DataFrame:
    """The site-motion model's own hazard at the site's ruptures against the site's curves, per measure and target (10 % and 2 % in
    50 years): λ_model(x) = Σ_r ν_r × the fraction of ``motions`` motions of rupture r (seed ``seed``) beyond x, at the site's level x
    of the target's rate, over that rate; and the model's level at that rate over the site's. The answer without a measure is
    the model's: where these part from 1 at the measure's period, the model's shaking there is not the site's curve."""
    from stochpound.analysis import rate_from_probability, rate_weighted_levels
    from stochpound.motions import site_motions

    values = {m: [] for m in measures}
    for scenario, _ in site.ruptures:
        per_rupture = {m: [] for m in measures}
        for start in range(0, motions, 2000):
            batch = site_motions(scenario=scenario, n=motions, seed=seed, realizations=list(range(start, min(motions, start + 2000))))
            for m, v in measure_values(batch["acceleration"].values, float(batch.attrs["dt"]), measures).items():
                per_rupture[m].append(v)
        for m in measures:
            values[m].append(np.concatenate(per_rupture[m]))
    rows = []
    rates = [rate for _, rate in site.ruptures]
    for m in measures:
        pooled = np.concatenate(values[m])
        weights = np.concatenate([np.full(v.size, nu / v.size) for nu, v in zip(rates, values[m])])
        for probability in (0.1, 0.02):
            target = float(rate_from_probability(probability))
            x = float(site.hazard(m).intensity_at(target))
            rows.append({"target": probability, "measure": m, "site level": x, "model rate / site rate": weights[pooled > x].sum() / target,
                         "model level / site level": rate_weighted_levels(values[m], rates, [target])[0] / x})
    return pd.DataFrame(rows).set_index(["target", "measure"]).sort_index(level="target", ascending=False, sort_remaining=False)


def measure_values(acceleration: np.ndarray, dt: float, measures: list[str]) -> dict[str, np.ndarray]:
    """Each measure's value (g) of every motion (rows of ``acceleration``, m/s², at ``dt`` s): PGA, PSA at a period, or Sa_avg the
    geometric mean of PSA over its periods (5 % damping)."""
    from stochpound.motions import pseudo_spectra

    periods = np.unique([p for kind, period in map(MEASURE_ARGS.get, measures) if kind != "pga" for p in np.atleast_1d(period)])
    psa = pseudo_spectra(acceleration, dt, periods) / G if periods.size else None
    values = {}
    for m in measures:
        kind, period = MEASURE_ARGS[m]
        if kind == "pga":
            values[m] = np.abs(acceleration).max(axis=1) / G
        else:
            values[m] = np.exp(np.log(psa[:, np.searchsorted(periods, np.atleast_1d(period))]).mean(axis=1))
    return values


def measure_free_rows(comparison: pd.DataFrame) -> list[list[str]]:
    """The rows of :func:`measure_free`'s table: per configuration, measure and target, the median g* over the seeds (their range),
    the answer without a measure (its interval) and their ratio."""
    return [[f"{configuration}, {measure}, {target:.0%} in 50 yr", f"{row['median']:.3f} ({row['lowest']:.3f}–{row['highest']:.3f})",
             f"{row['measure-free']:.3f} ({row['lower']:.3f}–{row['upper']:.3f})", f"{row['ratio']:.2f}"]
            for (configuration, measure, target), row in comparison.iterrows()]


def consistency_rows(configuration: str, ratios: xr.DataArray) -> list[list[str]]:
    """Per conditioning measure, each checked measure's recomputed / site hazard: the median over the seeds (their range) at 10 % / 2 %
    in 50 years."""
    def cell(values: np.ndarray) -> str:
        finite = values[np.isfinite(values)]
        if not finite.size:
            return "–"
        reached = "" if finite.size == values.size else f", {finite.size} of {values.size} seeds"
        return f"{np.median(finite):.2f} ({finite.min():.2f}–{finite.max():.2f}{reached})"

    def cells(values: xr.DataArray) -> str:
        return " / ".join(cell(v) for v in values.transpose("target", "seed").values)

    return [[f"{configuration}, {measure}", *(cells(ratios.sel(measure=measure, checked=name)) for name in ratios["checked"].values)]
            for measure in ratios["measure"].values]


def markdown(header: list[str], rows: list[list[str]]) -> list[str]:
    return ["| " + " | ".join(header) + " |", "|" + "---|" * len(header), *("| " + " | ".join(row) + " |" for row in rows)]


def tables(folder: Path, configurations: list[str], measures: list[str], seeds: list[int], estimator: str = "lognormal",
           site: Site = FOX_PLAZA) -> tuple[list[list[str]], list[list[str]], list[float], dict]:
    """The rows of the g* table and of the selections' table, each experiment's seconds and the first result's settings; g* and
    λ_P from the results' lognormal demand per stripe (``estimator`` "lognormal") or the risk chain's fits to the stores kept in
    ``FOLDER/work`` at ``site`` ("fragility", :func:`fragility_separation`)."""
    spreads, selected, seconds, settings = [], [], [], {}
    for configuration in configurations:
        separation, rate, selections = load(folder, configuration, measures, seeds)
        if estimator == "fragility":
            separation, rate = fragility_separation(folder, configuration, measures, seeds, site)
        spreads += spread_rows(configuration, separation, rate)
        selected += selection_rows(configuration, selections)
        seconds += [r.attrs["seconds"] for runs in selections.values() for r in runs]
        settings = settings or selections[measures[0]][0].attrs
    return spreads, selected, seconds, settings


G_HEADER = ["max/min over the measures' medians", "over measures and seeds", "seed spread of g*, largest (measure)",
            "seed spread of λ at the median g*, largest (measure)"]
SELECTION_HEADER = ["configuration, measure", "fitted scenario", "ε of the stripes", "stripes off by > 0.1", "worst: mean / σ of ln Sa off by",
                    "simulated motions a stripe", "earthquakes a stripe"]


def result_motions(settings: dict) -> int:
    """The motions a stripe of a result (its attributes): :data:`MOTIONS` for results from before ``--motions``."""
    return int(settings.get("motions", MOTIONS))


def _motions_option(settings: dict) -> str:
    """The ``--motions`` option of a study's command, where its results ran other than :data:`MOTIONS` a stripe."""
    motions = result_motions(settings)
    return "" if motions == MOTIONS else f" --motions {motions}"


def section(folder: Path, configurations: list[str], measures: list[str], seeds: list[int]) -> str:
    """The section of docs/benchmarks.md (its markers included)."""
    spreads, selected, seconds, settings = tables(folder, configurations, measures, seeds)
    provenance = json.loads((folder / "provenance.json").read_text()) if (folder / "provenance.json").exists() else {}
    lines = [SECTION.start, "## g* by conditioning measure and selection seed at Fox Plaza", "",
             f"`python -m benchmarks measure_seeds run FOLDER{_motions_option(settings)} --simulated {settings['simulated']} --sampling "
             f"{settings['sampling']}`, then "
             "`python -m benchmarks measure_seeds table FOLDER --write` (issue 43's measure/seed study; "
             f"{len(seconds)} experiments, {min(seconds):.0f}–{max(seconds):.0f} s each, {sum(seconds) / 60:.0f} min in all; "
             f"commit {provenance.get('commit', 'unknown')}, started {provenance.get('date', 'unknown')}, "
             f"load {provenance.get('load average (1 min) at start', 'unknown')} as the first began; two invocations, one per configuration, "
             "may share the cores, and then each experiment's time is under that load). The elastic buildings of `benchmarks.site_consistency`, "
             f"contact-free, stripes at the intensities of {', '.join(f'{t:g}' for t in RETURN_PERIODS[:-1])} and {RETURN_PERIODS[-1]:g} years of each measure "
             "(PSA(0.3 s)'s curve stops at 3431 years: its top stripe there), each measure with its own scenario fitted to the "
             f"site's PGA, PSA(1, 2, 3 s) curves (and its own), Vs30 400 m/s, reverse faulting; {result_motions(settings)} motions a stripe, at most {MAX_PER_EARTHQUAKE} of "
             "one earthquake, scale factor ≤ 5, from the 100 FEMA P695 records and "
             f"{settings['simulated']} site-based stochastic motions a stripe ({settings['sampling']} sampling, `[site] simulated_sampling`; "
             "the hazard-compatible model with its current calibration; the selection's seed is the motions' seed too, so another "
             f"seed is another pool). Seeds {', '.join(map(str, seeds))}. g* (m) from a lognormal demand per stripe "
             "(`stripe_demand_rate`): the median over the seeds (their range); the spread over the measures' medians and over "
             "every measure and seed; the largest seed-to-seed spread of one measure, in g* and in the rate of pounding λ at "
             "that measure's median g*:", ""]
    lines += markdown(["configuration, target", *measures, *G_HEADER], spreads)
    lines += ["", "The selections, over all seeds: the fitted scenario, the stripes' ε, the stripes that miss their target by "
              "more than 0.1 in the mean or σ of ln Sa at some period, the worst difference, and what the stripes hold:", ""]
    lines += markdown(SELECTION_HEADER, selected)
    if SA_AVG in measures:
        lines += ["", f"{SA_AVG}'s curve is DERIVED, not published (the bundled Fox Plaza curves are per period): the hazard of the "
                  "ruptures fitted to the site's 17 curves at Vs30 400 m/s (`benchmarks.site_consistency.fox_plaza_sa_avg`), its scenario "
                  "fitted to the four curves and that one, given to `[site] curves` as a file."]
    lines += ["", "Conclusions: [intensity.md](intensity.md) (\"The measure and seed study on tilted pools\", \"Which measure is right at "
              "Fox Plaza\").", SECTION.end]
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    """``run``, ``table``, ``consistency`` or ``measure_free`` (module docstring)."""
    parser = argparse.ArgumentParser(prog="python -m benchmarks measure_seeds", description=__doc__.splitlines()[0])
    parser.add_argument("action", choices=("run", "table", "consistency", "measure_free"))
    parser.add_argument("folder", type=Path)
    parser.add_argument("--configurations", nargs="+", default=list(CONFIGURATIONS), choices=list(CONFIGURATIONS))
    parser.add_argument("--measures", nargs="+", default=None, choices=list(MEASURE_ARGS), help="default: the site's")
    parser.add_argument("--seeds", nargs="+", type=int, default=list(SEEDS))
    parser.add_argument("--motions", type=int, default=MOTIONS, help="run: motions a stripe (default %(default)s; another number, another folder)")
    parser.add_argument("--simulated", type=int, default=2000, help="simulated motions a stripe (default %(default)s)")
    parser.add_argument("--sampling", choices=("scenario", "tilted"), default="tilted")
    parser.add_argument("--write", action="store_true", help="rewrite the section of docs/benchmarks.md (Fox Plaza's study)")
    parser.add_argument("--site", choices=("fox_plaza", "fox_plaza_ruptures", "scenario"), default="fox_plaza",
                        help="the bundled Fox Plaza site; its stand-in ruptures at --vs30 as a site of ruptures (exact conditional spectra); "
                             "or benchmarks.site_consistency's site of one scenario (--scenario)")
    parser.add_argument("--scenario", nargs=4, metavar=("M", "R_KM", "MECHANISM", "RATE"), default=list(SCENARIO))
    parser.add_argument("--vs30", type=float, default=400.0,
                        help="--site fox_plaza: the Vs30 assumed (m/s), its scenarios fitted at it (default %(default)s; benchmarks.site_condition)")
    parser.add_argument("--runs", type=int, default=20000, help="measure_free: runs of the answer without a measure (default %(default)s)")
    parser.add_argument("--workers", type=int, default=1, help="measure_free: its processes (default %(default)s)")
    parser.add_argument("--model-motions", type=int, default=20000,
                        help="measure_free: motions a rupture for the model's own curves (default %(default)s)")
    parser.add_argument("--estimator", choices=("lognormal", "fragility"), default="lognormal",
                        help="measure_free and table: each measure's g* from a lognormal demand per stripe (default) or the risk chain's fragility fits")
    arguments = parser.parse_args(argv)
    if arguments.motions < 2:  # before the folder is made: the experiments' own check would come as a traceback, mid-study
        parser.error(f"--motions: must be at least 2 motions a stripe, got {arguments.motions}")
    if arguments.site == "scenario" and arguments.vs30 != 400.0:
        parser.error("--vs30: Fox Plaza's assumed Vs30; the site of one scenario takes its own in --scenario's site")
    if arguments.site != "scenario":
        check_site_vs30(parser, "--vs30", arguments.vs30)
    if arguments.site == "fox_plaza_ruptures" and arguments.action == "run" and arguments.sampling != "scenario":
        parser.error("--sampling: a site of ruptures draws each stripe's simulated motions from its causal ruptures: --sampling scenario")
    site = (fox_plaza_site(arguments.vs30) if arguments.site == "fox_plaza" else fox_plaza_ruptures_site(arguments.vs30)
            if arguments.site == "fox_plaza_ruptures" else parse_scenario_site(parser, arguments.scenario))
    arguments.measures = site_measures(parser, site, arguments.measures)
    if arguments.write and site is not FOX_PLAZA:
        parser.error("--write: the section is Fox Plaza's study at Vs30 400 m/s; print another site's tables without it")
    if arguments.action == "run":
        arguments.folder.mkdir(parents=True, exist_ok=True)
        provenance = arguments.folder / "provenance.json"
        if not provenance.exists():
            provenance.write_text(json.dumps(machine()))  # its commit, date and load as the study starts
        run(arguments.folder, arguments.configurations, arguments.measures, arguments.seeds,
            Pool(arguments.motions, arguments.simulated, MAX_PER_EARTHQUAKE, arguments.sampling), site)
        return 0
    if arguments.action == "measure_free":
        if site.ruptures is None:  # Fox Plaza: ruptures fitted to its 17 curves stand in for the ones it does not give
            site = replace(site, ruptures=fitted_ruptures(arguments.vs30))
        if arguments.runs < 2 * len(site.ruptures):
            parser.error(f"--runs: must be at least {2 * len(site.ruptures)} (two runs of each of the site's ruptures), got {arguments.runs}")
        curves = model_curves(site, arguments.measures, arguments.model_motions)
        print("\n".join(markdown(["target, measure", "site's level (g)", "model's rate there / site's", "model's level / site's"],
                                  [[f"{t:.0%} in 50 yr, {m}", f"{row['site level']:.4f}", f"{row['model rate / site rate']:.2f}",
                                    f"{row['model level / site level']:.2f}"] for (t, m), row in curves.iterrows()])) + "\n", flush=True)
        for configuration in arguments.configurations:
            comparison, free = measure_free(arguments.folder, configuration, arguments.measures, arguments.seeds, site, arguments.runs,
                                            arguments.workers, arguments.estimator)
            print("\n".join(markdown(["configuration, measure, target", "g* (m): median over the seeds (range)",
                                        "without a measure (95 % interval)", "ratio"], measure_free_rows(comparison))))
            print(free.conditions())
        return 0
    if arguments.action == "consistency":
        for configuration in arguments.configurations:
            ratios = consistency(arguments.folder, configuration, arguments.measures, arguments.seeds, site)
            print("\n".join(markdown(["conditioning measure", *ratios["checked"].values], consistency_rows(configuration, ratios))) + "\n")
        return 0
    if arguments.write and arguments.estimator != "lognormal":
        parser.error("--write: the section is the lognormal demand's; print the fragility estimator's tables without it")
    if site is not FOX_PLAZA or arguments.estimator != "lognormal":  # the tables alone
        spreads, selected, _, _ = tables(arguments.folder, arguments.configurations, arguments.measures, arguments.seeds, arguments.estimator,
                                         site)
        print("\n".join(markdown(["configuration, target", *arguments.measures, *G_HEADER], spreads) + [""] + markdown(SELECTION_HEADER, selected)))
        return 0
    text = section(arguments.folder, arguments.configurations, arguments.measures, arguments.seeds)
    print(text)
    if arguments.write:
        SECTION.write(REPOSITORY / "docs" / "benchmarks.md", text)
    return 0
