"""``stochpound site``: a site of ruptures' hazard and disaggregation at chosen return periods."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import TYPE_CHECKING

import click

if TYPE_CHECKING:
    import xarray as xr

    from stochpound.analysis import StoreMeasureFree
    from stochpound.hazard import RuptureSite

DEFAULT_RETURN_PERIODS = "72,475,2475,10000"
"""Return periods (yr) printed by default: 50 %, 10 %, 2 % in 50 years, and 10 000 years."""


@click.command("site")
@click.argument("site", metavar="TABLE|NAME")
@click.option("--measure", type=click.Choice(["pga", "psa", "sa_avg"]), default="pga", show_default=True, help="The intensity measure.")
@click.option("--period", default=None, metavar="T[,T...]", help="T* (s) for psa; the averaging periods (s, comma-separated) for sa_avg.")
@click.option("--return-periods", "return_periods", default=DEFAULT_RETURN_PERIODS, show_default=True, metavar="YEARS,...",
              help="Return periods (yr) of the levels to disaggregate.")
@click.option("--vs30", type=float, default=None, help="The site's Vs30 (m/s), where the table does not state it.")
@click.option("--z1p0-km", "z1p0_km", type=float, default=None, help="The site's depth to 1.0 km/s (km).")
@click.option("--z2p5-km", "z2p5_km", type=float, default=None, help="The site's depth to 2.5 km/s (km).")
@click.option("--top", default=3, show_default=True, type=click.IntRange(min=0), help="Ruptures listed per level, by share.")
def site(site: str, measure: str, period: str | None, return_periods: str, vs30: float | None, z1p0_km: float | None, z2p5_km: float | None,
         top: int) -> None:
    """The hazard of a site of ruptures (a rupture table or a bundled site's name) and its disaggregation at each return period."""
    from stochpound._errors import SiteError
    from stochpound.analysis import RuptureSite, bundled_rupture_sites

    given = {"vs30": vs30, "z1p0_km": z1p0_km, "z2p5_km": z2p5_km}
    try:
        if Path(site).is_file():
            ruptures = RuptureSite.from_file(Path(site), **given)
        elif site in bundled_rupture_sites():
            ruptures = RuptureSite.bundled(site, **given)
        else:
            raise SiteError(f"TABLE|NAME: {site!r} is neither a file nor a bundled site of ruptures (bundled: {', '.join(bundled_rupture_sites())})")
        conditioning = _periods(period, measure)
        years = _numbers(return_periods, "--return-periods")
        if min(years) <= 1.0 / sum(ruptures.rate):
            raise SiteError(f"--return-periods: each must exceed {1.0 / sum(ruptures.rate):.4g} yr (one over the site's total rate of "
                            f"occurrence), got {return_periods!r}")
        levels = ruptures.intensity_at(measure, conditioning, [1.0 / t for t in years])
        result = ruptures.disaggregation(measure, conditioning, levels=levels)
    except SiteError as error:
        message = str(error)
        raise click.ClickException(f"--{message}" if message.startswith("period:") else message) from None
    click.echo(ruptures.describe())
    click.echo(f"{result.attrs['measure']} in g; means of M, R_rup and epsilon by the ruptures' shares of the exceedances")
    click.echo(f"{'return period (yr)':>18s}{'rate (1/yr)':>13s}{'level (g)':>11s}{'mean M':>8s}{'mean R (km)':>13s}{'mean eps':>10s}  largest shares")
    for j, years_j in enumerate(years):
        at = result.isel(level=j)
        order = at.share.values.argsort()[::-1][:top]
        shares = ", ".join(f"{at.rupture.values[i]} {at.share.values[i]:.2f}" for i in order)
        click.echo(f"{years_j:18g}{float(at.rate):13.4g}{float(at.level):11.4g}{float(at.mean_magnitude):8.2f}{float(at.mean_distance_km):13.1f}"
                   f"{float(at.mean_epsilon):10.2f}  {shares}")


def _numbers(text: str, option: str) -> list[float]:
    from stochpound._errors import SiteError

    try:
        values = [float(part) for part in text.split(",") if part.strip()]
    except ValueError:
        raise SiteError(f"{option}: must be numbers separated by commas, got {text!r}") from None
    if not values or any(not value > 0 for value in values):
        raise SiteError(f"{option}: must be one or more numbers > 0, got {text!r}")
    return values


def _periods(text: str | None, measure: str) -> float | list[float] | None:
    """``--period`` as the measure takes it: none for pga, one period for psa, a list for sa_avg."""
    if text is None:
        return None
    values = _numbers(text, "--period")
    return values[0] if measure == "psa" and len(values) == 1 else values


def rupture_site_option(value: str, option: str) -> RuptureSite:
    """The site of ruptures an option names: a rupture table's file or a bundled site's name, or a one-line error naming the option."""
    from stochpound._errors import SiteError
    from stochpound.hazard import named_rupture_site

    try:
        site = named_rupture_site(value, Path("."), {}, "site")
    except SiteError as error:
        raise click.BadParameter(str(error).removeprefix("site.ruptures: "), param_hint=option) from None
    return site if site.name else dataclasses.replace(site, name=Path(value).stem)


def measure_free_answer(store: xr.Dataset, site: RuptureSite, runs: int, seed: int, targets: tuple[float, ...], years: float,
                        workers: int) -> StoreMeasureFree:
    """``stochpound.analysis.store_measure_free`` of the store at the site, its budget's error naming ``--ruptures-runs``."""
    from stochpound.analysis import store_measure_free

    try:
        return store_measure_free(store, site, runs=runs, seed=seed, targets=targets, years=years, workers=workers)
    except ValueError as error:
        message = str(error)
        raise click.BadParameter(message.removeprefix("runs: "), param_hint="--ruptures-runs") if message.startswith("runs:") else error from None


def measure_free_lines(answer: StoreMeasureFree, hazard: str) -> list[str]:
    """The answer without an intensity measure as ``stochpound risk`` prints it, saying whose site it is and its conditions."""
    return [
        f"\nWithout an intensity measure (docs/measure-free.md): at the site of ruptures {answer.site}; {answer.conditions()}. "
        f"The answers above are at the hazard's site ({hazard}); this one is at the ruptures' site, the same site only where that "
        "hazard is of these ruptures. Level of each demand at each target (m; its interval), from the same runs; the closure's is g*:",
        answer.display_frame().to_string(),
    ]
