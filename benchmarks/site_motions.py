"""The site-based stochastic motions: ``python -m benchmarks site_motions {speed,calibrate,check [--held-out],tail}``.

``speed`` times :func:`stochpound.motions.site_motions` (motions of 40 s at
dt = 0.01 s; target ≥ 500 motions per second on 2 cores: 1 and 2 threads,
and the first call's cost in a new process) and rewrites the "Site-based stochastic motions" section of
``docs/benchmarks.md``. ``calibrate`` fits the hazard-compatible calibration
(``stochpound.motions._site_calibration``) and writes
``data/site_motions/calibration.toml`` with its provenance. ``check``
simulates the calibrated model over the check's scenarios (2000 motions each
by default) against the NGA-West2 models and Baker–Jayaram, and rewrites the
calibration table of ``docs/site-motions.md`` and its figure. ``tail`` counts how often the simulated motions of the
bundled demo site's ruptures exceed the site's 475- and 2475-year PGA, PSA(1 s) and PSA(3 s) and compares the rate with the
hazard's (docs/site-motions.md). ``check --held-out``
runs the same check at scenarios that are not the fit's (:data:`HELD_OUT_SCENARIOS`,
refused if the calibration file lists one of them) and rewrites its section of
``docs/benchmarks.md``.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

from benchmarks import report
from benchmarks.sections import Section
from benchmarks.timing import REPOSITORY, single_thread_environment

SPEED = Section("<!-- site motions speed: start -->", "<!-- site motions speed: end -->")
CHECK = Section("<!-- site motions check: start -->", "<!-- site motions check: end -->")
HELD_OUT = Section("<!-- site motions held-out check: start -->", "<!-- site motions held-out check: end -->")
TAIL = Section("<!-- site motions tail check: start -->", "<!-- site motions tail check: end -->")
#: The tail check: the bundled site, its return periods (years), its measures (PGA; PSA at 1 s and at 3 s, the isolators' band) and the
#: band of the ratio.
TAIL_SITE, TAIL_RETURN_PERIODS, TAIL_PERIODS, TAIL_BAND = "demo_three_sources", (475.0, 2475.0), (None, 1.0, 3.0), (0.8, 1.25)
#: Motions computed at a time in the tail check (memory: 8 n_time bytes a motion).
TAIL_BATCH = 250
SECTION = SPEED
"""This benchmark's section of docs/benchmarks.md."""
SCENARIO = {"magnitude": 7.0, "distance_km": 20.0, "vs30": 400.0, "mechanism": "strike_slip"}
DURATION, DT = 40.0, 0.01
FIGURE_NAME = "site_motions_calibration.png"
HELD_OUT_FIGURE_NAME = "site_motions_held_out.png"
CALIBRATION = REPOSITORY / "data" / "site_motions" / "calibration.toml"
TOLERANCES = {"median": 0.2, "sigma": 0.1, "correlation": 0.15}
#: Scenarios of the held-out check (M, R_rup km, Vs30 m/s, mechanism): none is the fit's; mostly midway between its
#: magnitudes, distances and Vs30, over M 5.5-8, R_rup 5-100 km, Vs30 200-1100 m/s and the three mechanisms.
HELD_OUT_SCENARIOS: tuple[tuple[float, float, float, str], ...] = (
    (5.5, 10.0, 450.0, "reverse"), (5.75, 35.0, 900.0, "strike_slip"), (6.25, 15.0, 250.0, "normal"),
    (6.25, 70.0, 560.0, "reverse"), (6.75, 30.0, 350.0, "strike_slip"), (6.75, 5.0, 1100.0, "normal"),
    (7.25, 15.0, 450.0, "reverse"), (7.25, 60.0, 200.0, "normal"), (7.75, 25.0, 760.0, "strike_slip"),
    (8.0, 100.0, 300.0, "reverse"),
)  # fmt: skip


def parse_arguments(argv: list[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="python -m benchmarks site_motions", description=__doc__.splitlines()[0])
    parser.add_argument("task", choices=("speed", "calibrate", "check", "tail"))
    parser.add_argument("--n", type=int, default=None, help="motions per process (speed: 500), per scenario (calibrate: 400, check: 2000), per rupture (tail: 2000)")
    parser.add_argument("--out", type=Path, default=None, help="the document whose section is rewritten")
    parser.add_argument("--held-out", action="store_true", help="check: at the held-out scenarios (docs/benchmarks.md) instead of the fit's (docs/motions.md)")
    return parser.parse_args(argv)


def _in_new_process(code: str, threads: int, cache: str | None = None) -> list[float]:
    """The numbers a new process running ``code`` prints, on ``threads`` threads (numba's cache in ``cache``; None: the package's)."""
    environment = single_thread_environment(dict(os.environ))  # BLAS on one thread, site_motions on numba's
    environment["NUMBA_NUM_THREADS"] = str(threads)
    if cache:
        environment["NUMBA_CACHE_DIR"] = cache
    result = subprocess.run([sys.executable, "-c", code], env=environment, capture_output=True, text=True, check=True, cwd=REPOSITORY)
    return [float(value) for value in result.stdout.split()]


def _call(n: int, seed: int) -> str:
    return f"site_motions(**{SCENARIO!r}, n={n}, seed={seed}, dt={DT}, duration={DURATION})"


def _timed(n: int, threads: int) -> tuple[float, float]:
    """Best of 3 wall-clock and CPU seconds of ``n`` motions on ``threads`` threads, after a warm-up, in a new process."""
    code = ("import time; from stochpound.motions import site_motions; " + _call(2, 0) + "\n"
            "runs = []\nfor _ in range(3):\n    wall, cpu = time.perf_counter(), time.process_time(); " + _call(n, 1)
            + "; runs.append((time.perf_counter() - wall, time.process_time() - cpu))\nprint(*min(runs))")
    wall, cpu = _in_new_process(code, threads)
    return wall, cpu


def speed(n: int) -> dict[str, Any]:
    """Motions per second on 1 and 2 threads (wall clock; and per CPU second on 1), and a new process's first call."""
    first = "import time; from stochpound.motions import site_motions; start = time.perf_counter(); " + _call(2, 0) + "; print(time.perf_counter() - start)"
    with tempfile.TemporaryDirectory() as cache:
        compile_seconds = _in_new_process(first, 1, cache)[0]
    _in_new_process(first, 1)  # fills the package's own cache, so the next call finds it
    cached_seconds = _in_new_process(first, 1)[0]
    one, two = _timed(n, 1), _timed(n, 2)
    return {"n": n, "one": n / one[0], "two": n / two[0], "cpu": n / one[1], "compile": compile_seconds, "cached": cached_seconds}


def _machine(info: dict[str, str]) -> str:
    """How busy the machine was: idle below a load of 1.5 (of its 2 cores), else shared with other work."""
    return "idle machine" if float(info["load average (1 min) at start"]) < 1.5 else "on a machine shared with other work"


def speed_section(data: dict[str, Any], info: dict[str, str]) -> str:
    """The Markdown section, markers included."""
    verdict = "met" if data["two"] >= 500 else "not met"
    return "\n".join([
        SPEED.start,
        "## Site-based stochastic motions",
        "",
        f"`stochpound.motions.site_motions` for M {SCENARIO['magnitude']:g}, R {SCENARIO['distance_km']:g} km, Vs30 {SCENARIO['vs30']:g} m/s, "
        f"strike-slip: {data['n']} motions of {DURATION:g} s at dt = {DT:g} s ({int(DURATION / DT) + 1} samples), best of 3 after a warm-up in a new process "
        f"(commit {info['commit']}, {info['date']}, load {info['load average (1 min) at start']} at start, "
        f"{_machine(info)}). Target: ≥ 500 motions per second on 2 cores. "
        "`python -m benchmarks site_motions speed` rewrites this section.",
        "",
        "| threads | motions per second (wall clock) |",
        "|---:|---:|",
        f"| 1 | {data['one']:.0f} ({data['cpu']:.0f} per CPU second) |",
        f"| 2 | {data['two']:.0f} |",
        "",
        f"Target **{verdict}** at this load (on a machine shared with other work the wall-clock figures are lower bounds; "
        "the rate per CPU second is what one free core gives). `site_motions` runs on numba's thread count "
        "(the environment variable `NUMBA_NUM_THREADS`, default the cores), 16 motions at a time per thread; the motions do not depend on it. "
        "Most of the cost is the time-varying filter: every sample's impulse response is followed "
        "until its envelope has decayed to 10⁻⁴ (a few hundred samples at the median filter frequency and damping, "
        "thousands for the low-frequency, lightly damped draws). "
        f"First call in a new process: {data['compile']:.1f} s with numba's cache empty (compiling the kernels), "
        f"{data['cached']:.1f} s with it filled (the package's own cache). Memory: 8 bytes a sample, "
        f"{8 * (int(DURATION / DT) + 1) / 1e3:.0f} kB a motion here (10⁴ motions of 60 s: 0.5 GB), plus 16 motions' work arrays per thread.",
        SPEED.end,
    ]) + "\n"


def calibrate(n: int) -> Path:
    """Fit the calibration and write its data file with the provenance."""
    from stochpound.motions import fit_calibration

    start = time.perf_counter()
    fit = fit_calibration(n=n, workers=2)
    return write_calibration(fit, time.perf_counter() - start)


def _rows(matrix: list[list[float]]) -> list[str]:
    return [f"    [{', '.join(f'{v:.6g}' for v in row)}]," for row in matrix]


def write_calibration(fit: dict[str, Any], elapsed: float) -> Path:
    """Write data/site_motions/calibration.toml from a fit (:func:`stochpound.motions.fit_calibration`'s result)."""
    info = report.machine()
    history = "; ".join(f"{m:.2f} / {s:.2f}" for m, s in fit["history"])
    lines = [
        "# Hazard-compatible calibration of the Rezaeian & Der Kiureghian (2010) model (docs/site-motions.md).",
        "# Written by `python -m benchmarks site_motions calibrate` (stochpound.motions._site_calibration.fit_calibration):",
        f"# {fit['n']} motions per scenario (scenario i: realizations of seed {fit['seed']} + 1000 i), dt 0.01 s, {fit['iterations']} fixed-point",
        f"# iterations on each scenario's own layer then {fit['regressed_iterations']} on the regressions' layer, against the NGA-West2 average "
        "(ASK14, BSSA14, CB14, CY14 in pygmm: mean of ln medians, rms of sigmas) and the",
        f"# Baker-Jayaram (2008) correlation; commit {info['commit']}, {info['date']}, {elapsed:.0f} s. Largest |ln ratio| of medians /",
        f"# |sigma difference| over the fit's scenarios and shape periods at each iteration's simulation: {history}.",
        "# Scenarios (M, R_rup km, Vs30 m/s, mechanism): " + "; ".join(f"{s[0]:g} {s[1]:g} {s[2]:g} {s[3]}" for s in fit["scenarios"]),
        "",
        f'name = "{fit["name"]}"',
        "",
        "[residual_scale]  # multiplies the published total residual standard deviation",
        *(f"{parameter} = {factor:.6g}" for parameter, factor in fit["residual_scale"].items()),
        "",
        "[corner]  # ln f_c (Hz) = ln_hz[0] + ln_hz[1] (M - 7) + sigma_ln z: the published 0.2 Hz",
        "ln_hz = [-1.60944, 0.0]",
        "sigma_ln = 0.0",
        "",
        "[spectral_shape]  # ln gain at periods T_j: mu_j - mean_j . x + sqrt(max(sigma_j^2 - variance_j . x, 0)) (L z)_j, L L' = correlation;",
        "# x = [1, M - 7, ln(R/25), ln(Vs30/750), reverse, normal, (M - 7)^2, (M - 7) ln(R/25), ln(R/25)^2, ln(Vs30/750)^2, ln(R/25) ln(Vs30/750)]",
        f"periods = [{', '.join(f'{p:g}' for p in fit['periods'])}]",
        "mean = [", *_rows(fit["mean"]), "]",
        "variance = [", *_rows(fit["variance"]), "]",
        "correlation = [", *_rows(fit["correlation"]), "]",
        "",
    ]
    CALIBRATION.write_text("\n".join(lines))
    return CALIBRATION


def fitted_scenarios(path: Path = CALIBRATION) -> tuple[tuple[float, float, float, str], ...]:
    """The scenarios a calibration file was fitted at (M, R_rup km, Vs30 m/s, mechanism), read from its header."""
    prefix = "# Scenarios (M, R_rup km, Vs30 m/s, mechanism): "
    line = next((line for line in path.read_text().splitlines() if line.startswith(prefix)), None)
    if line is None:
        raise ValueError(f"{path}: no '{prefix.strip()}' line in the header (write it with `python -m benchmarks site_motions calibrate`)")
    fields = [entry.split() for entry in line[len(prefix):].split(";")]
    return tuple((float(m), float(r), float(vs30), mechanism) for m, r, vs30, mechanism in fields)


def held_out_scenarios(path: Path = CALIBRATION) -> tuple[tuple[float, float, float, str], ...]:
    """:data:`HELD_OUT_SCENARIOS`, refused if the calibration of ``path`` was fitted at any of them."""
    shared = set(HELD_OUT_SCENARIOS) & set(fitted_scenarios(path))
    if shared:
        raise ValueError(f"held-out scenarios {sorted(shared)} are among the fit's scenarios in {path.name}")
    return HELD_OUT_SCENARIOS


def _figure(table: Any, path: Path) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    x = np.array([0.01 if p is None else p for p in table.periods])
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(7.0, 6.0), sharex=True)
    for ratio, difference in zip(table.ln_median_ratio, table.sigma_difference):
        top.semilogx(x, ratio, "-", color="0.4", lw=0.8)
        bottom.semilogx(x, difference, "-", color="0.4", lw=0.8)
    for axis, bound, label in ((top, TOLERANCES["median"], "ln(simulated median / NGA-West2)"), (bottom, TOLERANCES["sigma"], "σ simulated − σ NGA-West2")):
        axis.axhline(0.0, color="k", lw=0.8)
        axis.axhline(bound, color="r", ls="--", lw=0.8)
        axis.axhline(-bound, color="r", ls="--", lw=0.8)
        axis.set_ylabel(label)
    top.set_title(f"{len(table.scenarios)} scenarios, {table.n} motions each (PGA drawn at 0.01 s)")
    bottom.set_xlabel("period T (s)")
    return report.save_figure(fig, path)


def largest_misses(table: Any) -> dict[str, float]:
    """The check's largest |ln ratio| of medians, |Δσ| and |Δρ| of the ε correlations (keys of :data:`TOLERANCES`)."""
    return {"median": float(np.max(np.abs(table.ln_median_ratio))), "sigma": float(np.max(np.abs(table.sigma_difference))),
            "correlation": max(abs(a - b) for a, b in table.correlation.values())}


def shares_within(table: Any) -> dict[str, float]:
    """Share of the check's cells within :data:`TOLERANCES`: medians and σ (scenario × period), ε correlations (pairs)."""
    correlation_misses = np.array([simulated - bj for simulated, bj in table.correlation.values()])
    return {"median": float(np.mean(np.abs(table.ln_median_ratio) <= TOLERANCES["median"])),
            "sigma": float(np.mean(np.abs(table.sigma_difference) <= TOLERANCES["sigma"])),
            "correlation": float(np.mean(np.abs(correlation_misses) <= TOLERANCES["correlation"]))}


def _introduction(table: Any, info: dict[str, str], elapsed: float, held_out: bool) -> str:
    run = (f"commit {info['commit']}, {info['date']}, load {info['load average (1 min) at start']} at start, {elapsed / 60:.0f} min; "
           f"`python -m benchmarks site_motions check{' --held-out' if held_out else ''}` rewrites this section")
    scenarios = (f"scenarios that are not among the calibration's {len(fitted_scenarios())} (the command refuses any that its data file lists), "
                 "simulated with the calibrated model (`hazard_compatible`): " if held_out else "scenarios, ")
    where = ("They lie mostly midway between the fit's magnitudes, distances and Vs30 (the check at 14 of the fit's own scenarios: "
             "[Site-based motions: the calibration](site-motions.md)); pygmm warns that normal faulting above M 7 lies outside "
             "some of the four models' recommended range, as at the fit's M 7.5 normal scenario. " if held_out else "")
    return (f"{len(table.scenarios)} {scenarios}{table.n} motions each, dt = 0.01 s ({run}). {where}"
            "ln of the simulated median over the NGA-West2 average's (first row of a scenario) and σ_sim − σ_NGA-West2 of ln Sa "
            "(second row), at PGA and 5 %-damped PSA(T), T in s:")


def _verdict(table: Any) -> str:
    misses = largest_misses(table)
    words = {"median": "|ln ratio|", "sigma": "|Δσ|", "correlation": "|Δρ|"}
    met = [key for key in misses if misses[key] <= TOLERANCES[key]]
    missed = [f"{words[key]} up to {misses[key]:.2f} > {TOLERANCES[key]}" for key in misses if key not in met]
    if not missed:
        return "**The issue's thresholds are met** at every cell of these scenarios."
    return (f"**The issue's thresholds are not met** at every cell of these scenarios: {'; '.join(missed)}"
            + (f" (met: {', '.join(words[key] for key in met)})." if met else "."))


def check_section(table: Any, info: dict[str, str], elapsed: float, held_out: bool = False) -> str:
    """The check's section, markers included: the calibration table of docs/site-motions.md, or (``held_out``) of docs/benchmarks.md."""
    section, figure = (HELD_OUT, HELD_OUT_FIGURE_NAME) if held_out else (CHECK, FIGURE_NAME)
    head = ["PGA" if p is None else f"{p:g}" for p in table.periods]
    lines = [section.start, *(["## Site-based stochastic motions at held-out scenarios"] if held_out else []), "",
             _introduction(table, info, elapsed, held_out), "",
             "| M | R (km) | Vs30 (m/s) | mechanism | | " + " | ".join(head) + " |", "|---" * (5 + len(head)) + "|"]
    for scenario, ratio, difference in zip(table.scenarios, table.ln_median_ratio, table.sigma_difference):
        label = f"| {scenario[0]:g} | {scenario[1]:g} | {scenario[2]:g} | {scenario[3].replace('_', '-')} "
        lines.append(label + "| ln ratio | " + " | ".join(f"{v:+.2f}" for v in ratio) + " |")
        lines.append("| | | | | Δσ | " + " | ".join(f"{v:+.2f}" for v in difference) + " |")
    worst, shares = largest_misses(table), shares_within(table)
    lines += ["", f"Largest |ln ratio| {worst['median']:.2f} (target ≤ {TOLERANCES['median']}: {100 * shares['median']:.0f} % of the cells within); "
              f"largest |Δσ| {worst['sigma']:.2f} (target ≤ {TOLERANCES['sigma']}: {100 * shares['sigma']:.0f} % within).", "",
              "| periods (s) | ρ of ε, simulated | Baker–Jayaram | difference |", "|---|---:|---:|---:|"]
    for pair, (simulated, bj) in table.correlation.items():
        lines.append(f"| {pair[0]:g}, {pair[1]:g} | {simulated:.2f} | {bj:.2f} | {simulated - bj:+.2f} |")
    lines += ["", f"{len(table.correlation)} pairs, {100 * shares['correlation']:.0f} % within {TOLERANCES['correlation']} of Baker–Jayaram. "
              + _verdict(table), "", f"![calibration check{' at held-out scenarios' if held_out else ''}](figures/{figure})", "", section.end]
    return "\n".join(lines) + "\n"


def check(n: int, out: Path, held_out: bool = False) -> tuple[dict[str, float], dict[str, float]]:
    """Simulate the calibrated model over the check's scenarios (``held_out``: :func:`held_out_scenarios`) and rewrite the table of ``out``."""
    from stochpound.motions import calibration_table

    info = report.machine()
    start = time.perf_counter()
    table = calibration_table(n=n, **({"scenarios": held_out_scenarios()} if held_out else {}))
    elapsed = time.perf_counter() - start
    _figure(table, out.parent / "figures" / (HELD_OUT_FIGURE_NAME if held_out else FIGURE_NAME))
    (HELD_OUT if held_out else CHECK).write(out, check_section(table, info, elapsed, held_out))
    return largest_misses(table), shares_within(table)


def rupture_exceedance(site: Any, n: int, seed: int, levels: np.ndarray, periods: tuple = TAIL_PERIODS, dt: float = 0.01) -> np.ndarray:
    """P(IM > x | r) [rupture, measure, level] counted over ``n`` simulated motions of every rupture of ``site`` (its full scenario,
    geometry included; rupture r: realizations of seed ``seed + r``), ``levels`` [measure, level] in g, IM PGA or PSA at ``periods``."""
    from stochpound.motions import DEFAULT_G, response_spectrum, site_motions

    oscillators = [p for p in periods if p is not None]
    counts = np.zeros((len(site), *levels.shape))
    for r in range(len(site)):
        scenario = site.scenario(r)
        for start in range(0, n, TAIL_BATCH):
            motions = site_motions(scenario=scenario, n=n, seed=seed + r, dt=dt, realizations=list(range(start, min(start + TAIL_BATCH, n))))
            for a in motions["acceleration"].values:
                psa = iter(response_spectrum(a, dt, oscillators)["psa"].values if oscillators else [])
                im = np.array([np.max(np.abs(a)) if p is None else next(psa) for p in periods]) / DEFAULT_G
                counts[r] += im[:, None] > levels
    return counts / n


def tail_check(n: int, seed: int = 11, site_name: str = TAIL_SITE, return_periods: tuple = TAIL_RETURN_PERIODS) -> dict[str, Any]:
    """The simulated motions' rate of exceeding the site's hazard levels, Σ_r ν_r P(IM_sim > x | r), against the hazard's λ(x).

    ``ratio`` [measure, return period] the simulated rate over the hazard's, ``low``/``high`` its 95 % interval
    (binomial: Var = Σ ν_r² p_r (1 − p_r) / n), ``levels`` the site's intensities (g) at ``return_periods``.
    """
    from stochpound.hazard import RuptureSite

    site = RuptureSite.bundled(site_name)
    rates = 1.0 / np.asarray(return_periods)
    measures = [("pga", None) if p is None else ("psa", p) for p in TAIL_PERIODS]
    levels = np.array([site.intensity_at(measure, period, rates) for measure, period in measures])
    hazard = np.array([site.rate_of_exceedance(measure, period, level) for (measure, period), level in zip(measures, levels)])
    p = rupture_exceedance(site, n, seed, levels)
    nu = np.asarray(site.rate)[:, None, None]
    simulated = np.sum(nu * p, axis=0)
    error = 1.96 * np.sqrt(np.sum(nu**2 * p * (1.0 - p), axis=0) / n)
    shares = nu * p / np.maximum(simulated, 1e-300)
    return {"site": site_name, "n": n, "seed": seed, "periods": list(TAIL_PERIODS), "return_periods": list(return_periods), "levels": levels, "hazard": hazard,
            "ratio": simulated / hazard, "low": (simulated - error) / hazard, "high": (simulated + error) / hazard,
            "names": list(site.names), "largest_share": [[site.names[int(np.argmax(shares[:, i, j]))] for j in range(len(return_periods))]
                                                         for i in range(len(measures))]}


def tail_section(result: dict[str, Any], info: dict[str, str], elapsed: float) -> str:
    """The tail check's section of docs/site-motions.md, markers included."""
    low, high = TAIL_BAND
    lines = [TAIL.start, "", f"The bundled site `{result['site']}` ({len(result['names'])} ruptures): {result['n']} motions of each rupture "
             f"(rupture r: seed {result['seed']} + r; its scenario with its geometry), P(IM > x | r) counted, "
             f"against the site's hazard at its own levels (commit {info['commit']}, {info['date']}, load "
             f"{info['load average (1 min) at start']} at start, {elapsed / 60:.0f} min; `python -m benchmarks site_motions tail` rewrites "
             "this section):", "",
             "| measure | return period (yr) | level (g) | λ hazard (1/yr) | Σ ν_r P̂(IM_sim > x \\| r) / λ | 95 % interval | largest share |",
             "|---|---:|---:|---:|---:|---|---|"]
    met = True
    for i, period in enumerate(result["periods"]):
        name = "PGA" if period is None else f"PSA({period:g} s)"
        for j, years in enumerate(result["return_periods"]):
            ratio = result["ratio"][i, j]
            met &= bool(low <= ratio <= high)
            lines.append(f"| {name} | {years:g} | {result['levels'][i, j]:.3f} | {result['hazard'][i, j]:.2e} | {ratio:.2f} | "
                         f"{result['low'][i, j]:.2f}–{result['high'][i, j]:.2f} | {result['largest_share'][i][j].replace('_', ' ')} |")
    verdict = "**met** at every row" if met else "**not met** at every row"
    lines += ["", f"Target: the ratio within ×{low:g}–{high:g}: {verdict}.", "", TAIL.end]
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    """Run the task."""
    arguments = parse_arguments(argv)
    if arguments.task == "speed":
        out = arguments.out or REPOSITORY / "docs" / "benchmarks.md"
        info = report.machine()
        data = speed(arguments.n or 500)
        SPEED.write(out, speed_section(data, info))
        print(f"{data['one']:.0f} motions/s on one thread ({data['cpu']:.0f} per CPU second), {data['two']:.0f} on two; "
              f"first call {data['compile']:.1f} s uncached, {data['cached']:.1f} s cached; wrote {out}")
    elif arguments.task == "calibrate":
        print(f"wrote {calibrate(arguments.n or 400)}")
    elif arguments.task == "tail":
        out = arguments.out or REPOSITORY / "docs" / "site-motions.md"
        info, start = report.machine(), time.perf_counter()
        result = tail_check(arguments.n or 2000)
        TAIL.write(out, tail_section(result, info, time.perf_counter() - start))
        print(f"ratios {np.round(result['ratio'], 2).tolist()} (measures x return periods); wrote {out}")
    else:
        out = arguments.out or REPOSITORY / "docs" / ("benchmarks.md" if arguments.held_out else "site-motions.md")
        worst, shares = check(arguments.n or 2000, out, arguments.held_out)
        print(", ".join(f"largest {key} miss {worst[key]:.3f} ({100 * shares[key]:.0f} % within {TOLERANCES[key]})" for key in worst) + f"; wrote {out}")
    return 0
