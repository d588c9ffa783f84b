"""Subset simulation on Au & Beck's oscillator: ``python -m benchmarks rare_events``.

The linear oscillator of Au & Beck (2001) — ω = 7.85 rad/s, ζ = 0.02, white
noise of two-sided PSD S = 1 m²/s³ for 30 s at dt = 0.02 s (1501 standard
normals) — and P(max_k |x(t_k)| > b) at thresholds down to about 1e-6:
:func:`stochpound.analysis.subset_simulation` repeated with 20 seeds (N = 1000
samples a level, p0 = 0.1) against importance sampling with elementary events
(ISEE, Au & Beck 2001), unbiased with a CoV of about 1.5 % from 4000 samples.
The displacement at the samples is the linear map X = A u of the exact
discretisation of ẍ + 2ζωẋ + ω²x = −a_g for an acceleration linear between
the samples (the solvers' motion), so that both methods sample the same
response exactly; tests/test_subset_simulation.py checks that the solver's
runs give it.

``python -m benchmarks rare_events pair`` measures a pounding pair instead:
the bundled elastic pair with Building 2's masses doubled and its contacts
never closing (gap ``inf``), under a Kanai–Tajimi motion (``method =
"filter"``), its top contact's closure by subset simulation against crude
Monte Carlo of the seeded ensemble, at the closures crude Monte Carlo
reaches (P ≈ 1e-1 to 1e-2), run by the solver.

Each rewrites its section of ``docs/rare-events.md``.
"""

from __future__ import annotations

import argparse
import math
import time
import tomllib
from dataclasses import replace
from pathlib import Path

import numpy as np
from scipy.linalg import expm
from scipy.signal import fftconvolve
from scipy.special import ndtr, ndtri

from benchmarks import report
from benchmarks.sections import Section
from benchmarks.timing import REPOSITORY
import stochpound
from stochpound.analysis import subset_simulation
from stochpound.model import Scene, bundled_scene_path
from stochpound.motions.ground import SampledMotion

START = "<!-- rare events benchmark: start -->"
END = "<!-- rare events benchmark: end -->"
SECTION = Section(START, END)
"""This benchmark's section of docs/rare-events.md."""
OSCILLATOR = {"omega": 7.85, "zeta": 0.02, "S": 1.0, "dt": 0.02, "duration": 30.0}
"""Au & Beck's (2001) oscillator: rad/s, 1, m²/s³, s, s."""
THRESHOLDS = (1.6, 2.1, 2.3, 2.4)
"""Thresholds b of the displacement, m."""
PAIR_START = "<!-- rare events pair: start -->"
PAIR_END = "<!-- rare events pair: end -->"
PAIR_SECTION = Section(PAIR_START, PAIR_END)
"""The pounding pair's section of docs/rare-events.md."""
PAIR_MOTION = {"type": "kanai_tajimi", "omega_g": 15.0, "zeta_g": 0.6, "pga": 2.0, "envelope": "jennings", "method": "filter", "duration": 10.0, "dt": 0.02}
"""The pair's ground motion (a synthetic ensemble's fields)."""
PAIR_THRESHOLDS = (0.03, 0.036, 0.042, 0.046, 0.05, 0.06, 0.07)
"""Closures of the pair's top contact, m."""


class Oscillator:
    """The oscillator's displacement at the samples as a linear map of the white noise's standard normals."""

    def __init__(self, omega: float, zeta: float, S: float, dt: float, duration: float) -> None:
        self.n = int(round(duration / dt)) + 1
        system = np.zeros((4, 4))
        system[:2, :2] = ((0.0, 1.0), (-omega**2, -2.0 * zeta * omega))
        system[:2, 2], system[2, 3] = (0.0, -1.0), 1.0
        step = expm(system * dt)
        phi, ramp = step[:2, :2], step[:2, 3] / dt
        hold = step[:2, 2] - ramp
        powers = [np.eye(2)]
        for _ in range(self.n):
            powers.append(phi @ powers[-1])
        scale = math.sqrt(2.0 * math.pi * S / dt)
        self.kernel = scale * np.array([ramp[0]] + [(powers[m] @ ramp + powers[m - 1] @ hold)[0] for m in range(1, self.n)])
        self.first = scale * np.array([0.0] + [(powers[m - 1] @ hold)[0] for m in range(1, self.n)])

    def displacements(self, u: np.ndarray) -> np.ndarray:
        """X = A u for rows of u, m."""
        x = fftconvolve(u, self.kernel[None, :], axes=1)[:, : self.n]
        return x + (self.first - self.kernel)[None, :] * u[:, :1]

    def peak(self, u: np.ndarray) -> np.ndarray:
        """max_k |X_k| for rows of u, m."""
        return np.abs(self.displacements(u)).max(axis=1)

    def isee(self, b: float, samples: int, seed: int) -> tuple[float, float]:
        """P(max |X_k| > b) and its CoV by importance sampling with elementary events {|X_k| > b}."""
        rows = self.displacements(np.eye(self.n)).T[1:]
        norms = np.linalg.norm(rows, axis=1)
        weights = 2.0 * ndtr(-b / norms)
        rng = np.random.default_rng(seed)
        chosen = rng.choice(len(rows), samples, p=weights / weights.sum())
        direction = rows[chosen] / norms[chosen, None]
        along = -ndtri(ndtr(-b / norms[chosen]) * rng.random(samples)) * np.where(rng.random(samples) < 0.5, -1.0, 1.0)
        z = rng.standard_normal((samples, self.n))
        u = z + (along - np.sum(direction * z, axis=1))[:, None] * direction
        estimates = weights.sum() / np.count_nonzero(np.abs(self.displacements(u)[:, 1:]) > b, axis=1)
        return float(estimates.mean()), float(estimates.std() / math.sqrt(samples) / estimates.mean())


def measure(repeats: int, samples: int, reference_samples: int) -> dict:
    """The reference and ``repeats`` subset runs at every threshold, with their wall times."""
    oscillator = Oscillator(**OSCILLATOR)
    references = [oscillator.isee(b, reference_samples, seed=1000 + i) for i, b in enumerate(THRESHOLDS)]
    runs, times = [], []
    for seed in range(repeats):
        start = time.perf_counter()
        runs.append(subset_simulation(oscillator.peak, thresholds=list(THRESHOLDS), samples_per_level=samples, p0=0.1, seed=seed, dimension=oscillator.n))
        times.append(time.perf_counter() - start)
    return {"references": references, "runs": runs, "times": times, "samples": samples}


def section(measured: dict, info: dict[str, str]) -> str:
    """The Markdown section of the measurements."""
    runs = measured["runs"]
    estimates = np.array([r.probability.values for r in runs])
    reported = np.array([r.cov.values for r in runs])
    lines = [
        START,
        "## Certified on Au & Beck's oscillator",
        "",
        f"ω = 7.85 rad/s, ζ = 0.02, white noise S = 1 m²/s³, 30 s at dt = 0.02 s (1501 normals); P(max |x| > b). "
        f"{len(runs)} subset runs (seeds 0–{len(runs) - 1}, N = {measured['samples']} a level, p0 = 0.1) against ISEE "
        f"({'commit ' + info['commit']}, {info['date']}, load {info['load average (1 min) at start']}). "
        "`python -m benchmarks rare_events` rewrites this section.",
        "",
        "| b (m) | reference (ISEE, its CoV) | mean estimate | within 3 reported CoV | reported CoV (mean) | empirical CoV | ratio | runs (mean) |",
        "|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for column, (b, (reference, reference_cov)) in enumerate(zip(THRESHOLDS, measured["references"])):
        values, covs = estimates[:, column], reported[:, column]
        within = int(np.count_nonzero(np.abs(values - reference) <= 3.0 * np.hypot(covs, reference_cov) * reference))
        empirical = float(np.sqrt(np.mean((values - reference) ** 2)) / reference)
        needed = np.mean([_runs_to(r, b) for r in runs])
        lines.append(f"| {b:g} | {reference:.3g} ({reference_cov:.1%}) | {values.mean():.3g} | {within} of {len(runs)} | {covs.mean():.2f} | "
                     f"{empirical:.2f} | {covs.mean() / empirical:.2f} | {needed:.0f} |")
    lines += [
        "",
        "The empirical CoV is the root mean square of the estimates' relative error from the reference. Runs: the runs "
        "(evaluations of the response) a run needs to reach the threshold's level. "
        f"Wall time of one run down to the largest threshold, response included (its FFT convolution): {np.median(measured['times']):.1f} s "
        f"(median of {len(runs)}) on {info['cores']} cores.",
        END,
    ]
    return "\n".join(lines) + "\n"


def _runs_to(result, b: float) -> float:
    """The runs spent on the levels whose threshold is below b (and on the level that estimates it)."""
    bounds = np.asarray(result.attrs["level_thresholds"], dtype=float)
    levels = int(np.searchsorted(bounds, b, side="right"))
    samples = result.attrs["samples_per_level"]
    return samples + levels * samples * (1.0 - result.attrs["p0"])


def pounding_pair() -> Scene:
    """The bundled elastic pair, Building 2's masses doubled, its contacts never closing."""
    table = tomllib.loads(bundled_scene_path("elastic_pair").read_text())
    table["building"][1]["mass"] = [2.0 * m for m in table["building"][1]["mass"]]
    for contact in table["contact"]:
        contact["gap"] = math.inf
    table["motion"] = {"type": "constant", "acceleration": 0.0, "duration": 1.0, "dt": 0.5}  # replaced by the motion sampled
    return stochpound.scene_from_dict(table)


def pair_measure(crude_runs: int, samples: int, seed: int) -> dict:
    """The top contact's largest closure: crude Monte Carlo of the seeded ensemble and one subset run."""
    scene = pounding_pair()
    fields = {k: v for k, v in PAIR_MOTION.items() if k != "type"}
    start = time.perf_counter()
    closures = []
    for first in range(0, crude_runs, 500):
        ensemble = getattr(stochpound.motions, PAIR_MOTION["type"])(min(500, crude_runs - first), start=first, seed=seed, **fields)
        for values in ensemble.values:
            run = stochpound.simulate(replace(scene, motion=SampledMotion(PAIR_MOTION["dt"], values)))
            closures.append(float(run["peak_contact_closure"].values[1]))
    crude_time = time.perf_counter() - start
    start = time.perf_counter()
    result = subset_simulation(scene, motion=PAIR_MOTION, response="closure", contact=1, thresholds=list(PAIR_THRESHOLDS), samples_per_level=samples, p0=0.1, seed=seed)
    return {"closures": np.array(closures), "result": result, "crude_time": crude_time, "subset_time": time.perf_counter() - start}


def pair_section(measured: dict, info: dict[str, str]) -> str:
    """The Markdown section of the pair's measurements."""
    closures, result = measured["closures"], measured["result"]
    lines = [
        PAIR_START,
        "## A pounding pair against crude Monte Carlo",
        "",
        "The bundled elastic pair with Building 2's masses doubled, contacts never closing (gap `inf`), under a Kanai–Tajimi "
        "motion (ω_g = 15 rad/s, ζ_g = 0.6, expected PGA 2 m/s², Jennings envelope, 10 s at dt = 0.02 s, `method = \"filter\"`): "
        f"P(top contact's closure > b), which is P(pounding) at a gap b. Crude Monte Carlo of {closures.size} runs of the seeded "
        f"ensemble ({measured['crude_time']:.0f} s) against one subset run of {result.attrs['runs']} runs "
        f"(N = {result.attrs['samples_per_level']}, p0 = 0.1; {measured['subset_time']:.0f} s) on {info['cores']} cores "
        f"(commit {info['commit']}, {info['date']}, load {info['load average (1 min) at start']}). "
        "`python -m benchmarks rare_events pair` rewrites this section.",
        "",
        "| b (m) | crude MC (its CoV) | subset simulation (reported CoV) | difference / combined standard deviation |",
        "|---:|---:|---:|---:|",
    ]
    for b, probability, cov in zip(PAIR_THRESHOLDS, result.probability.values, result.cov.values):
        crude = float(np.mean(closures > b))
        crude_cov = math.sqrt((1.0 - crude) / (crude * closures.size)) if crude > 0.0 else math.nan
        combined = math.hypot(cov * probability, crude_cov * crude) if crude > 0.0 else math.nan
        crude_text = f"{crude:.3g} ({crude_cov:.0%})" if crude > 0.0 else "0"
        lines.append(f"| {b:g} | {crude_text} | {probability:.3g} ({cov:.0%}) | "
                     + (f"{(probability - crude) / combined:+.1f} |" if crude > 0.0 else "crude MC has no run beyond |"))
    lines.append(PAIR_END)
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    """Run the measurements and rewrite the section of ``--out``."""
    if argv and argv[0] == "pair":
        return _pair_main(argv[1:])
    parser = argparse.ArgumentParser(prog="python -m benchmarks rare_events", description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=20, help="subset runs (seeds 0 ..)")
    parser.add_argument("--samples", type=int, default=1000, help="samples a level")
    parser.add_argument("--reference-samples", type=int, default=4000, help="ISEE samples per threshold")
    parser.add_argument("--out", type=Path, default=REPOSITORY / "docs" / "rare-events.md")
    arguments = parser.parse_args(argv)
    info = report.machine()
    SECTION.write(arguments.out, section(measure(arguments.repeats, arguments.samples, arguments.reference_samples), info))
    print(f"wrote the section 'Certified on Au & Beck's oscillator' of {arguments.out}")
    return 0


def _pair_main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks rare_events pair", description="the pounding pair against crude Monte Carlo")
    parser.add_argument("--crude-runs", type=int, default=4000, help="crude Monte Carlo runs")
    parser.add_argument("--samples", type=int, default=500, help="subset samples a level")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--out", type=Path, default=REPOSITORY / "docs" / "rare-events.md")
    arguments = parser.parse_args(argv)
    info = report.machine()
    PAIR_SECTION.write(arguments.out, pair_section(pair_measure(arguments.crude_runs, arguments.samples, arguments.seed), info))
    print(f"wrote the section 'A pounding pair against crude Monte Carlo' of {arguments.out}")
    return 0
