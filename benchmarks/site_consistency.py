"""g* by conditioning measure at the bundled Fox Plaza site: ``python -m benchmarks.site_consistency``.

The same buildings at the same site, stripes of motions chosen to the
conditional spectrum (``selection = "conditional_spectrum"``, 20 motions
per stripe from the 100 FEMA P695 motions, scale factor <= 5, the scenario
fitted to the site's four curves: ``[site] scenario = "fitted"``), at the
intensities of return periods 72-5000 years of each conditioning measure;
the risk-targeted separation g* at 10 % and 2 % in 50 years. Two
configurations of the elastic buildings issue 36 measured the scaled suite
with (experiments/risk before its buildings were code-designed): the fixed
pair (the reference study's Building 1 beside its neighbour with masses
x 0.5, stiff, or x 2, flexible) and Building 1 on a friction pendulum
(R 2.24 m, mu 0.05, no moat wall, stiff neighbour).

It prints the table and draws ``docs/figures/site_consistency.png`` (g*
against the conditioning measure). About 4 minutes on 2 cores for the four
measures; ``--measures PGA "PSA(1 s)"`` runs fewer. tests/test_benchmark_site_consistency.py
runs the reduced check with the same experiments.
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd
import xarray as xr

from benchmarks.timing import REPOSITORY

if TYPE_CHECKING:
    from stochpound.risk import StoreRisk

RETURN_PERIODS = np.array([72.0, 224.0, 475.0, 975.0, 2475.0, 5000.0])
CURVES = ["fox_plaza_los_angeles_pga", "fox_plaza_los_angeles_sa1p0s", "fox_plaza_los_angeles_sa2p0s", "fox_plaza_los_angeles_sa3p0s"]
MEASURES = {  # measure: ([intensity] lines, bundled hazard)
    "PGA": ('measure = "pga"', CURVES[0]),
    "PSA(1 s)": ('measure = "psa"\nperiod = 1.0', CURVES[1]),
    "PSA(2 s)": ('measure = "psa"\nperiod = 2.0', CURVES[2]),
    "PSA(3 s)": ('measure = "psa"\nperiod = 3.0', CURVES[3]),
}
CONFIGURATIONS = {  # name: (B1's base, an edit of the bundled pair; the neighbour's variants)
    "fixed pair": ("", "[variants.neighbour.stiff.building.B2]\nmass_factor = 0.5\n[variants.neighbour.flexible.building.B2]\nmass_factor = 2.0"),
    "isolated": ("[scene.building.B1]\nbase = { mass = 13134.0, mu = 0.05, radius = 2.24 }", "[variants.neighbour.stiff.building.B2]\nmass_factor = 0.5"),
}
PAIR = """
[scene]
bundled = "elastic_pair"
{base}
{variants}
[grid]
gap = [inf]
[[records]]
suite = "fema_p695_far_field"
[[records]]
suite = "fema_p695_near_field"
"""
FIGURE = REPOSITORY / "docs" / "figures" / "site_consistency.png"


def experiment_text(measure: str, configuration: str, seed: int | None = None) -> str:
    """The experiment file of one conditioning measure and configuration (the selection's ``seed``, or its default)."""
    from stochpound.analysis import HazardCurve

    lines, curve = MEASURES[measure]
    levels = HazardCurve.bundled(curve).intensity_at(1.0 / RETURN_PERIODS)
    base, variants = CONFIGURATIONS[configuration]
    curves = ", ".join(f'"{name}"' for name in CURVES)
    return (f'[experiment]\nname = "site_{curve}"\nstudied = "B1"\n{PAIR.format(base=base, variants=variants)}\n[intensity]\n{lines}\n'
            f"levels = [{', '.join(f'{x:.4f}' for x in levels)}]\n"
            'selection = "conditional_spectrum"\nmotions = 20\nmax_scale_factor = 5.0\n' + ("" if seed is None else f"seed = {seed}\n") +
            f'[site]\nscenario = "fitted"\ncurves = [{curves}]\nvs30 = 400.0\nmechanism = "reverse"\n')


def measure_risk(folder: Path, measure: str, configuration: str, bootstrap: int = 0, seed: int | None = None) -> tuple[xr.Dataset, StoreRisk]:
    """The store and the risk answer (g* at 10 % and 2 % in 50 years, ``bootstrap`` resamples for its 95 % interval) of one
    measure and configuration (the selection's ``seed``, or its default), run in ``folder``."""
    from stochpound import open_store
    from stochpound.analysis import HazardCurve, store_risk
    from stochpound.experiment import load_experiment, run_experiment

    name = f"{measure.replace('(', '').replace(' s)', '').replace(' ', '').lower()}.toml"
    path = folder / name
    path.write_text(experiment_text(measure, configuration, seed))
    report = run_experiment(load_experiment(path), workers=0, progress=False)
    if not report.complete:
        raise RuntimeError(f"{configuration}, {measure}: the experiment did not complete")
    store = open_store(report.store).load()
    return store, store_risk(store, HazardCurve.bundled(MEASURES[measure][1]), targets=(0.1, 0.02), bootstrap=bootstrap)


def g_star(folder: Path, measure: str, configuration: str) -> xr.DataArray:
    """g* (m) at 10 % and 2 % in 50 years of one measure and configuration, run in ``folder``."""
    return measure_risk(folder, measure, configuration)[1].separation["separation"]


def diagnosis(store: xr.Dataset, risk: StoreRisk) -> pd.DataFrame:
    """What a measure's g* rests on, per configuration cell and target: g* and its 95 % bootstrap interval (m); the fragility at
    g* (θ in g and β, interpolated in ln g between the risk's gaps); the share of the MAF at g* owed to the fragility's rise
    beyond the top stripe (extrapolated: λ minus the λ of the hazard cut at the top stripe, whose rate above it counts at
    F(top)); the stripes whose selection misses its target."""
    from stochpound.analysis import HazardCurve
    from stochpound.risk import mean_annual_frequency

    hazard, fragility = risk.hazard, risk.fragility
    top = float(fragility["intensity"].max())
    below = hazard.im[hazard.im < top]
    cut = HazardCurve(np.append(below, top), np.exp(hazard.log_rate(np.log(np.append(below, top)))))
    misses = int(store["selection_misses_target"].sum())
    rows = []
    separation = risk.separation.to_dataframe()
    for index, row in separation.iterrows():
        labels = dict(zip(separation.index.names, index if isinstance(index, tuple) else (index,)))
        cell = fragility.sel({k: v for k, v in labels.items() if k in fragility.dims})
        log_gap = np.log(cell["gap"].values)
        with np.errstate(divide="ignore"):  # θ = 0 at gaps every motion closes
            log_theta = np.log(cell["theta"].values)
        theta = float(np.exp(np.interp(np.log(row["separation"]), log_gap, log_theta)))
        beta = float(np.interp(np.log(row["separation"]), log_gap, cell["beta"].values))
        frag = xr.Dataset({"theta": theta, "beta": beta})
        total = float(mean_annual_frequency(frag, hazard))
        rows.append({**labels, "g*": row["separation"], "lower": row.get("lower", np.nan), "upper": row.get("upper", np.nan),
                     "theta": theta, "beta": beta, "extrapolated": 1.0 - float(mean_annual_frequency(frag, cut)) / total,
                     "missed stripes": f"{misses}/{store.sizes['intensity']}"})
    return pd.DataFrame(rows)


def _subfolder(folder: Path, name: str) -> Path:
    (folder / name).mkdir(exist_ok=True)
    return folder / name


def main(argv: list[str] | None = None) -> None:
    """Run, print the table, draw the figure."""
    from matplotlib.figure import Figure

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--measures", nargs="+", default=list(MEASURES), choices=list(MEASURES))
    parser.add_argument("--configurations", nargs="+", default=list(CONFIGURATIONS), choices=list(CONFIGURATIONS))
    parser.add_argument("--bootstrap", type=int, default=200, help="resamples of the 95 %% interval of g* (0: none)")
    parser.add_argument("--seeds", nargs="*", type=int, default=[], help="other seeds of the selection: g* of every measure again with each")
    args = parser.parse_args(argv)
    figure = Figure(figsize=(7.5, 3.4), layout="constrained")
    axes = figure.subplots(1, 2, sharey=True)
    for ax, target in zip(axes, (0.1, 0.02)):
        ax.set_title(f"{target:.0%} in 50 years", fontsize=9)
        ax.set_yscale("log")
        ax.grid(True, which="both", lw=0.3, color="0.85")
    for configuration in args.configurations:
        answers, diagnoses = [], []
        with tempfile.TemporaryDirectory() as folder:
            for measure in args.measures:
                store, risk = measure_risk(Path(folder), measure, configuration, bootstrap=args.bootstrap)
                answers.append(risk.separation["separation"])
                diagnoses.append(diagnosis(store, risk).assign(measure=measure))
        values = xr.concat(answers, dim="measure").assign_coords(measure=args.measures)
        print(f"\n{configuration}: g* (m) by conditioning measure")
        print(values.to_dataframe().unstack("measure")["separation"].to_string(float_format=lambda v: f"{v:.3f}"))
        ratio = values.max("measure") / values.min("measure")
        print("max/min:", ratio.to_pandas().to_string(float_format=lambda v: f"{v:.2f}"))
        print(f"\n{configuration}: what g* rests on (95 % bootstrap interval of {args.bootstrap} resamples; fragility at g*; MAF share extrapolated beyond the top stripe)")
        print(pd.concat(diagnoses).set_index(["measure"]).to_string(float_format=lambda v: f"{v:.3g}"))
        if args.seeds:
            with tempfile.TemporaryDirectory() as folder:
                again = xr.concat([xr.concat([measure_risk(_subfolder(Path(folder), f"seed{seed}"), measure, configuration, seed=seed)[1].separation["separation"]
                                              for measure in args.measures], dim="measure") for seed in args.seeds], dim="seed")
            again = xr.concat([values.expand_dims(seed=["default"]), again.assign_coords(seed=args.seeds, measure=args.measures)], dim="seed")
            print(f"\n{configuration}: g* (m) by the selection's seed (the same experiments otherwise)")
            print(again.to_dataframe().unstack("seed")["separation"].to_string(float_format=lambda v: f"{v:.3f}"))
        others = [d for d in values.dims if d not in ("measure", "target")]
        stacked = values.stack(cell=others) if others else values.expand_dims(cell=[""])
        for ax, j in zip(axes, range(values.sizes["target"])):
            for k in range(stacked.sizes["cell"]):
                cell = stacked["cell"].values[k]
                label = configuration + (", " + ", ".join(map(str, cell if isinstance(cell, tuple) else (cell,))) + " neighbour" if others else "")
                ax.plot(args.measures, stacked.isel(target=j, cell=k).values, "o-", label=label)
    axes[0].set_ylabel("g* (m)")
    axes[1].legend(fontsize=7)
    figure.savefig(FIGURE, dpi=150)
    print(f"\nfigure: {FIGURE.relative_to(REPOSITORY)}")


if __name__ == "__main__":
    main()
