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
runs give it. The same for a linear pair: the top floors' closure of the
contact-free pair of :func:`pounding_pair` under white noise, its linear map
built from the fixed-base twin's responses to a unit normal.

``python -m benchmarks rare_events pair`` measures a pounding pair instead:
the bundled elastic pair with Building 2's masses doubled and its contacts
never closing (gap ``inf``), under a Kanai–Tajimi motion (``method =
"filter"``), its top contact's closure by subset simulation against crude
Monte Carlo of the seeded ensemble, at the closures crude Monte Carlo
reaches (P ≈ 1e-1 to 1e-2), run by the solver.

``--proposal acs`` and ``--p0`` certify another proposal or p0 in a section of
their own; ``--repeats`` sets the repetitions (the ratio of reported to
empirical CoV is given with a 95 % bootstrap interval over them).
``python -m benchmarks rare_events half_spaces`` compares both proposals on
linear limit states of exact probability (a half-space and a union of 20
half-spaces in 100 normals, P ≈ 1e-6 and 2e-5).

Each rewrites its section of ``docs/rare-events.md`` ("Certified on Au & Beck's
oscillator and a linear pair", "A pounding pair against crude Monte Carlo",
"The proposals on linear limit states").
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
from benchmarks.scenes import PAIR_MOTION
from benchmarks.sections import Section
from benchmarks.timing import REPOSITORY
import stochpound
from stochpound.analysis import subset_simulation
from stochpound.model import Scene, bundled_scene_path
from stochpound.motions import normal_motion
from stochpound.motions.ground import SampledMotion
from stochpound.solvers.twin import fixed_base_displacements

START = "<!-- rare events benchmark: start -->"
END = "<!-- rare events benchmark: end -->"
SECTION = Section(START, END)
"""This benchmark's section of docs/rare-events.md."""
OSCILLATOR = {"omega": 7.85, "zeta": 0.02, "S": 1.0, "dt": 0.02, "duration": 30.0}
"""Au & Beck's (2001) oscillator: rad/s, 1, m²/s³, s, s."""
THRESHOLDS = (1.6, 2.1, 2.3, 2.4)
"""Thresholds b of the displacement, m."""
PAIR_WHITE_NOISE = {"S0": 0.01, "dt": 0.02, "duration": 30.0}
"""The linear pair's white noise: m²/s³, s, s."""
PAIR_LINEAR_THRESHOLDS = (0.06, 0.07, 0.077, 0.083)
"""Top-floor closures of the linear pair, m."""
PAIR_START = "<!-- rare events pair: start -->"
PAIR_END = "<!-- rare events pair: end -->"
PAIR_SECTION = Section(PAIR_START, PAIR_END)
"""The pounding pair's section of docs/rare-events.md."""
PAIR_THRESHOLDS = (0.03, 0.036, 0.042, 0.046, 0.05, 0.06, 0.07)
"""Closures of the pair's top contact, m."""


class LinearResponse:
    """A response at the samples that is a linear map X = A u of the white noise's standard normals.

    A is lower triangular and Toeplitz but for its first column: ``kernel[m]``
    is X_{j+m} for a unit normal at sample j >= 1, ``first[m]`` is X_m for a
    unit normal at sample 0. ``two_sided``: the peak is max |X_k| (a
    displacement), else max X_k (a closure).
    """

    def __init__(self, kernel: np.ndarray, first: np.ndarray, two_sided: bool) -> None:
        self.kernel, self.first, self.two_sided, self.n = kernel, first, two_sided, kernel.size

    def displacements(self, u: np.ndarray) -> np.ndarray:
        """X = A u for rows of u, m."""
        x = fftconvolve(u, self.kernel[None, :], axes=1)[:, : self.n]
        return x + (self.first - self.kernel)[None, :] * u[:, :1]

    def peak(self, u: np.ndarray) -> np.ndarray:
        """max_k |X_k| (or max_k X_k) for rows of u, m."""
        x = self.displacements(u)
        return (np.abs(x) if self.two_sided else x).max(axis=1)

    def isee(self, b: float, samples: int, seed: int) -> tuple[float, float]:
        """P(peak > b) and its CoV by importance sampling with elementary events {|X_k| > b} (or {X_k > b})."""
        rows = self.displacements(np.eye(self.n)).T
        rows = rows[np.linalg.norm(rows, axis=1) > 0.0]
        norms = np.linalg.norm(rows, axis=1)
        sides = 2.0 if self.two_sided else 1.0
        weights = sides * ndtr(-b / norms)
        rng = np.random.default_rng(seed)
        chosen = rng.choice(len(rows), samples, p=weights / weights.sum())
        direction = rows[chosen] / norms[chosen, None]
        sign = np.where(rng.random(samples) < 0.5, -1.0, 1.0) if self.two_sided else np.ones(samples)
        along = -ndtri(ndtr(-b / norms[chosen]) * rng.random(samples)) * sign
        z = rng.standard_normal((samples, self.n))
        u = z + (along - np.sum(direction * z, axis=1))[:, None] * direction
        x = self.displacements(u)
        estimates = weights.sum() / np.count_nonzero((np.abs(x) if self.two_sided else x) > b, axis=1)
        return float(estimates.mean()), float(estimates.std() / math.sqrt(samples) / estimates.mean())


def oscillator(omega: float, zeta: float, S: float, dt: float, duration: float) -> LinearResponse:
    """Au & Beck's oscillator's displacement, from the exact discretisation of ẍ + 2ζωẋ + ω²x = −a_g (a_g linear between samples)."""
    n = int(round(duration / dt)) + 1
    system = np.zeros((4, 4))
    system[:2, :2] = ((0.0, 1.0), (-omega**2, -2.0 * zeta * omega))
    system[:2, 2], system[2, 3] = (0.0, -1.0), 1.0
    step = expm(system * dt)
    phi, ramp = step[:2, :2], step[:2, 3] / dt
    hold = step[:2, 2] - ramp
    powers = [np.eye(2)]
    for _ in range(n):
        powers.append(phi @ powers[-1])
    scale = math.sqrt(2.0 * math.pi * S / dt)
    kernel = scale * np.array([ramp[0]] + [(powers[m] @ ramp + powers[m - 1] @ hold)[0] for m in range(1, n)])
    first = scale * np.array([0.0] + [(powers[m - 1] @ hold)[0] for m in range(1, n)])
    return LinearResponse(kernel, first, two_sided=True)


def linear_pair(S0: float, dt: float, duration: float) -> LinearResponse:
    """The top-floor closure of the contact-free linear pair (:func:`pounding_pair`'s buildings) under white noise of PSD S0.

    Each building's response to a unit normal at samples 0 and 1 by the
    fixed-base twin (:mod:`stochpound.solvers.twin`, the exact recursion).
    """
    motion = normal_motion({"type": "white_noise", "S0": S0, "duration": duration, "dt": dt})
    unit = [SampledMotion(dt, a) for a in motion(np.eye(motion.dimension)[:2])]
    pair = pounding_pair()
    tops = [fixed_base_displacements(replace(pair, buildings=(building,), contacts=()), unit)[:, -1, :] for building in pair.buildings]
    closure = tops[0] - tops[1]  # left minus right: the gap closes where it is positive
    return LinearResponse(np.append(closure[1, 1:], 0.0), closure[0], two_sided=False)


def measure(response: LinearResponse, thresholds: tuple[float, ...], repeats: int, samples: int, reference_samples: int, proposal: str = "mma",
            p0: float = 0.1) -> dict:
    """The reference and ``repeats`` subset runs at every threshold (the chains' ``proposal``, ``p0``), with their wall times."""
    references = [response.isee(b, reference_samples, seed=1000 + i) for i, b in enumerate(thresholds)]
    runs, times = [], []
    for seed in range(repeats):
        start = time.perf_counter()
        runs.append(subset_simulation(response.peak, thresholds=list(thresholds), samples_per_level=samples, p0=p0, seed=seed, dimension=response.n,
                                      proposal=proposal, max_levels=40))
        times.append(time.perf_counter() - start)
    return {"thresholds": thresholds, "references": references, "runs": runs, "times": times, "samples": samples, "proposal": proposal, "p0": p0}


def certification_section(proposal: str, p0: float) -> Section:
    """The section of docs/rare-events.md of one proposal and p0 (Au & Beck's modified Metropolis at p0 = 0.1: :data:`SECTION`)."""
    if (proposal, p0) == ("mma", 0.1):
        return SECTION
    return Section(f"<!-- rare events benchmark {proposal} p0={p0:g}: start -->", f"<!-- rare events benchmark {proposal} p0={p0:g}: end -->")


def table(measured: dict) -> list[str]:
    """The Markdown table of one system's measurements: the reported CoV (the genealogy's) and Au & Beck's against the empirical
    one, and, on the log scale the report's intervals p·exp(±1.96 δ) use, against the spread of ln(estimate / reference)."""
    runs = measured["runs"]
    estimates = np.array([r.probability.values for r in runs])
    reported = np.array([r.cov.values for r in runs])
    au_beck = np.array([r.cov_au_beck.values for r in runs])
    lines = [
        "| b (m) | reference (ISEE, its CoV) | mean estimate | empirical CoV | reported CoV (mean) | ratio (95 % bootstrap interval) "
        "| Au & Beck's CoV: ratio (interval) | sd of ln(estimate / reference) | reported CoV / it | 95 % intervals holding the reference "
        "| within 3 reported CoV: log scale (largest \\|ln(estimate / reference)\\| / δ) | within 3 reported CoV: linear | runs (mean) |",
        "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for column, (b, (reference, reference_cov)) in enumerate(zip(measured["thresholds"], measured["references"])):
        values, covs, covs_ab = estimates[:, column], reported[:, column], au_beck[:, column]
        spread = np.hypot(covs, reference_cov)
        within = int(np.count_nonzero(np.abs(values - reference) <= 3.0 * spread * reference))
        logs = np.log(values / reference)
        holding = int(np.count_nonzero(np.abs(logs) <= 1.96 * spread))
        log_within, largest = int(np.count_nonzero(np.abs(logs) <= 3.0 * spread)), float(np.max(np.abs(logs) / spread))
        empirical = float(np.sqrt(np.mean((values - reference) ** 2)) / reference)
        needed = np.mean([_runs_to(r, b) for r in runs])
        low, high = ratio_interval(values, covs, reference)
        low_ab, high_ab = ratio_interval(values, covs_ab, reference)
        lines.append(
            f"| {b:g} | {reference:.3g} ({reference_cov:.1%}) | {values.mean():.3g} | {empirical:.2f} | {covs.mean():.2f} | "
            f"{covs.mean() / empirical:.2f} ({low:.2f}–{high:.2f}) | {covs_ab.mean() / empirical:.2f} ({low_ab:.2f}–{high_ab:.2f}) | "
            f"{logs.std():.2f} | {covs.mean() / logs.std():.2f} | {holding} of {len(runs)} | {log_within} of {len(runs)} ({largest:.2f}) | "
            f"{within} of {len(runs)} | {needed:.0f} |"
        )
    return lines


def ratio_interval(values: np.ndarray, covs: np.ndarray, reference: float, resamples: int = 4000, seed: int = 0) -> tuple[float, float]:
    """A 95 % interval of the ratio of the mean reported CoV to the empirical CoV: percentiles of the ratio over
    ``resamples`` bootstrap resamples of the repeated runs (estimate and reported CoV kept together)."""
    rng = np.random.default_rng(seed)
    chosen = rng.integers(0, len(values), (resamples, len(values)))
    empirical = np.sqrt(np.mean((values[chosen] - reference) ** 2, axis=1)) / reference
    ratios = covs[chosen].mean(axis=1) / empirical
    return float(np.percentile(ratios, 2.5)), float(np.percentile(ratios, 97.5))


def section(oscillator_runs: dict, pair_runs: dict, info: dict[str, str]) -> str:
    """The Markdown section of the measurements."""
    repeats, proposal, p0 = len(oscillator_runs["runs"]), oscillator_runs["proposal"], oscillator_runs["p0"]
    marked = certification_section(proposal, p0)
    options = "" if marked is SECTION else f" --proposal {proposal} --p0 {p0:g}"
    lines = [
        marked.start,
        "## Certified on Au & Beck's oscillator and a linear pair" + ("" if marked is SECTION else f": `proposal = \"{proposal}\"`, p0 = {p0:g}"),
        "",
        f"{repeats} subset runs each (seeds 0–{repeats - 1}, N = {oscillator_runs['samples']} a level, p0 = {p0:g}, "
        f"{'modified Metropolis' if proposal == 'mma' else 'adaptive conditional sampling'}) against ISEE "
        f"(commit {info['commit']}, {info['date']}, load {info['load average (1 min) at start']}). "
        f"`python -m benchmarks rare_events{options}` rewrites this section.",
        "",
        "**Au & Beck's oscillator**: ω = 7.85 rad/s, ζ = 0.02, white noise S = 1 m²/s³, 30 s at dt = 0.02 s (1501 normals); "
        "P(max |x| > b).",
        "",
        *table(oscillator_runs),
        "",
        f"**A linear pair**: the elastic pair of the next section (Building 2's masses doubled), white noise S0 = {PAIR_WHITE_NOISE['S0']:g} m²/s³, "
        "30 s at dt = 0.02 s; P(max of the top floors' closure at the samples > b). Its linear map is "
        "built from the fixed-base twin's responses to a unit normal.",
        "",
        *table(pair_runs),
        "",
        "The reported CoV is the genealogy's (docs/rare-events.md, \"The coefficient of variation\"); Au & Beck's leaves out the levels' "
        "correlation. The 95 % intervals are the report's, p·exp(±1.96 δ) with δ the reported CoV (and the reference's CoV) combined. "
        "Within 3 reported CoV: on the log scale of those intervals, |ln(estimate / reference)| ≤ 3δ (in brackets the largest ratio of "
        "the two over the runs), and on the linear one, |estimate − reference| ≤ 3δ × reference, which the estimator's right skew "
        "fails more often (docs/rare-events.md, \"Reading the CoV\"). "
        f"The empirical CoV is the root mean square of the estimates' relative error from the reference; from {repeats} runs it is "
        f"itself uncertain by about 1/√{2 * repeats - 2} ≈ {1 / math.sqrt(2 * repeats - 2):.0%} for Gaussian estimates (more for skewed ones): the ratio's "
        "interval is the 2.5–97.5 percentiles of the ratio over 4000 bootstrap resamples of the runs, which assumes no shape. Runs: the runs "
        "(evaluations of the response) a run needs to reach the threshold's level. "
        f"Wall time of one run down to the largest threshold, response included (its FFT convolution): "
        f"{np.median(oscillator_runs['times']):.1f} s and {np.median(pair_runs['times']):.1f} s "
        f"(medians) on {info['cores']} cores.",
        marked.end,
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


HALF_SPACES = {"a half-space": 1, "a union of 20 half-spaces": 20}
"""The linear limit states g(u) = max_{k < m} u_k in 100 normals (m half-spaces along orthogonal directions)."""
HALF_SPACE_THRESHOLD = 4.75
HALF_SPACE_START = "<!-- rare events half-spaces: start -->"
HALF_SPACE_SECTION = Section(HALF_SPACE_START, "<!-- rare events half-spaces: end -->")
"""The proposals' comparison on linear limit states, in docs/rare-events.md."""


def half_space_section(repeats: int, samples: int, info: dict[str, str]) -> str:
    """Both proposals on :data:`HALF_SPACES` at b = 4.75, P = 1 − (1 − Φ(−b))^m exactly: the Markdown section."""
    lines = [
        HALF_SPACE_START,
        "## The proposals on linear limit states",
        "",
        f"g(u) = max of the first m of 100 standard normals, P(g > {HALF_SPACE_THRESHOLD:g}) = 1 − (1 − Φ(−{HALF_SPACE_THRESHOLD:g}))^m exactly; "
        f"{repeats} subset runs each (seeds 0–{repeats - 1}, N = {samples} a level, p0 = 0.1; commit {info['commit']}, {info['date']}, "
        f"load {info['load average (1 min) at start']}). `python -m benchmarks rare_events half_spaces` rewrites this section.",
        "",
        "| limit state | exact P | proposal | mean estimate / exact − 1 | empirical CoV | reported CoV (mean) | ratio (95 % bootstrap interval) "
        "| Au & Beck's CoV (mean) | its ratio (interval) | runs (mean) |",
        "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for name, m in HALF_SPACES.items():
        exact = float(1.0 - (1.0 - ndtr(-HALF_SPACE_THRESHOLD)) ** m)
        for proposal in ("mma", "acs"):
            runs = [subset_simulation(lambda u, m=m: u[:, :m].max(axis=1), thresholds=[HALF_SPACE_THRESHOLD], samples_per_level=samples, p0=0.1,
                                      seed=seed, dimension=100, proposal=proposal) for seed in range(repeats)]
            values, covs = np.array([r.probability.values[0] for r in runs]), np.array([r.cov.values[0] for r in runs])
            covs_ab = np.array([r.cov_au_beck.values[0] for r in runs])
            empirical = float(np.sqrt(np.mean((values - exact) ** 2)) / exact)
            (low, high), (low_ab, high_ab) = ratio_interval(values, covs, exact), ratio_interval(values, covs_ab, exact)
            lines.append(f"| {name} | {exact:.3g} | `{proposal}` | {values.mean() / exact - 1:+.2f} | {empirical:.2f} | {covs.mean():.2f} | "
                         f"{covs.mean() / empirical:.2f} ({low:.2f}–{high:.2f}) | {covs_ab.mean():.2f} | {covs_ab.mean() / empirical:.2f} "
                         f"({low_ab:.2f}–{high_ab:.2f}) | {np.mean([r.attrs['runs'] for r in runs]):.0f} |")
    lines.append(HALF_SPACE_SECTION.end)
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    """Run the measurements and rewrite the section of ``--out``."""
    if argv and argv[0] == "pair":
        return _pair_main(argv[1:])
    if argv and argv[0] == "half_spaces":
        parser = argparse.ArgumentParser(prog="python -m benchmarks rare_events half_spaces", description="both proposals on linear limit states")
        parser.add_argument("--repeats", type=int, default=30)
        parser.add_argument("--samples", type=int, default=500)
        parser.add_argument("--out", type=Path, default=REPOSITORY / "docs" / "rare-events.md")
        arguments = parser.parse_args(argv[1:])
        HALF_SPACE_SECTION.write(arguments.out, half_space_section(arguments.repeats, arguments.samples, report.machine()))
        print(f"wrote the section 'The proposals on linear limit states' of {arguments.out}")
        return 0
    if argv and argv[0] == "nonlinear":
        from benchmarks import rare_events_nonlinear

        return rare_events_nonlinear.main(argv[1:])
    if argv and argv[0] == "moat":
        from benchmarks import rare_moat

        return rare_moat.main(argv[1:])
    if argv and argv[0] == "moat_isee":
        from benchmarks import rare_moat

        return rare_moat.isee_main(argv[1:])
    parser = argparse.ArgumentParser(prog="python -m benchmarks rare_events", description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=20, help="subset runs (seeds 0 ..)")
    parser.add_argument("--samples", type=int, default=1000, help="samples a level")
    parser.add_argument("--reference-samples", type=int, default=4000, help="ISEE samples per threshold")
    parser.add_argument("--proposal", choices=("mma", "acs"), default="mma", help="the chains' proposal")
    parser.add_argument("--p0", type=float, default=0.1, help="each level's conditional probability")
    parser.add_argument("--out", type=Path, default=REPOSITORY / "docs" / "rare-events.md")
    arguments = parser.parse_args(argv)
    info = report.machine()
    settings = (arguments.repeats, arguments.samples, arguments.reference_samples, arguments.proposal, arguments.p0)
    measured = [measure(oscillator(**OSCILLATOR), THRESHOLDS, *settings), measure(linear_pair(**PAIR_WHITE_NOISE), PAIR_LINEAR_THRESHOLDS, *settings)]
    certification_section(arguments.proposal, arguments.p0).write(arguments.out, section(*measured, info))
    print(f"wrote the section 'Certified on Au & Beck's oscillator and a linear pair' of {arguments.out}")
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
