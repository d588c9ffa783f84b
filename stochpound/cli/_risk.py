"""``stochpound risk``: the risk-targeted separation and the code rules in risk terms, from an experiment store."""

from __future__ import annotations

from pathlib import Path

import click
import pandas as pd

from stochpound.analysis._fragility_ensemble import BOOTSTRAP
from stochpound.analysis._risk import TARGETS
from stochpound._errors import StochpoundError, os_error_message


def _targets(value: str) -> tuple[float, ...]:
    try:
        targets = tuple(float(item) for item in value.split(","))
    except ValueError:
        raise click.BadParameter(f"must be probabilities in (0, 1) separated by commas, e.g. 0.10,0.02; got {value!r}") from None
    if not targets or not all(0.0 < t < 1.0 for t in targets):
        raise click.BadParameter(f"must be probabilities in (0, 1) separated by commas, e.g. 0.10,0.02; got {value!r}")
    return targets


@click.command("risk")
@click.argument("store", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option("--hazard", "hazard", metavar="FILE|NAME",
              help="The site's hazard curve: a CSV of rows 'im, rate' (in the store's intensity measure and the units of its levels) "
                   "or a bundled curve's name. Default: the hazard the store carries (its experiment's [hazard]).")
@click.option("--target", "target", default=",".join(f"{t:g}" for t in TARGETS), show_default=True,
              help="Target probabilities of pounding in --years, separated by commas.")
@click.option("--years", default=50.0, show_default=True, type=click.FloatRange(min=0.0, min_open=True), help="Exposure time (years).")
@click.option("--bootstrap", default=BOOTSTRAP, show_default=True, type=click.IntRange(min=0),
              help="Resamples of the motions for the intervals (0: none).")
@click.option("--seed", default=0, show_default=True, type=click.IntRange(min=0), help="Seed of the resamples.")
@click.option("--csv", "csv_path", type=click.Path(dir_okay=False, path_type=Path), help="Also write both tables to this CSV file.")
def risk(store: Path, hazard: str | None, target: str, years: float, bootstrap: int, seed: int, csv_path: Path | None) -> None:
    """Print the risk-targeted separation g* and the code rules' risks of the experiment STORE at a site.

    For every configuration of the store (each combination of its grid's
    axes other than the gap): g* for each target probability in --years,
    with its 95 % bootstrap interval over the motions, then each code rule
    (ABS, SRSS, 0.7 SRSS, DDC, and D_TM for a sliding studied building)
    at the hazard's 2 %/50 yr and 10 %/50 yr intensities: its gap and
    the mean annual frequency of pounding there, as a return period and
    a probability in --years. The store needs intensity stripes (with
    contact-free cases, gap = inf) or IDA capacities (docs/risk.md).
    """
    from stochpound.analysis._store_risk import store_risk
    from stochpound.cli._measure_choice import efficient_measure_lines
    from stochpound.experiment import open_store
    from stochpound.experiment._hazard import hazard_option, stored_hazard
    from stochpound.experiment._intensity import describe_measure
    from stochpound.report.sections._intensity import intensity_setting
    from stochpound.report.sections._risk import risk_headline, rules_frame, separation_frame

    targets = _targets(target)
    try:
        data = open_store(store)
        setting = intensity_setting(data)
        if setting is None:
            raise click.ClickException("store: has no intensity stripes or IDA capacities (run an experiment with an [intensity] table)")
        hz = hazard_option(hazard, setting) if hazard is not None else stored_hazard(data)
        if hz is None:
            raise click.ClickException("--hazard: the store carries no hazard (its experiment has no [hazard] table): give a hazard file or a bundled curve's name")
        result = store_risk(data, hz, targets, years, studied=data.attrs.get("studied_building"), bootstrap=bootstrap, seed=seed)
    except (StochpoundError, ValueError) as error:
        raise click.ClickException(str(error)) from None
    except OSError as error:
        raise click.ClickException(os_error_message(error)) from None
    stripes = f"{data.sizes['intensity']} stripes" if "intensity" in data.dims else "IDA capacities"
    source = hz.source.splitlines()[0] if hz.source else repr(hz)
    click.echo(f"{data.attrs.get('experiment_name', store.stem)}: {result.motions} motions, {stripes} of {describe_measure(setting)} "
               f"in {setting['units']}; hazard: {source}")
    interval = "95 % BCa bootstrap interval over the motions" if bootstrap else "no bootstrap"
    separation = separation_frame(result)
    click.echo(f"\nRisk-targeted separation g* (m; {interval}; inf: wider than every gap of the grid):")
    click.echo(separation.to_string(float_format=lambda v: f"{v:.3f}"))
    rules = rules_frame(result)
    if result.rules is None:
        click.echo(f"\nCode rules: not evaluated: {result.rules_note}.")
    else:
        click.echo(f"\nCode rules in risk terms (gap at the code intensity's stripe; λ_P: pounding per year at that gap; "
                   f"'once in N years'; P in {years:g} years):")
        click.echo(rules.to_string(float_format=lambda v: f"{v:.4g}"))
    click.echo("\n".join(efficient_measure_lines(data, hazard)))
    if csv_path is not None:
        frames = [risk_headline(result).assign(table="separation")]
        if not rules.empty:
            frames.append(rules.reset_index().assign(table="rules"))
        try:
            pd.concat(frames, ignore_index=True).to_csv(csv_path, index=False)
        except OSError as error:
            raise click.ClickException(os_error_message(error)) from None
        click.echo(f"\ntables: {csv_path}")
