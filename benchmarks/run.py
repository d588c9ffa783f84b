"""Command line of the benchmark suite: ``python -m benchmarks`` or ``python benchmarks/run.py``.

``python -m benchmarks scaling`` runs the experiment-scaling benchmark instead
(:mod:`benchmarks.experiment_scale`), ``python -m benchmarks compare REV`` the
comparison with an earlier revision (:mod:`benchmarks.compare`),
``python -m benchmarks spectrum`` the response spectrum's (:mod:`benchmarks.spectrum`),
``python -m benchmarks yielding`` the yielding storeys' (:mod:`benchmarks.yielding`),
``python -m benchmarks rare_events`` subset simulation's on Au & Beck's oscillator (:mod:`benchmarks.rare_events`),
``python -m benchmarks site_motions`` the site-based stochastic motions' (:mod:`benchmarks.site_motions`),
``python -m benchmarks startup`` the quick start's start-up (:mod:`benchmarks.startup`),
``python -m benchmarks measure_free`` the measure-free risk at the demo site (:mod:`benchmarks.measure_free`),
``python -m benchmarks simulated_pool`` the cost of a pool of simulated motions per motion (:mod:`benchmarks.simulated_pool`),
``python -m benchmarks flagship_selection FILE`` a flagship's stripes chosen without running a case (:mod:`benchmarks.flagship_selection`),
``python -m benchmarks measure_seeds run|table FOLDER`` g* by conditioning measure and selection seed at Fox Plaza (:mod:`benchmarks.measure_seeds`),
``python -m benchmarks stripe_tails FOLDER`` a measure's g* from the site-motion model's own stripes (:mod:`benchmarks.stripe_tails`),
``python -m benchmarks inelastic_demand`` simulated and recorded motions' inelastic demand at matched spectra (:mod:`benchmarks.inelastic_demand`).

The thread pools of BLAS, OpenMP and numba are set to one thread here,
before numpy is imported, so that every in-process measurement runs on one core.
"""

from __future__ import annotations

import os
import sys

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from benchmarks.timing import single_thread_environment  # noqa: E402  (numpy-free module)

single_thread_environment()

import argparse  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

from benchmarks import compare, experiment_scale, measure_free, rare_events, rare_moat, report, site_motions, spectrum, startup, suite, yielding  # noqa: E402
from benchmarks import inelastic_demand, measure_comparison, measure_seeds, simulated_pool, stripe_tails  # noqa: E402
from benchmarks.sections import keep_sections  # noqa: E402
from benchmarks.timing import REPOSITORY  # noqa: E402


def parse_arguments(argv: list[str] | None = None) -> argparse.Namespace:
    """Options of the command line."""
    parser = argparse.ArgumentParser(prog="python -m benchmarks", description="Benchmark stochpound's solvers; write benchmarks.md and the work-precision figure.")
    parser.add_argument("--quick", action="store_true", help="smoke run (< 1 min): scene (a), 10 s of El Centro, one setting per solver")
    parser.add_argument("--out", type=Path, default=None, help="output folder (default: docs/ for a full run, a temporary folder for --quick)")
    parser.add_argument("--no-opensees", action="store_true", help="leave OpenSeesPy out even when it is installed")
    return parser.parse_args(argv)


def output_folder(arguments: argparse.Namespace) -> Path:
    """Where benchmarks.md and figures/ go."""
    if arguments.out is not None:
        return arguments.out
    if arguments.quick:
        return Path(tempfile.gettempdir()) / "stochpound-benchmarks-quick"
    return REPOSITORY / "docs"


def main(argv: list[str] | None = None) -> int:
    """Run the suite and write its outputs; return the exit status."""
    argv = sys.argv[1:] if argv is None else argv
    if argv[:1] == ["scaling"]:
        return experiment_scale.main(argv[1:])
    if argv[:1] == ["compare"]:
        return compare.main(argv[1:])
    if argv[:1] == ["spectrum"]:
        return spectrum.main(argv[1:])
    if argv[:1] == ["yielding"]:
        return yielding.main(argv[1:])
    if argv[:1] == ["rare_events"]:
        return rare_events.main(argv[1:])
    if argv[:1] == ["site_motions"]:
        return site_motions.main(argv[1:])
    if argv[:1] == ["startup"]:
        return startup.main(argv[1:])
    if argv[:1] == ["measure_free"]:
        return measure_free.main(argv[1:])
    if argv[:1] == ["simulated_pool"]:
        return simulated_pool.main(argv[1:])
    if argv[:1] == ["flagship_selection"]:
        from benchmarks import flagship_selection

        return flagship_selection.main(argv[1:])
    if argv[:1] == ["measure_seeds"]:
        return measure_seeds.main(argv[1:])
    if argv[:1] == ["stripe_tails"]:
        return stripe_tails.main(argv[1:])
    if argv[:1] == ["inelastic_demand"]:
        return inelastic_demand.main(argv[1:])
    arguments = parse_arguments(argv)
    config = suite.Config.quick_preset() if arguments.quick else suite.Config.full()
    if arguments.no_opensees:
        config = suite.dataclasses.replace(config, opensees_steps=())
    folder = output_folder(arguments)
    info = report.machine()
    start = time.perf_counter()
    results = suite.run_all(config, log=lambda message: print(f"[{time.perf_counter() - start:7.1f} s] {message}", flush=True))
    elapsed = time.perf_counter() - start
    figure = report.figure(results, folder / "figures" / report.FIGURE_NAME)
    markdown = folder / "benchmarks.md"
    old = markdown.read_text() if markdown.exists() else ""
    sections = (experiment_scale.SECTION, compare.SECTION, spectrum.SECTION, yielding.SECTION, site_motions.SECTION, site_motions.HELD_OUT,
                startup.SECTION, measure_free.SECTION, rare_moat.SECTION)
    sections += (measure_comparison.SECTION, measure_seeds.UNTILTED, measure_seeds.SECTION, inelastic_demand.SECTION, simulated_pool.SECTION, simulated_pool.STARTUP)
    markdown.write_text(keep_sections(old, report.document(results, info, elapsed), sections))
    print(f"wrote {markdown} and {figure} in {elapsed:.1f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
