"""Whether a measure's g* parts from the answer by its motions or by its estimator: ``python -m benchmarks stripe_tails FOLDER --scenario M R MECH RATE``.

At a site of one scenario (:func:`benchmarks.site_consistency.scenario_site`) the site-motion model's world can be conditioned on a
measure without any selection. ``--motions`` motions of the scenario (:func:`stochpound.motions.site_motions`, ``--seed``) are each
measured (every measure of the site) and run on each configuration cell's scene, as ``measure_seeds run`` ran it (the first
measure's store of the first seed in ``FOLDER/work``), for the contact-free closure D. Then per configuration cell and measure:

- **the answer without a measure** from the same runs: the g* at which ν × the share of runs with D above it reaches each target
  rate (10 % and 2 % in 50 years);
- **the model's own stripes**: at each of the experiment's stripe levels, the ``--nearest`` runs whose measure is nearest in ln
  (no selection, no scaling: the model's conditional closures), fed to the estimator ``measure_seeds`` judges the measures by,
  a lognormal demand per stripe (:func:`stochpound.risk.stripe_demand_rate`) on the site's curve: its g* over the answer. Where it
  parts from 1 as the experiment's stripes do (``measure_seeds measure_free``), the parting is the estimator's, not the motions';
- **the shape of ln D within the stripes**: its skewness, the median over the stripes, of the model's stripes and of the experiment's
  (the seeds given, their stores in ``FOLDER/work``): the lognormal demand takes it as 0;
- **the tail the lognormal sees**: over the experiment's stripes (every seed) whose lognormal puts the answer's g* at 2 % in 50 years
  in its upper tail (less than :data:`TAIL` of the stripe's runs expected beyond it: the stripes of frequent shaking whose rare
  closures carry an inefficient measure's rate), the runs with D at or above that g*, against the number the lognormal of each
  stripe expects, Σ_j n_j p_j Φ((m_j − ln g)/s_j) (m_j, s_j the mean and standard deviation of ln D over the stripe's runs with
  D > 0, p_j their share of its n_j runs).
"""

from __future__ import annotations

import argparse
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd
import xarray as xr

from benchmarks.measure_seeds import SEEDS, markdown, measure_values, store_path
from benchmarks.site_consistency import CONFIGURATIONS, MEASURE_ARGS, SCENARIO, Site, parse_scenario_site, site_measures

#: Runs of the model's world, and the nearest of them that make a stripe (the experiment's motions a stripe).
MOTIONS, NEAREST = 20000, 40
#: The targets (probability in 50 years).
TARGETS = (0.1, 0.02)
#: A stripe whose lognormal expects less than this share of its runs at or above a gap has the gap in its upper tail.
TAIL = 0.1
#: The dimensions of a store's closure that are its cases, not its configuration cells.
CASE_DIMS = ("intensity", "record", "realization")


def model_world(site: Site, store: xr.Dataset, measures: list[str], motions: int, seed: int) -> xr.Dataset:
    """``motions`` motions of the site's one scenario: each measure's value (g) and the contact-free closure D (m) of every
    configuration cell of ``store`` (dims ``motion`` and the cells' dimensions)."""
    from stochpound import simulate
    from stochpound.motions import site_motions
    from stochpound.motions.ground import SampledMotion
    from stochpound.risk import configuration_scene, contact_free_closure

    if site.ruptures is None or len(site.ruptures) != 1:
        raise ValueError("site: the model's world is conditioned at a site of one scenario (benchmarks.site_consistency.scenario_site)")
    (scenario, _), = site.ruptures
    closure = contact_free_closure(store)
    cells = closure.isel({dim: 0 for dim in CASE_DIMS if dim in closure.dims}, drop=True)
    stacked = cells.expand_dims("one").stack(cell=["one", *cells.dims])
    scenes = [configuration_scene(store, {dim: value for dim, value in zip(stacked.indexes["cell"].names, labels) if dim != "one"})
              for labels in stacked.indexes["cell"]]
    values, closures = {m: [] for m in measures}, []
    for start in range(0, motions, 1000):
        batch = site_motions(scenario=scenario, n=motions, seed=seed, realizations=list(range(start, min(motions, start + 1000))))
        dt, acceleration = float(batch.attrs["dt"]), batch["acceleration"].values
        for m, v in measure_values(acceleration, dt, measures).items():
            values[m].append(v)
        closures.append([[float(np.max(simulate(replace(scene, motion=SampledMotion(dt, a, "linear", "site motion")))["peak_contact_closure"].values))
                          for scene in scenes] for a in acceleration])
    closure = xr.DataArray(np.concatenate(closures), dims=("motion", "cell"), coords={"cell": stacked.indexes["cell"]}).unstack("cell")
    return xr.Dataset({"closure": closure.squeeze("one", drop=True), **{m: ("motion", np.concatenate(v)) for m, v in values.items()}})


def nearest_stripes(measure: np.ndarray, closure: np.ndarray, levels: np.ndarray, nearest: int) -> np.ndarray:
    """The closures (stripe, run) of the ``nearest`` runs whose measure is nearest each level in ln (ties: the earlier run)."""
    distance = np.abs(np.log(measure)[None, :] - np.log(np.asarray(levels, dtype=float))[:, None])
    return np.asarray(closure)[np.argsort(distance, axis=1, kind="stable")[:, :nearest]]


def lognormal_tail(stripes: np.ndarray, gap: float, tail: float = TAIL) -> tuple[int, float]:
    """Over the stripes of closures (stripe, run; NaN not run) whose lognormal puts ``gap`` in its upper tail (a share below
    ``tail`` of the stripe's runs expected at or above it): the runs with D ≥ ``gap`` and the number each stripe's lognormal of its
    D > 0 expects (module docstring)."""
    from scipy.special import ndtr

    from stochpound.risk import stripe_demand_moments

    stripes = np.asarray(stripes, dtype=float)
    mean, std, fraction = stripe_demand_moments(stripes)
    share = fraction * ndtr((mean - np.log(gap)) / std)  # of a stripe's runs, expected at or above the gap
    tailed = share < tail
    observed = int(np.count_nonzero(stripes[tailed] >= gap))
    expected = float((share * np.isfinite(stripes).sum(-1))[tailed].sum())
    return observed, expected


def skewness(stripes: np.ndarray) -> float:
    """The median over stripes (stripe, run; NaN not run) of the sample skewness of ln D over each stripe's runs with D > 0."""
    from scipy.stats import skew

    rows = [np.log(row[np.isfinite(row) & (row > 0.0)]) for row in np.asarray(stripes, dtype=float)]
    return float(np.median([skew(row) for row in rows]))


def _g_star(closure: xr.DataArray, hazard, levels: np.ndarray, gaps: np.ndarray) -> np.ndarray:
    """g* (m) at :data:`TARGETS` of the lognormal demand per stripe of ``closure`` (stripe, run)."""
    from stochpound.risk import risk_targeted_separation, stripe_demand_rate

    demand = xr.DataArray(np.asarray(closure, dtype=float), dims=("intensity", "record"), coords={"intensity": levels})
    rate = stripe_demand_rate(demand, gaps, hazard)
    return risk_targeted_separation(xr.Dataset({"maf": rate}), list(TARGETS))["separation"].values


def rows(world: xr.Dataset, site: Site, folder: Path, configuration: str, measures: list[str], seeds: list[int], nearest: int) -> pd.DataFrame:
    """Per configuration cell and measure (module docstring): the answer's g*, the model's stripes' g* over it, the skewness of
    ln D in the model's and the experiment's stripes, and the experiment's runs beyond the answer's g* at 2 % in 50 years against
    the lognormal's expectation."""
    from stochpound import open_store
    from stochpound.analysis import rate_from_probability, rate_weighted_levels
    from stochpound.risk import contact_free_closure

    (_, nu), = site.ruptures
    stores = {(m, s): open_store(store_path(folder, configuration, m, s)) for m in measures for s in seeds}
    try:
        experiment = {key: contact_free_closure(store).load() for key, store in stores.items()}
    finally:
        for store in stores.values():
            store.close()
    cells = [dim for dim in world["closure"].dims if dim != "motion"]
    out = []
    for labels in (world["closure"].isel(motion=0).stack(cell=cells).indexes["cell"] if cells else [()]):
        where = dict(zip(cells, labels if isinstance(labels, tuple) else (labels,)))
        closure = world["closure"].sel(where).values
        answer = rate_weighted_levels([closure], [nu], [float(rate_from_probability(p)) for p in TARGETS])
        gaps = np.exp(np.linspace(np.log(answer.min() / 20.0), np.log(answer.max() * 20.0), 400))
        for m in measures:
            levels = experiment[(m, seeds[0])]["intensity"].values
            model = nearest_stripes(world[m].values, closure, levels, nearest)
            ours = [experiment[(m, s)].sel(where).transpose("intensity", ...).values.reshape(levels.size, -1) for s in seeds]
            observed, expected = np.sum([lognormal_tail(stripes, answer[-1]) for stripes in ours], axis=0)
            g_model = _g_star(model, site.hazard(m), levels, gaps)
            out.append({"cell": ", ".join(f"{v} {d}" for d, v in where.items()) or "-", "measure": m, **{f"answer {p:.0%}": a for p, a in zip(TARGETS, answer)},
                        **{f"model stripes / answer {p:.0%}": g / a for p, g, a in zip(TARGETS, g_model, answer)},
                        "skewness, model stripes": skewness(model), "skewness, experiment stripes": float(np.median([skewness(s) for s in ours])),
                        "runs beyond": int(observed), "lognormal expects": float(expected)})
    return pd.DataFrame(out)


def table(frame: pd.DataFrame) -> list[str]:
    """The markdown table of :func:`rows`."""
    body = [[f"{row['cell']}, {row['measure']}", f"{row['answer 10%']:.3f} / {row['answer 2%']:.3f}",
             f"{row['model stripes / answer 10%']:.2f} / {row['model stripes / answer 2%']:.2f}",
             f"{row['skewness, model stripes']:+.2f} / {row['skewness, experiment stripes']:+.2f}",
             f"{row['runs beyond']} / {row['lognormal expects']:.1f}"] for _, row in frame.iterrows()]
    return markdown(["configuration, measure", "answer without a measure, g* (m) 10 % / 2 %", "model's stripes' g* / answer, 10 % / 2 %",
                     "skewness of ln D, model's / experiment's stripes", "experiment's runs beyond the 2 % answer / the lognormal's expectation, stripes with it in their tail"], body)


def main(argv: list[str] | None = None) -> int:
    """Print the table of every configuration (module docstring)."""
    from stochpound import open_store

    parser = argparse.ArgumentParser(prog="python -m benchmarks stripe_tails", description=__doc__.splitlines()[0])
    parser.add_argument("folder", type=Path, help="the folder of `python -m benchmarks measure_seeds run ... --site scenario`")
    parser.add_argument("--scenario", nargs=4, metavar=("M", "R_KM", "MECHANISM", "RATE"), default=list(SCENARIO))
    parser.add_argument("--configurations", nargs="+", default=list(CONFIGURATIONS), choices=list(CONFIGURATIONS))
    parser.add_argument("--measures", nargs="+", default=None, choices=list(MEASURE_ARGS), help="default: the site's")
    parser.add_argument("--seeds", nargs="+", type=int, default=list(SEEDS), help="the experiment's selection seeds")
    parser.add_argument("--motions", type=int, default=MOTIONS, help="runs of the model's world (default %(default)s)")
    parser.add_argument("--nearest", type=int, default=NEAREST, help="runs of a model's stripe (default %(default)s)")
    parser.add_argument("--seed", type=int, default=11, help="the model world's motions' seed (default %(default)s)")
    arguments = parser.parse_args(argv)
    site = parse_scenario_site(parser, arguments.scenario)
    measures = site_measures(parser, site, arguments.measures)
    if not 2 <= arguments.nearest <= arguments.motions:
        parser.error(f"--nearest: must be 2 to --motions ({arguments.motions}), got {arguments.nearest}")
    for configuration in arguments.configurations:  # every store checked before the model's world is made (minutes)
        for seed in arguments.seeds:
            for measure in measures:
                path = store_path(arguments.folder, configuration, measure, seed)
                if not path.exists():
                    parser.error(f"{configuration}, seed {seed}: no store {path.name} in the folder (run measure_seeds run first)")
    for configuration in arguments.configurations:
        first = store_path(arguments.folder, configuration, measures[0], arguments.seeds[0])
        with open_store(first) as store:
            world = model_world(site, store.load(), measures, arguments.motions, arguments.seed)
        print("\n".join(table(rows(world, site, arguments.folder, configuration, measures, arguments.seeds, arguments.nearest))))
        print(f"\n{configuration}: {arguments.motions} motions of the scenario (seed {arguments.seed}), the model's stripes the "
              f"{arguments.nearest} runs nearest each level; the experiment's stripes of seeds {', '.join(map(str, arguments.seeds))}\n", flush=True)
    return 0
