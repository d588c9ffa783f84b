"""A pounding pair's impact force and a yielding building's ductility at 1e-6: ``python -m benchmarks rare_events nonlinear``.

Two of issue 46's nonlinear cases, under the Kanai–Tajimi motion of the
pounding pair (:data:`benchmarks.scenes.PAIR_MOTION`, ``method =
"filter"``, exactly Gaussian), each by one subset run (modified Metropolis,
p0 = 0.1) down to 1e-6 and by crude Monte Carlo of the same response
(independent normals of another seed) at the response values where the
subset curve gives 1e-1, 1e-2 and 1e-3:

- the largest impact force at the top contact of the elastic pair with
  Building 2's masses doubled, at the bundled gap (2 cm): P(impact force >
  F). Pounding happens in about half the runs, so the force varies in more
  than p0 of level 0's runs and the levels split it; the levels after the
  first hold pounding runs only.
- the ductility of Building 1 alone (the study's two-storey shear
  building) with bilinear storeys yielding at a drift of 1 cm (yield forces
  k_i × 0.01 m, 5 % hardening): P(peak first-storey drift / 1 cm > μ).

It rewrites its section of docs/rare-events.md ("Nonlinear and impact cases
at 1e-6").
"""

from __future__ import annotations

import argparse
import time
import tomllib
from pathlib import Path
from typing import Callable

import numpy as np

from benchmarks import report
from benchmarks.rare_moat import crude_rows
from benchmarks.scenes import PAIR_MOTION
from benchmarks.sections import Section
from benchmarks.timing import REPOSITORY
import stochpound
from stochpound.analysis import SubsetSampler, scene_response, subset_simulation
from stochpound.model import Scene, bundled_scene_path

START = "<!-- rare events nonlinear: start -->"
SECTION = Section(START, "<!-- rare events nonlinear: end -->")
"""This benchmark's section of docs/rare-events.md."""
YIELD_DRIFT = 0.01
"""The storeys' yield drift, m."""
HARDENING = 0.05
CRUDE_PROBABILITIES = (0.1, 0.01, 0.001)


def pounding_pair() -> Scene:
    """The bundled elastic pair, Building 2's masses doubled, its contacts at the bundled gaps (2 cm)."""
    table = tomllib.loads(bundled_scene_path("elastic_pair").read_text())
    table["building"][1]["mass"] = [2.0 * m for m in table["building"][1]["mass"]]
    table["motion"] = {"type": "constant", "acceleration": 0.0, "duration": 1.0, "dt": 0.5}  # replaced by the motion sampled
    return stochpound.scene_from_dict(table)


def yielding_building() -> Scene:
    """Building 1 of the bundled pair alone, its storeys bilinear: yield force k_i × :data:`YIELD_DRIFT`, :data:`HARDENING`."""
    table = tomllib.loads(bundled_scene_path("elastic_pair").read_text())
    building = table["building"][0]
    building["yield_force"] = [k * YIELD_DRIFT for k in building["stiffness"]]
    building["hardening"] = HARDENING
    table = {"g": table["g"], "building": [building], "motion": {"type": "constant", "acceleration": 0.0, "duration": 1.0, "dt": 0.5}}
    return stochpound.scene_from_dict(table)


def cases() -> dict[str, tuple[Callable[[np.ndarray], np.ndarray], int, str]]:
    """The two responses as functions of the motion's normals: g(u), n and the units of the section's table."""
    force, n, _ = scene_response(pounding_pair(), PAIR_MOTION, "impact_force", contact=1)
    drift, m, _ = scene_response(yielding_building(), PAIR_MOTION, "peak_storey_drift", building="B1", floor=1)
    return {"impact force at the top contact (kN)": (lambda u: force(u) / 1e3, n, "kN"),
            "ductility of storey 1 (peak drift / yield drift)": (lambda u: drift(u) / YIELD_DRIFT, m, "1")}


def measure(samples: int, crude_runs: int, seed: int) -> dict[str, dict]:
    """Each case's subset run to 1e-6 and its crude Monte Carlo, with their wall times."""
    measured = {}
    for name, (function, n, units) in cases().items():
        start = time.perf_counter()
        result = subset_simulation(function, target_probability=1e-6, samples_per_level=samples, p0=0.1, seed=seed, dimension=n)
        subset_time = time.perf_counter() - start
        start = time.perf_counter()
        crude = SubsetSampler(function, n, crude_runs, 0.1, seed + 1000).start(range(crude_runs))[1]
        measured[name] = {"result": result, "subset_time": subset_time, "crude": crude, "crude_time": time.perf_counter() - start, "units": units}
    return measured


def section(measured: dict[str, dict], info: dict[str, str], samples: int) -> str:
    """The Markdown section of the measurements."""
    lines = [
        START,
        "## Nonlinear and impact cases at 1e-6",
        "",
        "Under the pounding pair's Kanai–Tajimi motion (ω_g = 15 rad/s, ζ_g = 0.6, expected PGA 2 m/s², Jennings envelope, 10 s at "
        f"dt = 0.02 s, `method = \"filter\"`): one subset run each (N = {samples} a level, p0 = 0.1, modified Metropolis, target 1e-6) "
        "against crude Monte Carlo of the same response (another seed), in one process on a machine of "
        f"{info['cores']} cores, load {info['load average (1 min) at start']} at the start (commit {info['commit']}, {info['date']}). "
        "The pair is the elastic pair with Building 2's masses doubled at the bundled 2 cm gaps; the yielding building is Building 1 "
        f"alone, its storeys bilinear, yielding at a drift of {YIELD_DRIFT * 100:g} cm with {HARDENING:.0%} hardening. "
        "`python -m benchmarks rare_events nonlinear` rewrites this section.",
        "",
    ]
    for name, m in measured.items():
        result, crude = m["result"], m["crude"]
        probability, cov, thresholds = result.probability.values, result.cov.values, result.threshold.values
        last = int(np.flatnonzero(probability > 0)[-1])
        unit, heading = (f" {m['units']}", f" ({m['units']})") if m["units"] != "1" else ("", "")
        lines += [
            f"**{name[0].upper() + name[1:]}**: {result.attrs['levels']} levels, {result.attrs['runs']} runs, {m['subset_time']:.0f} s; "
            f"P = {probability[last]:.3g} (reported CoV {cov[last]:.0%}) above {thresholds[last]:.3g}{unit}; "
            f"crude Monte Carlo {crude.size} runs, {m['crude_time']:.0f} s.",
            "",
            f"| threshold{heading} | subset simulation (reported CoV) | crude MC (its CoV) | difference / combined standard deviation |",
            "|---:|---:|---:|---:|",
        ]
        lines += crude_rows(thresholds, probability, cov, crude, "{:.3g}", CRUDE_PROBABILITIES)
        lines.append("")
    lines[-1] = SECTION.end
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    """Run the measurements and rewrite the section of ``--out``."""
    parser = argparse.ArgumentParser(prog="python -m benchmarks rare_events nonlinear", description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=1000, help="subset samples a level")
    parser.add_argument("--crude-runs", type=int, default=4000, help="crude Monte Carlo runs of each case")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--out", type=Path, default=REPOSITORY / "docs" / "rare-events.md")
    arguments = parser.parse_args(argv)
    info = report.machine()
    SECTION.write(arguments.out, section(measure(arguments.samples, arguments.crude_runs, arguments.seed), info, arguments.samples))
    print(f"wrote the section 'Nonlinear and impact cases at 1e-6' of {arguments.out}")
    return 0
