"""g* by conditioning measure at the bundled Fox Plaza site, or at a site of one scenario: ``python -m benchmarks.site_consistency``.

The same buildings at the same site, stripes of motions chosen to the
conditional spectrum (``selection = "conditional_spectrum"``, 20 motions
per stripe from the 100 FEMA P695 motions, scale factor <= 5, the scenario
fitted to the site's four curves: ``[site] scenario = "fitted"``), at the
intensities of return periods 10-5000 years of each conditioning measure
(the frequent shaking included: a measure far from the structure's periods
sees pounding at 10 % in 50 years come partly from it); the risk-targeted
separation g* at 10 % and 2 % in 50 years. Two
configurations of the elastic buildings issue 36 measured the scaled suite
with (experiments/risk before its buildings were code-designed): the fixed
pair (the reference study's Building 1 beside its neighbour with masses
x 0.5, stiff, or x 2, flexible) and Building 1 on a friction pendulum
(R 2.24 m, mu 0.05, no moat wall, stiff neighbour).

It prints g* as the risk chain computes it (``stochpound.risk.store_risk``:
a lognormal fragility fitted to the counts at every gap), g* from a
lognormal demand per stripe (:func:`stochpound.risk.stripe_demand_rate`:
every run's closure enters, not only whether it reaches a gap) and what
each g* rests on, and draws both in ``docs/figures/site_consistency.png``
(g* against the conditioning measure); ``--seeds`` repeats both with other
seeds of the selection, ``--return-periods`` moves the stripes.
``--motions 40 --simulated-motions 1000 --max-per-earthquake 3`` runs 40
motions a stripe from the records and 1000 site-based stochastic motions of
each stripe's scenario (``[site] simulated_motions``), at most 3 of an
earthquake (docs/intensity.md, "the pool extended by simulated motions").
At Fox Plaza the measures are PGA, PSA(1 s), PSA(2 s), PSA(3 s) and PSA at
Building 1's own period on a fixed base, PSA(T1 = 0.3 s) (its scenario
fitted to the four curves and its own; its curve stops at 3431 years, its
top stripe there) and the average spectral acceleration over 0.5-4 s,
``Sa_avg(0.5-4 s)``, whose curve is DERIVED, not published: the hazard of
the ruptures fitted to the site's 17 curves (:func:`fox_plaza_sa_avg`),
written beside the experiment and given to ``[site] curves`` as a file.

``--site scenario`` runs the same at a site shaken by one earthquake
scenario (``--scenario M R mechanism rate``, default M 7.5 at 10 km,
strike-slip, 0.01 per year; Vs30 400 m/s), its four curves from the same
models as the conditional spectra (:func:`stochpound.analysis.scenario_hazard`)
and that scenario given at every level (``[site] scenario = "given"``):
hazard-consistent by construction, so the measures must agree there up to
what the pool and the stripes cannot carry (docs/intensity.md, finding 8).
That site has a curve of any measure, so it adds the average spectral
acceleration over 0.5-4 s (``Sa_avg(0.5-4 s)``), the band the isolated
building's closure follows; the figure is then
``docs/figures/site_consistency_scenario.png``. About 6
minutes per configuration on 2 cores for the four measures (3 times that
with two more seeds); ``--measures PGA "PSA(1 s)"`` runs fewer. tests/test_benchmark_site_consistency.py
runs the reduced check with the same experiments.
"""

from __future__ import annotations

import argparse
import tempfile
from collections.abc import Callable
from dataclasses import dataclass, replace
from functools import lru_cache, partial
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd
import xarray as xr

from benchmarks.timing import REPOSITORY

if TYPE_CHECKING:
    from stochpound.analysis import HazardCurve, RuptureSite
    from stochpound.risk import StoreRisk

RETURN_PERIODS = np.array([10.0, 25.0, 72.0, 224.0, 475.0, 975.0, 2475.0, 5000.0])
CURVES = ["fox_plaza_los_angeles_pga", "fox_plaza_los_angeles_sa1p0s", "fox_plaza_los_angeles_sa2p0s", "fox_plaza_los_angeles_sa3p0s"]
#: PSA at Building 1's first-mode period on a fixed base (0.30 s), the measure of the building's own period: Fox Plaza's curve of it.
T1_MEASURE, T1_CURVE = "PSA(T1 = 0.3 s)", "fox_plaza_los_angeles_sa0p3s"
#: Fox Plaza's measures, each with its bundled hazard curve (the scenario of each is fitted to :data:`CURVES` and its own).
MEASURES = {**dict(zip(("PGA", "PSA(1 s)", "PSA(2 s)", "PSA(3 s)"), CURVES)), T1_MEASURE: T1_CURVE}
#: The periods (s) of the average spectral acceleration the site of one scenario adds to the measures: the band the isolated
#: building's closure follows (docs/intensity.md, finding 8).
SA_AVG_PERIODS = (0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5, 4.0)
SA_AVG = "Sa_avg(0.5-4 s)"
#: Every measure as stochpound's measure and period (s): Fox Plaza's five, and Sa_avg (at Fox Plaza on a derived curve).
MEASURE_ARGS: dict[str, tuple[str, float | tuple[float, ...] | None]] = {
    "PGA": ("pga", None), "PSA(1 s)": ("psa", 1.0), "PSA(2 s)": ("psa", 2.0), "PSA(3 s)": ("psa", 3.0), T1_MEASURE: ("psa", 0.3),
    SA_AVG: ("sa_avg", SA_AVG_PERIODS)}
CONFIGURATIONS = {  # name: (B1's base, an edit of the bundled pair; the neighbour's variants)
    "fixed pair": ("", "[variants.neighbour.stiff.building.B2]\nmass_factor = 0.5\n[variants.neighbour.flexible.building.B2]\nmass_factor = 2.0"),
    "isolated": ("[scene.building.B1]\nbase = { mass = 13134.0, mu = 0.05, radius = 2.24 }", "[variants.neighbour.stiff.building.B2]\nmass_factor = 0.5"),
}
PAIR = """
[scene]
bundled = "elastic_pair"
{base}
{variants}
[grid]
gap = [inf]
[[records]]
suite = "fema_p695_far_field"
[[records]]
suite = "fema_p695_near_field"
"""
FIGURES = {"fox_plaza": REPOSITORY / "docs" / "figures" / "site_consistency.png",
           "scenario": REPOSITORY / "docs" / "figures" / "site_consistency_scenario.png"}
#: The default scenario of ``--site scenario``: magnitude, rupture distance (km), mechanism, annual rate (1/yr).
SCENARIO = (7.5, 10.0, "strike_slip", 0.01)


@dataclass(frozen=True)
class Pool:
    """The stripes' motions: ``motions`` a stripe, ``simulated`` site-based stochastic motions of each stripe's scenario added to the
    100 records (``[site] simulated_motions``; 0: none), drawn by ``sampling`` (``[site] simulated_sampling``: "scenario", or "tilted"
    to each stripe's level), at most ``max_per_earthquake`` of an earthquake a stripe (None: no limit)."""

    motions: int = 20
    simulated: int = 0
    max_per_earthquake: int | None = None
    sampling: str = "scenario"

    def intensity_lines(self) -> str:
        """The pool's lines of the ``[intensity]`` table."""
        return f"motions = {self.motions}\n" + ("" if self.max_per_earthquake is None else f"max_per_earthquake = {self.max_per_earthquake}\n")

    def site_lines(self) -> str:
        """The pool's lines of the ``[site]`` table."""
        if not self.simulated:
            return ""
        return f"simulated_motions = {self.simulated}\n" + ("" if self.sampling == "scenario" else f'simulated_sampling = "{self.sampling}"\n')


#: The records alone, 20 motions a stripe (the pool of docs/intensity.md's first tables).
RECORDS_ONLY = Pool()


@dataclass(frozen=True)
class Site:
    """Where the stripes are: each measure's hazard curve, the experiment's ``[site]`` table, the default stripes' return periods (yr),
    the measures it has a hazard curve of, and its ruptures where it has them (a site of one scenario: the answer without a measure)."""

    name: str
    hazard: Callable[[str], HazardCurve]
    table: str
    return_periods: np.ndarray
    measures: tuple[str, ...]
    ruptures: RuptureSite | None = None
    derived: tuple[str, ...] = ()
    """The measures whose curve is not the site's own but derived; a fitted scenario reads it from a file beside the experiment
    (:func:`derived_curve_file`)."""
    files: tuple[tuple[str, str], ...] = ()
    """Files the ``table`` names, as (name, text), written beside every experiment (a site of ruptures' rupture table)."""

    def derived_curve_file(self, measure: str) -> str:
        """The file name of the derived curve of ``measure``, beside the experiment."""
        return f"{self.name}_{experiment_file(Path('.'), measure).stem}.csv"

    def companion_files(self, measure: str) -> dict[str, str]:
        """The files an experiment of ``measure`` at the site reads beside it, by name: :attr:`files` and a derived curve's."""
        files = dict(self.files)
        if measure in self.derived:
            files[self.derived_curve_file(measure)] = self.hazard(measure).to_csv()
        return files


@lru_cache(maxsize=4)
def fox_plaza_ruptures(vs30: float) -> tuple[np.ndarray, RuptureSite]:
    """Fox Plaza's stand-in ruptures at ``vs30`` (m/s): :func:`benchmarks.site_condition.fit_ruptures` on its 17 curves within the
    site-motion model's range, and ln(recomputed / site) at every fitted point of the curves."""
    from benchmarks.site_condition import fit_ruptures, site_curves

    error, _, ruptures = fit_ruptures(vs30, site_curves(), name=f"fox_plaza_fitted_vs30_{vs30:g}")
    return error, ruptures


@lru_cache(maxsize=4)
def fox_plaza_sa_avg(vs30: float) -> HazardCurve:
    """Fox Plaza's hazard of :data:`SA_AVG`, DERIVED: no curve of it is published for the site, so it is the curve of the ruptures
    fitted to the site's 17 curves at ``vs30`` (m/s; :func:`fox_plaza_ruptures`, the stand-in whose answer without a measure referees
    the measures), with that provenance."""
    error, ruptures = fox_plaza_ruptures(vs30)
    curve = ruptures.hazard_curve(*MEASURE_ARGS[SA_AVG])
    curve.source = (f"Fox Plaza (Los Angeles), {SA_AVG} in g, DERIVED: the hazard of the {len(ruptures)} ruptures whose NGA-West2 curves "
                    f"give back the site's 17 bundled curves at Vs30 {vs30:g} m/s (rms {np.sqrt(np.mean(error ** 2)):.2f} in ln rate; "
                    "python -m benchmarks.site_condition's fit_ruptures), not a published curve")
    return curve


def _fox_plaza_hazard(vs30: float, measure: str) -> HazardCurve:
    """Fox Plaza's curve of ``measure``: bundled, or for :data:`SA_AVG` derived at ``vs30`` (:func:`fox_plaza_sa_avg`)."""
    from stochpound.analysis import HazardCurve

    return fox_plaza_sa_avg(vs30) if measure == SA_AVG else HazardCurve.bundled(MEASURES[measure])


#: The bundled Fox Plaza site, the scenario fitted to its four curves (Vs30 and mechanism assumed: the curves state neither);
#: PSA(T1)'s to them and its own; Sa_avg's to them and its derived curve (:func:`fox_plaza_sa_avg`), written beside the experiment.
FOX_PLAZA = Site("fox_plaza", partial(_fox_plaza_hazard, 400.0), '[site]\nscenario = "fitted"\ncurves = [' + ", ".join(f'"{name}"' for name in CURVES) +
                 ']\nvs30 = 400.0\nmechanism = "reverse"\n', RETURN_PERIODS, (*MEASURES, SA_AVG), derived=(SA_AVG,))


def fox_plaza_ruptures_site(vs30: float = 400.0) -> Site:
    """Fox Plaza's stand-in ruptures at ``vs30`` (m/s; :func:`fox_plaza_ruptures`) as a site of ruptures: every measure's curve is
    theirs, the stripes' targets their exact conditional spectra (``[site] ruptures``, the table written beside the experiment),
    the pool's simulated motions their causal ruptures', and the answer without a measure the same ruptures'. What is left of the
    measures' parting there is the chain's, not the fitted scenario's."""
    _, ruptures = fox_plaza_ruptures(float(vs30))
    name = f"{ruptures.name}.csv"

    def hazard(measure: str) -> HazardCurve:
        kind, period = MEASURE_ARGS[measure]
        return ruptures.hazard_curve(kind, period)

    return Site(f"fox_plaza_ruptures_vs30_{vs30:g}", hazard, f'[site]\nruptures = "{name}"\n', RETURN_PERIODS, tuple(MEASURE_ARGS), ruptures,
                files=((name, ruptures.to_csv()),))


def fox_plaza_site(vs30: float = 400.0) -> Site:
    """:data:`FOX_PLAZA` with another assumed Vs30 (m/s): its scenarios fitted at that Vs30 (benchmarks.site_condition: the curves imply
    a softer site than 400 m/s), its derived Sa_avg curve too. :data:`FOX_PLAZA` itself at 400."""
    if vs30 == 400.0:
        return FOX_PLAZA
    return replace(FOX_PLAZA, name=f"fox_plaza_vs30_{vs30:g}", hazard=partial(_fox_plaza_hazard, float(vs30)),
                   table=FOX_PLAZA.table.replace("vs30 = 400.0", f"vs30 = {float(vs30)}"))


def scenario_site(magnitude: float, distance_km: float, mechanism: str, rate: float, vs30: float = 400.0) -> Site:
    """A site shaken by one scenario recurring at ``rate`` (1/yr): its curves from the conditional spectrum's models, the scenario given
    at every level. Default stripes: 1.5 / rate years (the scenario's median shaking, ε about −0.4), the return periods of
    :data:`RETURN_PERIODS` beyond it, and 10 000 years. Its measures: Fox Plaza's four and :data:`SA_AVG`."""
    from stochpound.analysis import RuptureSite, scenario_hazard
    from stochpound.motions import given_scenario

    scenario = given_scenario(None, magnitude, distance_km, vs30, mechanism)  # checked (SiteError naming the field), its geometry estimated once

    def hazard(measure: str) -> HazardCurve:
        kind, period = MEASURE_ARGS[measure]
        return scenario_hazard(kind, period, scenario=scenario, rate=rate)

    hazard(next(iter(MEASURE_ARGS)))  # the rate checked (ValueError naming it) before it is used
    table = f'[site]\nmagnitude = {magnitude}\ndistance_km = {distance_km}\nvs30 = {vs30}\nmechanism = "{mechanism}"\n'
    lowest = 1.5 / rate
    ruptures = RuptureSite.from_scenarios([(scenario, rate)], name="scenario")  # the same scenario as the curves': the answer without a measure
    return Site("scenario", hazard, table, np.unique(np.r_[lowest, RETURN_PERIODS[RETURN_PERIODS > lowest], 10000.0]), tuple(MEASURE_ARGS),
                ruptures)


def _intensity_lines(measure: str) -> str:
    """The measure's lines of an experiment's ``[intensity]`` table."""
    kind, period = MEASURE_ARGS[measure]
    if kind == "pga":
        return 'measure = "pga"'
    if kind == "psa":
        return f'measure = "psa"\nperiod = {period}'
    return f'measure = "sa_avg"\nperiods = [{", ".join(f"{t:g}" for t in period)}]'


def experiment_text(measure: str, configuration: str, seed: int | None = None, return_periods: np.ndarray | None = None,
                    site: Site = FOX_PLAZA, pool: Pool = RECORDS_ONLY) -> str:
    """The experiment file of one conditioning measure and configuration at ``site`` (the selection's ``seed``, or its default;
    stripes at the site's intensities of ``return_periods``, yr, by default the site's; the stripes' motions from ``pool``)."""
    periods = site.return_periods if return_periods is None else np.asarray(return_periods, dtype=float)
    curve = site.hazard(measure)
    levels = curve.intensity_at(np.maximum(1.0 / periods, float(curve.rate.min())))  # a curve that stops short (PSA(0.3 s): 3431 yr): its last level
    base, variants = CONFIGURATIONS[configuration]
    table = site.table
    if 'scenario = "fitted"' in table and measure in site.derived:  # the four curves and the measure's derived one, its file stating it
        kind, period = MEASURE_ARGS[measure]
        entry = f'{{ file = "{site.derived_curve_file(measure)}", measure = "{kind}", periods = [{", ".join(f"{t:g}" for t in period)}], damping = 0.05, units = "g" }}'
        table = table.replace(f'"{CURVES[-1]}"]', f'"{CURVES[-1]}", {entry}]')
    elif 'scenario = "fitted"' in table and MEASURES[measure] not in CURVES:  # a scenario fitted to the four curves and the measure's own
        table = table.replace(f'"{CURVES[-1]}"]', f'"{CURVES[-1]}", "{MEASURES[measure]}"]')
    return (f'[experiment]\nname = "site_{site.name}"\nstudied = "B1"\n{PAIR.format(base=base, variants=variants)}\n[intensity]\n'
            f"{_intensity_lines(measure)}\nlevels = [{', '.join(f'{x:.4f}' for x in levels)}]\n"
            'selection = "conditional_spectrum"\n' + pool.intensity_lines() + "max_scale_factor = 5.0\n" + ("" if seed is None else f"seed = {seed}\n") +
            table + pool.site_lines())


def experiment_file(folder: Path, measure: str) -> Path:
    """The experiment file :func:`measure_risk` writes in ``folder`` for ``measure`` (its store: the same name, ``.nc``)."""
    return folder / f"{measure.replace('(', '').replace(' s)', '').replace(' ', '').replace('.', 'p').lower()}.toml"


def measure_risk(folder: Path, measure: str, configuration: str, bootstrap: int = 0, seed: int | None = None,
                 return_periods: np.ndarray | None = None, site: Site = FOX_PLAZA, pool: Pool = RECORDS_ONLY) -> tuple[xr.Dataset, StoreRisk]:
    """The store and the risk answer (g* at 10 % and 2 % in 50 years, ``bootstrap`` resamples for its 95 % interval) of one
    measure and configuration at ``site`` (the selection's ``seed``, or its default; stripes at ``return_periods``, by default
    the site's; motions from ``pool``), run in ``folder``."""
    from stochpound import open_store
    from stochpound.risk import store_risk
    from stochpound.experiment import load_experiment, run_experiment

    path = experiment_file(folder, measure)
    for name, text in site.companion_files(measure).items():
        (folder / name).write_text(text)
    path.write_text(experiment_text(measure, configuration, seed, return_periods, site, pool))
    report = run_experiment(load_experiment(path), workers=0, progress=False, checkpoint=float("inf"))  # no store written mid-run: read at the end only
    if not report.complete:
        raise RuntimeError(f"{configuration}, {measure}: the experiment did not complete")
    store = open_store(report.store).load()
    return store, store_risk(store, site.hazard(measure), targets=(0.1, 0.02), bootstrap=bootstrap)


def lognormal_rate(store: xr.Dataset, risk: StoreRisk) -> xr.DataArray:
    """The rate of pounding (1/yr) over the risk's gap grid from a lognormal demand per stripe
    (:func:`stochpound.risk.stripe_demand_rate`): every run's closure enters, not only whether it reaches a gap."""
    from stochpound.risk import contact_free_closure, stripe_demand_rate

    return stripe_demand_rate(contact_free_closure(store), risk.fragility["gap"].values, risk.hazard)


def rate_g_star(rate: xr.DataArray, risk: StoreRisk) -> xr.DataArray:
    """g* (m) at the risk's targets of a rate of pounding over gaps (1/yr)."""
    from stochpound.risk import risk_targeted_separation

    return risk_targeted_separation(xr.Dataset({"maf": rate}), risk.separation["target"].values, risk.years)["separation"]


def lognormal_g_star(store: xr.Dataset, risk: StoreRisk) -> xr.DataArray:
    """g* (m) at the risk's targets from a lognormal demand per stripe (:func:`lognormal_rate`)."""
    return rate_g_star(lognormal_rate(store, risk), risk)


def g_star(folder: Path, measure: str, configuration: str, site: Site = FOX_PLAZA) -> xr.DataArray:
    """g* (m) at 10 % and 2 % in 50 years of one measure and configuration at ``site`` from a lognormal demand per stripe, run in
    ``folder``."""
    return lognormal_g_star(*measure_risk(folder, measure, configuration, site=site))


def diagnosis(store: xr.Dataset, risk: StoreRisk) -> pd.DataFrame:
    """What a measure's g* rests on, per configuration cell and target: g* and its 95 % bootstrap interval (m); the fragility at
    g* (θ in g and β); the shares of the MAF at g* from shaking weaker than the lowest stripe and from the fitted fragility's
    rise beyond the top one (:attr:`stochpound.risk.StoreRisk.outside_stripes`); the stripes whose selection misses its target."""
    misses = int(store["selection_misses_target"].sum())
    columns = {"separation": "g*", "lower": "lower", "upper": "upper", "theta": "theta", "beta": "beta", "below": "below", "above": "extrapolated"}
    table = xr.merge([risk.separation.drop_vars("target_rate", errors="ignore"), risk.outside_stripes], compat="override").to_dataframe()
    table = table[[name for name in columns if name in table]].rename(columns=columns).reset_index()
    return table.assign(**{"missed stripes": f"{misses}/{store.sizes['intensity']}"})


def _print_seeds(configuration: str, args: argparse.Namespace, counted: xr.DataArray, fitted: xr.DataArray) -> None:
    """g* both ways with the selection's other seeds (``args.seeds``), beside the default seed's."""
    again: dict[str, list[xr.DataArray]] = {"counted": [], "lognormal demand per stripe": []}
    with tempfile.TemporaryDirectory() as folder:
        for seed in args.seeds:
            runs = [measure_risk(_subfolder(Path(folder), f"seed{seed}"), measure, configuration, seed=seed, return_periods=args.return_periods,
                                 site=args.site, pool=args.pool)
                    for measure in args.measures]
            again["counted"].append(xr.concat([risk.separation["separation"] for _, risk in runs], dim="measure"))
            again["lognormal demand per stripe"].append(xr.concat([lognormal_g_star(store, risk) for store, risk in runs], dim="measure"))
    for (name, others), first in zip(again.items(), (counted, fitted)):
        values = xr.concat(others, dim="seed").assign_coords(seed=args.seeds, measure=args.measures)
        values = xr.concat([first.expand_dims(seed=["default"]), values], dim="seed")
        print(f"\n{configuration}: g* (m, {name}) by the selection's seed (the same experiments otherwise)")
        print(values.to_dataframe().unstack("seed")["separation"].to_string(float_format=lambda v: f"{v:.3f}"))
        spread = values.max(("measure", "seed")) / values.min(("measure", "seed"))
        print("max/min over measures and seeds:", spread.to_pandas().to_string(float_format=lambda v: f"{v:.2f}"))


def _draw(axes: list, configuration: str, counted: xr.DataArray, fitted: xr.DataArray) -> None:
    """g* against the measure, per target (a panel each) and configuration cell: from the lognormal demand per stripe
    (solid) and from the counts (dashed, the same colour)."""
    others = [d for d in counted.dims if d not in ("measure", "target")]
    stacks = [values.stack(cell=others) if others else values.expand_dims(cell=[""]) for values in (fitted, counted)]
    for ax, j in zip(axes, range(counted.sizes["target"])):
        for k in range(stacks[0].sizes["cell"]):
            cell = stacks[0]["cell"].values[k]
            label = configuration + (", " + ", ".join(map(str, cell if isinstance(cell, tuple) else (cell,))) + " neighbour" if others else "")
            (line,) = ax.plot(counted["measure"].values, stacks[0].isel(target=j, cell=k).values, "o-", label=label)
            ax.plot(counted["measure"].values, stacks[1].isel(target=j, cell=k).values, "x--", color=line.get_color(), alpha=0.6, lw=0.8)


def _print_table(title: str, values: xr.DataArray) -> None:
    """A g* table over the measures with its max/min, and over the others alone where :data:`SA_AVG` is among them."""
    print(f"\n{title}")
    print(values.to_dataframe().unstack("measure")["separation"].to_string(float_format=lambda v: f"{v:.3f}"))
    print("max/min:", (values.max("measure") / values.min("measure")).to_pandas().to_string(float_format=lambda v: f"{v:.2f}"))
    if SA_AVG in values["measure"].values and values.sizes["measure"] > 2:
        four = values.drop_sel(measure=SA_AVG)
        print(f"max/min without {SA_AVG}:", (four.max("measure") / four.min("measure")).to_pandas().to_string(float_format=lambda v: f"{v:.2f}"))


def _subfolder(folder: Path, name: str) -> Path:
    (folder / name).mkdir(exist_ok=True)
    return folder / name


def check_site_vs30(parser: argparse.ArgumentParser, option: str, vs30: float) -> None:
    """End the run with a one-line usage error naming ``option`` unless ``vs30`` (m/s) lies within both the NGA-West2 models' range
    (the fitted scenarios') and the site-motion model's (the simulated motions')."""
    from stochpound import SiteError
    from stochpound.motions import SITE_MOTION_LIMITS, Scenario

    try:
        Scenario.of(6.0, 10.0, vs30, "reverse", names={"vs30": option})
        Scenario.of(6.0, 10.0, vs30, "reverse", names={"vs30": option}, limits=SITE_MOTION_LIMITS, source="the site-motion model's range")
    except SiteError as error:
        parser.error(str(error))


def parse_scenario_site(parser: argparse.ArgumentParser, values: list[str]) -> Site:
    """The site of ``--scenario M R_KM MECHANISM RATE``; a bad value ends the run with a one-line usage error naming it."""
    from stochpound import SiteError

    try:
        magnitude, distance_km, rate = float(values[0]), float(values[1]), float(values[3])
    except ValueError:
        parser.error(f"--scenario: M, R_KM and RATE must be numbers, got {' '.join(values)}")
    try:
        return scenario_site(magnitude, distance_km, values[2], rate)
    except (SiteError, ValueError) as error:
        parser.error(f"--scenario: {error}")


def site_measures(parser: argparse.ArgumentParser, site: Site, measures: list[str] | None) -> list[str]:
    """``--measures``, by default the site's; one the site has no hazard curve of ends the run with a one-line usage error."""
    measures = list(site.measures) if measures is None else measures
    if not set(measures) <= set(site.measures):
        parser.error(f"--measures: the site {site.name} has hazard curves of {', '.join(site.measures)} only")
    return measures


def main(argv: list[str] | None = None) -> None:
    """Run, print the table, draw the figure."""
    from matplotlib.figure import Figure

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--measures", nargs="+", default=None, choices=list(MEASURE_ARGS),
                        help=f"default: the site's (Fox Plaza's five and {SA_AVG} on its derived curve; at the site of one scenario the four and {SA_AVG})")
    parser.add_argument("--configurations", nargs="+", default=list(CONFIGURATIONS), choices=list(CONFIGURATIONS))
    parser.add_argument("--bootstrap", type=int, default=200, help="resamples of the 95 %% interval of g* (0: none)")
    parser.add_argument("--return-periods", nargs="+", type=float, default=None,
                        help=f"return periods (yr) of the stripes' intensities (default: the site's; Fox Plaza {list(RETURN_PERIODS)})")
    parser.add_argument("--seeds", nargs="*", type=int, default=[], help="other seeds of the selection: g* of every measure again with each")
    parser.add_argument("--site", choices=list(FIGURES), default="fox_plaza", help="the bundled Fox Plaza site, or a site of one scenario")
    parser.add_argument("--scenario", nargs=4, metavar=("M", "R_KM", "MECHANISM", "RATE"), default=list(SCENARIO),
                        help="--site scenario's magnitude, rupture distance (km), mechanism and annual rate (default %(default)s)")
    parser.add_argument("--motions", type=int, default=RECORDS_ONLY.motions, help="motions a stripe (default %(default)s)")
    parser.add_argument("--simulated-motions", type=int, default=0, help="site-based stochastic motions of each stripe's scenario added to the pool")
    parser.add_argument("--max-per-earthquake", type=int, default=None, help="at most this many motions of an earthquake a stripe")
    parser.add_argument("--sampling", choices=("scenario", "tilted"), default="scenario",
                        help="how the simulated motions are drawn ([site] simulated_sampling; default %(default)s)")
    args = parser.parse_args(argv)
    args.pool = Pool(args.motions, args.simulated_motions, args.max_per_earthquake, args.sampling)
    args.site = FOX_PLAZA if args.site == "fox_plaza" else parse_scenario_site(parser, args.scenario)
    args.return_periods = args.site.return_periods if args.return_periods is None else np.asarray(args.return_periods, dtype=float)
    args.measures = site_measures(parser, args.site, args.measures)
    print(f"site: {args.site.name}; stripes at return periods {', '.join(f'{t:g}' for t in args.return_periods)} yr")
    figure = Figure(figsize=(7.5, 3.4), layout="constrained")
    axes = figure.subplots(1, 2, sharey=True)
    for ax, target in zip(axes, (0.1, 0.02)):
        ax.set_title(f"{target:.0%} in 50 years", fontsize=9)
        ax.set_yscale("log")
        ax.grid(True, which="both", lw=0.3, color="0.85")
        ax.tick_params(axis="x", labelsize=7, labelrotation=20)
    for configuration in args.configurations:
        answers, lognormal, diagnoses = [], [], []
        with tempfile.TemporaryDirectory() as folder:
            for measure in args.measures:
                store, risk = measure_risk(Path(folder), measure, configuration, bootstrap=args.bootstrap, return_periods=args.return_periods,
                                           site=args.site, pool=args.pool)
                answers.append(risk.separation["separation"])
                lognormal.append(lognormal_g_star(store, risk))
                diagnoses.append(diagnosis(store, risk).assign(measure=measure))
        counted = xr.concat(answers, dim="measure").assign_coords(measure=args.measures)
        fitted = xr.concat(lognormal, dim="measure").assign_coords(measure=args.measures)
        _print_table(f"{configuration}: g* (m) by conditioning measure", counted)
        _print_table(f"{configuration}: g* (m) from a lognormal demand per stripe (stochpound.risk.stripe_demand_rate)", fitted)
        print(f"\n{configuration}: what g* rests on (95 % bootstrap interval of {args.bootstrap} resamples; fragility at g*; MAF shares from below the lowest "
              "stripe and extrapolated beyond the top one)")
        print(pd.concat(diagnoses).set_index(["measure"]).to_string(float_format=lambda v: f"{v:.3g}"))
        if args.seeds:
            _print_seeds(configuration, args, counted, fitted)
        _draw(axes, configuration, counted, fitted)
    axes[0].set_ylabel("g* (m): lognormal demand per stripe (solid), counts (dashed)", fontsize=7)
    axes[1].legend(fontsize=7)
    figure.savefig(FIGURES[args.site.name], dpi=150)
    print(f"\nfigure: {FIGURES[args.site.name].relative_to(REPOSITORY)}")


if __name__ == "__main__":
    main()
