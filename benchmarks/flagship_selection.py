"""A flagship's stripes chosen, without running a case: ``python -m benchmarks flagship_selection FILE [--simulated N]``.

Loads the experiment file (its scenario fitted, ``[site] simulated_motions``
replaced by ``--simulated N`` where given), computes its selection (the fit,
the pool of records and simulated motions, pre-screened beyond
``stochpound.experiment._site.SCREEN_BASE`` motions, and every stripe's
choice: :attr:`stochpound.experiment.Experiment.selection`) and prints, per
stripe, its level, ε, N Φ(−ε) (the pool's simulated motions expected beyond
the stripe's ε), the pool's motions after the pre-screen, the chosen set's
recorded and simulated motions, the largest share of one earthquake, and its
worst differences from the target in mean and standard deviation of ln Sa
(with their periods): a markdown table, then the time the selection took
(from the file's loading), the load at its start and the commit; with
``--picks FILE`` every stripe's chosen motions and scale factors as JSON
(to compare two trees' selections).
"""

from __future__ import annotations

import argparse
import json
import os
import re
import tempfile
import time
from collections import Counter
from pathlib import Path

import numpy as np
from scipy.special import ndtr

from benchmarks.report import machine

SIMULATED_LINE = re.compile(r"^simulated_motions\s*=\s*\d+", re.MULTILINE)
"""The ``[site] simulated_motions`` line of a flagship file."""


def with_simulated(path: Path, count: int | None, folder: Path) -> Path:
    """The experiment file with ``simulated_motions = count`` (a copy in ``folder``; the file itself for None)."""
    if count is None:
        return path
    text = path.read_text()
    if not SIMULATED_LINE.search(text):
        raise SystemExit(f"{path.name}: no [site] simulated_motions line to replace")
    copy = folder / path.name
    copy.write_text(SIMULATED_LINE.sub(f"simulated_motions = {count}", text, count=1))
    return copy


def worst(difference: np.ndarray, periods: np.ndarray) -> str:
    """The largest difference in magnitude, signed, with its period."""
    i = int(np.argmax(np.abs(difference)))
    return f"{difference[i]:+.3f} ({periods[i]:.3g} s)"


def stripe_rows(experiment, count: int) -> list[list[str]]:
    """One row per stripe (module docstring)."""
    chosen = experiment.selection
    rows = []
    for level, selection, target in zip(chosen.experiment_levels, chosen.selections, chosen.targets):
        epsilon = float(target.attrs["epsilon"])
        periods = selection.period.values
        mean = selection["mean_ln"].values - np.log(selection["median"].values)
        sigma = selection["std_ln"].values - selection["sigma_ln"].values
        simulated = int(sum(str(m) in chosen.simulated for m in selection["motion"].values))
        share = max(Counter(str(e) for e in selection["earthquake"].values).values()) / selection.sizes["selected"]
        miss = max(np.max(np.abs(mean)), np.max(np.abs(sigma))) > 0.1
        rows.append([f"{level:.3g}", f"{epsilon:.2f}", f"{count * ndtr(-epsilon):.1f}", str(selection.attrs["pool"]),
                     f"{selection.sizes['selected'] - simulated} + {simulated}", f"{share:.3f}", worst(mean, periods), worst(sigma, periods),
                     "**miss**" if miss else "met"])
    return rows


def main(argv: list[str] | None = None) -> int:
    """Print the flagship's stripes (module docstring)."""
    parser = argparse.ArgumentParser(prog="python -m benchmarks flagship_selection", description=__doc__.splitlines()[0])
    parser.add_argument("experiment", type=Path)
    parser.add_argument("--simulated", type=int, default=None, help="[site] simulated_motions (default: the file's)")
    parser.add_argument("--picks", type=Path, default=None, help="write every stripe's chosen motions and scale factors here (JSON)")
    arguments = parser.parse_args(argv)
    from stochpound.experiment import load_experiment

    info = machine()  # the commit and load as the run starts
    with tempfile.TemporaryDirectory() as folder:
        began = time.time()
        experiment = load_experiment(with_simulated(arguments.experiment, arguments.simulated, Path(folder)))
        experiment.selection
        elapsed = time.time() - began
    count = experiment.intensity.selection.simulated.count
    header = ["level (g)", "ε", "N Φ(−ε)", "pool", "recorded + simulated", "largest share of an earthquake", "mean", "σ", ""]
    print(f"{arguments.experiment.name}, N = {count}, {experiment.selection.periods[0]:.3g}-{experiment.selection.periods[-1]:.3g} s")
    print("| " + " | ".join(header) + " |")
    print("|" + "---|" * len(header))
    for row in stripe_rows(experiment, count):
        print("| " + " | ".join(row) + " |")
    if arguments.picks is not None:
        arguments.picks.write_text(json.dumps([{"motion": [str(m) for m in s["motion"].values], "scale_factor": s["scale_factor"].values.tolist()}
                                               for s in experiment.selection.selections]))
    print(f"selection (fit, pool, stripes) {elapsed:.0f} s; load {info['load average (1 min) at start']} at start; commit {info['commit']}; "
          f"NUMBA_NUM_THREADS {os.environ.get('NUMBA_NUM_THREADS', 'default')}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
