"""``stochpound experiment``: run an experiment into its store, check it, show a store's status."""

from __future__ import annotations

import logging
import sys
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Iterator

import click

from stochpound.cli._group import HelpGroup
from stochpound.cli._scene_notes import experiment_warnings, periods_text, say_scene_warnings
from stochpound._errors import StochpoundError, os_error_message
from stochpound.experiment import LARGE_RUN_BYTES, LARGE_RUN_CASES, parts_folder
from stochpound.store import MotionTable, TomlTable
from stochpound._memory import format_bytes

if TYPE_CHECKING:
    from stochpound.experiment import RunReport


@click.group("experiment", cls=HelpGroup)
def experiment() -> None:
    """Grids and ensembles of scenes, run on dask into a crash-safe store (docs/experiments.md)."""


@experiment.command("run")
@click.argument("experiment_files", metavar="EXPERIMENT_FILE...", nargs=-1, required=True, type=click.Path(dir_okay=False))
@click.option("--store", "store", type=click.Path(dir_okay=False), default=None, help="Store file (default: beside EXPERIMENT_FILE, suffix .nc; only with one file).")
@click.option("--workers", type=click.IntRange(min=0), default=None, help="Local dask worker processes (default: the machine's cores; 0: run in this process).")
@click.option("--scheduler", default=None, metavar="ADDRESS", help="Run on an existing dask.distributed cluster, e.g. tcp://host:8786.")
@click.option("--restart", is_flag=True, help="Discard the existing store and its finished cases (also one of another definition).")
@click.option("--batch", "batch_size", type=click.IntRange(min=1), default=None, help="Cases per dask task (default: automatic).")
@click.option("--checkpoint", type=click.FloatRange(min=0.0), default=30.0, show_default=True, help="Seconds between rebuilds of the store file during the run.")
@click.option("--yes", "large_ok", is_flag=True, help=f"Run a large experiment (over {LARGE_RUN_CASES:,} cases or {format_bytes(LARGE_RUN_BYTES)} of store to write) without asking.")
@click.option("--quiet", is_flag=True, help="No progress bar and no start-up messages.")
@click.option("--seed", type=click.IntRange(min=0), default=None,
              help="Run with this [intensity] seed instead of the file's (the conditional-spectrum selection's: another sample of motions); "
                   "the store records the file's text with that seed (default store: seedN/ beside the file, e.g. seed2/NAME.nc).")
def run_command(
    experiment_files: tuple[str, ...], store: str | None, workers: int | None, scheduler: str | None, restart: bool, batch_size: int | None, checkpoint: float, large_ok: bool, quiet: bool,
    seed: int | None,
) -> None:
    """Run the missing cases of each EXPERIMENT_FILE into its store, one after the other.

    Finished cases are kept in STORE.parts/; rerunning the same command
    completes only the missing ones, and rebuilds a damaged store file from
    them. Ctrl-C stops cleanly. Every file is checked before any runs; the
    time and size of each run are estimated before it starts.
    """
    from stochpound.experiment import is_rare_event_file, load_experiment, load_rare_event, run_experiment

    if workers is not None and scheduler is not None:
        raise click.BadParameter("give --workers or --scheduler, not both", param_hint="--workers")
    if store is not None and len(experiment_files) > 1:
        raise click.BadParameter("--store names one store: give one EXPERIMENT_FILE with it", param_hint="--store")
    several = len(experiment_files) > 1
    loaded = []
    for path in experiment_files:
        with _errors_of(path, several):
            if is_rare_event_file(path):  # a [rare_event] table: one subset simulation (docs/rare-events.md)
                if seed is not None:
                    raise click.BadParameter(f"{path}: a [rare_event] file's seed is its [rare_event] seed, not set by --seed", param_hint="--seed")
                loaded.append(load_rare_event(path))
                continue
            loaded.append(load_experiment(path, seed=seed))
            say_scene_warnings([f"{path}: {line}" if several else line for line in experiment_warnings(loaded[-1])])
    failed = False
    for experiment_file, definition in zip(experiment_files, loaded):
        if several:
            click.echo(f"{experiment_file}:")
        if not hasattr(definition, "n_cases"):
            with _errors_of(experiment_file, several):
                _run_rare_event(definition, store, workers, scheduler, restart, quiet)
            continue
        with _errors_of(experiment_file, several), _silenced(quiet):
            try:
                report = run_experiment(
                    definition, store, workers=workers, scheduler=scheduler, restart=restart, progress=not quiet, checkpoint=checkpoint,
                    batch_size=batch_size, large_ok=large_ok, say=None if quiet else _say,
                )
            except KeyboardInterrupt:  # a second Ctrl-C while the first one's clean-up ran
                click.echo("interrupted; rerun the same command to complete the missing cases")
                sys.exit(130)
        _summary(report)
        if report.interrupted:
            sys.exit(130)
        failed |= bool(report.failed)
    if failed:
        sys.exit(1)


def _run_rare_event(definition, store: str | None, workers: int | None, scheduler: str | None, restart: bool, quiet: bool) -> None:
    """Run a rare-event experiment (in this process unless --workers or --scheduler) and say what it did."""
    from stochpound.experiment import run_rare_event

    report = run_rare_event(definition, store, workers=workers or 0, scheduler=scheduler, restart=restart, say=None if quiet else _say)
    state = "interrupted" if report.interrupted else ("complete" if report.complete else "incomplete")
    click.echo(f"{state}: {report.levels} levels, {report.runs} runs ({report.batches_now} batches this run, {report.batches_before} of the level "
               f"under way before) on {report.executor}; {report.elapsed:.1f} s")
    click.echo(f"store: {report.store}; next: stochpound report build {report.store} --out {report.store.with_suffix('')}-report"
               if report.complete else "rerun the same command to complete the missing batches")
    if report.interrupted:
        sys.exit(130)


@contextmanager
def _errors_of(path: str, name_it: bool) -> Iterator[None]:
    """Turn a stochpound or file-system error into a one-line command error; prefix it with ``path`` if ``name_it`` and it does not name it already."""
    try:
        yield
    except (StochpoundError, ValueError, OSError) as error:
        message = os_error_message(error) if isinstance(error, OSError) else str(error)
        if name_it and not message.startswith(path):
            message = f"{path}: {message}"
        raise click.ClickException(message) from None


@contextmanager
def _silenced(quiet: bool) -> Iterator[None]:
    """With ``quiet``, the library's own start-up line (the solver's compile, a log record of ``stochpound``) is not shown either."""
    logger = logging.getLogger("stochpound")
    level = logger.level
    if quiet:
        logger.setLevel(logging.ERROR)
    try:
        yield
    finally:
        logger.setLevel(level)


def _say(message: str) -> None:
    click.echo(message, err=True)


def _summary(report: RunReport) -> None:
    if report.nothing_to_run:
        click.echo(f"nothing to run: store complete ({report.done}/{report.total} cases)")
    else:
        running = report.elapsed - report.setup
        rate = f", {report.done_now / running:.2f} cases/s" if running > 0 and report.done_now else ""
        state = "interrupted" if report.interrupted else ("complete" if report.complete else "incomplete")
        click.echo(
            f"{state}: {report.done}/{report.total} cases done ({report.done_now} this run, {report.done_before} before) on {report.executor}; "
            f"{report.elapsed:.1f} s in all: {report.setup:.1f} s start-up, {running:.1f} s running{rate}"
        )
    if report.repaired:
        click.echo(f"the store file was damaged: rebuilt from the finished cases in {parts_folder(report.store).name}/")
    for described, error in report.failed[:5]:
        click.echo(f"FAILED {described}\n{error}", err=True)
    if len(report.failed) > 5:
        click.echo(f"... and {len(report.failed) - 5} more failed cases", err=True)
    size = report.store.stat().st_size if report.store.exists() else 0
    click.echo(f"store: {report.store} ({size / 1e6:.2f} MB); open it with stochpound.open_store({str(report.store)!r})")
    if not report.complete:
        click.echo("rerun the same command to complete the missing cases")
    else:
        build = f"stochpound report build {report.store} --out {report.store.with_suffix('')}-report"
        click.echo(f"next: stochpound risk {report.store} (the risk-targeted separation at its site); {build}" if _has_hazard(report.store)
                   else f"next: {build}")


def _has_hazard(store: Path) -> bool:
    """Whether a store carries a hazard (its experiment has ``[hazard]``): then its answer is ``stochpound risk``'s."""
    from stochpound.experiment import open_store

    with open_store(store) as data:
        return data.pound.hazard is not None


@experiment.command("check")
@click.argument("experiment_file", type=click.Path(dir_okay=False))
def check_command(experiment_file: str) -> None:
    """Validate EXPERIMENT_FILE and list its dimensions (runs nothing)."""
    from stochpound.experiment import is_rare_event_file, load_experiment, load_rare_event, periods_of_interest, resolve_motions

    if is_rare_event_file(experiment_file):
        with _errors_of(experiment_file, False):
            rare = load_rare_event(experiment_file)
        click.echo(f"{experiment_file}: valid rare-event experiment; definition sha256 {rare.sha256}")
        click.echo(f"  {rare.table.method} simulation of {rare.table.response} under {MotionTable.of(TomlTable(rare.motion, 'motion')).type}, target {rare.table.target_probability:g}, "
                   f"N = {rare.table.samples_per_level}, p0 = {rare.table.p0:g}, seed {rare.table.seed}")
        return
    try:
        loaded = load_experiment(experiment_file)
        resolve_motions(loaded)
        n_reference = int(loaded.in_grid("reference").sum())  # a conditional-spectrum selection is made here: its errors too
        n_cases = loaded.n_cases
    except (StochpoundError, ValueError) as error:
        raise click.ClickException(str(error)) from None
    click.echo(f"{experiment_file}: valid; definition sha256 {loaded.sha256}")
    for dim in loaded.dims:
        click.echo(f"  {dim.name:14s} {len(dim.values):5d}  {', '.join(_fmt(v) for v in dim.values[:8])}{' ...' if len(dim.values) > 8 else ''}")
    click.echo(f"  {n_cases - n_reference} cases + {n_reference} fixed-base reference cases")
    with _errors_of(experiment_file, False):
        click.echo(f"  {'periods':14s} {periods_text(periods_of_interest(loaded))}")
        say_scene_warnings(experiment_warnings(loaded))


def _fmt(value) -> str:
    return f"{value:g}" if isinstance(value, float) else str(value)


@experiment.command("status")
@click.argument("store", type=click.Path(dir_okay=False))
@click.option("--all", "show_all", is_flag=True, help="List every missing case (default: the first 20).")
@click.option("--done", "show_done", is_flag=True, help="Also list the done cases.")
@click.option("--no-rebuild", is_flag=True, help="Do not rewrite the store file from the finished cases.")
def status_command(store: str, show_all: bool, show_done: bool, no_rebuild: bool) -> None:
    """List the done and missing cases of STORE (and refresh the file from the finished cases)."""
    from stochpound.experiment import store_status

    with _errors_of(store, False):
        report = store_status(Path(store), rebuild=not no_rebuild)
    click.echo(f"experiment {report.experiment.name} (definition sha256 {report.experiment.sha256[:12]}…)")
    click.echo(f"{report.n_done}/{report.experiment.n_cases} cases done, {report.n_missing} missing" + ("; a run is writing this store now" if report.running else ""))
    if show_done:
        for case in report.cases(done=True):
            click.echo(f"done     {case.case_id}  {case.describe()}")
    shown = report.cases(done=False, limit=None if show_all else 20)
    for case in shown:
        click.echo(f"missing  {case.case_id}  {case.describe()}")
    if len(shown) < report.n_missing:
        click.echo(f"... {report.n_missing - len(shown)} more (--all lists them)")
    if report.rebuilt:
        click.echo(f"store rebuilt from the finished cases: {report.store}")
    if report.not_rebuilt:
        click.echo(f"store not rebuilt (its finished cases are kept in its parts): {report.not_rebuilt}", err=True)
