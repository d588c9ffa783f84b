"""``stochpound report``: build the report (HTML page, PDF, figures, tables) from experiment stores."""

from __future__ import annotations

from pathlib import Path

import click

from stochpound.analysis import MEASURE_FREE_RUNS
from stochpound.cli._group import HelpGroup
from stochpound.cli._risk import SENSITIVITY_HELP, sensitivity_stores
from stochpound.cli._site import rupture_site_option
from stochpound._errors import StochpoundError, os_error_message
from stochpound.cli._store_errors import store_variables

FORMAT_CHOICES = ("html", "pdf")


@click.group("report", cls=HelpGroup)
def report() -> None:
    """Reports (HTML page, PDF, figures, tables) built from experiment stores: any experiment's, the reference study's among them."""


@report.command("build")
@click.argument("stores", metavar="STORE [STORE ...]", nargs=-1, required=True, type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option("--out", "out", required=True, type=click.Path(file_okay=False, path_type=Path), help="Output folder (created if needed).")
@click.option(
    "--format",
    "formats",
    multiple=True,
    type=click.Choice(FORMAT_CHOICES),
    default=FORMAT_CHOICES,
    show_default=True,
    help="Document to write; repeat for several.",
)
@click.option("--partial", is_flag=True,
              help="Report a store with missing cases from the cases that ran (the report says how many ran); without it such a store "
                   "is refused.")
@click.option("--accept-edited", "accept_edited", is_flag=True,
              help="Build the report of a store whose definition does not match its recorded sha256 (changed since it was written); refused otherwise.")
@click.option("--ruptures", "ruptures", metavar="FILE|NAME", help="Also give each Risk section's answer without an intensity measure at this "
              "site of ruptures (a rupture table or a bundled site's name; docs/measure-free.md), in a section of its own.")
@click.option("--ruptures-runs", "ruptures_runs", default=MEASURE_FREE_RUNS, show_default=True, type=click.IntRange(min=2),
              help="Runs a configuration of --ruptures.")
@click.option("--sensitivity-store", "sensitivity", multiple=True, metavar="KIND=PATH", help=SENSITIVITY_HELP)
def build_command(stores: tuple[Path, ...], out: Path, formats: tuple[str, ...], partial: bool, accept_edited: bool, ruptures: str | None,
                  ruptures_runs: int, sensitivity: tuple[str, ...]) -> None:
    """Build the report from the experiment STORE files into --out.

    Writes OUT/index.html (self-contained page), OUT/report.pdf, and every
    figure and table as OUT/figures/<key>.png and OUT/tables/<key>.csv.
    Figures and tables of an earlier build into OUT that this one does not
    write again are removed (only those: OUT/.stochpound-report.json lists them).
    The stores are only read (they may be on a read-only disk); OUT is
    checked to be writable before any work. A store with missing cases
    (a run stopped, or cases that failed) is refused unless --partial.
    A --sensitivity-store gives the sensitivity table of g* of each store
    it differs from only in its KIND's choice a column of its own.
    """
    from stochpound.report.assemble import assemble_report
    from stochpound.report.render.output import check_output_folder, write_report

    site = None if ruptures is None else rupture_site_option(ruptures, "--ruptures")
    alternatives = sensitivity_stores(sensitivity)
    try:
        check_output_folder(out, stores)
        with store_variables(stores):
            document = assemble_report(list(stores), progress=_progress, partial=partial, edited="accept" if accept_edited else "refuse",
                                       ruptures=site, ruptures_runs=ruptures_runs, alternatives=alternatives)
        written = write_report(document, out, formats, progress=_progress)
    except (StochpoundError, ValueError) as error:
        raise click.ClickException(str(error)) from None
    except OSError as error:
        raise click.ClickException(os_error_message(error)) from None
    counts = {"figures": f" ({len(document.figures())} PNG files)", "tables": f" ({len(document.tables())} CSV files)"}
    for name, path in written.items():
        click.echo(f"{name}: {_shown(path, out)}{counts.get(name, '')}")


def _progress(message: str) -> None:
    click.echo(f"  {message}", err=True)


def _shown(path: Path, out: Path) -> str:
    """``path`` as the user named the output folder (no absolute path of this machine)."""
    return str(out / path.relative_to(out))
