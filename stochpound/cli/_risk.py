"""``stochpound risk``: the risk-targeted separation and the code rules in risk terms, from an experiment store."""

from __future__ import annotations

import contextlib
from pathlib import Path
from typing import TYPE_CHECKING

import click

from stochpound import StochpoundError
from stochpound._plurals import counted
from stochpound._atomic import check_not_input
from stochpound._errors import os_error_message
from stochpound._text_files import read_text_file
from stochpound.cli._site import measure_free_answer, measure_free_lines, rupture_site_option
from stochpound.cli._store_errors import store_variables
from stochpound.analysis import MEASURE_FREE_RUNS
from stochpound.risk import BOOTSTRAP, TARGETS
from stochpound.store import Design, TomlTable, VariableAttributes

if TYPE_CHECKING:
    import pandas as pd


def _targets(value: str) -> tuple[float, ...]:
    try:
        targets = tuple(float(item) for item in value.split(","))
    except ValueError:
        raise click.BadParameter(f"must be probabilities in (0, 1) separated by commas, e.g. 0.10,0.02; got {value!r}") from None
    if not targets or not all(0.0 < t < 1.0 for t in targets):
        raise click.BadParameter(f"must be probabilities in (0, 1) separated by commas, e.g. 0.10,0.02; got {value!r}")
    return targets


def _toml_table(path: Path, name: str, docs: str, beside: tuple[str, ...] = ()) -> TomlTable:
    """The TOML file's ``[name]`` table (the file's top level with that table only) and the tables ``beside`` it has, or a one-line error."""
    import tomllib

    try:
        table = tomllib.loads(read_text_file(path, click.ClickException))
    except tomllib.TOMLDecodeError as error:
        raise click.ClickException(f"{path}: not TOML: {error}") from None
    if name not in table:
        raise click.ClickException(f"{path}: has no [{name}] table ({docs})")
    return TomlTable({key: table[key] for key in (name, *beside) if key in table})


def objective_lines(objectives: pd.DataFrame | None) -> list[str]:
    """What governs each configuration against the limit states' objectives, in each treatment of the runs beyond the model, and
    whether the treatments agree (``stochpound.risk.objectives_frame``), as printed lines."""
    from stochpound.risk import disagreement_text

    if objectives is None:
        return ["note: no limit state has a performance objective (a target): none is said to govern (docs/risk.md)."]
    both = "governs, collapses apart" in objectives
    head = ("\nWhat governs, judged against each limit state's objective (λ/λ_target, λ_target = −ln(1 − p)/50 yr for its target p; "
            "the largest ratio above 1 governs" + (", as run and with the runs beyond the model counted apart as collapses" if both else "")
            + "):")
    lines = [head, objectives.to_string(float_format=lambda v: f"{v:.3g}")]
    agreement = disagreement_text(objectives)
    if agreement:
        lines.append(("warning: " if "disagree" in agreement else "note: ") + agreement)
    return lines


def _limit_states(path: Path) -> tuple:
    """The limit states of a TOML file's ``[limit_states]`` table (``stochpound.risk.limit_states_from_table``)."""
    from stochpound.risk import limit_states_from_table

    return limit_states_from_table(_toml_table(path, "limit_states", "docs/risk.md").raw("limit_states"))


def _design(path: Path) -> Design | None:
    """The buildings' code design of a TOML file's ``[design]`` table (the experiment file's table, docs/experiments.md; its
    ``[hazard]``, if any, gives a sliding building's chapter 17 spectrum)."""
    from stochpound.experiment import parse_design

    return parse_design(_toml_table(path, "design", "docs/experiments.md", beside=("hazard",)))


def _check_csv(csv_dir: Path, inputs: list[tuple[str | Path, str]]) -> None:
    """Refuse a --csv folder where a table's file would replace an input of the command."""
    try:
        for name in CSV_TABLES:
            check_not_input(csv_dir / f"{name}.csv", [(path, what) for path, what in inputs if path], "--csv")
    except ValueError as error:
        raise click.BadParameter(str(error), param_hint="--csv") from None


def sensitivity_stores(values: tuple[str, ...], option: str = "--sensitivity-store") -> list[tuple[str, Path]]:
    """The ``KIND=PATH`` values of ``option``: (kind, path) each, KIND one of ``stochpound.risk.ALTERNATIVES``, PATH an existing file."""
    from stochpound.risk import ALTERNATIVES

    pairs = []
    for value in values:
        kind, _, path = value.partition("=")
        if kind not in ALTERNATIVES or not path:
            raise click.BadParameter(f"must be KIND=PATH with KIND one of {', '.join(ALTERNATIVES)}, got {value!r}", param_hint=option)
        if not Path(path).is_file():
            raise click.BadParameter(f"{kind}: no store file at {path}", param_hint=option)
        pairs.append((kind, Path(path)))
    return pairs


SENSITIVITY_HELP = ("Another store of the same experiment that differs only in one choice, for the sensitivity table of g*: KIND is "
                    "seed (the [intensity] seed), measure (the conditioning measure: its levels, scenarios and [hazard] follow) or wall "
                    "(the moat walls' stiffness); refused where it differs in anything else. Repeat for several (docs/risk.md).")
"""The help of ``--sensitivity-store`` (``stochpound risk`` and ``stochpound report build``)."""


CSV_TABLES = ("separation", "rules", "limit_states")
"""The tables ``--csv`` writes (one file each)."""


@click.command("risk")
@click.argument("store", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option("--hazard", "hazard", metavar="FILE|NAME",
              help="The site's hazard curve: a file (stochpound's CSV, OpenQuake's hazard-curve CSV or nshmp-haz's curve output; "
                   "docs/risk.md) or a bundled curve's name. Default: the hazard the store carries (its experiment's [hazard]).")
@click.option("--hazard-measure", "hazard_measure", metavar="TEXT",
              help="What the --hazard file's curve is of, when the file does not say, e.g. 'PSA(1.0 s, 5 %) in g' or 'PGA in m/s2'.")
@click.option("--hazard-units", "hazard_units", metavar="UNITS", help="Units of the --hazard file's intensities (g, m/s2, cm/s2, m/s, cm/s).")
@click.option("--investigation-time", "investigation_time", type=click.FloatRange(min=0.0, min_open=True), metavar="YEARS",
              help="Years of a --hazard file of probabilities of exceedance (a 'poe' column, in [0, 1]: per cent is refused), converted to annual rates.")
@click.option("--hazard-site", "hazard_site", metavar="ROW|NAME", help="The site of a --hazard file of several (its row, 0-based, or name).")
@click.option("--extrapolate", is_flag=True, help="Extend the hazard table beyond its intensities as power laws (stated in the output).")
@click.option("--target", "target", default=",".join(f"{t:g}" for t in TARGETS), show_default=True,
              help="Target probabilities of pounding in --years, separated by commas.")
@click.option("--years", default=50.0, show_default=True, type=click.FloatRange(min=0.0, min_open=True), help="Exposure time (years).")
@click.option("--bootstrap", default=BOOTSTRAP, show_default=True, type=click.IntRange(min=0),
              help="Resamples of the motions for the intervals (0: none).")
@click.option("--seed", default=0, show_default=True, type=click.IntRange(min=0), help="Seed of the resamples.")
@click.option("--limit-states", "limit_states", type=click.Path(exists=True, dir_okay=False, path_type=Path), metavar="FILE",
              help="A TOML file with a [limit_states] table (docs/risk.md): also print each limit state's mean annual frequency "
                   "at the grid's finite gaps against the contact-free twins (what the gap costs).")
@click.option("--design", "design", type=click.Path(exists=True, dir_okay=False, path_type=Path), metavar="FILE",
              help="A TOML file with a [design] table (docs/experiments.md) that replaces the store's: the buildings' code design "
                   "whose design analysis gives the codes' own gaps.")
@click.option("--partial", is_flag=True,
              help="Answer from the cases that ran of a store with missing cases (its header says how many ran); without it such a "
                   "store is refused.")
@click.option("--accept-edited", "accept_edited", is_flag=True,
              help="Answer for a store whose definition does not match its recorded sha256 (changed since it was written); refused otherwise.")
@click.option("--csv", "csv_dir", type=click.Path(file_okay=False, path_type=Path), metavar="DIR",
              help="Also write the tables to this folder (created), one CSV file per table: separation.csv, rules.csv "
                   "(and limit_states.csv, objectives.csv with --limit-states).")
@click.option("--ruptures", "ruptures", metavar="FILE|NAME", help="Also print the answer without an intensity measure at this site of "
              "ruptures (a rupture table or a bundled site's name, e.g. demo_three_sources; docs/measure-free.md): every configuration "
              "run under simulated motions of each rupture, seeded by --seed.")
@click.option("--ruptures-runs", "ruptures_runs", default=MEASURE_FREE_RUNS, show_default=True, type=click.IntRange(min=2),
              help="Runs a configuration of --ruptures (half of them two or more of each rupture, the rest where g* needs them).")
@click.option("--workers", default=1, show_default=True, type=click.IntRange(min=1), help="Processes running --ruptures (the answer does not depend on them).")
@click.option("--sensitivity-store", "sensitivity", multiple=True, metavar="KIND=PATH", help=SENSITIVITY_HELP)
def risk(store: Path, hazard: str | None, hazard_measure: str | None, hazard_units: str | None, investigation_time: float | None,
         hazard_site: str | None, extrapolate: bool, target: str, years: float, bootstrap: int, seed: int, limit_states: Path | None,
         design: Path | None, partial: bool, accept_edited: bool, csv_dir: Path | None, ruptures: str | None, ruptures_runs: int,
         workers: int, sensitivity: tuple[str, ...]) -> None:
    """Print the risk-targeted separation g* and the code rules' risks of the experiment STORE at a site.

    For every configuration of the store (each combination of its grid's
    axes other than the gap): g* for each target probability in --years,
    with its 95 % bootstrap interval over the motions, then each code rule
    (ABS, SRSS, 0.7 SRSS, DDC, and the suite-mean peak base displacement,
    ASCE 7's D_M form, for a sliding studied building)
    at the hazard's 2 %/50 yr and 10 %/50 yr intensities: its gap and
    the mean annual frequency of pounding there, as a return period and
    a probability in --years. The store needs intensity stripes (with
    contact-free cases, gap = inf) or IDA capacities (docs/risk.md).
    A hazard file must say (or the options state) its measure and units;
    they are checked against the store's and converted (docs/risk.md).
    With --limit-states, the limit states beyond first contact (storey
    drift ratio, ductility, floor acceleration, impact force, a bearing's
    stop) at each finite gap against the contact-free twins.
    With --ruptures, beside g*: the answer without an intensity measure at
    that site of ruptures (docs/measure-free.md), each configuration's
    contact-free scene run under simulated motions of each rupture, its
    closure (g*), base displacements and storey drifts at the targets.

    A target rarer than the stripes reach (its rate below the hazard's at
    the top stripe, or g* wider than every gap the top stripe's runs close)
    gets g* as a lower bound, "≥ x", with no interval and no gap to design
    to, and a note saying which stripes to add. A store with missing cases
    is refused unless --partial; --bootstrap is refused beyond the memory
    limit (STOCHPOUND_MEMORY_LIMIT, default half the machine's memory).

    For stripes, the sensitivity table of g*: g* under each choice it rests
    on, each alone (the gap grid refined once more near g*, the runs beyond
    the model counted apart, modelling dispersion, and with
    --sensitivity-store the selection seed, the conditioning measure or the
    moat wall's stiffness from another store), with its change from g*.
    """
    from stochpound.cli._measure_choice import efficient_measure_lines
    from stochpound.experiment import open_store
    from stochpound.motions import TARGET_TOLERANCE, TRUNCATION_EPSILON
    from stochpound.risk import (MODEL_DRIFT_LIMIT, check_alternative, collapse_risk, gap_cost_frame, limit_state_risk,
                                 objectives_frame, read_risk_inputs, separation_sensitivity, site_hazard, store_risk)

    targets = _targets(target)
    others = sensitivity_stores(sensitivity)
    site = None if ruptures is None else rupture_site_option(ruptures, "--ruptures")
    if hazard is None and (hazard_measure or hazard_units or investigation_time is not None or hazard_site is not None):
        raise click.UsageError("--hazard-measure, --hazard-units, --investigation-time and --hazard-site describe a --hazard file: give one")
    if csv_dir is not None:
        _check_csv(csv_dir, [(store, "the store"), (hazard or "", "the --hazard file"), (limit_states or "", "the --limit-states file"),
                             (design or "", "the --design file")])
    try:
        with store_variables([store]), contextlib.ExitStack() as opened:  # every store closed once the answer is read
            data = opened.enter_context(open_store(store, edited="accept" if accept_edited else "refuse"))
            alternatives = [(kind, opened.enter_context(open_store(path, edited="accept" if accept_edited else "refuse"))) for kind, path in others]
            for kind, other in alternatives:  # refused before any work
                check_alternative(data, other, kind)
            hz = site_hazard(data, hazard, measure=hazard_measure, units=hazard_units, investigation_time=investigation_time,
                             site=hazard_site, extrapolate=extrapolate)
            inputs = read_risk_inputs(data, hz, design=None if design is None else _design(design), partial=partial)  # the chain's one read
            result = store_risk(inputs, targets=targets, years=years, bootstrap=bootstrap, seed=seed)
            states = None if limit_states is None else limit_state_risk(data, _limit_states(limit_states), hz)
            costs = None if states is None else gap_cost_frame(states, years)
            objectives = None if states is None else objectives_frame(states)
            collapse = None if result.method != "stripes" else collapse_risk(data, hz, result.fragility["gap"].values, targets, years)
            if others and result.method != "stripes":
                raise click.BadParameter("the sensitivity table is of stripes; the store holds IDA capacities", param_hint="--sensitivity-store")
            spread = None if result.method != "stripes" else separation_sensitivity(result, data, collapse, alternatives=alternatives)
            missed, unreachable, beyond = inputs.selection_misses, inputs.unreachable_targets, inputs.beyond_truncation  # every read of the
            # store before the first answer
            measure_lines = efficient_measure_lines(data, hazard)
            free = None if site is None else measure_free_answer(data, site, ruptures_runs, seed, targets, years, workers)
    except (StochpoundError, ValueError) as error:
        raise click.ClickException(str(error)) from None
    except OSError as error:
        raise click.ClickException(os_error_message(error)) from None
    stripes = f"{result.stripes} stripes" if result.stripes is not None else "IDA capacities"
    source = hz.source.splitlines()[0] if hz.source else hz.describe()
    done = f"{result.progress}, answered from the cases that ran (--partial); " if result.progress else ""
    click.echo(f"{result.experiment or store.stem}: {done}{counted(result.motions, 'motion')}, {stripes} of {result.measure} "
               f"in {result.setting.units}; hazard: {source}")
    if missed:
        click.echo(f"warning: the motions chosen for the site miss their conditional-spectrum target (mean or std of ln Sa off by more than "
                   f"{TARGET_TOLERANCE:g} at a period) at the stripes {', '.join(f'{level:g}' for level in missed)} {result.setting.units}")
    if unreachable:
        click.echo(f"warning: at the stripes {', '.join(f'{level:g}' for level in unreachable)} {result.setting.units} no set of the pool's "
                   f"motions can meet the target within {TARGET_TOLERANCE:g} (linear-programming bounds under the selection's rules): the "
                   "pool lacks the target's spectral shape there (more or tilted simulated motions may supply it)")
    if beyond:
        click.echo(f"warning: the scenario puts the stripes {', '.join(f'{level:g}' for level in beyond)} {result.setting.units} beyond "
                   f"ε {TRUNCATION_EPSILON:g}, where hazard models truncate the ground motion: no earthquake of that scenario causes them there")
    for line in hz.source.splitlines():
        if line.startswith("stochpound: "):
            click.echo(f"note: hazard {line.removeprefix('stochpound: ')}")
    if hz.extrapolated:
        click.echo(f"note: the hazard table [{hz.im[0]:g}, {hz.im[-1]:g}] {hz.units} was extrapolated beyond its intensities as power laws (--extrapolate)")
    interval = f"95 % interval, {VariableAttributes.of(result.separation['lower'], method='BCa bootstrap').method}" if "lower" in result.separation else (
        "no interval: not estimable" if result.no_interval else "no bootstrap")
    separation = result.separation_frame()
    click.echo(f"\nRisk-targeted separation g* (m; {interval}; inf: wider than every gap of the grid; ≥: a lower bound, the target "
               "beyond the stripes' runs):")
    click.echo(separation.to_string(float_format=lambda v: f"{v:.3f}"))
    if result.no_interval:
        click.echo(f"note: no interval is estimable for g*, the rates or the code rules: {result.no_interval}.")
    if free is not None:
        click.echo("\n".join(measure_free_lines(free, source)))
    design = result.design_frame()
    given = design["design"].notna()
    if not given.any():
        basis = "none: every g* is a lower bound"
    elif "upper" in result.separation:
        basis = (f"the {design.loc[given, 'basis'].iloc[0]}, not g* itself: it bounds the record-to-record sampling of the motions "
                 "only, none of the choices of the sensitivity table below")
    else:
        basis = design.loc[given, "basis"].iloc[0]
    click.echo(f"\nDesign to (m; {basis}):")
    click.echo(design.assign(design=[f"{v:.3f}" if ok else b for v, ok, b in zip(design["design"], given, design["basis"])])
               .drop(columns="basis").assign(target=[result.target_text(p) for p in design["target"]]).to_string(index=False))
    beyond = result.beyond_stripes_text()
    if beyond:
        click.echo(f"warning: {beyond}")
    if collapse is not None and collapse.collapsed:
        click.echo(f"\n{collapse.text(years)}\ng* both ways (m):")
        click.echo(collapse.both_ways(result.separation, years).to_string(float_format=lambda v: f"{v:.4g}"))
    elif collapse is not None:
        click.echo(f"note: no contact-free run passes a {100 * MODEL_DRIFT_LIMIT:g} % storey drift: every run is within what the model "
                   "represents, and g* needs no collapse treatment.")
    if spread is not None:
        click.echo(f"\n{spread.text()}\nSensitivity of g* (m; Δ: % from g*):")
        click.echo(spread.frame.to_string(float_format=lambda v: f"{v:.3f}"))
        seeds = spread.seeds_beside_design(design, years)
        if not seeds.empty:
            click.echo(f"\nThe {spread.seeds} selection seeds' largest g* beside the gap to design to (m): above it in {int(seeds['above'].sum())} "
                       f"of {counted(len(seeds), 'row')} (the gap to design to does not bound which motions are chosen):")
            click.echo(seeds.to_string(float_format=lambda v: f"{v:.3f}"))
    degenerate = result.degenerate_text()
    if degenerate:
        click.echo(f"note: {degenerate}")
    rules = result.rules_frame()
    if result.rules is None:
        click.echo(f"\nCode rules: suite-mean rules not evaluated: {result.rules_note}.")
    if not rules.empty:
        click.echo(f"\nCode rules in risk terms, the suite-mean rows applied to the suite-mean peaks of the code intensity's stripe (λ_P: pounding "
                   f"per year at that gap; 'once in N years'; P in {years:g} years; each with its interval; fit: lognormal, a degenerate step "
                   f"or flat):")
        click.echo(rules.to_string(float_format=lambda v: f"{v:.4g}"))
    if result.dtm_text():
        click.echo(f"note: {result.dtm_text()}")
    click.echo(result.design_rules_text())
    if costs is not None and costs.empty:
        click.echo("\nLimit states beyond first contact: none to give: the store's grid has no finite gap (only its contact-free "
                   "runs, gap = inf), and a limit state's cost is taken at a finite gap against its contact-free twin.")
    elif costs is not None:
        click.echo(f"\nLimit states beyond first contact (λ: per year at each finite gap; contact-free: the same motions without "
                   f"contact; Δλ: what the gap costs; P in {years:g} years; fit: the fragility's kind; where it is not a lognormal the "
                   "runs identify, λ is the fit's extrapolation and λ⁻, λ⁺ are the bounds the stripes' fractions alone give it):")
        click.echo(costs.to_string(float_format=lambda v: f"{v:.4g}"))
        click.echo("\n".join(objective_lines(objectives)))
    click.echo("\n".join(measure_lines))
    if csv_dir is not None:
        tables = {"separation": result.to_frame()}
        if not rules.empty:
            tables["rules"] = rules.reset_index()
        if costs is not None:
            tables["limit_states"] = costs.reset_index()
        if objectives is not None:
            tables["objectives"] = objectives.reset_index()
        try:
            csv_dir.mkdir(parents=True, exist_ok=True)
            for name, frame in tables.items():
                frame.to_csv(csv_dir / f"{name}.csv", index=False)
        except OSError as error:
            raise click.ClickException(os_error_message(error)) from None
        click.echo(f"\ntables: {', '.join(str(csv_dir / f'{name}.csv') for name in tables)}")

