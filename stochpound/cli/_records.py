"""``stochpound records``: list the bundled records and suites, show one, draw its response spectrum."""

from __future__ import annotations

import math

import click

from stochpound.cli._group import HelpGroup
from stochpound._atomic import check_not_input
from stochpound._errors import RecordError
from stochpound.motions import DEFAULT_G


def _units_option(context: click.Context, parameter: click.Parameter, units: str | None) -> str | None:
    """The ``--units`` option's value in its canonical spelling (g, m/s2 or cm/s2); None when not given."""
    from stochpound.motions.records import normalize_units

    if units is None:
        return None
    try:
        return normalize_units(units)
    except ValueError as error:
        raise click.BadParameter(str(error)) from None


@click.group("records", cls=HelpGroup)
def records() -> None:
    """Bundled ground-motion records (and record files)."""


@records.command("list")
@click.option("--suite", default=None, help="List the motions of a suite (fema_p695_far_field, ...) or of a folder of record files instead.")
def list_command(suite: str | None) -> None:
    """List the bundled records and their named variants with their units, then the suites (or the motions of one suite)."""
    from stochpound.motions.records import SUITES, load_record, registry_entries

    if suite is not None:
        _list_suite(suite)
        return
    for name, entry in registry_entries().items():
        kind = f"variant of {entry.base}" if entry.is_variant else f"{entry.file}"
        flag = "  [SUBSTITUTE]" if entry.substitute_for else ""
        try:
            units = load_record(name).units
        except RecordError as error:
            raise click.ClickException(str(error)) from None
        click.echo(f"{name:38s}{units:7s}{kind}{flag}")
        click.echo(f"{'':38s}{entry.description}")
    click.echo("\nsuites (stochpound records list --suite NAME):")
    for name, source in SUITES.items():
        click.echo(f"{name:38s}{source.description}")


def _list_suite(suite: str) -> None:
    from stochpound.motions.records import load_suite

    try:
        motions = load_suite(suite)
    except RecordError as error:
        raise click.ClickException(str(error)) from None
    click.echo(f"{'name':34s}{'event':30s}{'station':32s}{'component':18s}{'M':>5s}{'R (km)':>8s}{'Vs30':>7s}{'dt (s)':>8s}{'npts':>7s}  units")
    for record in motions:
        meta = record.metadata
        click.echo(
            f"{record.name:34s}{str(meta.get('event', ''))[:29]:30s}{str(meta.get('station', ''))[:31]:32s}{str(meta.get('component', ''))[:17]:18s}"
            f"{meta.get('magnitude', float('nan')):5.1f}{meta.get('distance', float('nan')):8.1f}{meta.get('vs30', float('nan')):7.0f}{record.dt:8.4f}{record.npts:7d}  {record.units}"
        )


@records.command("show")
@click.argument("name")
@click.option("--plot", "plot_path", type=click.Path(dir_okay=False), default=None, help="Write a plot of the accelerogram (PNG, PDF, SVG).")
@click.option("--g", "g", type=float, default=DEFAULT_G, show_default=True,
              help="g (m/s²) for conversions, peak in g and Arias intensity (the study's Table 3.2 used 9.814).")
@click.option("--dt", type=float, default=None, help="Step (s) of a one-column text file.")
@click.option("--units", callback=_units_option, default=None, metavar="UNITS",
              help="Units of a text file's values: g, m/s2 or cm/s2, in any usual spelling (gal, cm/s², cm/s/s, m/s^2, ...).")
def show_command(name: str, plot_path: str | None, g: float, dt: float | None, units: str | None) -> None:
    """Statistics of NAME (a bundled record or a file), with the reference study's Table 3.2 beside ours for its records."""
    from stochpound.motions.records import load_record, plot_record
    from stochpound.studies.agarwal2004 import record_report

    if not g > 0:
        raise click.BadParameter(f"must be > 0, got {g}", param_hint="--g")
    _check_plot(plot_path, name)
    try:
        record = load_record(name, dt=dt, units=units)
    except RecordError as error:
        raise click.ClickException(str(error)) from None
    click.echo(record_report(record, g=g))
    if plot_path:
        plot_record(record, plot_path, g=g)
        click.echo(f"\nplot written to {plot_path}")


def _check_plot(plot_path: str | None, name: str) -> None:
    """Refuse a --plot that is the record file itself (it would be overwritten by the picture)."""
    if plot_path is None:
        return
    try:
        check_not_input(plot_path, [(name, "the record file")], "--plot")
    except ValueError as error:
        raise click.BadParameter(str(error), param_hint="--plot") from None


def parse_periods(text: str) -> list[float]:
    """Periods (s) from ``"0.1,0.2,1"`` or a log-spaced range ``"0.05:5:30"`` (first:last:count)."""
    import numpy as np

    try:
        if ":" in text:
            first, last, count = text.split(":")
            return np.geomspace(float(first), float(last), int(count)).tolist()
        return [float(value) for value in text.split(",") if value.strip()]
    except ValueError:
        raise click.BadParameter(f"a list 0.1,0.5,1 or a range first:last:count, got {text!r}", param_hint="--periods") from None


@records.command("spectrum")
@click.argument("name")
@click.option("--periods", "periods_text", default="0.05:5:30", show_default=True, help="Periods (s): a list 0.1,0.5,1 or a log-spaced range first:last:count.")
@click.option("--damping", type=float, default=0.05, show_default=True, help="Damping ratio of the oscillators.")
@click.option("--plot", "plot_path", type=click.Path(dir_okay=False), default=None, help="Write a plot of PSA against period (PNG, PDF, SVG).")
@click.option("--g", "g", type=float, default=DEFAULT_G, show_default=True, help="g (m/s²) for records in g, spectra in g and Arias intensity.")
@click.option("--dt", type=float, default=None, help="Step (s) of a one-column text file.")
@click.option("--units", callback=_units_option, default=None, metavar="UNITS",
              help="Units of a text file's values: g, m/s2 or cm/s2, in any usual spelling (gal, cm/s², cm/s/s, m/s^2, ...).")
def spectrum_command(name: str, periods_text: str, damping: float, plot_path: str | None, g: float, dt: float | None, units: str | None) -> None:
    """Intensity measures and the exact response spectrum of NAME (a bundled record, a suite's motion or a file)."""
    from stochpound.motions import intensity_measures
    from stochpound.motions.records import load_record, plot_spectra

    if not g > 0:
        raise click.BadParameter(f"must be > 0, got {g}", param_hint="--g")
    _check_plot(plot_path, name)
    periods = parse_periods(periods_text)
    try:
        record = load_record(name, dt=dt, units=units)
        measures = intensity_measures(record, periods=periods, damping=damping, g=g)
    except (RecordError, ValueError) as error:
        raise click.ClickException(str(error)) from None
    click.echo(f"{record.name}: {record.description}")
    click.echo(
        f"PGA {measures.pga.item() / g:.4f} g   PGV {measures.pgv.item():.4f} m/s   PGD {measures.pgd.item():.4f} m   "
        f"Arias {measures.arias_intensity.item():.4f} m/s   D5-95 {measures.significant_duration.item():.2f} s"
    )
    click.echo(f"\nresponse spectrum, damping {damping:g} (maxima located between samples)")
    click.echo(f"{'T (s)':>10s}{'SD (m)':>14s}{'PSV (m/s)':>14s}{'PSA (g)':>12s}{'SA (g)':>12s}")
    omega = 2.0 * math.pi / measures.period.values
    for period, w, sd, sa in zip(measures.period.values, omega, measures.sd.values, measures.sa.values):
        click.echo(f"{period:10.4g}{sd:14.6g}{w * sd:14.6g}{w * w * sd / g:12.5g}{sa / g:12.5g}")
    if plot_path:
        plot_spectra([(f"ζ = {damping:g}", measures.period.values, measures.psa.values)], plot_path, record.name, g=g)
        click.echo(f"\nplot written to {plot_path}")
