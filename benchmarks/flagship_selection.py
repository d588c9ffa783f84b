"""A flagship's stripes chosen, without running a case: ``python -m benchmarks flagship_selection FILE [--simulated N] [--sampling S]``.

Loads the experiment file (its scenario fitted, ``[site] simulated_motions``
replaced by ``--simulated N`` where given, ``[site] simulated_sampling = S``
added with ``--sampling``, ``[intensity] seed`` replaced by ``--seed`` as ``stochpound experiment run --seed`` does), computes its selection (the fit,
the pool of records and simulated motions, pre-screened beyond
``SCREEN_BASE`` (stochpound.experiment's site selection) motions, and every stripe's
choice: :attr:`stochpound.experiment.Experiment.selection`) and prints, per
stripe, its level, ε, N Φ(−ε) (the pool's simulated motions expected beyond
the stripe's ε), the pool's motions after the pre-screen, the chosen set's
recorded and simulated motions, the largest share of one earthquake, and its
worst differences from the target in mean and standard deviation of ln Sa
(with their periods), whether any set of its pool could meet the target's
mean (the selection's linear-programming bound, ``target_reachable``) and which rule chose the set (``misfit``, or ``tolerance``
where ``[intensity] tolerance_first`` replaced a set that missed): a markdown table, then the time the selection took
(from the file's loading), the load at its start and the commit; with
``--picks FILE`` every stripe's chosen motions and scale factors as JSON
(to compare two trees' selections); with ``--parameters`` per stripe the
medians of its chosen simulated motions' model D5–95, t_mid and f_mid, and
their own D5–95 and Arias intensity as run (scaled), regenerated from their
tables.
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
SAMPLING_LINE = re.compile(r'^simulated_sampling\s*=\s*"[a-z]+"', re.MULTILINE)
"""The ``[site] simulated_sampling`` line of a flagship file, where it has one (replaced, not repeated, by ``--sampling``)."""


def with_simulated(path: Path, count: int | None, folder: Path, sampling: str | None = None) -> Path:
    """The experiment file with ``simulated_motions = count`` and ``simulated_sampling = sampling`` (its line replaced, else one
    added after ``simulated_motions``): a copy in ``folder``; the file itself when both are None."""
    if count is None and sampling is None:
        return path
    text = path.read_text()
    found = SIMULATED_LINE.search(text)
    if not found:
        raise SystemExit(f"{path.name}: no [site] simulated_motions line to replace")
    if sampling is not None and SAMPLING_LINE.search(text):
        text = SAMPLING_LINE.sub(f'simulated_sampling = "{sampling}"', text, count=1)
    elif sampling is not None:
        end = text.index("\n", found.end())
        text = f'{text[:end]}\nsimulated_sampling = "{sampling}"{text[end:]}'
    if count is not None:
        text = SIMULATED_LINE.sub(f"simulated_motions = {count}", text, count=1)
    copy = folder / path.name
    copy.write_text(text)
    return copy


def worst(difference: np.ndarray, periods: np.ndarray) -> str:
    """The largest difference in magnitude, signed, with its period."""
    i = int(np.argmax(np.abs(difference)))
    return f"{difference[i]:+.3f} ({periods[i]:.3g} s)"


def stripe_rows(experiment, count: int, tilted: bool = False) -> list[list[str]]:
    """One row per stripe (module docstring); N Φ(−ε) is "-" for a tilted pool (each stripe's own N, centred on its level)."""
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
        rows.append([f"{level:.3g}", f"{epsilon:.2f}", "-" if tilted else f"{count * ndtr(-epsilon):.1f}", str(selection.attrs["pool"]),
                     f"{selection.sizes['selected'] - simulated} + {simulated}", f"{share:.3f}", worst(mean, periods), worst(sigma, periods),
                     "**miss**" if miss else "met", "yes" if selection.attrs["target_reachable"] else "**no**", selection.attrs["chosen_by"]])
    return rows


PARAMETERS = ("d5_95", "t_mid", "f_mid")
"""The chosen simulated motions' model parameters whose medians ``--parameters`` prints, beside two measured on the motions."""
COLUMNS = ["level (g)", "simulated chosen", "D5-95 (s)", "t_mid (s)", "f_mid (Hz)", "D5-95 measured (s)", "Arias intensity as run (m/s)"]
"""The columns of ``--parameters``: the model's D5–95, t_mid and f_mid, the motion's own D5–95 and the Arias intensity of it scaled."""


def parameter_rows(experiment) -> list[list[str]]:
    """Per stripe, the medians of its chosen simulated motions' :data:`PARAMETERS`, their own D5–95 and Arias intensity (scaled by
    their scale factors: as run), regenerated from their tables."""
    from stochpound.experiment import table_scenario
    from stochpound.motions import arias_intensity, significant_duration, site_motions
    from stochpound.store import canonical_json

    chosen = experiment.selection
    rows = []
    for level, selection in zip(chosen.experiment_levels, chosen.selections):
        labels = [str(m) for m in selection["motion"].values]
        factors = dict(zip(labels, selection["scale_factor"].values))
        groups: dict[str, list[str]] = {}
        for label in labels:
            if label in chosen.simulated:
                table = chosen.simulated[label].motion
                groups.setdefault(canonical_json({k: v for k, v in table.items() if k != "realization"}), []).append(label)
        values: dict[str, list[float]] = {name: [] for name in (*PARAMETERS, "duration", "arias")}
        for group in groups.values():
            table = chosen.simulated[group[0]].motion
            shift = table["normal_shift"] if "normal_shift" in table else None
            generated = site_motions(scenario=table_scenario(table), n=table["n"], seed=table["seed"], dt=table["dt"], model=table["model"],
                                     realizations=[chosen.simulated[label].motion["realization"] for label in group], normal_shift=shift)
            for name in PARAMETERS:
                values[name].extend(generated[name].values.tolist())
            for label, row in zip(group, generated["acceleration"].values):
                values["duration"].append(significant_duration(row, table["dt"]))
                values["arias"].append(arias_intensity(row * factors[label], table["dt"]))
        rows.append([f"{level:.3g}", str(len(values["d5_95"]))] + [f"{np.median(v):.3g}" if v else "-" for v in values.values()])
    return rows


def main(argv: list[str] | None = None) -> int:
    """Print the flagship's stripes (module docstring)."""
    parser = argparse.ArgumentParser(prog="python -m benchmarks flagship_selection", description=__doc__.splitlines()[0])
    parser.add_argument("experiment", type=Path)
    parser.add_argument("--simulated", type=int, default=None, help="[site] simulated_motions (default: the file's)")
    parser.add_argument("--picks", type=Path, default=None, help="write every stripe's chosen motions and scale factors here (JSON)")
    parser.add_argument("--sampling", choices=("scenario", "tilted"), default=None, help="[site] simulated_sampling (default: the file's)")
    parser.add_argument("--seed", type=int, default=None, help="[intensity] seed (default: the file's)")
    parser.add_argument("--parameters", action="store_true", help="print the medians of the chosen simulated motions' parameters")
    arguments = parser.parse_args(argv)
    from stochpound.experiment import load_experiment

    info = machine()  # the commit and load as the run starts
    with tempfile.TemporaryDirectory() as folder:
        began = time.time()
        experiment = load_experiment(with_simulated(arguments.experiment, arguments.simulated, Path(folder), arguments.sampling), seed=arguments.seed)
        experiment.selection
        elapsed = time.time() - began
    count = experiment.intensity.selection.simulated.count
    header = ["level (g)", "ε", "N Φ(−ε)", "pool", "recorded + simulated", "largest share of an earthquake", "mean", "σ", "",
              "mean reachable", "chosen by"]
    sampling = experiment.intensity.selection.simulated.sampling
    print(f"{arguments.experiment.name}, N = {count} ({sampling}), seed {experiment.intensity.selection.seed}, {experiment.selection.periods[0]:.3g}-{experiment.selection.periods[-1]:.3g} s")
    print("| " + " | ".join(header) + " |")
    print("|" + "---|" * len(header))
    for row in stripe_rows(experiment, count, sampling == "tilted"):
        print("| " + " | ".join(row) + " |")
    if arguments.parameters:
        print("| " + " | ".join(COLUMNS) + " |")
        print("|" + "---|" * len(COLUMNS))
        for row in parameter_rows(experiment):
            print("| " + " | ".join(row) + " |")
    if arguments.picks is not None:
        arguments.picks.write_text(json.dumps([{"motion": [str(m) for m in s["motion"].values], "scale_factor": s["scale_factor"].values.tolist()}
                                               for s in experiment.selection.selections]))
    print(f"selection (fit, pool, stripes) {elapsed:.0f} s; load {info['load average (1 min) at start']} at start; commit {info['commit']}; "
          f"NUMBA_NUM_THREADS {os.environ.get('NUMBA_NUM_THREADS', 'default')}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
