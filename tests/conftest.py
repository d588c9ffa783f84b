"""Shared fixtures of the tests (shared builders and helpers are in ``tests/helpers.py``), and the order the files run in.

Before any test of a run with ``-n N``, the process that starts the workers fills numba's on-disk cache with the compiled
kernels (:func:`_fill_numba_cache`): the workers and the processes their tests start then load them instead of each
compiling them cold at the same time (the tests of a cold compile set a cache folder of their own). A run in one process
compiles each kernel once, where it is first used.

With ``-n N`` the suite runs file by file (xdist's ``loadfile``: a file's module fixtures are built once, on the worker
that runs the whole file, not on each worker its tests would be spread over), the longest files first
(:data:`LONGEST_FIRST`) so that the last file to finish is a short one. An explicit ``--dist`` other than ``load``
is kept.
"""

import pytest

from stochpound.experiment import load_experiment, run_experiment
from tests.helpers import laws_pair_text, tilted_site_text, write_experiment

#: The test files that take longest (measured, whole suite on 2 cores, 2026-12-03, session 10), longest first: they start first;
#: every other file follows in the usual order. Only the order changes: every test still runs.
LONGEST_FIRST = (
    "test_experiment_cli.py", "test_docs.py", "test_risk_workflow.py", "test_random_scenes.py", "test_experiment_resume.py",
    "test_engine_compile.py", "test_report_study.py", "test_rare_event_experiment.py", "test_exact.py", "test_energy_and_hard_cases.py",
    "test_numba_cache.py", "test_report_yielding.py", "test_engine_fuzz.py", "test_measure_free_store.py", "test_report_preserved.py",
    "test_report_laws.py", "test_report_engineer.py", "test_fitted_scenarios.py", "test_experiment_store.py", "test_report_render.py",
    "test_report_moat_clearance.py", "test_scaling.py", "test_experiment_distributed.py", "test_yielding.py",
)  # fmt: skip


def pytest_configure(config: pytest.Config) -> None:
    """xdist's ``load`` (what ``-n N`` alone gives) becomes ``loadfile``, its files in the collection's order; with ``-n N``,
    the process that starts the workers fills numba's cache first."""
    if getattr(config.option, "dist", "no") == "load":
        config.option.dist = "loadfile"
        config.option.loadscopereorder = False
    if config.getoption("numprocesses", None) and not hasattr(config, "workerinput") and not (config.option.collectonly or config.option.help):
        _fill_numba_cache()  # xdist's controller: several processes would compile the same kernels at once


def _fill_numba_cache() -> None:
    """Compile (or load) every cached kernel once: the exact solver's engine, the fixed-base twin's recursion, the response
    spectrum's and the site-based motions' kernels, as an experiment's warm-up does before its workers start.

    Measured on 2 cores (2026-12-03): without it, the first tests of both xdist workers, and the worker processes of the
    first subprocess runs, compiled the same kernels cold at the same time (a Ctrl-C test took 24 s instead of 7 s)."""
    from stochpound.experiment._compute import warm_up
    from stochpound.motions import site_motions

    warm_up(spectrum=True)
    site_motions(7.0, 20.0, 400.0, "strike_slip", n=1, seed=0, duration=1.0)


def pytest_addoption(parser: pytest.Parser) -> None:
    """``--benchmarks``: also run the tests marked ``benchmark`` (a benchmark's experiments, minutes each)."""
    parser.addoption("--benchmarks", action="store_true", help="also run the tests marked benchmark: the done-when experiments of the benchmarks (minutes)")


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """The files of :data:`LONGEST_FIRST` first, in its order; the tests of a file in their own order; without
    ``--benchmarks``, the tests marked ``benchmark`` skipped, each with the reason (``-ra`` lists them)."""
    rank = {name: place for place, name in enumerate(LONGEST_FIRST)}
    items.sort(key=lambda item: rank.get(item.path.name, len(LONGEST_FIRST)))  # stable: the rest keep their order
    if not config.getoption("--benchmarks"):
        skip = pytest.mark.skip(reason="a benchmark's done-when experiment (minutes): run with --benchmarks")
        for item in items:
            if item.get_closest_marker("benchmark"):
                item.add_marker(skip)


@pytest.fixture(scope="module")
def laws_store(tmp_path_factory):
    """An experiment over contact laws and walls, run (``tests.helpers.PAIR``): its file and its store."""
    folder = tmp_path_factory.mktemp("laws")
    report = run_experiment(load_experiment(write_experiment(folder, laws_pair_text(), "laws.toml")), workers=0, progress=False)
    assert report.complete and not report.failed
    return folder / "laws.toml", report.store


@pytest.fixture(scope="module")
def tilted_experiment(tmp_path_factory):
    """A small experiment of a pool tilted to each stripe (:func:`tests.helpers.tilted_site_text`; its pilot reduced to 48
    motions), its selection made."""
    from stochpound.experiment import _stripe_pools

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(_stripe_pools, "TILT_PILOT", 48)
        experiment = load_experiment(write_experiment(tmp_path_factory.mktemp("tilted"), tilted_site_text(), "tilted.toml"))
        experiment.selection
        return experiment
