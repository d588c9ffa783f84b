"""The cost of a pool of simulated motions, per motion: ``python -m benchmarks simulated_pool [--n 256]``.

On ``n`` motions of the fixed-pair flagship's fitted scenario (M 8.0 at
30 km, reverse, Vs30 400 m/s; the hazard-compatible model, dt = 0.01 s, its
window) and that flagship's 21 selection periods (0.043–1.29 s, T* = 1 s),
in one process on one core (``python -m benchmarks`` sets every thread pool
to one), it times:

* the generation (:func:`~stochpound.motions.site_motions`, the flagship's realizations 256 at a time as its pool draws them);
* the old pool of them: a :class:`~stochpound.motions.records.Record` per
  motion and :func:`~stochpound.motions.selection_pool` (a
  :func:`~stochpound.motions.response_spectrum` per motion: its hashing and
  cache, the total acceleration's peaks too, an xarray dataset);
* the new one, ``stochpound.motions._selection.array_pool`` (every
  motion's spectrum in one compiled call per batch, the displacement's
  peaks alone), checked equal to the old one bit for bit;
* the pre-screen's stage: the conditioning measure alone
  (``stochpound.motions._selection.pool_intensity``, one period).

Old and new alternate over ``--rounds`` rounds (best of them), so that the
load of a shared machine falls on both; every round's motions are new (no
spectrum cached by ``response_spectrum``). It rewrites the section "A pool of
simulated motions" of ``docs/benchmarks.md``.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from typing import Any


import numpy as np

from benchmarks import report
from benchmarks.sections import Section
from benchmarks.timing import REPOSITORY

SECTION = Section("<!-- simulated pool: start -->", "<!-- simulated pool: end -->")
"""This benchmark's section of docs/benchmarks.md."""
STARTUP = Section("<!-- simulated pool start-up: start -->", "<!-- simulated pool start-up: end -->")
"""The flagship's start-up before and after, measured by hand (benchmarks/flagship_selection.py --picks): kept by the suite."""
SCENARIO = {"magnitude": 8.0, "distance_km": 30.0, "vs30": 400.0, "mechanism": "reverse"}
"""The fixed-pair flagship's fitted scenario (its motions: seed 1, dt = 0.01 s)."""
STRUCTURE, CONDITIONING = [0.2141, 0.3099, 0.4300], 1.0
"""The flagship's structure periods (s) and T* (s)."""
G = 9.81


def measure(n: int, rounds: int) -> dict[str, Any]:
    """Seconds per motion of each stage (best of ``rounds``), and whether old and new pools are identical."""
    from stochpound.motions import Scenario, array_pool, pool_intensity, selection_periods, selection_pool, site_motions
    from stochpound.motions.records import Record

    periods = selection_periods(STRUCTURE, [CONDITIONING])
    scenario = Scenario(SCENARIO["magnitude"], SCENARIO["distance_km"], SCENARIO["vs30"], SCENARIO["mechanism"])
    names = [str(i) for i in range(n)]
    metadata = {"magnitude": SCENARIO["magnitude"], "distance": SCENARIO["distance_km"], "vs30": SCENARIO["vs30"]}
    times: dict[str, list[float]] = {"generation": [], "old": [], "new": [], "screen": []}

    window: list[float] = []  # the table's window, found by the first call and given to the others, as the pool does

    def generate(rows: range) -> np.ndarray:  # a table of (rounds + 1) n motions: new motions every round, none cached
        motions = site_motions(scenario=scenario, n=(rounds + 1) * n, seed=1, realizations=list(rows), duration=(window or [None])[0])
        window[:] = [float(motions.time.values[-1])]
        return motions["acceleration"].values

    accelerations = generate(range(min(n, 8)))  # compile and warm every kernel
    array_pool(accelerations, 0.01, names[: len(accelerations)], periods, "psa", CONDITIONING, 0.05, G)
    selection_pool([Record("w", 0.01, accelerations[0], "m/s2")], periods, "psa", CONDITIONING, 0.05, G)
    identical = True
    for round_ in range(1, rounds + 1):
        began = time.perf_counter()
        accelerations = generate(range(round_ * n, (round_ + 1) * n))
        times["generation"].append(time.perf_counter() - began)
        began = time.perf_counter()
        records = [Record(name, 0.01, row, "m/s2", metadata={**metadata, "event": name}) for name, row in zip(names, accelerations)]
        old = selection_pool(records, periods, "psa", CONDITIONING, 0.05, G)
        times["old"].append(time.perf_counter() - began)
        began = time.perf_counter()
        new = array_pool(accelerations, 0.01, names, periods, "psa", CONDITIONING, 0.05, G, magnitude=8.0, distance_km=30.0, vs30=400.0)
        times["new"].append(time.perf_counter() - began)
        began = time.perf_counter()
        pool_intensity(accelerations, 0.01, "psa", CONDITIONING, 0.05, G)
        times["screen"].append(time.perf_counter() - began)
        identical = identical and old.identical(new)
    return {"per_motion": {name: min(values) / n for name, values in times.items()}, "identical": identical, "n_time": accelerations.shape[1],
            "periods": periods}


def section(data: dict[str, Any], info: dict[str, str], n: int, rounds: int) -> str:
    """The section of docs/benchmarks.md."""
    per = data["per_motion"]
    rows = [("generation (`site_motions`)", per["generation"]), ("old pool: a `Record` and `response_spectrum` per motion", per["old"]),
            ("new pool: `array_pool` (one compiled call per 16 motions)", per["new"]),
            ("pre-screen stage: the conditioning measure alone (1 period)", per["screen"])]
    table = "\n".join(f"| {name} | {seconds * 1e3:.2f} |" for name, seconds in rows)
    spectra = per["old"] / per["new"]
    return f"""{SECTION.start}
## A pool of simulated motions

{n} motions of the fixed-pair flagship's fitted scenario (M 8.0 at 30 km, reverse, Vs30 400 m/s; the hazard-compatible model, dt = 0.01 s,
{data['n_time']} samples) and its {len(data['periods'])} selection periods ({data['periods'][0]:.3g}–{data['periods'][-1]:.3g} s, T* = 1 s), on one
core, best of {rounds} rounds alternating old and new (commit {info['commit']}, {info['date']}, load {info['load average (1 min) at start']} at start).
`python -m benchmarks simulated_pool` rewrites this section.

| stage | ms per motion |
|---|---:|
{table}

The new pool is the old one bit for bit ({'identical' if data['identical'] else '**NOT identical**'}: every spectral value, measure and label) and
{spectra:.1f}× as fast: the cost is the recurrence itself (the per-motion hashing, cache, `Record` and xarray overhead are a small part); the
gain is the total acceleration's peaks, which a pool does not use, left out. What makes pools of 10⁴–10⁵ usable is the pre-screen
(docs/intensity.md, "How many simulated motions a stripe needs"): beyond the first 2000 motions only the conditioning measure is computed
for every motion, about {per['new'] / per['screen']:.0f}× cheaper than a whole spectrum, so such a pool costs about its generation
({per['generation'] * 1e3:.1f} ms a motion here) and little more. On a shared machine the times are wall-clock at its load: the
ratios are what they show.
{SECTION.end}
"""


def main(argv: list[str] | None = None) -> int:
    """Time the stages and rewrite the section (module docstring)."""
    parser = argparse.ArgumentParser(prog="python -m benchmarks simulated_pool", description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=256, help="motions")
    parser.add_argument("--rounds", type=int, default=3, help="rounds (best of)")
    parser.add_argument("--out", type=Path, default=REPOSITORY / "docs" / "benchmarks.md", help="the document whose section is rewritten")
    arguments = parser.parse_args(argv)
    info = report.machine()
    data = measure(arguments.n, arguments.rounds)
    SECTION.write(arguments.out, section(data, info, arguments.n, arguments.rounds))
    print({name: f"{value * 1e3:.2f} ms" for name, value in data["per_motion"].items()}, "identical" if data["identical"] else "NOT IDENTICAL")
    return 0 if data["identical"] else 1


if __name__ == "__main__":
    raise SystemExit(main())
