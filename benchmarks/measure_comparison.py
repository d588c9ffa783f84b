"""Each measure's conditioned g* against the answer without a measure at the demo site: ``python -m benchmarks.measure_comparison``.

At the bundled demonstration site of ruptures ``demo_three_sources``, the
risk flagship's configurations (``experiments/risk/``, their scenes as they
are): the code-designed yielding pair on fixed bases beside the stiff and
the flexible neighbour (``fixed_pair.toml``), and Building 1 on its
friction pendulum (μ 0.05, no moat wall) beside the stiff neighbour
(``isolated.toml``), contact-free. For each candidate measure of a
configuration and each seed of the selection, an experiment of stripes at
the site's intensities of the return periods, motions selected from the 100
FEMA P695 records (``--simulated N``: from N simulated motions a stripe of
the site's causal ruptures, ``[site] simulated_motions``, each rupture's
share its disaggregation weight at the level, and no records) to the exact
conditional spectrum of the site's ruptures
(``[site] ruptures``: the mixture over the causal ruptures weighted by the
disaggregation at each level), the hazard of the same ruptures (``[hazard]
ruptures``), and its g* at 10 % and 2 % in 50 years (the risk chain's,
from the counts, and from a lognormal demand per stripe); beside them, the
same store's answer without a measure
(:func:`stochpound.analysis.store_measure_free`), compared by
:func:`stochpound.analysis.compare_measures` with each measure's
sufficiency test on its first seed's store
(:func:`stochpound.analysis.store_sufficiency`: the closure's trend with M,
ln R and ε within the stripes), the reason given for a measure that misses.

Rewrites the section "Each measure against the answer without a measure"
of ``docs/benchmarks.md`` and its figure.
"""

from __future__ import annotations

import argparse
import pickle
import tempfile
import time
from collections.abc import Collection
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
import xarray as xr

from benchmarks import report
from benchmarks.sections import Section
from benchmarks.site_consistency import lognormal_g_star
from benchmarks.timing import REPOSITORY

SECTION = Section("<!-- measure comparison: start -->", "<!-- measure comparison: end -->")
"""This benchmark's section of docs/benchmarks.md."""
FIGURE = REPOSITORY / "docs" / "figures" / "measure_comparison.png"
"""The figure the section shows."""
SITE = "demo_three_sources"
MEASURES = {
    "PGA": ("pga", None),
    "PSA(0.3 s)": ("psa", 0.3),
    "PSA(0.5 s)": ("psa", 0.5),
    "PSA(1 s)": ("psa", 1.0),
    "PSA(2 s)": ("psa", 2.0),
    "PSA(3 s)": ("psa", 3.0),
    "Sa_avg(0.5–4 s)": ("sa_avg", (0.5, 0.75, 1.0, 1.5, 2.0, 3.0, 4.0)),
}
"""Candidate measures: stochpound's measure and period (s; Sa_avg's periods: the band the isolated building's closure follows)."""
RETURN_PERIODS = (25.0, 72.0, 224.0, 475.0, 975.0, 2475.0, 10000.0)
"""Return periods (yr) of the stripes: two stripes beside the 475-yr one (224, 975 yr), where the rate at 10 % in 50 years is made."""
EARLIER = (25.0, 72.0, 475.0, 2475.0, 10000.0)
"""The stripes of the earlier design (yr): g* from the counts is also given on these alone, from the same stores."""
TOLERANCE = 1.2
"""The issue's tolerance: a measure agrees when its g* is within this ratio of the measure-free one, either way."""


@dataclass(frozen=True)
class Flagship:
    """A flagship experiment file and the configurations of it compared.

    Attributes
    ----------
    name : str
        Short name (the option's value).
    file : str
        The file in ``experiments/risk/`` whose scene and variants are taken as they are.
    grid : str
        The ``[grid]`` table's body: the configurations run (contact-free).
    measures : tuple of str
        The candidate measures (keys of ``MEASURES``).
    """

    name: str
    file: str
    grid: str
    measures: tuple[str, ...]


FLAGSHIPS = (
    Flagship("fixed", "fixed_pair.toml", 'gap = [inf]\nmu = { values = [inf], buildings = ["B1"] }', ("PGA", "PSA(0.3 s)", "PSA(1 s)")),
    Flagship(
        "isolated", "isolated.toml", 'gap = [inf]\nmu = { values = [0.05], buildings = ["B1"] }\nneighbour = ["stiff"]\nmoat = ["none"]', ("PGA", "PSA(1 s)", "PSA(3 s)", "Sa_avg(0.5–4 s)", "PSA(2 s)")
    ),
)
"""The fixed pair beside the stiff and the flexible neighbour (B1's T1 0.30 s); B1 isolated (μ 0.05, no wall, T_b 3.0 s) beside the stiff one."""


def experiment_text(flagship: Flagship, measure: str, seed: int, motions: int, simulated: int = 0) -> str:
    """The experiment of one flagship's configurations, measure and selection seed at the demo site (the flagship's scene and variants).

    ``simulated`` > 0: the stripes' pool holds that many simulated motions a stripe of the site's causal ruptures (``[site]
    simulated_motions``, allotted by the disaggregation) and no record; 0: the 100 FEMA P695 records.
    """
    from stochpound.analysis import RuptureSite

    text = (REPOSITORY / "experiments" / "risk" / flagship.file).read_text()
    scene = text[text.index("\n[scene]") : text.index("\n[grid]")]
    kind, period = MEASURES[measure]
    levels = RuptureSite.bundled(SITE).intensity_at(kind, period, [1.0 / t for t in RETURN_PERIODS])
    field = "periods" if isinstance(period, tuple) else "period"
    lines = f'measure = "{kind}"' + ("" if period is None else f"\n{field} = {list(period) if field == 'periods' else period}")
    records = "" if simulated else '[[records]]\nsuite = "fema_p695_far_field"\n[[records]]\nsuite = "fema_p695_near_field"\n'
    pool = f"simulated_motions = {simulated}\n" if simulated else ""
    return (
        f'[experiment]\nname = "compare_{flagship.name}"\nstudied = "B1"\n{scene}\n[grid]\n{flagship.grid}\n{records}'
        f'[intensity]\n{lines}\nlevels = [{", ".join(f"{x:.6g}" for x in levels)}]\nmethod = "stripes"\nselection = "conditional_spectrum"\n'
        f'motions = {motions}\nmax_scale_factor = 5.0\nseed = {seed}\n[site]\nruptures = "{SITE}"\n{pool}[hazard]\nruptures = "{SITE}"\n'
    )


def conditioned(folder: Path, flagship: Flagship, measure: str, seed: int, motions: int, workers: int,
                simulated: int = 0) -> tuple[xr.Dataset, xr.DataArray, xr.DataArray, xr.DataArray]:
    """One measure and seed: its store, g* from the counts (the risk chain's), from a lognormal demand per stripe, and from the
    counts on the stripes of the earlier design alone (``EARLIER``)."""
    from stochpound import open_store
    from stochpound.experiment import load_experiment, run_experiment
    from stochpound.risk import store_risk

    code = measure.replace("(", "").replace(" s)", "").replace(".", "p").replace(" ", "").replace("–", "-").lower()
    path = folder / f"{flagship.name}_{code}_seed{seed}.toml"
    path.write_text(experiment_text(flagship, measure, seed, motions, simulated))
    run = run_experiment(load_experiment(path), workers=workers if workers > 1 else 0, progress=False)
    if not run.complete:
        raise RuntimeError(f"{flagship.name}, {measure}, seed {seed}: the experiment did not complete")
    store = open_store(run.store).load()
    risk = store_risk(store, targets=(0.1, 0.02), bootstrap=0)
    earlier = store.isel(intensity=[RETURN_PERIODS.index(t) for t in EARLIER])
    return store, risk.separation["separation"], lognormal_g_star(store, risk), store_risk(earlier, targets=(0.1, 0.02), bootstrap=0).separation["separation"]


def efficiency(store: xr.Dataset, flagship: Flagship, measure: str) -> xr.DataArray:
    """β (ln closure on ln IM over every run of ``store``, :func:`stochpound.risk.measure_efficiency`) of ``measure``, the measure
    the store's stripes are conditioned on, per configuration."""
    from stochpound.risk import measure_efficiency

    kind, period = MEASURES[measure]
    periods = {"stripes": period} if kind == "psa" else {"one second": 1.0}
    average = period if kind == "sa_avg" else None
    result = measure_efficiency(store, periods, sa_avg_periods=average)
    if kind == "psa":
        name = f"PSA({period:.3g} s, stripes)"
    else:
        name = "PGA" if kind == "pga" else next(str(m) for m in result["measure"].values if str(m).startswith("Sa_avg"))
    return result["beta"].sel(response="closure", measure=name, drop=True)


@dataclass
class Comparison:
    """One flagship file's comparison: by the counts and by a lognormal demand per stripe, the answer without a measure, the tests."""

    flagship: Flagship
    counts: pd.DataFrame
    lognormal: pd.DataFrame
    free: object
    earlier: pd.DataFrame
    efficiency: dict[str, list[xr.DataArray]]
    sufficiency: dict
    untested: dict[str, str]
    selections: dict[str, str]
    seconds: float


def compare(flagship: Flagship, measures: list[str], seeds: list[int], motions: int, runs: int, workers: int, simulated: int = 0,
            log=print, stores: Path | None = None) -> Comparison:
    """The comparisons (counts, lognormal demand, counts on the earlier stripes) of one flagship file, each measure's efficiency on
    its stores, and the measure-free answer; ``stores``: a folder that keeps the stores (default: a temporary one)."""
    from stochpound.analysis import RuptureSite, compare_measures, store_measure_free, store_sufficiency

    started = time.perf_counter()
    counted: dict[str, list] = {m: [] for m in measures}
    lognormal: dict[str, list] = {m: [] for m in measures}
    earlier: dict[str, list] = {m: [] for m in measures}
    betas: dict[str, list] = {m: [] for m in measures}
    sufficiency, untested, selections = {}, {}, {}
    free = None
    with tempfile.TemporaryDirectory() as temporary:
        folder = Path(temporary) if stores is None else stores
        folder.mkdir(parents=True, exist_ok=True)
        for name in measures:
            for seed in seeds:
                store, by_counts, by_demand, by_earlier = conditioned(folder, flagship, name, seed, motions, workers, simulated)
                counted[name].append(by_counts)
                lognormal[name].append(by_demand)
                earlier[name].append(by_earlier)
                betas[name].append(efficiency(store, flagship, name))
                log(f"{flagship.name}, {name}, seed {seed}: g* {by_counts.values.ravel()} (counts), {by_demand.values.ravel()} (lognormal demand), "
                    f"{by_earlier.values.ravel()} (counts, earlier stripes); beta {betas[name][-1].values.ravel()}")
                if seed == seeds[0]:
                    selections[name] = selection_words(store)
                    try:
                        sufficiency[name] = store_sufficiency(store)
                    except ValueError as error:  # e.g. too few earthquakes for clustered errors: said, not tested
                        untested[name] = str(error)
                        log(f"{name}, seed {seed}: sufficiency not tested: {error}")
                    else:
                        log(f"{name}, seed {seed}: {sufficiency[name].verdict()}")
                if free is None:  # first: the same for every store of the file (their configurations are the same)
                    free_started = time.perf_counter()
                    free = store_measure_free(store, RuptureSite.bundled(SITE), runs=runs, seed=1, workers=workers)
                    log(f"{flagship.name}, measure-free: g* {[r[0].level.values for r in free.results]}, intervals "
                        f"{[(r[0].level_lower.values, r[0].level_upper.values) for r in free.results]} in {time.perf_counter() - free_started:.0f} s")
    return Comparison(
        flagship,
        compare_measures(counted, free, tolerance=TOLERANCE, sufficiency=sufficiency),
        compare_measures(lognormal, free, tolerance=TOLERANCE, sufficiency=sufficiency),
        free,
        compare_measures(earlier, free, tolerance=TOLERANCE, sufficiency=sufficiency),
        betas,
        sufficiency,
        untested,
        selections,
        time.perf_counter() - started,
    )


def selection_words(store: xr.Dataset) -> str:
    """What a store's stripes hold: motions and earthquakes a stripe, scale factors, the stripes that miss their target, the target's ε and M."""
    factors = store["selection_scale_factor"].values
    missed = int(np.sum(store["selection_misses_target"].values))
    simulated = store["selection_simulated"].values
    count = store["selection_recorded"].values + simulated
    magnitude = store["record_magnitude"].values.astype(float)
    chosen = [float(np.mean(magnitude[np.isfinite(row)])) for row in factors]  # the chosen motions' mean M, stripe by stripe
    return (
        f"{int(count.min())}–{int(count.max())} motions a stripe ({int(simulated.min())}–{int(simulated.max())} simulated) from "
        f"{int(store['selection_earthquakes'].min())}–{int(store['selection_earthquakes'].max())} earthquakes, the chosen motions' mean M "
        f"{', '.join(f'{m:.2f}' for m in chosen)} by stripe, scale factors "
        f"{np.nanmin(factors):.2f}–{np.nanmax(factors):.2f}, {missed} of {store.sizes['intensity']} stripes missing their target by more "
        f"than the tolerance; the target's mean ε {float(store['target_epsilon'].min()):.2f}–{float(store['target_epsilon'].max()):.2f}, "
        f"mean M {float(store['site_magnitude'].min()):.2f}–{float(store['site_magnitude'].max()):.2f} and R "
        f"{float(store['site_distance_km'].min()):.0f}–{float(store['site_distance_km'].max()):.0f} km over the stripes"
    )


def parallel_words(settings: argparse.Namespace) -> str:
    """How the comparisons ran, when ``--assemble`` put together several runs (in parallel: the time is the longest one's)."""
    parts = getattr(settings, "parallel", 1)
    return f" in all ({parts} runs in parallel, one a flagship file, put together by `--assemble`; the time is the longest run's)" if parts > 1 else ""


def pool_words(simulated: int) -> str:
    """What the stripes' pool holds, in words."""
    if not simulated:
        return "the 100 FEMA P695 records"
    return (f"a pool of {simulated} simulated motions a stripe of the site's causal ruptures (`[site] simulated_motions`: "
            "each rupture's share of the pool its disaggregation weight at the level, rounded by the largest remainders; no records)")


def table(comparison: pd.DataFrame, tested: Collection[str]) -> list[str]:
    """A comparison as Markdown rows; ``tested``: the measures whose sufficiency was tested (the others say "not tested")."""
    lines = [
        "| configuration | target | measure | conditioned g*, median (m) | over the seeds (m) | seed spread | measure-free g* (m), 95 % interval "
        "| ratio | within ×1.2 | trend within the stripes (p < 0.05) |",
        "|---|---|---|---:|---:|---:|---:|---:|---|---|",
    ]
    for (configuration, measure_name, target), row in comparison.iterrows():
        trend = (row["insufficient"] or "none") if measure_name in tested else "not tested"
        lines.append(
            f"| {configuration} | {target:.0%} in 50 yr | {measure_name} | {row['median']:.4f} | {row['lowest']:.4f}–{row['highest']:.4f} | "
            f"×{row['seed spread']:.2f} | {row['measure-free']:.4f} ({row['lower']:.4f}–{row['upper']:.4f}) | {row['ratio']:.2f} | "
            f"{'yes' if row['agrees'] else '**no**'} | {trend} |"
        )
    return lines


def efficiency_words(seeds: list[int]) -> str:
    """What the efficiency table holds, in words."""
    return (f"Efficiency: β, the residual standard deviation of ln closure on ln IM over every run of the measure's own store "
            f"(`stochpound.risk.measure_efficiency`; one a selection seed, {', '.join(map(str, seeds))}), the least mean β in bold:")


def efficiency_table(comparisons: list[Comparison]) -> list[str]:
    """Each configuration's β of each of its measures (on the measure's own stores, one a seed), the least mean in bold."""
    lines = ["| configuration | measure | β by seed | mean β |", "|---|---|---:|---:|"]
    for comparison in comparisons:
        labels = dict.fromkeys(comparison.counts.index.get_level_values(0))  # the configurations in compare_measures' words and order
        for label, configuration in zip(labels, comparison.free.configurations):
            where = {dim: value for dim, value in configuration}
            values = {m: [float(b.sel(where)) for b in betas] for m, betas in comparison.efficiency.items()}
            best = min(values, key=lambda m: np.mean(values[m]))
            for measure_name, beta in values.items():
                mean = f"**{np.mean(beta):.3f}**" if measure_name == best else f"{np.mean(beta):.3f}"
                lines.append(f"| {label} | {measure_name} | {' / '.join(f'{b:.3f}' for b in beta)} | {mean} |")
    return lines


def short_label(configuration: str) -> str:
    """A configuration's label for the figure: "fixed pair, stiff neighbour", "isolated, stiff neighbour"."""
    neighbour = configuration.split("neighbour ")[1].split(",")[0]
    return f"{'fixed pair' if 'mu fixed' in configuration else 'isolated'}, {neighbour} neighbour"


def figure(comparisons: list[Comparison], path: Path) -> None:
    """Each measure's conditioned g* over the measure-free one (median, seeds' range), from the counts and from a lognormal demand
    per stripe, with the ×1.2 band and the measure-free interval."""
    from matplotlib.figure import Figure

    rows = sum(len(dict.fromkeys(c.counts.index.droplevel(2))) for c in comparisons)
    fig = Figure(figsize=(7.5, 1.2 + 0.28 * rows + 0.2 * len(comparisons)), layout="constrained")
    axes = fig.subplots(1, 2, sharey=True)
    for ax, target in zip(axes, (0.1, 0.02)):
        y, ticks, labels = 0.0, [], []
        for comparison in comparisons:
            for configuration in dict.fromkeys(comparison.counts.index.get_level_values(0)):
                counts = comparison.counts.xs((configuration, target), level=(0, 2))
                lognormal = comparison.lognormal.xs((configuration, target), level=(0, 2))
                reference = counts["measure-free"].iloc[0]
                ax.fill_betweenx([y - 0.4, y + len(counts) - 0.6], counts["lower"].iloc[0] / reference, counts["upper"].iloc[0] / reference, color="0.88", lw=0)
                for (measure_name, row), (_, other) in zip(counts.iterrows(), lognormal.iterrows()):
                    for shift, data, marker in ((-0.15, row, "o"), (0.15, other, "^")):
                        span = [[data["ratio"] - data["lowest"] / reference], [data["highest"] / reference - data["ratio"]]]
                        ax.errorbar(data["ratio"], y + shift, xerr=span, fmt=marker, ms=4, capsize=2, color="C0" if data["agrees"] else "C3")
                    ticks.append(y)
                    labels.append(f"{short_label(configuration)}: {measure_name}")
                    y += 1
                y += 0.6
        for bound in (1 / TOLERANCE, 1.0, TOLERANCE):
            ax.axvline(bound, color="k", lw=0.8 if bound == 1.0 else 0.6, ls="-" if bound == 1.0 else "--")
        ax.set_xscale("log")
        ax.set_xlim(0.25, 2.0)
        ax.set_xticks([0.3, 0.5, 1 / TOLERANCE, 1.0, TOLERANCE, 2.0], ["0.3", "0.5", f"1/{TOLERANCE:g}", "1", f"{TOLERANCE:g}", "2"])
        ax.minorticks_off()
        ax.set_title(f"g* at {target:.0%} in 50 years", fontsize=9)
        ax.set_xlabel("conditioned g* / measure-free g*", fontsize=8)
        ax.tick_params(labelsize=7)
        ax.grid(True, axis="x", lw=0.3, color="0.85")
    axes[0].set_yticks(ticks, labels)
    axes[0].invert_yaxis()  # shared: once
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=130)


def section(comparisons: list[Comparison], settings: argparse.Namespace, info: dict[str, str], elapsed: float) -> str:
    """The Markdown section."""
    from stochpound.motions import site_model_provenance

    figure_path = Path(settings.figure)
    shown = figure_path.relative_to(REPOSITORY / "docs") if figure_path.is_relative_to(REPOSITORY / "docs") else figure_path.name
    lines = [
        SECTION.start,
        "## Each measure against the answer without a measure",
        "",
        f"At the bundled demonstration site `{SITE}`, the risk flagship's configurations (`experiments/risk/`, their scenes and variants as "
        "they are): the code-designed yielding pair on fixed bases beside the stiff and the flexible neighbour (`fixed_pair.toml`), and "
        "Building 1 on its friction pendulum (μ 0.05, no moat wall) beside the stiff neighbour (`isolated.toml`), contact-free. Per measure "
        f"and selection seed ({', '.join(map(str, settings.seeds))}): stripes at the site's intensities of "
        f"{', '.join(f'{t:g}' for t in RETURN_PERIODS)} years, {settings.motions} motions a stripe selected from {pool_words(settings.simulated)} "
        "(scale factor ≤ 5) to the exact conditional spectrum of the site's ruptures (the mixture over the causal ruptures weighted by the "
        "disaggregation at each level), the hazard of the same ruptures, g* at 10 % and 2 % in 50 years. Beside it, the same scene's answer "
        f"without a measure (`stochpound.analysis.store_measure_free`, seed 1, simulated motions of each rupture, "
        f"site-motion model {site_model_provenance()}), compared by `stochpound.analysis.compare_measures` (within ×{TOLERANCE:g} either way). "
        f"Commit {info['commit']}, {info['date']}, load {info['load average (1 min) at start']}, {settings.workers} worker "
        f"process{'es' if settings.workers > 1 else ''}{parallel_words(settings)}, {elapsed:.0f} s in all. "
        "`python -m benchmarks.measure_comparison [--flagships ... --measures ... --seeds ... --motions N --runs N N --simulated N]` rewrites this section "
        "and its figure.",
        "",
        f"![Each measure's conditioned g* over the measure-free g*]({shown})",
        "",
        f"*Figure: per configuration and measure, the conditioned g* over the measure-free g*, from the counts (the risk chain's; "
        f"circle) and from a lognormal demand per stripe (triangle): the median over the seeds (blue within ×{TOLERANCE:g}, the dashed "
        "lines; red not) and the seeds' range (bar); grey, the measure-free g*'s 95 % interval over the measure-free g*.*",
    ]
    for comparison in comparisons:
        name = comparison.flagship.file
        lines += ["", f"**{name}** ({comparison.seconds:.0f} s). Answer without a measure: {comparison.free.conditions()}."]
        for measure_name, words in comparison.selections.items():
            lines.append(f"- {measure_name}, selection (seed {settings.seeds[0]}): {words}.")
        for measure_name, test in comparison.sufficiency.items():
            lines.append(
                f"- Sufficiency of {measure_name} for the closure (`stochpound.analysis.store_sufficiency`, seed {settings.seeds[0]}'s store; {test.results[0].conditions()}): {test.verdict()}."
            )
        for measure_name, reason in comparison.untested.items():
            lines.append(f"- Sufficiency of {measure_name} for the closure: not tested ({reason}).")
    lines += ["", efficiency_words(settings.seeds), "", *efficiency_table(comparisons)]
    earlier = f"the counts on the {len(EARLIER)} stripes of the earlier design alone ({', '.join(f'{t:g}' for t in EARLIER)} yr; the same stores)"
    for attribute, words in (("counts", "the counts (the risk chain, `store_risk`)"), ("lognormal", "a lognormal demand per stripe (`stripe_demand_rate`)"),
                             ("earlier", earlier)):
        lines += ["", f"g* from {words}:", ""]
        for comparison in comparisons:
            rows = table(getattr(comparison, attribute), comparison.sufficiency)
            lines += rows if comparison is comparisons[0] else rows[2:]
    lines.append(SECTION.end)
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    """Run the experiments and the measure-free answers, and rewrite the section of ``--out`` and its figure."""
    parser = argparse.ArgumentParser(prog="python -m benchmarks.measure_comparison", description=__doc__.splitlines()[0])
    parser.add_argument("--flagships", nargs="+", default=[f.name for f in FLAGSHIPS], choices=[f.name for f in FLAGSHIPS])
    parser.add_argument("--measures", nargs="+", choices=list(MEASURES), help="only these of each configuration's candidate measures")
    parser.add_argument("--seeds", nargs="+", type=int, default=[1, 2], help="seeds of the selection")
    parser.add_argument("--motions", type=int, default=40, help="motions a stripe")
    parser.add_argument("--runs", nargs=2, type=int, default=[1400, 3000], metavar=("FIXED", "ISOLATED"), help="runs a configuration of the answer without a measure, for each flagship file")
    parser.add_argument("--simulated", type=int, default=0, metavar="N",
                        help="select from N simulated motions a stripe of the site's causal ruptures (allotted by the disaggregation) instead of the records")
    parser.add_argument("--workers", type=int, default=1, help="worker processes (the result does not depend on them)")
    parser.add_argument("--out", type=Path, default=REPOSITORY / "docs" / "benchmarks.md")
    parser.add_argument("--figure", type=Path, default=FIGURE)
    parser.add_argument("--stores", type=Path, help="keep the stores in this folder (default: a temporary one, removed)")
    parser.add_argument("--save", type=Path, help="also pickle the comparisons to this file (for --assemble)")
    parser.add_argument("--assemble", type=Path, nargs="+", metavar="SAVED",
                        help="run nothing: write the section and figure from the comparisons --save pickled (e.g. one file a flagship, run in parallel)")
    arguments = parser.parse_args(argv)
    if arguments.assemble:
        parts = [pickle.loads(path.read_bytes()) for path in arguments.assemble]
        comparisons = [c for part in parts for c in part["comparisons"]]
        settings, info = parts[0]["settings"], parts[0]["info"]
        settings.workers, settings.figure = sum(part["settings"].workers for part in parts), arguments.figure
        settings.parallel = len(parts)
        elapsed = max(part["elapsed"] for part in parts)  # in parallel: the longest part's wall-clock time
    else:
        settings, info, start = arguments, report.machine(), time.perf_counter()
        comparisons = []
        for flagship, runs in zip(FLAGSHIPS, arguments.runs):
            if flagship.name in arguments.flagships:
                measures = [m for m in flagship.measures if arguments.measures is None or m in arguments.measures]
                comparisons.append(compare(flagship, measures, arguments.seeds, arguments.motions, runs, arguments.workers, arguments.simulated,
                                           stores=arguments.stores))
        elapsed = time.perf_counter() - start
        if arguments.save:
            arguments.save.write_bytes(pickle.dumps({"comparisons": comparisons, "settings": arguments, "info": info, "elapsed": elapsed}))
    figure(comparisons, arguments.figure)
    SECTION.write(arguments.out, section(comparisons, settings, info, elapsed))
    print(f"wrote the section 'Each measure against the answer without a measure' of {arguments.out} and {arguments.figure}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
