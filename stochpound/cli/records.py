"""``stochpound records``: list the bundled records and show one."""

from __future__ import annotations

import click

from stochpound.cli.group import HelpGroup
from stochpound.errors import RecordError


@click.group("records", cls=HelpGroup)
def records() -> None:
    """Bundled ground-motion records (and record files)."""


@records.command("list")
def list_command() -> None:
    """List the bundled records and their named variants."""
    from stochpound.motions.records import registry_entries

    for name, entry in registry_entries().items():
        fields = entry.fields
        kind = f"variant of {fields['base']}" if entry.is_variant else f"{fields.get('file')}"
        flag = "  [SUBSTITUTE]" if entry.substitute_for else ""
        click.echo(f"{name:38s}{kind}{flag}")
        click.echo(f"{'':38s}{entry.description}")


@records.command("show")
@click.argument("name")
@click.option("--plot", "plot_path", type=click.Path(dir_okay=False), default=None, help="Write a plot of the accelerogram (PNG, PDF, SVG).")
@click.option("--g", "g", type=float, default=9.814, show_default=True, help="g (m/s²) for conversions, peak in g and Arias intensity.")
@click.option("--dt", type=float, default=None, help="Step (s) of a one-column text file.")
@click.option("--units", type=click.Choice(["g", "m/s2", "cm/s2"]), default=None, help="Units of a text file's values.")
def show_command(name: str, plot_path: str | None, g: float, dt: float | None, units: str | None) -> None:
    """Statistics of NAME (a bundled record or a file), with the study's Table 3.2 beside ours."""
    from stochpound.motions.records import load_record
    from stochpound.motions.records.plot import plot_record
    from stochpound.motions.records.report import record_report

    if not g > 0:
        raise click.BadParameter(f"must be > 0, got {g}", param_hint="--g")
    try:
        record = load_record(name, dt=dt, units=units)
    except RecordError as error:
        raise click.ClickException(str(error)) from None
    click.echo(record_report(record, g=g))
    if plot_path:
        plot_record(record, plot_path, g=g)
        click.echo(f"\nplot written to {plot_path}")
