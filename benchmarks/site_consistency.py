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

import numpy as np
import xarray as xr

from benchmarks.timing import REPOSITORY

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


def experiment_text(measure: str, configuration: str) -> str:
    """The experiment file of one conditioning measure and configuration."""
    from stochpound.analysis import HazardCurve

    lines, curve = MEASURES[measure]
    levels = HazardCurve.bundled(curve).intensity_at(1.0 / RETURN_PERIODS)
    base, variants = CONFIGURATIONS[configuration]
    curves = ", ".join(f'"{name}"' for name in CURVES)
    return (f'[experiment]\nname = "site_{curve}"\nstudied = "B1"\n{PAIR.format(base=base, variants=variants)}\n[intensity]\n{lines}\n'
            f"levels = [{', '.join(f'{x:.4f}' for x in levels)}]\n"
            'selection = "conditional_spectrum"\nmotions = 20\nmax_scale_factor = 5.0\n'
            f'[site]\nscenario = "fitted"\ncurves = [{curves}]\nvs30 = 400.0\nmechanism = "reverse"\n')


def g_star(folder: Path, measure: str, configuration: str) -> xr.DataArray:
    """g* (m) at 10 % and 2 % in 50 years of one measure and configuration, run in ``folder``."""
    from stochpound import open_store
    from stochpound.analysis import HazardCurve, store_risk
    from stochpound.experiment import load_experiment, run_experiment

    name = f"{measure.replace('(', '').replace(' s)', '').replace(' ', '').lower()}.toml"
    path = folder / name
    path.write_text(experiment_text(measure, configuration))
    report = run_experiment(load_experiment(path), workers=0, progress=False)
    if not report.complete:
        raise RuntimeError(f"{configuration}, {measure}: the experiment did not complete")
    risk = store_risk(open_store(report.store).load(), HazardCurve.bundled(MEASURES[measure][1]), targets=(0.1, 0.02), bootstrap=0)
    return risk.separation["separation"]


def main(argv: list[str] | None = None) -> None:
    """Run, print the table, draw the figure."""
    from matplotlib.figure import Figure

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--measures", nargs="+", default=list(MEASURES), choices=list(MEASURES))
    args = parser.parse_args(argv)
    figure = Figure(figsize=(7.5, 3.4), layout="constrained")
    axes = figure.subplots(1, 2, sharey=True)
    for ax, target in zip(axes, (0.1, 0.02)):
        ax.set_title(f"{target:.0%} in 50 years", fontsize=9)
        ax.set_yscale("log")
        ax.grid(True, which="both", lw=0.3, color="0.85")
    for configuration in CONFIGURATIONS:
        with tempfile.TemporaryDirectory() as folder:
            values = xr.concat([g_star(Path(folder), measure, configuration) for measure in args.measures], dim="measure")
        values = values.assign_coords(measure=args.measures)
        print(f"\n{configuration}: g* (m) by conditioning measure")
        print(values.to_dataframe().unstack("measure")["separation"].to_string(float_format=lambda v: f"{v:.3f}"))
        ratio = values.max("measure") / values.min("measure")
        print("max/min:", ratio.to_pandas().to_string(float_format=lambda v: f"{v:.2f}"))
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
