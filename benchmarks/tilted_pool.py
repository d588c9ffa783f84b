"""What a pool tilted to a stripe does to the motions at its level: ``python -m benchmarks.tilted_pool FILE STRIPE [STRIPE ...]``.

For a flagship with one scenario (``[site] scenario = "fitted"`` or one given
for every level), fits the tilt (the experiment's tilt pilot's
line, on the scenario's first ``TILT_PILOT`` untilted motions), then for
every stripe asked (from 1, in the order of the sorted levels) draws its
tilted pool (the ``[site] simulated_motions`` N of the file, the stripe's
seed and shift, as the experiment does) and prints, for the motions at the
level (|ln IM* − ln x| < :data:`WINDOW`), the geometric means of D5–95,
t_mid, f_mid and the model's Arias intensity: of the untilted pilot's, of
the tilted pool's, and of the tilted pool's reweighted by the exact density
ratio exp(−s·z + |s|²/2) (s the shift, z the parameter normals: the
scenario's own distribution), with the reweighted effective sample size
(docs/intensity.md, "A pool tilted to each stripe"). Then the time and the
machine's load.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from benchmarks.report import machine

WINDOW = 0.25
"""Half-width, in ln IM*, of the motions "at the level"."""
PARAMETERS = ("d5_95", "t_mid", "f_mid", "arias_intensity")
"""The parameters compared."""


def pool(table: dict, measure: str, period, g: float) -> tuple[np.ndarray, np.ndarray, dict[str, np.ndarray]]:
    """ln IM* (g), the parameter normals and the parameters of every motion of a simulated motions' table."""
    from stochpound.experiment import table_chunks, table_scenario
    from stochpound.motions import parameter_normals, site_motions

    ln_intensity = np.log(np.concatenate([intensity for _, _, intensity in table_chunks(table, measure, period, g)]))
    shift = np.array(table["normal_shift"]) if "normal_shift" in table else None
    normals = parameter_normals(table["seed"], range(table["n"]), table["model"]) + (0.0 if shift is None else shift)
    brief = site_motions(scenario=table_scenario(table), n=table["n"], seed=table["seed"], dt=table["dt"], model=table["model"],
                         duration=10 * table["dt"], normal_shift=None if shift is None else shift.tolist())  # the parameters alone
    return ln_intensity, normals, {name: brief[name].values for name in PARAMETERS}


def main(argv: list[str] | None = None) -> int:
    """Print the comparison (module docstring)."""
    parser = argparse.ArgumentParser(prog="python -m benchmarks.tilted_pool", description=__doc__.splitlines()[0])
    parser.add_argument("experiment", type=Path)
    parser.add_argument("stripes", type=int, nargs="+")
    arguments = parser.parse_args(argv)
    from stochpound.experiment import load_experiment
    from stochpound.experiment import TILT_PILOT, Tilt, scenario_table, tilted_seed

    info = machine()
    began = time.time()
    experiment = load_experiment(arguments.experiment)
    selection = experiment.intensity.selection
    setting, scenario = selection.simulated, selection.scenarios[0]
    if setting is None or any(other != scenario for other in selection.scenarios):
        raise SystemExit(f"{arguments.experiment.name}: one scenario for every level and [site] simulated_motions, please")
    measure, period, g = experiment.intensity.measure.kind, experiment.intensity.measure.spectral_period, experiment.definition.g
    y0, z0, p0 = pool(scenario_table(setting, scenario, TILT_PILOT, setting.seed), measure, period, g)
    tilt = Tilt.fit(z0, y0)
    slope = np.array(tilt.slope)
    r2 = 1.0 - np.var(y0 - tilt.intercept - z0 @ slope) / np.var(y0)
    print(f"{arguments.experiment.name}: M {scenario.magnitude:g} at {scenario.distance_km:g} km, {measure} {period}; pilot of {TILT_PILOT}: "
          f"b0 {tilt.intercept:.3f}, |a| {np.linalg.norm(slope):.3f}, σ {y0.std():.3f}, R² {r2:.3f}")
    print("| stripe | level (g) | ε_m | near the level: untilted, tilted (reweighted ESS) | "
          + " | ".join(f"{name}: untilted, tilted, reweighted (tilted/reweighted − 1)" for name in PARAMETERS) + " |")
    print("|" + "---|" * (4 + len(PARAMETERS)))
    levels = sorted(float(level) for level in experiment.intensity.levels)
    for stripe in arguments.stripes:
        level = levels[stripe - 1]
        x = np.log(level)
        shift = np.array(tilt.shift(level))
        table = {**scenario_table(setting, scenario, setting.count, tilted_seed(setting.seed, stripe - 1)), "normal_shift": shift.tolist()}
        y1, z1, p1 = pool(table, measure, period, g)
        weight = np.exp(-(z1 @ shift) + 0.5 * float(shift @ shift))
        near0, near1 = np.abs(y0 - x) < WINDOW, np.abs(y1 - x) < WINDOW
        w = weight[near1]
        cells = [str(stripe), f"{level:.3g}", f"{(x - tilt.intercept) / y0.std():.2f}", f"{near0.sum()}, {near1.sum()} ({w.sum() ** 2 / (w ** 2).sum():.0f})"]
        for name in PARAMETERS:
            untilted = np.exp(np.mean(np.log(p0[name][near0]))) if near0.any() else np.nan
            tilted = np.exp(np.mean(np.log(p1[name][near1])))
            reweighted = np.exp(np.sum(w * np.log(p1[name][near1])) / w.sum())
            cells.append(f"{untilted:.3g}, {tilted:.3g}, {reweighted:.3g} ({100 * (tilted / reweighted - 1):+.1f} %)")
        print("| " + " | ".join(cells) + " |")
    print(f"{time.time() - began:.0f} s; load {info['load average (1 min) at start']} at start; commit {info['commit']}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
