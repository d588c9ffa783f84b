"""Stripes of motions chosen for the site: ``[intensity] selection = "conditional_spectrum"`` and the ``[site]`` table.

With ``selection = "conditional_spectrum"`` (docs/intensity.md) every stripe
runs ``motions`` motions chosen from the pool (every ``[[records]]`` entry)
and scaled to the level within ``max_scale_factor``, so that their spectra
match the conditional spectrum of the stripe's scenario
(:func:`stochpound.motions.select_motions`). The ``[site]`` table gives the
scenario: ``vs30``, and ``magnitude``, ``distance_km`` and ``mechanism``,
each one value or one per level (in the order ``levels`` lists them); or,
with ``scenario = "fitted"``, ``vs30``, ``mechanism`` and ``curves`` (the
site's bundled hazard curves): the magnitude and distance of every level are
then fitted so that the stripes' conditional spectra reproduce the site's
curves at the other periods (:func:`stochpound.motions.fit_scenarios`), a
calibration standing in for a disaggregation; or, with ``ruptures`` (a
rupture table's file, relative to the experiment file, or a bundled site's
name) and the site's ``vs30`` (and ``z1p0_km``, ``z2p5_km``) where the table
does not state them, the site of those ruptures
(:class:`stochpound.analysis.RuptureSite`): every stripe's target is then its
exact conditional spectrum, the ruptures' mixture by their shares at the
level, and the ruptures themselves are part of the definition (its
``intensity.ruptures``, so of the identity).

The period range covers the structure: every building's first-mode period
on a fixed base and, for a building on a sliding base with a restoring
force (a friction pendulum), its isolated period 2π √(M/k_r) (M the
building's and base's mass, k_r the restoring stiffness), over every grid
point; the range runs from 0.2 times the shortest to 3 times the longest.

``[site] simulated_motions = N`` adds, to every stripe's pool, N
site-based stochastic motions of the stripe's scenario
(:func:`stochpound.motions.site_motions`, the hazard-compatible model, seed
``[intensity] seed``, dt = 0.01 s), mixed with the records. They are not
stored: the definition keeps the model, its calibration, the seed and N, and
a chosen motion is regenerated bit for bit from them (its ``realization``
among the N). Each simulated motion is its own earthquake for
``max_per_earthquake`` and never a pulse. The pool is generated a stripe at
a time, ``SIMULATED_CHUNK`` motions at once, their spectra in one compiled
call per batch. A pool of a scenario larger than ``SCREEN_BASE`` is
pre-screened (:func:`screen_level`): beyond its first ``SCREEN_BASE``
motions, only those whose own ε at the conditioning measure is within
``SCREEN_MARGIN`` of the top stripe's (or beyond) join it, the others'
spectra never computed. At a site of ruptures the
N motions of a stripe are of its causal ruptures, apportioned by their
weights in the stripe's exact conditional spectrum (:func:`rupture_allotment`,
the largest remainders), each rupture's motions from its own table shared by
the stripes (:func:`rupture_sources`). With simulated motions the pool needs
no records.

``[site] simulated_sampling = "tilted"`` (with a given or fitted scenario;
the default ``"scenario"`` adds nothing to the definition) gives every
stripe its own N motions, importance-sampled toward its level
(:func:`tilted_sources`): their parameter normals are drawn N(s, I) instead
of N(0, I), s along the direction of the least-squares line of ln IM* on
those normals (:func:`tilt_pilot`, fitted to the scenario's first
``TILT_PILOT`` untilted motions) and long enough to centre ln IM* on the
level; each motion's table keeps s (``normal_shift``). No pre-screen.

``[intensity] max_per_earthquake`` (at most that many motions of one
earthquake in a stripe; no limit unless given) and ``exclude_pulses = true``
(no record the metadata mark as a pulse) are the selection's rules
(:func:`stochpound.motions.select_motions`); a stripe never holds the same
recording twice. ``tolerance_first = true`` puts the target's tolerance
before the misfit: a stripe whose set of least misfit misses its target
takes a set within the tolerance where the selection's integer programme
finds one (the store's ``selection_tolerance_first``).

The simulated motions of the pools (their tables, chunks, pre-screen, tilt and
ruptures' shares) are :mod:`stochpound.experiment._stripe_pools`'s.

The default ``selection = "scale"`` (every motion scaled to every level)
adds nothing to the definition, so the identities of existing experiments
are unchanged.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from stochpound.hazard import site_curve_label
from stochpound.model import fields as toml_fields
from stochpound.motions import CONDITIONING_MEASURES, MODEL_DAMPING, PERIOD_RANGE, Measure, Scenario
from stochpound.store import CONDITIONAL_SPECTRUM, SCENARIO_KINDS, ExperimentGrid, Intensity, MotionSource, Selection, SimulatedMotions, Site
from stochpound.experiment._stripe_pools import (SITE_FIELDS, Tilt, rupture_allotment, rupture_sources, screen_level, shared_simulated_pool,
                                                 simulated_sources, tilted_sources)


SELECTIONS = ("scale", CONDITIONAL_SPECTRUM)
"""``[intensity] selection``: every motion scaled to every level, or motions chosen per stripe."""
DEFAULT_SEED = 1
"""Seed of the selection when ``[intensity] seed`` is not given."""
SIMULATED_MODEL = "hazard_compatible"
"""The site-motion model of ``[site] simulated_motions``."""
SIMULATED_DT = 0.01
"""Time step of the simulated motions, s."""
SIMULATED_LIMIT = 100_000
"""Largest ``[site] simulated_motions`` (per stripe)."""
RULES = ("max_per_earthquake", "exclude_pulses", "tolerance_first")
"""``[intensity]`` fields of the selection's rules (:attr:`stochpound.store.Selection.rules`), in the definition only where given."""
PER_LEVEL = ("magnitude", "distance_km", "mechanism")
"""``[site]`` fields that take one value per level."""
SAMPLINGS = ("scenario", "tilted")
"""``[site] simulated_sampling``: the scenario's motions (one pool for its stripes), or each stripe's own, tilted to its level."""


def parse_selection(table: Mapping[str, Any], site: Any, levels: list[float], setting: Intensity,
                    base_dir: Path = Path(".")) -> tuple[Selection, str] | None:
    """The selection of the ``[intensity]`` table, checked, and the note saying how it chooses (None for the default ``scale``).

    Parameters
    ----------
    table : mapping
        The ``[intensity]`` table.
    site : mapping or None
        The ``[site]`` table.
    levels : list of float
        The levels as the file lists them.
    setting : Intensity
        The ``[intensity]`` setting parsed so far (its measure, units, method; no selection yet).
    base_dir : Path
        The experiment file's folder (a rupture table's path is relative to it).

    Raises
    ------
    SiteError
        Naming the field: an unknown selection, a measure or unit the
        conditional spectrum does not take, a missing or short ``[site]``
        field, a scenario outside the models' range.
    """
    from stochpound._errors import SiteError

    intensity_table = toml_fields.TomlTable(table, "intensity", raises=SiteError)
    selection = intensity_table.string("selection", SELECTIONS[0], choices=SELECTIONS)
    if selection == SELECTIONS[0]:
        for key in ("motions", "max_scale_factor", "seed", *RULES):
            if key in table:
                raise SiteError(f'intensity.{key}: only with selection = "{CONDITIONAL_SPECTRUM}"')
        if site is not None:
            raise SiteError(f'site: only with [intensity] selection = "{CONDITIONAL_SPECTRUM}" (the scenario of its targets)')
        return None
    measure = setting.measure
    if measure.kind not in CONDITIONING_MEASURES:
        raise SiteError(f"intensity.measure: the conditional spectrum conditions on {', '.join(CONDITIONING_MEASURES)}, got {measure.kind!r}")
    if setting.units != "g":
        raise SiteError(f'intensity.units: the conditional spectrum takes levels in g, got {setting.units!r}')
    if setting.method != "stripes":
        raise SiteError('intensity.method: the conditional spectrum chooses motions per stripe: method = "stripes"')
    if measure.damping is not None and measure.damping != MODEL_DAMPING:
        raise SiteError(f"intensity.damping: the NGA-West2 models give 5 % damped spectra only (0.05), got {measure.damping!r}")
    low, high = PERIOD_RANGE
    for period in [measure.period] if measure.period is not None else measure.periods:
        if not low <= period <= high:
            key = "intensity.period" if measure.period is not None else "intensity.periods"
            raise SiteError(f"{key}: must be within {low:g}-{high:g} s for the conditional spectrum (the NGA-West2 models' range), got {period:g}")
    motions = intensity_table.integer("motions", low=2, meaning="motions per stripe")
    max_scale = intensity_table.number("max_scale_factor", low=1.0)
    seed = intensity_table.integer("seed", DEFAULT_SEED, low=0)
    note = f"{motions} motions per stripe chosen from the pool and scaled to the conditional spectrum of its scenario"
    max_per_earthquake, exclude_pulses, tolerance_first = parse_rules(table)
    if isinstance(site, dict) and "ruptures" in site:
        ruptures = rupture_site(site, base_dir)
        simulated = parse_simulated(site, seed)
        note = f"{motions} motions per stripe chosen from the pool and scaled to the exact conditional spectrum of the site's {len(ruptures)} ruptures"
        if simulated is not None:
            note += f" (the pool: {simulated.count} simulated motions a stripe of the causal ruptures, allotted by their disaggregation weights)"
        return Selection(selection, motions, max_scale, seed, mixture_scenarios(ruptures, levels, measure), max_per_earthquake, exclude_pulses,
                         tolerance_first=tolerance_first,
                         simulated=simulated, ruptures=ruptures.to_entry(identity=True)), note
    scenarios = parse_site(site, levels, measure, base_dir)
    if toml_fields.TomlTable(site, "site", raises=SiteError).string("scenario", SCENARIO_KINDS[0]) == "fitted":
        note += f" (the scenario fitted to the site's hazard curves {', '.join(map(site_curve_label, site['curves']))}, standing in for a disaggregation)"
    return Selection(selection, motions, max_scale, seed, scenarios, max_per_earthquake, exclude_pulses, simulated=parse_simulated(site, seed),
                     tolerance_first=tolerance_first), note


def parse_rules(table: Mapping[str, Any]) -> tuple[int | None, bool | None, bool | None]:
    """The selection's rules, ``max_per_earthquake``, ``exclude_pulses`` and ``tolerance_first``: each None unless the table gives it (so that the definitions
    of files without them keep their identity)."""
    from stochpound._errors import SiteError

    max_per_earthquake = table["max_per_earthquake"] if "max_per_earthquake" in table else None
    if max_per_earthquake is not None and (not isinstance(max_per_earthquake, int) or isinstance(max_per_earthquake, bool) or max_per_earthquake < 1):
        raise SiteError("intensity.max_per_earthquake: at most this many motions of one earthquake per stripe, an integer >= 1, "
                        f"got {max_per_earthquake!r}")
    exclude_pulses = toml_fields.boolean(table, "exclude_pulses", "intensity", default=False) if "exclude_pulses" in table else None
    tolerance_first = toml_fields.boolean(table, "tolerance_first", "intensity", default=False) if "tolerance_first" in table else None
    return max_per_earthquake, exclude_pulses, tolerance_first


def parse_simulated(site: Mapping[str, Any], seed: int) -> SimulatedMotions | None:
    """The simulated motions of ``[site] simulated_motions`` (seed: the selection's); None without them."""
    from stochpound._errors import SiteError
    from stochpound.motions import site_model_provenance

    sampling = toml_fields.TomlTable(site, "site", raises=SiteError).string("simulated_sampling", SAMPLINGS[0], choices=SAMPLINGS)
    if "simulated_motions" not in site:
        if "simulated_sampling" in site:
            raise SiteError("site.simulated_sampling: only with site.simulated_motions (how the pool's simulated motions are drawn)")
        return None
    count = site["simulated_motions"]
    if not isinstance(count, int) or isinstance(count, bool) or not 1 <= count <= SIMULATED_LIMIT:
        raise SiteError(f"site.simulated_motions: simulated motions a stripe in its pool (of its scenario, or of the site's causal ruptures), "
                        f"an integer within 1-{SIMULATED_LIMIT}, got {count!r}")
    if sampling == "tilted" and "ruptures" in site:
        raise SiteError('site.simulated_sampling: "tilted" takes a given or fitted scenario, not a site of ruptures (use "scenario")')
    return SimulatedMotions(count, SIMULATED_MODEL, site_model_provenance(SIMULATED_MODEL), seed, SIMULATED_DT, sampling)


def rupture_site(site: Mapping[str, Any], base_dir: Path) -> Any:
    """The :class:`~stochpound.analysis.RuptureSite` of a ``[site]`` table with ``ruptures`` (a file or a bundled site's name).

    Raises
    ------
    SiteError
        Naming the field: an unknown key, neither a file nor a bundled site,
        a table's error (its file, line and field), a site field missing or contradicting the table.
    """
    from stochpound.hazard import RUPTURE_SITE_FIELDS, named_rupture_site

    toml_fields.reject_unknown(site, {"ruptures", "simulated_motions", "simulated_sampling", *RUPTURE_SITE_FIELDS}, "site")
    return named_rupture_site(site["ruptures"], base_dir, {key: site[key] for key in RUPTURE_SITE_FIELDS if key in site}, "site")


def mixture_scenarios(ruptures: Any, levels: list[float], measure: Measure) -> tuple[Scenario, ...]:
    """The scenario of every level (sorted) a store records of a site of ruptures: the means of M and R_rup by the exact conditional
    spectrum's weights P(r | IM* = x) (:meth:`~stochpound.analysis.RuptureSite.disaggregation`'s ``density_share``), Vs30 and the
    mechanism of the largest weight (:meth:`~stochpound.analysis.RuptureSite.mean_scenario`)."""
    shares = ruptures.disaggregation(measure.kind, measure.spectral_period, levels=sorted(float(level) for level in levels))["density_share"].values
    return tuple(ruptures.mean_scenario(share) for share in shares)


def site_entry(site: Any, intensity: Intensity | None) -> Site | None:
    """The definition's ``site``: how the stripes' scenario was obtained, typed (None without a ``[site]`` table).

    ``scenario`` is ``"given"``, ``"fitted"`` or ``"ruptures"``; a fitted one
    names the ``curves`` it was fitted to, a site of ruptures its ``ruptures``
    (the file or bundled site as ``[site]`` names it). Called with the parsed ``intensity`` entry,
    once :func:`parse_selection` has checked the table. Not part of the
    identity (``stochpound.store.NOT_IN_IDENTITY``): the runs depend on the
    scenarios themselves (the ``intensity`` entry's ``site``), not on how
    they came.

    Raises
    ------
    SiteError
        A ``[site]`` table without ``[intensity]``.
    """
    from stochpound._errors import SiteError

    if site is None:
        return None
    if intensity is None:
        raise SiteError(f'site: only with [intensity] selection = "{CONDITIONAL_SPECTRUM}" (the scenario of its targets)')
    if "ruptures" in site:
        return Site("ruptures", ruptures=site["ruptures"])
    kind = toml_fields.TomlTable(site, "site", raises=SiteError).string("scenario", SCENARIO_KINDS[0])
    return Site(kind, curves=tuple(map(site_curve_label, site["curves"]))) if kind == "fitted" else Site(kind)


def parse_site(site: Any, levels: list[float], measure: Measure, base_dir: Path = Path(".")) -> tuple[Scenario, ...]:
    """One scenario per level, in the order of the sorted levels, from the ``[site]`` table (given, or fitted to its ``curves``, files
    relative to ``base_dir``)."""
    from stochpound._errors import SiteError

    if not isinstance(site, dict):
        raise SiteError("site: a [site] table is required with the conditional spectrum (vs30, magnitude, distance_km, mechanism)")
    scenario_kind = toml_fields.TomlTable(site, "site", raises=SiteError).string("scenario", SCENARIO_KINDS[0], choices=SCENARIO_KINDS[:2],
                                                                     hint='a site of ruptures: ruptures = "<file or bundled site>"')
    if scenario_kind == "fitted":
        return fitted_site(site, levels, measure, base_dir)
    if "curves" in site:
        raise SiteError('site.curves: only with site.scenario = "fitted"')
    toml_fields.reject_unknown(site, {*SITE_FIELDS, "scenario", "simulated_motions", "simulated_sampling"}, "site")
    columns: dict[str, list[Any]] = {}
    for key in SITE_FIELDS:
        if key not in site:
            raise SiteError(f"site.{key}: missing (the scenario of the site's hazard, from its disaggregation)")
        value = site[key]
        if isinstance(value, list):
            if key not in PER_LEVEL:
                raise SiteError(f"site.{key}: one value for every level, got a list")
            if len(value) != len(levels):
                raise SiteError(f"site.{key}: {len(value)} values for {len(levels)} levels (one scenario, or one per level in the order of intensity.levels)")
            columns[key] = value
        else:
            columns[key] = [value] * len(levels)
    scenarios = []
    for i in range(len(levels)):
        names = {key: f"site.{key}[{i}]" if isinstance(site[key], list) else f"site.{key}" for key in SITE_FIELDS}
        scenarios.append(Scenario.of(columns["magnitude"][i], columns["distance_km"][i], columns["vs30"][i], columns["mechanism"][i], names=names))
    order = sorted(range(len(levels)), key=lambda i: levels[i])
    return tuple(scenarios[i] for i in order)


def fitted_site(site: Mapping[str, Any], levels: list[float], conditioning_measure: Measure, base_dir: Path = Path(".")) -> tuple[Scenario, ...]:
    """The scenario of every level (sorted) fitted to the site's hazard curves (:func:`stochpound.motions.fit_scenarios`).

    ``site.curves`` lists bundled curves (:func:`stochpound.analysis.bundled_curves`) or hazard-curve files (relative to
    ``base_dir``), each read by :func:`stochpound.hazard.site_curve`: the one of the conditioning measure gives the stripes'
    rates, the others (PGA or PSA) are reproduced by the fit.
    """
    from stochpound._errors import SiteError
    from stochpound.analysis import stripe_rate_weights
    from stochpound.hazard import site_curve
    from stochpound.motions import fit_levels, fit_scenarios

    toml_fields.reject_unknown(site, {"scenario", "curves", "vs30", "mechanism", "simulated_motions", "simulated_sampling"}, "site")
    for key in ("vs30", "mechanism"):
        if key not in site:
            raise SiteError(f"site.{key}: missing (the site's Vs30 and the mechanism of its faults)")
        if isinstance(site[key], list):
            raise SiteError(f'site.{key}: one value with scenario = "fitted", got a list')
    Scenario.of(6.0, 10.0, site["vs30"], site["mechanism"], names={"vs30": "site.vs30", "mechanism": "site.mechanism"})
    curves = toml_fields.TomlTable(site, "site", raises=SiteError).raw("curves")
    if not isinstance(curves, list) or len(curves) < 2:
        raise SiteError(f"site.curves: two or more of the site's hazard curves (bundled curves' names or hazard-curve files), got {curves!r}")
    conditioning = None
    others = []
    for index, entry in enumerate(curves):
        where = f"site.curves[{index}]"
        measure, curve = site_curve(entry, base_dir, where)
        if measure.kind == conditioning_measure.kind and measure.spectral_period == conditioning_measure.spectral_period:
            conditioning = curve
        elif measure.kind in ("pga", "psa"):
            others.append((measure.period, curve.im, curve.rate))
        else:
            raise SiteError(f"{where}: the fit reproduces curves of PGA or PSA; {measure.description} only as the conditioning measure's curve")
    if conditioning is None:
        raise SiteError("site.curves: none of them is the curve of the conditioning measure ([intensity] measure and period)")
    if not others:
        raise SiteError("site.curves: the fit needs one or more curves at other periods than the conditioning measure's")
    ordered = sorted(float(level) for level in levels)
    try:
        fine = fit_levels(ordered, conditioning.support[1], conditioning.support[0])
        scenarios = fit_scenarios(conditioning_measure.kind, conditioning_measure.spectral_period, ordered, fine, stripe_rate_weights(fine, conditioning, "intensity.levels"),
                                  others, float(site["vs30"]), site["mechanism"])
    except SiteError as error:  # the fit's own, naming its argument: the file's field instead
        message = str(error)
        raise SiteError(f"site.curves: {message.removeprefix('others: ')}" if message.startswith("others:") else f"intensity.{message}") from None
    except ValueError as error:  # a level outside the conditioning curve
        raise SiteError(f"intensity.levels: outside the site's curve of the conditioning measure ({error})") from None
    return tuple(Scenario(**scenario) for scenario in scenarios)


def periods_of_interest(experiment: ExperimentGrid) -> dict[str, float]:
    """The structure's periods of interest (s), by name: first-mode periods on a fixed base and isolated periods, over every grid point.

    Names: ``"B1 first mode"``, ``"B1 isolated"``, with the grid point's
    variant labels where a building's period differs between points.
    """
    from stochpound.store import CASE
    from stochpound.model.modal_solution import scene_periods
    from stochpound.model.scene_file import scene_from_dict

    found: dict[str, set[float]] = {}
    labels: dict[tuple[str, float], str] = {}
    for point in experiment.points(CASE):
        variants = ", ".join(f"{name}={value}" for name, value in point.labels if name in {v.name for v in experiment.variants})
        for key, period in scene_periods(scene_from_dict(experiment.structure(point), base_dir=experiment.base_dir)).items():
            period = round(period, 12)
            found.setdefault(key, set()).add(period)
            labels.setdefault((key, period), variants)
    named = {}
    for key, values in found.items():
        for period in sorted(values):
            named[key if len(values) == 1 else f"{key} ({labels[(key, period)]})"] = period
    return named


def structure_periods(experiment: ExperimentGrid) -> list[float]:
    """The distinct periods of :func:`periods_of_interest` (s), ascending."""
    return sorted(set(periods_of_interest(experiment).values()))


@dataclass
class StripeSelections:
    """The motions chosen for every stripe of an experiment (:func:`stripe_selections`)."""

    experiment_levels: list[float]
    labels: list[str]
    periods: np.ndarray
    structure: list[float]
    selections: list[xr.Dataset]
    targets: list[xr.Dataset]
    simulated: dict[str, MotionSource] = field(default_factory=dict)
    """The chosen simulated motions' sources, by label (``[site] simulated_motions``; :func:`simulated_sources`)."""

    @cached_property
    def chosen(self) -> np.ndarray:
        """Which motions run at every level (bool, level × motion)."""
        mask = np.zeros((len(self.experiment_levels), len(self.labels)), dtype=bool)
        for i, selection in enumerate(self.selections):
            mask[i, [self.labels.index(m) for m in selection["motion"].values]] = True
        return mask

    def coordinates(self) -> dict[str, xr.Variable]:
        """The store's record of the selection: per stripe the chosen motions' scale factors, the target and the set's spectra, the scenario."""
        from stochpound.motions import TARGET_TOLERANCE, misses_target

        scale = np.full(self.chosen.shape, np.nan)
        for i, selection in enumerate(self.selections):
            scale[i, [self.labels.index(m) for m in selection["motion"].values]] = selection["scale_factor"].values
        stack = {name: np.stack([s[name].values for s in self.selections]) for name in ("median", "sigma_ln", "mean_ln", "std_ln")}
        per_stripe = ("intensity", "selection_period")
        scenario = [t.attrs for t in self.targets]
        return {
            "selection_period": xr.Variable(
                ("selection_period",), self.periods,
                {"units": "s", "long_name": "period of the conditional-spectrum targets", "structure_periods": " ".join(f"{t:.6g}" for t in self.structure)},
            ),
            "selection_scale_factor": xr.Variable(("intensity", "record"), scale, {"units": "1", "long_name": "scale factor of a motion chosen for the stripe (NaN: not chosen)"}),
            "target_median": xr.Variable(per_stripe, stack["median"], {"units": "g", "long_name": "conditional spectrum: median Sa given the level"}),
            "target_sigma_ln": xr.Variable(per_stripe, stack["sigma_ln"], {"units": "1", "long_name": "conditional spectrum: standard deviation of ln Sa"}),
            "selection_mean_ln": xr.Variable(per_stripe, stack["mean_ln"], {"units": "1", "long_name": "mean ln Sa (g) of the chosen, scaled motions"}),
            "selection_std_ln": xr.Variable(per_stripe, stack["std_ln"], {"units": "1", "long_name": "standard deviation of ln Sa of the chosen, scaled motions"}),
            "selection_misses_target": xr.Variable(
                ("intensity",), misses_target(stack["mean_ln"], stack["std_ln"], stack["median"], stack["sigma_ln"]).astype(np.int8),
                {"units": "1", "long_name": f"1 where the stripe's selection misses its target (mean or std of ln Sa off by > {TARGET_TOLERANCE:g} at a period)"},
            ),
            "selection_target_reachable": xr.Variable(
                ("intensity",), np.array([s.attrs["target_reachable"] for s in self.selections], dtype=np.int8),
                {"units": "1", "long_name": f"0 where no set of the stripe's pool can meet its target's mean and std of ln Sa within {TARGET_TOLERANCE:g} "
                 "at every period (linear-programming bounds over its candidates and rules): a miss there is the pool's, not the search's"},
            ),
            "selection_tolerance_first": xr.Variable(
                ("intensity",), np.array([s.attrs["chosen_by"] == "tolerance" for s in self.selections], dtype=np.int8),
                {"units": "1", "long_name": "1 where the stripe's set of least misfit missed its target and [intensity] tolerance_first "
                 "chose a set within the tolerance instead"},
            ),
            "target_epsilon": xr.Variable(("intensity",), np.array([s["epsilon"] for s in scenario]), {"units": "1", "long_name": "epsilon of the level in its scenario"}),
            "site_magnitude": xr.Variable(("intensity",), np.array([s["magnitude"] for s in scenario]), {"units": "1", "long_name": "scenario moment magnitude"}),
            "site_distance_km": xr.Variable(("intensity",), np.array([s["distance_km"] for s in scenario]), {"units": "km", "long_name": "scenario rupture distance"}),
            "site_vs30": xr.Variable(("intensity",), np.array([s["vs30"] for s in scenario]), {"units": "m/s", "long_name": "scenario Vs30"}),
            "site_mechanism": xr.Variable(("intensity",), np.array([s["mechanism"] for s in scenario], dtype=object), {"units": "1", "long_name": "scenario mechanism"}),
            **self.stripe_counts(),
        }  # fmt: skip

    def stripe_counts(self) -> dict[str, xr.Variable]:
        """Per stripe: its recorded and simulated motions and its earthquakes (a simulated motion is its own)."""
        counts = {"recorded": [], "simulated": [], "earthquakes": []}
        for selection in self.selections:
            simulated = int(sum(str(m) in self.simulated for m in selection["motion"].values))
            counts["simulated"].append(simulated)
            counts["recorded"].append(selection.sizes["selected"] - simulated)
            counts["earthquakes"].append(len(set(selection["earthquake"].values.astype(str))))
        names = {"recorded": "recorded motions in the stripe", "simulated": "simulated motions in the stripe ([site] simulated_motions)",
                 "earthquakes": "earthquakes in the stripe (a simulated motion is its own)"}
        return {f"selection_{key}": xr.Variable(("intensity",), np.array(values, dtype=np.int64), {"units": "1", "long_name": names[key]})
                for key, values in counts.items()}


def stripe_selections(experiment: ExperimentGrid) -> StripeSelections:
    """Choose and scale the motions of every stripe (module docstring).

    Raises
    ------
    ExperimentError
        Naming the field: a synthetic ensemble in the pool, ``intensity.motions``
        more than the pool (the records and any simulated motions) has within
        ``max_scale_factor`` of a level under the rules.
    """
    from stochpound._errors import ExperimentError, SiteError, field_errors
    from stochpound.analysis import RuptureSite
    from stochpound.store import CASE
    from stochpound.model.scene_file import scene_from_dict
    from stochpound.motions import conditional_spectrum, select_motions, selection_periods, selection_pool
    from stochpound.motions.records import Record

    intensity = experiment.intensity
    scene = experiment.structure(experiment.points(CASE)[0])
    records = []
    metadata = pool_metadata(experiment)
    for label, source in experiment.recorded_motions.items():  # the motions as the cases run them (a duration or a start applied)
        with field_errors(scene_prefix=source.field):
            motion = scene_from_dict({**scene, "motion": experiment.motion_table(label)}, base_dir=experiment.base_dir).motion
        records.append(Record(label, motion.dt, motion.values, "m/s2", metadata=metadata[label]))
    measure = intensity.measure.kind
    period = intensity.measure.spectral_period
    chosen = intensity.selection
    conditioning = [] if period is None else list(np.atleast_1d(period))
    structure = structure_periods(experiment)
    periods = selection_periods(structure, conditioning)
    g = experiment.definition.g
    pool = selection_pool(records, periods, measure, period, MODEL_DAMPING, g) if records else None  # None: simulated motions alone
    selections, targets, simulated = [], [], {}
    if chosen.ruptures is not None:  # the exact conditional spectrum of every stripe
        stripe_targets = RuptureSite.from_entry(chosen.ruptures).conditional_spectra(measure, period, levels=list(intensity.levels), periods=periods)
    else:
        stripe_targets = [conditional_spectrum(measure, period, level=level, periods=periods, scenario=scenario)
                          for level, scenario in zip(intensity.levels, chosen.scenarios)]
    allotment = None
    if chosen.ruptures is not None and chosen.simulated is not None:
        site = RuptureSite.from_entry(chosen.ruptures)
        allotment = rupture_allotment(site, measure, period, list(intensity.levels), chosen.simulated.count)
    generated: dict[str, xr.Dataset] = {}  # the simulated pool of each distinct table: stripes of one table share it, relabelled
    tilts: dict[Scenario, Tilt] = {}  # the tilt of each scenario of a tilted pool (its pilot's regression)
    for stripe, (level, scenario, target) in enumerate(zip(intensity.levels, chosen.scenarios, stripe_targets)):
        tilted = chosen.simulated is not None and chosen.simulated.sampling == "tilted"
        try:
            groups = (rupture_sources(chosen.simulated, stripe, site, allotment) if allotment is not None
                      else [tilted_sources(chosen.simulated, stripe, scenario, level, tilts, measure, period, g)] if tilted
                      else [simulated_sources(chosen.simulated, stripe, scenario)])
        except SiteError as error:  # a scenario outside the site-motion model's calibrated range (the tilt's pilot)
            raise ExperimentError(f"site.simulated_motions: the stripe {level:g} g's scenario: {error}") from None
        parts = [] if pool is None else [pool]
        screen = (None if allotment is not None or tilted
                  else screen_level(chosen.simulated, stripe, chosen.scenarios, stripe_targets, measure, period))
        for group in filter(None, groups):
            try:
                parts.append(shared_simulated_pool(group, periods, measure, period, g, generated, screen))
            except SiteError as error:  # a scenario outside the site-motion model's calibrated range
                table = next(iter(group.values())).motion
                where = f"rupture {table['rupture']}" if "rupture" in table else "scenario"
                raise ExperimentError(f"site.simulated_motions: the stripe {level:g} g's {where}: {error}") from None
        stripe_pool = xr.concat(parts, "motion") if len(parts) > 1 else parts[0]
        sources = {label: source for group in groups for label, source in group.items()}
        try:
            selection = select_motions(stripe_pool, target, chosen.motions, chosen.max_scale_factor, chosen.seed, **chosen.rules)
        except SiteError as error:
            raise ExperimentError(f"intensity.{error} (stripe {level:g} g)") from None
        simulated.update({str(label): sources[str(label)] for label in selection["motion"].values if str(label) in sources})
        selections.append(selection)
        targets.append(target)
    labels = list(experiment.recorded_motions) + list(simulated)
    return StripeSelections(list(intensity.levels), labels, periods, structure, selections, targets, simulated)


def pool_metadata(experiment: ExperimentGrid) -> dict[str, dict[str, float | str]]:
    """The metadata of every record of the pool, by label (:func:`stochpound.motions.records.record_metadata`).

    Raises
    ------
    ExperimentError
        A synthetic ensemble in the pool, or records without metadata (no
        earthquake: the selection's rules and per-stripe counts need it),
        named, with where metadata come from.
    """
    from stochpound._errors import ExperimentError
    from stochpound.motions.records import SEARCH_RESULTS, record_metadata

    metadata, missing = {}, []
    for label, source in experiment.recorded_motions.items():
        if source.kind != "record":
            raise ExperimentError(f"{source.field}: the conditional-spectrum pool takes records and suites, not synthetic ensembles")
        record = source.motion["record"] if "record" in source.motion else None
        metadata[label] = record_metadata(str(record), experiment.base_dir) if record is not None else {}
        if not ("event" in metadata[label] and metadata[label]["event"]):
            missing.append(label)
    if missing:
        shown = ", ".join(missing[:5]) + (f" and {len(missing) - 5} more" if len(missing) > 5 else "")
        raise ExperimentError(f"records: the conditional-spectrum selection takes records with metadata (earthquake, magnitude, distance, Vs30), "
                              f"{len(missing)} have none: {shown} (use a named suite, or a folder of PEER downloads with its {SEARCH_RESULTS})")
    return metadata
