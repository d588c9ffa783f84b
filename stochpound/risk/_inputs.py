"""The risk chain's inputs: every read of an experiment store by the chain, in one module.

The chain needs, from a store: its definition's ``[intensity]`` and
``[hazard]`` entries, its studied building and the moat walls at that
building's base; its contact-free (and wall-free) cases, found by the gap
axes; and, per case, the peak contact closures, the inputs of the code
separation rules, the peak base displacements, the stored demands and the
summaries the limit states beyond first contact read, with
the motions (records, and the realizations of a synthetic ensemble) on one
``record`` dimension. Nothing else in :mod:`stochpound.risk` opens, selects
or parses a store, so a new way to read stores is a change of this module
alone. :func:`read_risk_inputs` reads what :func:`~stochpound.risk.store_risk`
needs once, into one frozen :class:`RiskInputs` that the chain's steps take
instead of the store.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from collections.abc import Mapping
from typing import Any

import numpy as np
import xarray as xr

from stochpound._plurals import counted
from stochpound.codes import store_contact_demands
from stochpound.hazard import HazardCurve, check_covers, hazard_curve, hazard_option, parse_units, stored_hazard, StatedMeasure
from stochpound.model import Scene
from stochpound.model.scene_tables import BuildingTable
from stochpound.motions import DEFAULT_G, TARGET_TOLERANCE, TRUNCATION_EPSILON
from stochpound.risk._assumptions import scene_assumptions, simulated_motions_text
from stochpound.risk._code_rules import MINIMUM_MOTIONS
from stochpound.store import (LIMIT_STATE_DEMANDS, Definition, Design, Intensity, Label, LimitStates, MuAxis, cases_done, check_finished as _check_finished, contact_free, gap_dims,
                              has_contact_free, has_wall_free, motions_that_ran, scenario_kind, scenario_ranges, wall_free, with_contacts)

CLOSURE = "peak_contact_closure"
"""The store's variable of per-case, per-contact peak closures (m)."""
CAPACITY = "ida_capacity"
"""The variable of an IDA store (its presence marks one)."""
SLIDING = "peak_sliding_displacement"
"""The store's variable of per-case, per-building peak base (sliding) displacements max|s| (m)."""
DEMANDS = {
    "peak_interstorey_drift": ("peak storey drift", "m", 1.0),
    "peak_floor_acceleration": ("peak floor acceleration", "g", 1.0 / DEFAULT_G),
}
"""Demands of a store with ``[output] demands = true`` given as hazard curves: (name, display units, factor from SI)."""
NOT_INTENSITY = "store: has no intensity stripes or IDA capacities (run an experiment with an [intensity] table)"
"""The error of a store without intensity-conditioned runs."""


CASE_DIMS = ("intensity", "record", "contact")
"""The dimensions of the contact-free demands that are not a configuration's (the stripes, the motions, the contacts)."""


class RiskInputError(ValueError):
    """A store cannot go through the risk chain (the message says why, in one line)."""


@dataclasses.dataclass(frozen=True)
class RiskInputs:
    """What the risk chain of :func:`~stochpound.risk.store_risk` reads of one store, read once (:func:`read_risk_inputs`).

    The chain's steps take it instead of the store: none of them goes back
    to the store.

    Attributes
    ----------
    setting : Intensity or None
        The store's ``[intensity]`` setting (its measure, units and levels).
    hazard : HazardCurve
        The site's hazard, in the store's intensity measure and units.
    studied : str or None
        The studied building (its suite-mean peak base displacement is the D_M-form rule, not D_TM).
    method : str
        ``"stripes"`` or ``"ida"``.
    closure : xarray.DataArray
        The largest contact-free peak closure over the contacts (m), one motion dimension ``record`` (:func:`contact_free_closure`).
    motion_intensity : xarray.DataArray or None
        IDA runs: each motion's intensity at scale 1 (IM units); None for stripes.
    motions : int
        The motions of every stripe: the fewest that ran in a stripe and configuration.
    stripes : int or None
        The intensity stripes that ran (None for IDA runs).
    progress : str
        ``288/704 cases done`` for a store with missing cases, "" for a finished one.
    experiment : str or None
        The store's experiment name.
    assumptions : dict of str to str
        What an answer rests on besides the hazard, in words (``assumptions``).
    design : Design or None
        The buildings' code design (the ``[design]`` table, given or the store's).
    demands : xarray.Dataset or None
        The inputs of the code separation rules of every contact-free case
        (``contact_free_demands``); read for stripes with a design or at
        least ``MINIMUM_MOTIONS`` (7) motions, else None.
    isolator : xarray.DataArray or None
        The studied building's wall-free peak base displacement (m) for the
        suite-mean D_TM (``free_base_displacement``); read with the suite-mean rules.
    dtm_note : str
        Why ``isolator`` is None though the rules were read ("" otherwise).
    scenes : dict
        The scene of each configuration of ``demands`` (keyed by its labels
        on the dimensions of ``demands["peak_closure"]`` other than
        ``CASE_DIMS``, in their order), for the design analysis; empty without a design.
    selection_misses : tuple of float
        The levels whose stripe's selection for the site misses its target (:func:`selection_misses`).
    unreachable_targets : tuple of float
        Of ``selection_misses``, the levels whose pool no set can meet the target from (:func:`unreachable_targets`).
    beyond_truncation : tuple of float
        The levels whose stripe's scenario puts them beyond the ground motion's truncation (:func:`stripes_beyond_truncation`).
    """

    setting: Intensity | None
    hazard: HazardCurve
    studied: str | None
    method: str
    closure: xr.DataArray
    motion_intensity: xr.DataArray | None
    motions: int
    stripes: int | None
    progress: str
    experiment: str | None
    assumptions: dict[str, str]
    design: Design | None
    demands: xr.Dataset | None
    isolator: xr.DataArray | None
    dtm_note: str
    scenes: dict[tuple[Any, ...], Scene]
    selection_misses: tuple[float, ...]
    unreachable_targets: tuple[float, ...]
    beyond_truncation: tuple[float, ...]


def read_risk_inputs(store: xr.Dataset, hazard: HazardCurve | None = None, *, studied: str | None = None,
                     design: Design | None = None, partial: bool = False) -> RiskInputs:
    """Read once what the risk chain needs of a store: its :class:`RiskInputs`.

    Parameters
    ----------
    store : xarray.Dataset
        An experiment store with intensity stripes (contact-free cases at ``gap = inf``) or IDA capacities.
    hazard : HazardCurve, optional
        The site's hazard; default the one the store carries (:func:`site_hazard`).
    studied : str, optional
        The building of the D_M-form rule; default the store's ``studied`` building.
    design : Design, optional
        The ``[design]`` table whose design analysis gives the codes' own gaps; default the store's.
    partial : bool
        Read the cases that ran of a store with missing cases; without it such a store is refused.

    Raises
    ------
    ValueError
        (``RiskInputError``) A store without stripes or IDA capacities, or
        without contact-free runs, or without a hazard when none is given;
        (``UnfinishedStoreError``) a store with missing cases without ``partial``.
    """
    check_finished(store, partial)
    hazard = site_hazard(store) if hazard is None else hazard
    studied = studied_building(store) if studied is None else studied
    closure = contact_free_closure(store)
    ida = is_ida(store)
    motions = stripe_motions(store, closure)
    design = design_entry(store) if design is None else design
    rules = not ida and motions >= MINIMUM_MOTIONS
    demands = contact_free_demands(store) if not ida and (rules or design is not None) else None
    isolator, dtm_note = free_base_displacement(store, studied) if rules else (None, "")
    read = {"setting": intensity_setting(store), "motion_intensity": motion_intensity(store) if ida else None,
            "stripes": stripes_run(store, closure), "progress": progress(store), "experiment": experiment_name(store),
            "assumptions": assumptions(store, _scenes_or_none(store, closure)), "selection_misses": tuple(selection_misses(store)),
            "unreachable_targets": tuple(unreachable_targets(store)), "beyond_truncation": tuple(stripes_beyond_truncation(store))}
    scenes = configuration_scenes(store, demands["peak_closure"]) if demands is not None and design is not None else {}
    return RiskInputs(hazard=hazard, studied=studied, method="ida" if ida else "stripes", closure=closure, motions=motions, design=design,
                      demands=demands, isolator=isolator, dtm_note=dtm_note, scenes=scenes, **read)


def intensity_setting(store: xr.Dataset) -> Intensity | None:
    """The definition's ``intensity`` entry of a store (None if it has none), through its ``pound`` accessor."""
    return store.pound.intensity


def has_risk(store: xr.Dataset) -> bool:
    """Whether a store can go through the risk chain at its own site: intensity levels (stripes or IDA) and a stored hazard."""
    return intensity_setting(store) is not None and stored_hazard(store) is not None and ("intensity" in store.dims or CAPACITY in store)


def site_hazard(store: xr.Dataset, hazard: str | None = None, option: str = "--hazard", *, measure: str | None = None,
                units: str | None = None, investigation_time: float | None = None, site: str | None = None,
                extrapolate: bool = False) -> HazardCurve:
    """The hazard of a store's site: the one it carries, or ``hazard`` (a bundled curve's name or a hazard-curve file, named by ``option``).

    Parameters
    ----------
    store : xarray.Dataset
        An experiment store with intensity levels.
    hazard : str, optional
        A bundled curve's name or a hazard-curve file (stochpound's CSV,
        OpenQuake's hazard-curve CSV, nshmp-haz's curve output); default: the
        hazard the store carries.
    option : str
        The name of ``hazard`` in error messages.
    measure, units : str, optional
        What the file's curve is of and its intensities' units, where the file does not say (e.g. ``"PSA(1.0 s, 5 %) in g"``, ``"m/s2"``).
    investigation_time : float, optional
        Years of a file of probabilities of exceedance, converted to annual rates.
    site : str, optional
        The site (row or name) of a file of several.
    extrapolate : bool
        Extend the table beyond its intensities as power laws (stated in its source).

    Raises
    ------
    ValueError
        (``RiskInputError``) The store has no intensity levels, or carries no
        hazard and none is given, or the file's description is given without
        a file; (``IntensityError``) the hazard is of another measure, misses
        the stripes without ``extrapolate``, or cannot be read.
    """
    setting = intensity_setting(store)
    if setting is None:
        raise RiskInputError(NOT_INTENSITY)
    stated = _stated(measure, units)
    if hazard is None and (stated != StatedMeasure() or investigation_time is not None or site is not None):
        raise RiskInputError(f"{option}-measure, {option}-units, --investigation-time and {option}-site describe a {option} file: give one")
    if hazard is not None:
        hz = hazard_option(hazard, setting.measure, setting.units, store.pound.definition.g, stated=stated, investigation_time=investigation_time,
                           site=site, extrapolate=extrapolate, option=option)
    else:
        entry = store.pound.hazard
        if entry is None:
            raise RiskInputError(f"{option}: the store carries no hazard (its experiment has no [hazard] table): give a hazard file or a "
                                 "bundled curve's name")
        hz = hazard_curve(entry, extrapolate=extrapolate or None)
    if "intensity" in store.dims:
        check_covers(hz, [float(x) for x in store["intensity"].values], option, "the store's intensity levels", "pass --extrapolate")
    return hz


def _stated(measure: str | None, units: str | None) -> StatedMeasure:
    """The hazard file's measure and units given beside it, parsed (parts not given: None)."""
    try:
        stated = StatedMeasure.parse(measure) if measure is not None else StatedMeasure()
        return dataclasses.replace(stated, units=parse_units(units)) if units is not None else stated
    except ValueError as error:
        raise RiskInputError(f"--hazard-{error}") from None


def studied_building(store: xr.Dataset) -> str | None:
    """The store's studied building (its experiment's ``studied``), or None."""
    return store.pound.definition.studied


def design_entry(store: xr.Dataset) -> Design | None:
    """The store's ``[design]`` entry, the buildings' code design (None without one)."""
    return store.pound.definition.design


def configuration_scene(store: xr.Dataset, labels: Mapping[str, Label]) -> Scene:
    """The scene of one configuration of a store (``labels`` on its variant and μ axes): its first contact-free case that ran.

    With motions selected per stripe, a motion runs only at the stripes that
    chose it: the first stripe and motion of a case that ran, not the first of each.
    """
    fixed = {dim: math.inf for dim in store.pound.gap_dims}
    motion_dims = [dim for dim in ("intensity", "record", "realization") if dim in store.dims]
    status = store["case_status"].sel({**fixed, **labels})
    ran = np.argwhere(status.transpose(*motion_dims).values == 1)
    if ran.size == 0:
        raise RiskInputError(f"store: no contact-free case of the configuration {dict(labels)} ran")
    fixed.update({dim: store[dim].values[index] for dim, index in zip(motion_dims, ran[0])})
    return store.pound.scene(**fixed, **labels)


def configuration_scenes(store: xr.Dataset, closure: xr.DataArray) -> dict[tuple[Any, ...], Scene]:
    """The scene of every configuration of ``closure`` (over a store's grid; :func:`configuration_scene`), keyed by its labels on
    the dimensions of ``closure`` other than :data:`CASE_DIMS`, in their order."""
    configs = [dim for dim in closure.dims if dim not in CASE_DIMS]
    return {labels: configuration_scene(store, dict(zip(configs, labels)))
            for labels in itertools.product(*(closure[dim].values for dim in configs))}


def store_definition(store: xr.Dataset) -> Definition:
    """The store's definition, typed (its every entry: ``to_dict()``), through its ``pound`` accessor."""
    return store.pound.definition


def experiment_name(store: xr.Dataset) -> str | None:
    """The store's experiment name, or None."""
    return store.attrs.get("experiment_name")


def _scenes_or_none(store: xr.Dataset, closure: xr.DataArray) -> dict[tuple[Any, ...], Scene]:
    """:func:`configuration_scenes` of ``closure``'s configurations, {} without contact-free cases (IDA runs at finite gaps) or
    where one has no contact-free case that ran (a partial store)."""
    if not has_contact_free(store):
        return {}
    try:
        return configuration_scenes(store, closure)
    except RiskInputError:
        return {}


def assumptions(store: xr.Dataset, scenes: Mapping[tuple[Any, ...], Scene] | None = None) -> dict[str, str]:
    """What a risk answer from ``store`` rests on, in words, from its definition: the structural model, the suite and its
    selection, and the scenario; with ``scenes`` (one per configuration: :func:`configuration_scenes`) the storeys, a sliding
    base's friction, the moat walls, the gap identity and the simulated motions that ran
    (``stochpound.risk._assumptions.scene_assumptions``)."""
    definition = store.pound.definition
    models = []
    for building in definition.tables.buildings:
        storey = "yielding (bilinear) storeys" if building.yields else "linear elastic storeys"
        models.append(f"{building.name}: {building.floors}-storey shear building, {storey}, on {_base_words(definition.mu, building)}")
    kinds = {"record": "records without a named suite", "synthetic": "synthetic ensembles"}
    ran = motions_that_ran(store) if "case_status" in store else {source.label for source in definition.motions}
    simulated = ran & {str(label) for label, kind in zip(store["record"].values, store["record_kind"].values) if kind == "simulated"} \
        if "record_kind" in store.coords else set()
    sources = [source for source in definition.motions if source.label in ran]
    suites = sorted({source.suite or kinds.get(source.kind, source.kind) for source in sources}) + (["simulated"] if simulated else [])
    count, pool = sum(source.count for source in sources) + len(simulated), sum(source.count for source in definition.motions)
    selection = definition.intensity.selection if definition.intensity is not None else None
    generated = selection.simulated if selection is not None else None
    pool_words = f"{pool} records" + (f" and {generated.pool_words}" if generated else "")
    suite = (f"{counted(count, 'motion')} ran ({', '.join(suites)}), "
             + (f"selected per stripe by {selection.method.replace('_', ' ')} from a pool of {pool_words}" if selection
                else "every motion scaled to every stripe (no selection)"))
    scenario = _scenario_words(store, scenario_kind(store)) if selection and selection.scenarios else ""
    said = simulated_motions_text(len(simulated), count, generated.model, generated.calibration) if simulated and generated else ""
    return {"structural model": "; ".join(models), **scene_assumptions(scenes or {}), "suite": suite,
            **({"simulated motions": said} if said else {}),
            "scenario": scenario or "none stated (the motions are not selected for a scenario)", **_selection_fit(store)}


def _selection_fit(store: xr.Dataset) -> dict[str, str]:
    """{"selection fit": ...} naming the stripes whose chosen motions miss their conditional-spectrum target and those its
    scenario puts beyond the truncation ε, which the answer still takes as the site's motions, and {"selection rule": ...}
    naming those whose set ``tolerance_first`` chose; {} where there are none."""
    misses, beyond = selection_misses(store), stripes_beyond_truncation(store)
    intensity = store.pound.definition.intensity
    units = f" {intensity.units}" if intensity is not None and intensity.units else ""
    unreachable = unreachable_targets(store)
    tolerance = tolerance_first_stripes(store)
    said = ([f"the motions chosen at the stripes {', '.join(f'{level:.4g}' for level in misses)}{units} miss their conditional-spectrum "
             f"target (mean or standard deviation of ln Sa off by more than {TARGET_TOLERANCE:g} at a period)"] if misses else []) + (
            [f"at the stripes {', '.join(f'{level:.4g}' for level in unreachable)}{units} no set of the pool's motions can meet the target "
             f"within {TARGET_TOLERANCE:g} (linear-programming bounds over the pool under the selection's rules): the miss is the pool's, whose motions "
             "lack the target's spectral shape there"] if unreachable else []) + (
            [f"the scenario puts the stripes {', '.join(f'{level:.4g}' for level in beyond)}{units} beyond ε {TRUNCATION_EPSILON:g}, "
             "where hazard models truncate the ground motion"] if beyond else [])
    chosen = ([f"the motions of the stripes {', '.join(f'{level:.4g}' for level in tolerance)}{units} were chosen with the tolerance first "
               f"([intensity] tolerance_first): within {TARGET_TOLERANCE:g} of the target at every period, where the set of least misfit "
               "missed, at the cost of a set nearer the tolerance's edge at other periods"] if tolerance else [])
    fit = {"selection fit": "; ".join(said) + ": the answer takes those stripes' motions as the site's there"} if said else {}
    return fit | ({"selection rule": "; ".join(chosen)} if chosen else {})


def tolerance_first_stripes(store: xr.Dataset) -> list[float]:
    """The levels (in the levels' units) whose stripe's set ``[intensity] tolerance_first`` chose (``selection_tolerance_first``); [] for a
    store without it."""
    if "selection_tolerance_first" not in store:
        return []
    return [float(level) for level, flag in zip(store["intensity"].values, store["selection_tolerance_first"].values) if flag]


def _base_words(mu: MuAxis | None, building: BuildingTable) -> str:
    """A building's base in words, as the grid's μ axis leaves it (the axis may fix a base or set its μ)."""
    has_base = "base" in building.table
    if mu is None or not mu.sets(building.name, has_base):
        return "a sliding base" if has_base else "a fixed base"
    if not mu.finite_values:
        return "a fixed base (μ = ∞ on the grid)"
    sliding = f"a sliding base (μ {', '.join(f'{v:g}' for v in mu.finite_values)} on the grid)"
    return f"{sliding} or a fixed base" if mu.has_fixed_base else sliding


def _scenario_words(store: xr.Dataset, kind: str | None) -> str:
    """The stripes' scenario in words: its values as stored, and how it was obtained (``kind``, the definition's ``site.scenario``)."""
    words = {"fitted": "fitted to the site's hazard curves (a calibration standing in for a disaggregation)",
             "given": "as the [site] table gives it (an assumption unless it comes from the site's disaggregation)",
             "ruptures": "the exact conditional spectrum of the site's ruptures (their mixture by the shares at each level; M and R its means)",
             None: "how it was obtained is not recorded (a store written before the definition kept it)"}[kind]
    ranges = scenario_ranges(store)
    return words if ranges is None else f"{ranges}, {words}"


def stripes(store: xr.Dataset) -> int | None:
    """The number of intensity stripes of a store (None for IDA runs)."""
    return store.sizes["intensity"] if "intensity" in store.dims else None


def is_ida(store: xr.Dataset) -> bool:
    """True for a store of IDA runs (``ida_capacity``, no intensity stripes); raises for a store with neither."""
    if "intensity" in store.dims:
        return False
    if CAPACITY in store:
        return True
    raise RiskInputError(NOT_INTENSITY)


def store_motions(data: xr.DataArray, record_dim: str = "record", realization_dim: str = "realization") -> xr.DataArray:
    """``data`` with one motion dimension ``record_dim``: a single realization dropped, several merged into the records."""
    if realization_dim not in data.dims:
        return data
    if data.sizes[realization_dim] == 1:
        return data.isel({realization_dim: 0}, drop=True)
    per_record = [name for name, coord in data.coords.items() if set(coord.dims) & {record_dim, realization_dim}]
    stacked = data.drop_vars(per_record).stack(_motion=(record_dim, realization_dim))
    labels = [f"{record}/{realization}" for record, realization in zip(data[record_dim].values.repeat(data.sizes[realization_dim]),
                                                                        np.tile(data[realization_dim].values, data.sizes[record_dim]))]
    stacked = stacked.drop_vars(["_motion", record_dim, realization_dim]).rename(_motion=record_dim)
    return stacked.assign_coords({record_dim: labels})


def contact_free_closure(store: xr.Dataset, contact_dim: str = "contact") -> xr.DataArray:
    """The largest peak closure over the contacts of every contact-free case of a store (m), one motion dimension ``record``.

    The contact-free cases are those at ``inf`` on every gap axis; in an
    IDA store every case runs contact-free, and the first gap's are taken.
    """
    if CLOSURE not in store:
        raise RiskInputError(f"store: has no {CLOSURE!r}")
    closure = store[CLOSURE]
    gaps = gap_dims(closure)
    if gaps and CAPACITY in store and "intensity" not in store.dims:
        closure = closure.isel({dim: 0 for dim in gaps}, drop=True)
    elif gaps and not has_contact_free(closure):
        raise RiskInputError(f"store: no contact-free cases (inf on every gap axis: {', '.join(gaps)}): add inf to the gaps")
    else:
        closure = contact_free(closure)
    if contact_dim in closure.dims:
        closure = closure.max(contact_dim, skipna=False)
    return store_motions(closure).load().assign_attrs(units="m", long_name="largest contact-free peak closure over the contacts")


def check_finished(store: xr.Dataset, partial: bool) -> None:
    """Refuse a store with missing cases unless ``partial`` (``UnfinishedStoreError``, naming the store's experiment)."""
    _check_finished(store, experiment_name(store) or "store", partial, option="--partial (partial=True from Python)")


def progress(store: xr.Dataset) -> str:
    """``288/704 cases done`` for a store with missing cases, "" for a finished one."""
    done, total = cases_done(store)
    return f"{done}/{total} cases done" if done < total else ""


def stripe_motions(store: xr.Dataset, closure: xr.DataArray) -> int:
    """The motions of every stripe: all of the store's (``closure``'s ``record``), the fewest chosen per stripe by a selection for
    the site, and of a store with missing cases the fewest that ran in a stripe and configuration (a contact-free closure)."""
    motions = closure.sizes["record"]
    if "selection_scale_factor" in store:
        motions = int(np.isfinite(store["selection_scale_factor"]).sum("record").min())
    if progress(store):
        motions = min(motions, int(closure.notnull().sum("record").min()))
    return motions


def stripes_run(store: xr.Dataset, closure: xr.DataArray) -> int | None:
    """The store's intensity stripes (None for IDA runs); of a store with missing cases, those with a contact-free run (``closure``)."""
    if stripes(store) is None or not progress(store):
        return stripes(store)
    return int(closure.notnull().any([d for d in closure.dims if d != "intensity"]).sum())


def selection_misses(store: xr.Dataset) -> list[float]:
    """The levels (in the levels' units) whose stripe's selection for the site misses its target (``selection_misses_target``); [] without a selection."""
    if "selection_misses_target" not in store:
        return []
    flags = store["selection_misses_target"].values.astype(bool)
    return [float(level) for level, flag in zip(store["intensity"].values, flags) if flag]


def unreachable_targets(store: xr.Dataset) -> list[float]:
    """The levels (in the levels' units) whose stripe misses its target and whose pool cannot meet it at all
    (``selection_target_reachable`` 0: no set of the pool can, by linear-programming bounds); [] for a store that does not say."""
    if "selection_target_reachable" not in store:
        return []
    unreachable = dict(zip(store["intensity"].values, store["selection_target_reachable"].values == 0))
    return [level for level in selection_misses(store) if unreachable[level]]


def stripes_beyond_truncation(store: xr.Dataset) -> list[float]:
    """The levels (in the levels' units) whose stripe's scenario puts them beyond ε :data:`~stochpound.motions.TRUNCATION_EPSILON`.

    Where hazard models truncate the ground motion (the USGS models of the
    bundled curves, at 3σ), no earthquake of that scenario causes such a
    level: the stripe stands for larger or nearer ones. [] without a
    selection for the site (``target_epsilon``).
    """
    if "target_epsilon" not in store:
        return []
    return [float(level) for level, epsilon in zip(store["intensity"].values, store["target_epsilon"].values) if epsilon > TRUNCATION_EPSILON]


def motion_intensity(store: xr.Dataset) -> xr.DataArray:
    """The intensity of every motion of an IDA store at scale 1 (in the units of its levels), one motion dimension ``record``."""
    intensity = store["motion_intensity"]
    return store_motions(intensity.isel(gap=0, drop=True) if "gap" in intensity.dims else intensity).load()


def contact_free_demands(store: xr.Dataset) -> xr.Dataset:
    """The inputs of the code separation rules of every contact-free case (:func:`~stochpound.analysis.store_contact_demands`)."""
    return xr.Dataset({name: store_motions(value) for name, value in store_contact_demands(contact_free(store)).items()}).load()


def has_walls(store: xr.Dataset) -> bool:
    """Whether a store's scene (or one of its variants) has a wall: without one, the walls' stiffness is no choice its answer rests on."""
    definition = store.pound.definition
    return bool(definition.tables.walls) or any(override.scene.walls for variant in definition.variants for override in variant.edits.values())


def base_displacement(store: xr.Dataset, studied: str | None, walls_free: bool = False) -> xr.DataArray | None:
    """A building's peak base displacement max|s| in every contact-free (and, with ``walls_free``, wall-free) case (m, one motion dimension).

    NaN in the configurations where it never slides; None when it slides
    in none (or the store has no such building or variable).
    """
    free = contact_free(store)
    free = wall_free(free) if walls_free else free
    if SLIDING not in free or studied is None or studied not in free["building"].values:
        return None
    sliding = store_motions(free[SLIDING].sel(building=studied, drop=True)).load()
    slides = (sliding > 0.0).any(["intensity", "record"])
    if not bool(slides.any()):
        return None
    return sliding.where(slides)


WALL_CLOSURE = "largest_wall_closure"
"""The store's per-case closure toward a wall (m; NaN in a case without walls)."""


def walled_configurations(store: xr.Dataset) -> xr.DataArray | None:
    """Per configuration of the contact-free runs (every grid label but the gap axes, the stripes and the motions), whether its
    runs have a moat wall (their closure toward a wall is known); None for a store without walls in any configuration."""
    if WALL_CLOSURE not in store:
        return None
    closure = store_motions(contact_free(store)[WALL_CLOSURE])
    walled = np.isfinite(closure).any([dim for dim in ("intensity", "record") if dim in closure.dims])
    return walled.reset_coords(drop=True) if bool(walled.any()) else None


def free_base_displacement(store: xr.Dataset, studied: str | None) -> tuple[xr.DataArray | None, str]:
    """The studied building's wall-free peak base displacement for the D_M-form rule (:func:`base_displacement`), or None and why not.

    A moat wall caps the displacement the rule is to size: with walls at its
    base, each configuration takes the displacement of its wall-free twin
    (``inf`` on the wall axes, or the value of a variant axis that sets no
    wall), and without one there is none ("" as the reason where the
    building simply does not slide).
    """
    if moat_clearances(store, studied) and not has_wall_free(store):
        axis = _wall_free_variant(store, studied)
        if axis is None:
            return None, ("the store has no wall-free runs (a moat wall caps the displacement the rule is to size): add inf to the wall axis, "
                          "or a variant without the wall")
        name, free = axis
        displacement = base_displacement(store.sel({name: free}), studied)
        return (None if displacement is None else displacement.expand_dims({name: store[name].values})), ""
    return base_displacement(store, studied, walls_free=True), ""


def _wall_free_variant(store: xr.Dataset, studied: str | None) -> tuple[str, str] | None:
    """A variant axis whose values alone set the walls at the studied building's base, with its value that sets none (the
    wall-free twin of the others: D_TM is the displacement without the wall), or None (walls in the base scene, or no such axis)."""
    definition = store.pound.definition
    if any(wall.at_base_of(studied) for wall in definition.tables.walls):
        return None
    for variant in definition.variants:
        edits = variant.edits
        walled = {value: value in edits and any(wall.at_base_of(studied) for wall in edits[value].scene.walls) for value in variant.values}
        free = [value for value, has in walled.items() if not has]
        if free and len(free) < len(walled) and variant.name in store.dims:
            return variant.name, free[0]
    return None


def stored_demands(store: xr.Dataset) -> dict[str, tuple[xr.DataArray, str]]:
    """The stored demands of every case without impacts (contacts open, walls never reached): label → (values, display units).

    Storey drift (m) and floor acceleration (g) of every building, one
    motion dimension; empty without ``[output] demands = true``.
    """
    free = wall_free(contact_free(store))
    return {f"{label} of {building}": (store_motions(free[variable].sel(building=building, drop=True)) * factor, units)
            for variable, (label, units, factor) in DEMANDS.items() if variable in free for building in free["building"].values}


def demand_drift(store: xr.Dataset) -> xr.DataArray | None:
    """The peak storey drift ratio of every case the demand curves read (without impacts: contact-free and wall-free), one
    motion dimension ``record`` (over ``building``); None without it."""
    free = wall_free(contact_free(store))
    return store_motions(free["peak_drift_ratio"]).load() if "peak_drift_ratio" in free else None


def moat_clearances(store: xr.Dataset, studied: str | None) -> list[float]:
    """The distinct gaps of the walls at the studied building's base in the definition (its scene, with the values of a gap axis
    that sets a wall instead of its own gap, and its variants), finite ones only."""
    definition = store.pound.definition
    walls = [(wall, axis.values if axis is not None else (wall.gap,)) for wall, axis in
             ((wall, definition.wall_gap_axis(index)) for index, wall in enumerate(definition.tables.walls))]
    for variant in definition.variants:
        walls += [(wall, (wall.gap,)) for override in variant.edits.values() for wall in override.scene.walls]
    return sorted({float(gap) for wall, gaps in walls for gap in gaps if wall.at_base_of(studied) and math.isfinite(float(gap))})


@dataclasses.dataclass(frozen=True)
class EfficiencyRuns:
    """What measure efficiency reads of a stripes (contact-free cases) or IDA store, every motion on one dimension ``record``.

    Attributes
    ----------
    responses : mapping of str to xarray.DataArray
        ``closure`` (peak closure, m), and ``base_displacement`` of a sliding studied building (m, stripes only).
    scale_factor : xarray.DataArray
        Each run's scale factor.
    psa : xarray.DataArray
        Each motion's PSA over ``spectrum_period`` at scale 1 (g).
    spectrum_periods : numpy.ndarray
        The periods of ``psa``, s.
    pga, pgv : xarray.DataArray
        Each motion's PGA and PGV at scale 1.
    intensity : xarray.DataArray
        Each motion's value of the store's own measure at scale 1.
    conditioning : float or None
        The store's measure's period T*, s, when it is 5 %-damped PSA in g; else None.
    covariates : mapping of str to xarray.DataArray
        ``record_magnitude`` and ``record_distance`` where the store has them.
    """

    responses: Mapping[str, xr.DataArray]
    scale_factor: xr.DataArray
    psa: xr.DataArray
    spectrum_periods: np.ndarray
    pga: xr.DataArray
    pgv: xr.DataArray
    intensity: xr.DataArray
    conditioning: float | None
    covariates: Mapping[str, xr.DataArray]


def efficiency_runs(store: xr.Dataset, studied: str | None) -> EfficiencyRuns:
    """What measure efficiency reads of a stripes (contact-free cases) or IDA store (:class:`EfficiencyRuns`), every motion on one dimension ``record``."""
    free = store.isel({d: 0 for d in gap_dims(store)}) if is_ida(store) else contact_free(store)
    responses = {"closure": contact_free_closure(store).load()}  # read once: every candidate measure is fitted to them
    sliding = None if is_ida(store) else base_displacement(free, studied)
    if sliding is not None:
        responses["base_displacement"] = sliding.load()
    setting = intensity_setting(store)
    psa_in_g = setting is not None and setting.measure.kind == "psa" and setting.measure.damping == 0.05 and setting.units == "g"
    return EfficiencyRuns(
        responses=responses,
        scale_factor=store_motions(free["scale_factor"]).load(),
        psa=store_motions(free["motion_psa"]).load(),
        spectrum_periods=free["spectrum_period"].values,
        pga=store_motions(free["motion_pga"]).load(),
        pgv=store_motions(free["motion_pgv"]).load(),
        intensity=store_motions(free["motion_intensity"]).load(),
        conditioning=float(setting.measure.period) if psa_in_g else None,
        covariates={name: store_motions(free[name]).load() for name in ("record_magnitude", "record_distance") if name in free.coords},
    )


def scene_g(store: xr.Dataset) -> float:
    """The acceleration of gravity of the store's scene, m/s²."""
    return store.pound.definition.g


def case_demand(store: xr.Dataset, variable: str, building: str | None, needs: str) -> xr.DataArray:
    """A per-case summary of every case of a store, its gap axes kept, one motion dimension ``record``.

    With a ``building`` dimension: that ``building``'s value, or (None) the
    largest over the buildings. ``needs`` says, in the error of a store
    without ``variable``, what the experiment must have to keep it.
    """
    if variable not in store:
        raise RiskInputError(f"store: has no {variable!r} (it needs {needs})")
    data = store[variable]
    if "building" in data.dims:
        names = [str(b) for b in data["building"].values]
        if building is not None and building not in names:
            raise RiskInputError(f"limit_states: building {building!r} is not one of the store's ({', '.join(names)})")
        data = data.max("building") if building is None else data.sel(building=building, drop=True)
    return store_motions(data).load().assign_attrs(units=store[variable].attrs.get("units", ""))


def limit_state_inputs(store: xr.Dataset, demands: list[tuple[str, str | None, str, bool]],
                       hazard: HazardCurve | None = None) -> tuple[HazardCurve, list[xr.DataArray], str]:
    """What :func:`~stochpound.risk.limit_state_risk` reads of a stripes store, read once: the site's hazard (``hazard``, or the
    store's), each limit state's demand (``demands``: its variable, building, what the store needs to keep it, and whether it is
    given in g: :func:`case_demand`, divided by the scene's g) and the intensity measure in words.

    Raises
    ------
    ValueError
        (``RiskInputError``) A store without stripes or hazard, or without a demand's variable or building.
    """
    if stripes(store) is None:
        raise RiskInputError("store: limit states need intensity stripes (run method = \"stripes\")")
    hazard = site_hazard(store) if hazard is None else hazard
    read = []
    for variable, building, needs, in_g in demands:
        demand = case_demand(store, variable, building, needs)
        read.append(demand / scene_g(store) if in_g else demand)
    return hazard, read, intensity_setting(store).description


def limit_state_variable(kind: str) -> str:
    """The per-case store summary a kind of limit state reads (``stochpound.store.LIMIT_STATE_DEMANDS``)."""
    return LIMIT_STATE_DEMANDS[kind]


def limit_states_table(store: xr.Dataset) -> LimitStates | None:
    """The experiment's ``[limit_states]`` entry (``source``, ``capacities``), or None without one."""
    return store.pound.definition.limit_states


def holds(store: xr.Dataset, variable: str) -> bool:
    """Whether the store has ``variable`` with at least one finite value."""
    return variable in store and bool(np.isfinite(store[variable]).any())


def stripe_levels(store: xr.Dataset) -> np.ndarray:
    """The levels of a stripes store's ``intensity`` dimension (IM units)."""
    return np.asarray(store["intensity"].values, dtype=float)


def run_summaries(store: xr.Dataset, variables: list[str]) -> tuple[dict[str, xr.DataArray], bool]:
    """Per-case summaries over the store's contact-free runs where it has them (else every run), one motion dimension ``record``.

    Returns the summaries held (with their units) and whether the runs are the contact-free ones.
    """
    free = has_contact_free(store)
    runs = contact_free(store) if free else store
    return {name: store_motions(runs[name]).load().assign_attrs(units=store[name].attrs.get("units", "")) for name in variables if name in store}, free


def contact_free_part(data: xr.Dataset) -> xr.Dataset:
    """The contact-free configurations of ``data`` (over a store's grid; ``data`` itself without contact axes)."""
    return contact_free(data)


def at_finite_gaps(data: xr.Dataset) -> xr.Dataset:
    """The configurations of ``data`` (over a store's grid) at finite gaps: its contact-free ones left out."""
    return with_contacts(data)


def contact_free_twins(data: xr.DataArray) -> xr.DataArray | None:
    """Each configuration's contact-free twin in ``data`` (``inf`` on every contact axis, broadcast over them), or None without them."""
    return contact_free(data).broadcast_like(data) if has_contact_free(data) else None


@dataclasses.dataclass(frozen=True)
class StripeSpectraRuns:
    """What the site-consistency check reads of a stripes store.

    Attributes
    ----------
    bundled : str or None
        The store's bundled hazard curve's name (None where its hazard is not a bundled curve).
    hazard : HazardCurve
        The hazard of the stripes' measure: the store's, or the one given.
    scale_factor : xarray.DataArray
        Per ``intensity`` and ``record``; NaN where the motion did not run in the stripe.
    pga : xarray.DataArray
        Each motion's PGA at scale 1, m/s².
    psa : xarray.DataArray
        Each motion's PSA over ``spectrum_period`` at scale 1, m/s².
    spectrum_periods : numpy.ndarray
        The periods of ``psa``, s.
    g : float
        The scene's acceleration of gravity, m/s².
    """

    bundled: str | None
    hazard: HazardCurve
    scale_factor: xr.DataArray
    pga: xr.DataArray
    psa: xr.DataArray
    spectrum_periods: np.ndarray
    g: float


def stripe_spectra_runs(store: xr.Dataset, hazard: HazardCurve | None = None) -> StripeSpectraRuns | None:
    """What the site-consistency check reads of a stripes store (:class:`StripeSpectraRuns`), its stripes' hazard the store's
    or ``hazard``; None for a store without stripes or spectra, or without a hazard of its own when ``hazard`` is not given."""
    entry = store.pound.hazard
    if "intensity" not in store.dims or "motion_psa" not in store or (entry is None and hazard is None):
        return None
    keep = ("intensity", "record", "realization", "spectrum_period")

    def first(name: str) -> xr.DataArray:
        return store[name].isel({d: 0 for d in store[name].dims if d not in keep})

    ran = (store["case_status"] == 1).any([d for d in store["case_status"].dims if d not in keep])
    return StripeSpectraRuns(
        bundled=entry.bundled if entry is not None else None,
        hazard=hazard if hazard is not None else site_hazard(store),
        scale_factor=store_motions(first("scale_factor").where(ran)),
        pga=store_motions(first("motion_pga")),
        psa=store_motions(first("motion_psa")),
        spectrum_periods=store["spectrum_period"].values,
        g=scene_g(store),
    )
