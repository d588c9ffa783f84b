"""The response spectrum: ``python -m benchmarks spectrum``.

Times :func:`stochpound.motions.response_spectrum` on the first 50 s of a
bundled record (NGA-West2 RSN 6, El Centro 1940, dt = 0.01 s: 5001 samples)
at 100 periods log-spaced over 0.05–10 s (target: 50 ms warm), against two
libraries that compute spectra, eqsig (Nigam–Jennings recurrence, maxima
read at the samples) and pyrotd (frequency domain), with their deviations
from the exact spectrum. It rewrites the "Response spectrum" section of
``docs/benchmarks.md`` and draws ``docs/figures/spectrum_benchmark.png``.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any, Callable

import numpy as np

from benchmarks import report
from benchmarks.sections import Section
from benchmarks.timing import REPOSITORY, best_of

START = "<!-- response spectrum: start -->"
END = "<!-- response spectrum: end -->"
SECTION = Section(START, END)
"""This benchmark's section of docs/benchmarks.md."""
RECORD = "el_centro_1940_ngaw2_rsn6"
DURATION = 50.0
PERIODS = np.geomspace(0.05, 10.0, 100)
FIGURE_NAME = "spectrum_benchmark.png"


def parse_arguments(argv: list[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="python -m benchmarks spectrum", description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=20, help="timed warm calls (best of)")
    parser.add_argument("--out", type=Path, default=REPOSITORY / "docs" / "benchmarks.md", help="the document whose section is rewritten")
    return parser.parse_args(argv)


def spectra(repeats: int) -> dict[str, Any]:
    """PSA of the three implementations and their warm times (s)."""
    from importlib.metadata import version

    import eqsig
    import pyrotd

    from stochpound.motions import response_spectrum
    from stochpound.motions.records import load_record

    record = load_record(RECORD)
    a = record.acceleration(9.81)[: int(round(DURATION / record.dt)) + 1]
    dt = record.dt
    calls: dict[str, Callable[[], np.ndarray]] = {
        "stochpound (exact, located maxima)": lambda: response_spectrum(a, dt, PERIODS).psa.values,
        f"eqsig {version('eqsig')} (recurrence, sampled maxima)": lambda: eqsig.sdof.pseudo_response_spectra(a, dt, PERIODS, xi=0.05)[2],
        f"pyrotd {version('pyrotd')} (frequency domain)": lambda: pyrotd.calc_spec_accels(dt, a, 1.0 / PERIODS, 0.05).spec_accel,
    }
    results = {}
    for name, call in calls.items():
        timing = best_of(call, repeats)
        results[name] = {"time": timing.best, "psa": np.asarray(timing.result, dtype=float)}
    return {"samples": a.size, "dt": dt, "results": results}


def figure(data: dict[str, Any], path: Path) -> Path:
    """PSA of the record and the deviations of eqsig and pyrotd from the exact spectrum."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    results = data["results"]
    names = list(results)
    exact = results[names[0]]["psa"]
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(7.0, 6.0), sharex=True)
    top.loglog(PERIODS, exact / 9.81, "k-", label=names[0])
    for name in names[1:]:
        top.loglog(PERIODS, results[name]["psa"] / 9.81, "--", label=name)
        bottom.semilogx(PERIODS, 100.0 * (results[name]["psa"] / exact - 1.0), label=name)
    top.set_ylabel("PSA (g), ζ = 5 %")
    top.legend(fontsize=8)
    top.set_title(f"{RECORD}, first {DURATION:g} s")
    bottom.axhline(0.0, color="k", lw=0.8)
    bottom.set_xlabel("period T (s)")
    bottom.set_ylabel("deviation from exact (%)")
    bottom.legend(fontsize=8)
    return report.save_figure(fig, path)


def section(data: dict[str, Any], info: dict[str, str]) -> str:
    """The Markdown section, markers included."""
    results = data["results"]
    names = list(results)
    exact = results[names[0]]["psa"]
    lines = [
        START,
        "## Response spectrum",
        "",
        f"`stochpound.motions.response_spectrum` on the first {DURATION:g} s of `{RECORD}` "
        f"({data['samples']} samples, dt = {data['dt']:g} s) at {PERIODS.size} periods log-spaced over "
        f"{PERIODS[0]:g}–{PERIODS[-1]:g} s, ζ = 5 %; best of warm calls on one core "
        f"(commit {info['commit']}, {info['date']}, load {info['load average (1 min) at start']}). "
        "Target: 50 ms. `python -m benchmarks spectrum` rewrites this section.",
        "",
        "| implementation | warm time (ms) | largest deviation of PSA from exact | at T (s) |",
        "|---|---:|---:|---:|",
    ]
    for name in names:
        deviation = results[name]["psa"] / exact - 1.0
        worst = int(np.argmax(np.abs(deviation)))
        lines.append(f"| {name} | {1e3 * results[name]['time']:.1f} | {100 * deviation[worst]:+.2f} % | {PERIODS[worst]:.3g} |")
    lines += [
        "",
        f"![PSA and deviations](figures/{FIGURE_NAME})",
        "",
        "Reading the maxima at the samples (eqsig) underestimates the short-period "
        "spectrum by up to several per cent (ω·dt grows as T falls); the frequency-domain method (pyrotd) treats the "
        "record as periodic after zero padding and interpolates it by Fourier series, "
        "not linearly, so it deviates at short and long periods alike.",
        END,
    ]
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    """Run the measurements and rewrite the section of ``--out``."""
    arguments = parse_arguments(argv)
    info = report.machine()
    data = spectra(arguments.repeats)
    figure(data, arguments.out.parent / "figures" / FIGURE_NAME)
    SECTION.write(arguments.out, section(data, info))
    print(f"wrote the section 'Response spectrum' of {arguments.out}")
    return 0
