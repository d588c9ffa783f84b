"""Every snippet of docs/getting-started.md runs as written: its Python blocks, the experiment and the report it builds."""

from __future__ import annotations

import re
import shlex
import shutil

import matplotlib
from click.testing import CliRunner

from stochpound.cli import main
from tests.helpers import REPOSITORY

PAGE = REPOSITORY / "docs" / "getting-started.md"


def blocks(language: str) -> list[str]:
    return re.findall(rf"```{language}\n(.*?)```", PAGE.read_text(), re.S)


def stochpound_commands() -> dict[str, list[str]]:
    """The page's first ``stochpound ...`` command line of each subcommand (``experiment``, ``report``, ...); the later ones
    (the risk flagship's, which takes minutes) are shown, not run."""
    lines = [line.split("#")[0].strip() for block in blocks("bash") for line in block.splitlines()]
    commands: dict[str, list[str]] = {}
    for args in (shlex.split(line) for line in lines if line.startswith("stochpound ") and " " in line):
        if len(args) > 1 and not args[1].startswith("-"):
            commands.setdefault(args[1], args[1:])
    return commands


def test_the_page_has_the_snippets_this_test_runs():
    commands = stochpound_commands()
    assert {"simulate", "experiment", "report"} <= commands.keys()
    assert len(blocks("python")) == 3


def test_getting_started_runs_as_written(tmp_path, monkeypatch):
    matplotlib.use("Agg")
    shutil.copytree(REPOSITORY / "experiments" / "scenes", tmp_path / "experiments" / "scenes")
    shutil.copy(REPOSITORY / "experiments" / "quickstart.toml", tmp_path / "experiments")
    monkeypatch.chdir(tmp_path)
    first, table, store = blocks("python")
    namespace: dict = {}
    exec(compile(first, "getting-started: a first scene", "exec"), namespace)
    assert (tmp_path / "first-scene.png").stat().st_size > 10_000
    assert namespace["run"].sizes["impact"] >= 1
    exec(compile(table, "getting-started: the impact table", "exec"), namespace)

    commands = stochpound_commands()
    runner = CliRunner()
    simulated = runner.invoke(main, commands["simulate"], catch_exceptions=False)
    assert simulated.exit_code == 0, simulated.output
    # as written, on the default local cluster would start dask workers: run in this process instead
    experiment = runner.invoke(main, commands["experiment"] + ["--workers", "0", "--quiet"], catch_exceptions=False)
    assert experiment.exit_code == 0, experiment.output
    assert (tmp_path / "experiments" / "quickstart.nc").is_file()

    exec(compile(store, "getting-started: open the store", "exec"), {})

    report = runner.invoke(main, commands["report"], catch_exceptions=False)
    assert report.exit_code == 0, report.output
    assert (tmp_path / "quickstart-report" / "index.html").is_file()
