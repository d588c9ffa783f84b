"""Experiments conditioned on intensity: the ``[intensity]`` table, scaling, stripes and IDA.

An ``[intensity]`` table (docs/intensity.md) scales every motion to target
levels of an intensity measure (``pga``, ``pgv``, ``psa`` at a period,
``sa_avg`` over periods):

* **stripes** (multi-stripe analysis): the levels are a grid dimension,
  ``intensity``; the case at level x runs the motion scaled by
  x / IM, IM the motion's own (unscaled) measure. A synthetic ensemble is
  scaled realization by realization, each exactly to the level
  (``synthetic = "each"``, the default), or every realization by x / E[IM],
  E[IM] the mean measure of the ensemble's realizations in the experiment
  (``synthetic = "expected"``: the realizations keep their scatter of
  intensity around the level).
* **ida**: where the scene's contact-free response is homogeneous in the
  input (fixed bases, no initial displacement or velocity, no walls), a
  motion scaled by λ closes every contact by λ D, D its closure at scale 1;
  so motion i first pounds at gap g at the intensity IM_i · g / D_i. Every
  case then runs once, contact-free (every contact's gap infinite), and the
  store gets that capacity per motion and gap (``ida_capacity``). When the
  scene is not homogeneous (a sliding base, say), stripes run instead; the
  definition's ``intensity.ran`` and ``intensity.note`` say which and why.

Every case also stores its motion's unscaled measures (``motion_*``, the
response spectrum over ``spectrum_period``) and its ``scale_factor``.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

from stochpound.model import fields as toml_fields
from stochpound.experiment._site import parse_selection
from stochpound.motions import arias_intensity, peak_ground_motion, response_spectrum, significant_duration
from stochpound._errors import IntensityError
from stochpound.motions import MODEL_DAMPING, Measure
from stochpound.store import MEASURES, ExperimentGrid, GapAxis, Intensity, Label, MuAxis, TomlTable, VariantAxis

INTENSITY_METHODS = ("stripes", "ida")
"""The methods of an ``[intensity]`` table: multi-stripe analysis, or incremental dynamic analysis where the scene allows it."""
UNITS = {"pga": ("g", "m/s2"), "psa": ("g", "m/s2"), "sa_avg": ("g", "m/s2"), "pgv": ("m/s", "cm/s")}
"""Units of ``levels`` allowed for each measure (the first is the default)."""
SYNTHETIC_SCALING = ("each", "expected")
"""How a synthetic ensemble is scaled: each realization exactly to the level, or all by the level over the ensemble's mean measure."""
ENSEMBLE_CHUNK = 256
"""Realizations generated at once for an ensemble's mean measure."""
PERIOD_SAMPLES = 2.0
"""Shortest period of a spectral measure, in steps of the motion: T ≥ 2·dt, the Nyquist period.

A sampled motion carries no information at frequencies above 1/(2 dt); an
oscillator tuned above it responds to the interpolation between samples,
not to the recorded ground motion."""
SPECTRUM_PERIODS = np.geomspace(0.05, 5.0, 25)
"""Periods (s) of the unscaled spectrum stored for every motion (5 % damping)."""
SPECTRUM_DAMPING = MODEL_DAMPING
"""Damping ratio of the stored spectrum: the ground-motion models' 5 % (what the risk's site-consistency check reads it at)."""
CaseVariables = dict[str, float | np.ndarray]
"""A case's per-case variables by store name (:data:`SUMMARIES`): numbers, and arrays (``motion_psa`` over :data:`SPECTRUM_PERIODS`)."""
_KEYS = {"measure", "period", "periods", "damping", "levels", "units", "method", "synthetic", "selection", "motions", "max_scale_factor", "seed",
         "max_per_earthquake", "exclude_pulses", "tolerance_first"}

#: Per-case variables of an intensity-conditioned store: units and long names (units of levels filled in).
SUMMARIES: dict[str, tuple[str, str]] = {
    "scale_factor": ("1", "factor applied to the motion to reach the case's intensity level"),
    "motion_intensity": ("{units}", "the motion's own (unscaled) intensity measure {measure}"),
    "motion_pga": ("m/s2", "peak ground acceleration of the unscaled motion"),
    "motion_pgv": ("m/s", "peak ground velocity of the unscaled motion"),
    "motion_pgd": ("m", "peak ground displacement of the unscaled motion"),
    "motion_arias_intensity": ("m/s", "Arias intensity of the unscaled motion"),
    "motion_significant_duration": ("s", "significant duration D5-95 of the unscaled motion"),
    "motion_psa": ("m/s2", "pseudo-spectral acceleration (5 % damping) of the unscaled motion"),
    "ida_capacity": ("{units}", "IDA pounding capacity: intensity at which the motion first closes the gap (contact-free run)"),
}


def parse_intensity(file: TomlTable, scene: TomlTable, variants: Sequence[VariantAxis], gaps: Sequence[GapAxis], mu: MuAxis | None,
                    base_dir: Path = Path(".")) -> Intensity | None:
    """The ``[intensity]`` setting of a definition, typed (None without an ``[intensity]`` table).

    ``file`` is the experiment file's top level and ``scene`` its base scene;
    ``base_dir`` is the experiment file's folder (a ``[site]`` rupture table's path is relative to it).

    Raises
    ------
    IntensityError, SceneError
        Naming the field: an unknown measure, method or unit, a period ≤ 0,
        levels not > 0, ``ida`` without a gap axis.
    """
    site = file.raw("site")
    if "intensity" not in file:
        if site is not None:
            raise IntensityError("site: only with an [intensity] table whose selection is conditional_spectrum")
        return None
    if not isinstance(file.raw("intensity"), dict):
        raise IntensityError("intensity: must be a table (measure, levels, ...)")
    table = file.table("intensity", _KEYS)
    measure = table.string("measure", choices=MEASURES)
    period, periods, damping = None, (), None
    if measure == "psa":
        period = table.number("period", low=0.0, low_open=True)
    elif measure == "sa_avg":
        periods = _periods(table.raw("periods"))
    for key, given in (("period", period is not None), ("periods", bool(periods))):
        if key in table and not given:
            raise IntensityError(f"intensity.{key}: only for measure = {'psa' if key == 'period' else 'sa_avg'}")
    if measure in ("psa", "sa_avg"):
        damping = table.number("damping", SPECTRUM_DAMPING, low=0.0, high=1.0, high_open=True)
    levels = _levels(table.raw("levels"))
    units = table.string("units", UNITS[measure][0], choices=UNITS[measure], hint=f"for {measure}")
    method = table.string("method", "stripes", choices=INTENSITY_METHODS)
    synthetic = table.string("synthetic", SYNTHETIC_SCALING[0], choices=SYNTHETIC_SCALING,
                             hint="each realization scaled to the level, or all by the level over the ensemble's mean measure")
    ran, note = _method_run(method, scene, variants, gaps, mu)
    try:
        scaled_measure = Measure(measure, period, periods, damping)
    except ValueError as error:
        raise IntensityError(f"intensity.{error}") from None
    setting = Intensity(scaled_measure, units, tuple(sorted(float(level) for level in levels)), method, ran, note,
                        synthetic)
    chosen = parse_selection(table.values, site, levels, setting, base_dir)
    if chosen is None:
        return setting
    selection, note = chosen
    return dataclasses.replace(setting, note=note, selection=selection)


def _periods(periods: object) -> tuple[float, ...]:
    """``intensity.periods`` of ``sa_avg``: at least 2 finite periods > 0 s."""
    if not isinstance(periods, list) or len(periods) < 2 or not all(toml_fields.is_number(p) and math.isfinite(p) and p > 0 for p in periods):
        raise IntensityError(f"intensity.periods: must be a list of at least 2 periods > 0 s (e.g. log-spaced over 0.2-3 T1), got {periods!r}")
    return tuple(float(p) for p in periods)


def _levels(levels: object) -> list[float]:
    """``intensity.levels``: a non-empty list of distinct finite levels > 0, as the file lists them."""
    if not isinstance(levels, list) or not levels:
        raise IntensityError(f"intensity.levels: must be a non-empty list of levels > 0, got {levels!r}")
    for i, level in enumerate(levels):
        if not toml_fields.is_number(level) or not math.isfinite(level) or level <= 0:
            raise IntensityError(f"intensity.levels[{i}]: must be > 0, got {level!r}")
    if len(set(levels)) != len(levels):
        raise IntensityError("intensity.levels: repeated level")
    return levels


def _method_run(method: str, scene: TomlTable, variants: Sequence[VariantAxis], gaps: Sequence[GapAxis], mu: MuAxis | None) -> tuple[str, str]:
    """The method that runs and why (IDA needs a homogeneous contact-free response and a gap axis)."""
    if method == "stripes":
        return "stripes", "every motion scaled to every level"
    if not gaps:
        raise IntensityError("intensity.method: ida needs a gap axis (grid.gap = [...]): its capacities are per gap")
    for where, building in _building_tables(scene, variants):
        if "yield_force" in building:
            raise IntensityError(f'intensity.method: ida needs elastic storeys, {where} has yield_force (yielding is not homogeneous in the input): '
                                 'run method = "stripes"')
    reason = inhomogeneity(scene, variants, mu)
    if reason:
        return "stripes", f"ida requested, stripes run: the contact-free response is not homogeneous in the input ({reason})"
    return "ida", "one contact-free run per motion; capacity IM·g/D per gap (homogeneous scene: fixed bases, at rest, no walls)"


def inhomogeneity(scene: TomlTable, variants: Sequence[VariantAxis], mu: MuAxis | None) -> str:
    """Why a scene's contact-free response is not homogeneous in the input ("" if it is)."""
    if scene.raw("wall"):
        return "the scene has walls"
    if mu is not None and mu.finite_values:
        return "grid.mu has finite friction coefficients (sliding bases)"
    for where, building in _building_tables(scene, variants):
        if isinstance(building.raw("base"), dict) and (mu is None or mu.finite_values):
            return f"{where}: a building on a sliding base"
        if building.raw("initial"):
            return f"{where}: a building not at rest at t = 0"
    return ""


def _building_tables(scene: TomlTable, variants: Sequence[VariantAxis]) -> list[tuple[str, TomlTable]]:
    """Every ``[[building]]`` table of a scene and of its variants' overrides, with where it is."""
    tables = [("scene", building) for building in scene.tables("building")]
    for variant in variants:
        for value, override in variant.overrides.items():
            where = f"variants.{variant.name}.{value}"
            edits = TomlTable(override, where).table_or_empty("building")
            tables += [(where, edits.table(name)) for name in edits]
    return tables


@dataclass(frozen=True)
class Scaling:
    """What a worker needs to scale an experiment's cases (:func:`task_settings`).

    Attributes
    ----------
    intensity : Intensity
        The ``[intensity]`` setting.
    g : float
        The scene's g, m/s².
    gap_axes : tuple of (str, tuple of int)
        Each gap axis's name and the contacts it sets.
    expected : mapping of int to float
        By motion number, an ensemble's mean measure (units of the levels), for ``[intensity] synthetic = "expected"``.
    """

    intensity: Intensity
    g: float
    gap_axes: tuple[tuple[str, tuple[int, ...]], ...]
    expected: Mapping[int, float]

    @property
    def ran(self) -> str:
        """The method that runs: ``stripes`` or ``ida``."""
        return self.intensity.ran


def level_to_si(intensity: Intensity, level: float, g: float) -> float:
    """A level in the units of ``levels`` in SI (m/s² or m/s)."""
    factor = {"g": g, "m/s2": 1.0, "m/s": 1.0, "cm/s": 0.01}[intensity.units]
    return float(level) * factor


def check_resolution(intensity: Intensity, dt: float, where: str) -> None:
    """Raise if a spectral measure's period is shorter than :data:`PERIOD_SAMPLES` steps of a motion."""
    measure = intensity.measure
    periods = [measure.period] if measure.period is not None else measure.periods
    shortest = PERIOD_SAMPLES * dt
    for period in periods:
        if period < shortest - 1e-12:
            key = "intensity.period" if measure.period is not None else "intensity.periods"
            raise IntensityError(
                f"{key}: {period:g} s is shorter than {PERIOD_SAMPLES:g}·dt = {shortest:g} s of {where}: "
                "the sampled motion carries nothing above its Nyquist frequency 1/(2 dt)"
            )


def motion_measures(values: np.ndarray, dt: float, intensity: Intensity, g: float, spectrum: bool = True) -> CaseVariables:
    """The unscaled measures of a motion (samples in m/s², linear between them), by store name.

    ``motion_intensity`` is in the units of ``levels``; ``spectrum=False`` leaves out ``motion_psa``.
    """
    pga, pgv, pgd = peak_ground_motion(values, dt)
    measure = intensity.measure
    if measure.kind == "pga":
        value = pga
    elif measure.kind == "pgv":
        value = pgv
    else:
        periods = [measure.period] if measure.kind == "psa" else list(measure.periods)
        psa = response_spectrum(values, dt, periods, measure.damping).psa.values
        value = float(np.exp(np.mean(np.log(psa))))
    measures = {
        "motion_intensity": value / level_to_si(intensity, 1.0, g),
        "motion_pga": pga,
        "motion_pgv": pgv,
        "motion_pgd": pgd,
        "motion_arias_intensity": arias_intensity(values, dt, g),
        "motion_significant_duration": significant_duration(values, dt),
    }
    if spectrum:
        measures["motion_psa"] = response_spectrum(values, dt, SPECTRUM_PERIODS, SPECTRUM_DAMPING).psa.values
    return measures


def ida_capacity(closure: np.ndarray, im: float, gap_axes: list[tuple[float, list[int]]]) -> float:
    """Intensity (units of ``levels``) at which a contact-free run first closes a gap: min over axes of IM·g/max D.

    Parameters
    ----------
    closure : np.ndarray
        Peak closure of every contact at scale 1, m.
    im : float
        The motion's unscaled measure.
    gap_axes : list of (gap, contacts)
        The case's gap on each gap axis (m) and the axis's contacts.
    """
    capacities = []
    for gap, contacts in gap_axes:
        reach = float(np.max(closure[list(contacts)]))
        capacities.append(math.inf if not reach > 0 else im * gap / reach)
    return float(min(capacities))


def summary_attrs(intensity: Intensity, name: str) -> dict[str, str]:
    """Units and long name of a per-case intensity variable."""
    units, long_name = SUMMARIES[name]
    return {"units": units.format(units=intensity.units), "long_name": long_name.format(measure=intensity.description)}


def store_names(intensity: Intensity | None) -> list[str]:
    """The per-case intensity variables of a store (none without intensity)."""
    if intensity is None:
        return []
    names = [name for name in SUMMARIES if name != "ida_capacity"]
    return names + (["ida_capacity"] if intensity.ran == "ida" else [])


def task_settings(experiment: ExperimentGrid, expected_intensity: Mapping[str, float | None]) -> Scaling | None:
    """What a worker needs to scale an experiment's cases (None without intensity).

    The intensity setting, g, the gap axes and, by motion number, the
    ensembles' mean measures (``expected``; ``[intensity] synthetic = "expected"``),
    from ``expected_intensity``: each motion's mean measure by label (None: scaled case by case).
    """
    if experiment.intensity is None:
        return None
    gap_axes = tuple((gap.name, gap.contacts) for gap in experiment.definition.gaps)
    means = {index: expected_intensity[label] for index, label in enumerate(experiment.motions)}
    expected = {index: mean for index, mean in means.items() if mean is not None}
    return Scaling(experiment.intensity, experiment.definition.g, gap_axes, expected)


def ensemble_intensity(intensity: Intensity, table: Mapping[str, Any], realizations: range, g: float) -> float:
    """Mean measure (units of ``levels``) of an ensemble's realizations, generated from its worker table in chunks."""
    from stochpound import motions as synthetic_motions

    parameters = {k: v for k, v in table.items() if k not in ("type", "interpolation", "realization")}
    generator = getattr(synthetic_motions, table["type"])
    total = 0.0
    for start in range(realizations.start, realizations.stop, ENSEMBLE_CHUNK):
        count = min(ENSEMBLE_CHUNK, realizations.stop - start)
        values = np.asarray(generator(count, start=start, **parameters).values, dtype=float)
        total += sum(motion_measures(row, float(table["dt"]), intensity, g, spectrum=False)["motion_intensity"] for row in values)
    return total / len(realizations)


def measures_of(settings: Scaling, ground: Any) -> CaseVariables:
    """:func:`motion_measures` of a sampled ground motion (a motion given by a formula cannot be scaled to a measure)."""
    from stochpound.motions.ground import SampledMotion

    if not isinstance(ground, SampledMotion):
        raise IntensityError(f"intensity: only sampled motions (records, suites, synthetic ensembles) can be scaled, not {type(ground).__name__}")
    return motion_measures(ground.values, ground.dt, settings.intensity, settings.g)


def scaled_case(
    settings: Scaling, record: int, labels: Mapping[str, Label], ground: Any, twin: np.ndarray, measures: CaseVariables
) -> tuple[Any, np.ndarray, CaseVariables]:
    """The case's motion and fixed-base twin scaled to its ``intensity`` level (unchanged for IDA), and its intensity variables.

    ``record`` is the motion's number (an ensemble scaled by its mean measure
    uses it). The twin is linear and starts at rest, so scaling its response
    equals running it on the scaled motion.
    """
    level = labels.get("intensity")
    reference = settings.expected.get(record, measures["motion_intensity"])
    scale = 1.0 if level is None else float(level) / reference
    extra = {**measures, "scale_factor": scale}
    if scale == 1.0:
        return ground, twin, extra
    scaled = dataclasses.replace(ground, values=ground.values * scale, description=f"{ground.description} x {scale:.9g}")
    return scaled, twin * scale, extra


def capacity_of(settings: Scaling, summary: CaseVariables, labels: Mapping[str, Label]) -> float:
    """:func:`ida_capacity` of a contact-free case from its summary and grid labels."""
    axes = [(float(labels[name]), contacts) for name, contacts in settings.gap_axes]
    return ida_capacity(np.asarray(summary["peak_contact_closure"], dtype=float), float(summary["motion_intensity"]), axes)


def warm_up() -> None:
    """Compile the response spectrum's kernel (or load it from numba's cache) before workers start."""
    response_spectrum(np.zeros(3), 0.01, [1.0])
