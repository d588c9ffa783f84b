"""What the stores ran, from their own definitions: buildings, bases, contacts, motions, grids.

Every store keeps its experiment's canonical definition (``definition``, JSON).
This module reads the scenes of each configuration of the grid from it
(``ds.pound.grid``, the :class:`stochpound.store.ExperimentGrid` of the
store) and describes them: nothing
here is fixed text, and a value appears only if a store ran it. Several
stores that ran the same building or contact share one row.
"""

from __future__ import annotations

import json
import math
from collections.abc import Hashable, Iterable, Mapping, Sequence
from typing import Any

import numpy as np
import pandas as pd

from stochpound import motions as synthetic_motions
from stochpound._plurals import counted
from stochpound.experiment import CASE, is_fixed_base
from stochpound.analysis import Configuration, ScenarioIntensity, StoreScenes
from stochpound.model import laws
from stochpound.motions.records import load_record, registry_entries
from stochpound.report.render import Paragraph, Table
from stochpound.report.sections._stripe_motions import stripe_motions_text
from stochpound.motions.records import is_suite_member
from stochpound.model.scene import Building, Contact, Scene
from stochpound.model.wall import Wall
from stochpound.store import MotionSource, MotionTable, TomlTable, motions_that_ran, simulated_that_ran


def number(value: float, digits: int = 6) -> str:
    """A number for a sentence or a table cell: ``digits`` significant digits, ∞ for infinity."""
    return "∞" if math.isinf(value) else f"{value:.{digits}g}"


def numbers(values: Iterable[float], digits: int = 6) -> str:
    """Numbers separated by commas."""
    return ", ".join(number(float(v), digits) for v in values)


def percent(values: Iterable[float]) -> str:
    """Ratios as percentages, e.g. ``1 %, 2.24 %``."""
    return ", ".join(f"{100.0 * float(v):.3g} %" for v in values)


class StoreDefinition(StoreScenes):
    """An experiment store's definition, with its configurations' scenes (:class:`stochpound.analysis.StoreScenes`), as the report describes it."""

    @property
    def mu_buildings_text(self) -> str:
        """The buildings the ``mu`` axis applies to, in words."""
        chosen = self.definition.mu.buildings
        return ", ".join(chosen) if chosen else "every building on a sliding base"


def _damping(building: Building) -> str:
    if building.damping_ratio is not None:
        return f"stiffness-proportional, C = a1·K with ζ1 = {percent([building.damping_ratio])}"
    return f"storey dashpots {numbers(building.damping)} N·s/m"


def _base(definition: StoreDefinition, building: Building, g: float) -> str:
    base = building.base
    if base is None:
        return "fixed"
    law = laws.FRICTION_LAWS[base.friction_law]
    if definition.takes_grid_mu(building):
        finite = [m for m in definition.mu_values if not is_fixed_base(m)]
        parts = [f"sliding, {law.title}, μ = μ_s ∈ {{{numbers(finite)}}}" + (" or fixed (μ = ∞)" if len(finite) < len(definition.mu_values) else "")]
    else:
        parts = [f"sliding, {law.describe(base)}"]
    parts.append(f"base mass {number(base.mass)} kg")
    parts.append(base.describe_restoring(g))
    return "; ".join(parts)


def has_yielding(definitions: Iterable[StoreDefinition]) -> bool:
    """Whether a building the stores ran has yielding (bilinear) storeys."""
    return any(b.yield_force is not None for d in definitions for c in d.configurations for b in c.scene.buildings)


def _storeys(definitions: Iterable[StoreDefinition]) -> bool:
    """Whether a building the stores ran has storey heights, yielding storeys or P-Δ (the table's storey columns)."""
    return any(b.yield_force is not None or b.storey_height is not None for d in definitions for c in d.configurations for b in c.scene.buildings)


def _yielding(building: Building) -> str:
    """A building's bilinear storeys: yield shears, yield drifts (and drift ratios) and hardening; ``elastic`` without."""
    if building.yield_force is None:
        return "elastic"
    drift = [force / k for force, k in zip(building.yield_force, building.stiffness)]
    ratio = f"; {percent(d / h for d, h in zip(drift, building.storey_height))} of h" if building.storey_height else ""
    return (f"F_y = {numbers(building.yield_force)} N (yield drift {numbers((1000.0 * d for d in drift), 3)} mm{ratio}), "
            f"hardening α = {percent([building.hardening])}")


def _p_delta(building: Building, g: float) -> str:
    """A building's P-Δ storey stiffnesses −W/h and their share of the elastic ones; ``no`` without P-Δ."""
    if not building.p_delta:
        return "no"
    geometric = building.geometric_stiffness(g)
    return f"W/h = {numbers(-geometric, 4)} N/m taken off k ({percent(-geometric / np.asarray(building.stiffness))})"


def design_paragraph(definition: StoreDefinition) -> Paragraph | None:
    """The code design a store's ``[design]`` states, and each yielding building's strength against it (None without both).

    The strength of a building with storey heights is set beside the ASCE 7-16
    equivalent lateral force yield shears of that design at the building's
    computed fixed-base period (:func:`stochpound.model.design_yield_shears`,
    without the S_1 floor of C_s, which ``[design]`` does not give).
    """
    design = definition.definition.design
    if design is None or not has_yielding([definition]):
        return None
    basis = (f"S_DS = {number(design.sds, 4)} g, S_D1 = {number(design.sd1, 4)} g, T_L = {number(design.tl)} s, R = {number(design.r)}, "
             f"C_d = {number(design.cd)}, Ω0 = {number(design.omega0)}, I_e = {number(design.ie)}")
    strengths: dict[str, list[str]] = {}
    for configuration in definition.configurations:
        g = configuration.scene.g
        for building in configuration.scene.buildings:
            if building.yield_force is None:
                continue
            weight = g * sum(building.mass)
            text = f"{building.name}: F_y,1 / W = {number(building.yield_force[0] / weight, 3)}"
            if building.storey_height is not None:
                period, code = definition.design_shears(building, g)
                text += (f", the design's Ω0 V / W = {number(code[0] / weight, 3)} at T1 = {number(period, 3)} s "
                         f"with yield shears {numbers(code, 4)} N, the building's {numbers(np.asarray(building.yield_force) / code, 3)} times those")
            strengths.setdefault(text, []).append(configuration.name)
    every = len(definition.configurations)
    return Paragraph(
        f"Experiment {definition.name}: the buildings' code design ([design], ASCE 7-16): {basis}. Strength (W = g Σ m, the floors' weight; "
        "ASCE 7-16 equivalent lateral force at the computed fixed-base period, without the S_1 floor of C_s): "
        + "; ".join(text + (f" ({' or '.join(names)})" if len(names) < every else "") for text, names in strengths.items()) + "."
    )


def buildings_table(definitions: Iterable[StoreDefinition]) -> Table:
    """Every building configuration the stores ran: masses, stiffnesses, damping, modes and base; storeys' heights, strength and P-Δ where any has them."""
    definitions = list(definitions)
    storeys = _storeys(definitions)
    rows: dict[tuple, list[str]] = {}
    for definition in definitions:
        for configuration in definition.configurations:
            for building in configuration.scene.buildings:
                modes = definition.modes(building)
                damping_note = "" if modes.classical else " (damping not classical: ζ from the diagonal of ΦᵀCΦ)"
                row = (
                    building.name,
                    str(building.n_floors),
                    numbers(building.mass),
                    numbers(building.stiffness),
                    _damping(building),
                    numbers(modes.periods, 4),
                    percent(modes.damping_ratio) + damping_note,
                    _base(definition, building, configuration.scene.g),
                )
                if storeys:
                    heights = numbers(building.storey_height) if building.storey_height else "–"
                    row += (heights, _yielding(building), _p_delta(building, configuration.scene.g))
                rows.setdefault(row, []).append((definition, configuration))
    columns = ["building", "floors", "masses (kg)", "storey stiffness (N/m)", "damping", "periods (s)", "modal damping", "base"]
    caption = "The buildings as run: floor masses (floor 1 upwards), storey stiffnesses, damping, the fixed-base modes and the base"
    note = "Periods and modal damping ratios are computed from the mass, stiffness and damping matrices of each building on a fixed base"
    if storeys:
        columns += ["storey height (m)", "storeys", "P-Δ"]
        caption += "; the storeys' heights, strength (yield shears F_y, storey 1 upwards) and P-Δ"
        note += (" (the elastic storey stiffnesses, without P-Δ). A yielding storey is bilinear with kinematic hardening: stiffness k "
                 "up to its yield shear F_y (yield drift F_y/k), α k beyond it, elastic unloading. With P-Δ each storey also carries "
                 "the geometric stiffness −W/h of the weight W above it (h its height)")
    return _merged_table("table-buildings", caption + ".", columns, rows, note + ".")


def _contact_row(definition: StoreDefinition, scene: Scene, index: int, contact: Contact) -> tuple[str, ...]:
    left, right = scene.buildings[contact.left], scene.buildings[contact.right]
    parameters = definition.contact_parameters(scene, contact)
    axis = definition.gap_axis(index)
    law = laws.CONTACT_LAWS[contact.law]
    return (
        f"{left.name} floor {contact.left_floor} – {right.name} floor {contact.right_floor}",
        law.describe(parameters),
        f"{{{numbers(axis.values)}}} (axis {axis.name})" if axis else number(contact.gap),
        law.separation(parameters),
    )


def _wall_row(definition: StoreDefinition, scene: Scene, index: int, wall: Wall) -> tuple[str, ...]:
    building = scene.buildings[wall.building]
    axis = definition.definition.wall_gap_axis(index)
    parameters = definition.wall_parameters(scene, wall)
    level = "base" if wall.level == 0 else f"floor {wall.level}"
    law = laws.CONTACT_LAWS[wall.law]
    return (
        f"{building.name} {level} – wall on its {wall.side_name} (moves with the ground)",
        law.describe(parameters),
        f"{{{numbers(axis.values)}}} (axis {axis.name})" if axis else number(wall.gap),
        law.separation(parameters),
    )


def contacts_table(definitions: Iterable[StoreDefinition]) -> Table | None:
    """Every contact element the stores ran, between buildings and against walls (None when no store has one)."""
    rows: dict[tuple, list[str]] = {}
    for definition in definitions:
        for configuration in definition.configurations:
            for index, contact in enumerate(configuration.scene.contacts):
                rows.setdefault(_contact_row(definition, configuration.scene, index, contact), []).append((definition, configuration))
            for index, wall in enumerate(configuration.scene.walls):
                rows.setdefault(_wall_row(definition, configuration.scene, index, wall), []).append((definition, configuration))
    if not rows:
        return None
    return _merged_table(
        "table-contacts",
        "The contact (impact) elements as run: floors joined, law with its parameters, at-rest gap and separation rule.",
        ["between", "law", "gap (m)", "separation"],
        rows,
        _contacts_note(definitions),
    )


def _contacts_note(definitions: Iterable[StoreDefinition]) -> str:
    """The contacts table's note: m_eff, then what only the laws and walls that ran need said."""
    scenes = [configuration.scene for definition in definitions for configuration in definition.configurations]
    walls = any(scene.walls for scene in scenes)
    ran = {element.law for scene in scenes for element in (*scene.contacts, *scene.walls)}
    note = "m_eff = m1 m2 / (m1 + m2) of the two floor masses" + (" (against a wall, the level's own mass)." if walls else ".")
    if laws.DEFAULT_CONTACT_LAW in ran:
        note += (" A Kelvin–Voigt element's dashpot from a restitution e is c = 2 ξ √(k m_eff), ξ = −ln e / √(π² + ln² e).")
    if walls:
        note += (" A wall is rigid in that it moves with the ground and has no mass of its own; it is reached through its contact "
                 "element, which it penetrates as that element's stiffness allows.")
    return note


def _where(uses: list[tuple[StoreDefinition, Configuration]]) -> str:
    """The experiments and configurations a row was run in, e.g. ``<experiment> (neighbour = stiff)``."""
    texts = []
    for definition in dict.fromkeys(d for d, _ in uses):
        chosen = [c for d, c in uses if d is definition]
        axes = []
        for axis in definition.experiment.variants:
            values = list(dict.fromkeys(c.labels[axis.name] for c in chosen))
            if len(values) < len(axis.values):
                axes.append(f"{axis.name} = {' or '.join(values)}")
        texts.append(definition.name + (f" ({', '.join(axes)})" if axes else ""))
    return "; ".join(texts)


def _merged_table(key: str, caption: str, columns: list[str], rows: Mapping[tuple, list[tuple[StoreDefinition, Configuration]]], note: str) -> Table:
    frame = pd.DataFrame([[*row, _where(uses)] for row, uses in rows.items()], columns=[*columns, "where"])
    frame.index = pd.RangeIndex(1, len(frame) + 1, name="#")
    return Table(key=key, caption=caption, frame=frame, note=note)


def _scenario_parameters(source: MotionSource) -> tuple[str, dict[str, float]]:
    """What a scenario ensemble's motions are (``type = "scenario_motions"``), as run (:meth:`~stochpound.analysis.ScenarioIntensity.of`:
    their high-pass corner, their PGA and PSA(1 s) beside the NGA-West2 average's), where the model is not valid, and its step and window."""
    table = source.motion
    ran = ScenarioIntensity.of(table, source.start, source.count)
    calibrated = table["model"] == "hazard_compatible"
    text = (f"Site-based stochastic motions of the scenario M {number(float(table['magnitude']))}, R_rup {number(float(table['distance_km']))} km, "
            f"Vs30 {number(float(table['vs30']))} m/s, {str(table['mechanism']).replace('_', '-')} (Rezaeian & Der Kiureghian 2010, "
            + ("calibrated to the NGA-West2 models" if calibrated else "the published equations, not calibrated")
            + f": {table['calibration']}): each realization's Arias intensity, D5–95, time of 45 % of it (its gamma-shaped modulation), "
            "filter frequency, its slope and damping drawn from the scenario with correlated residuals; "
            + (f"a high-pass post-filter, its corner fixed at {number(ran.corner_low, 3)} Hz" if ran.corner_low == ran.corner_high
               else f"a high-pass post-filter, its corner drawn per realization ({number(ran.corner_low, 3)}–{number(ran.corner_high, 3)} Hz)")
            + ("; then a spectral-shape filter whose random gains at 12 periods (0.05–5 s) are set so that the motions' median and σ of "
               "ln PSA follow the scenario's NGA-West2 average (ASK14, BSSA14, CB14, CY14)" if calibrated else "")
            + "; ends at rest; linear interpolation between samples. " + _scenario_intensity(ran)
            + " Not valid for: near-fault velocity pulses, directivity, basin effects beyond the NGA-West2 models' basin terms; "
            "one horizontal component stands for the models' RotD50 (docs/site-motions.md)")
    return text, {"dt": float(table["dt"]), "duration": float(table["duration"])}


def _scenario_intensity(ran: ScenarioIntensity) -> str:
    """The motions' median and σ of ln PGA and ln PSA(1 s) beside the scenario's NGA-West2 average, in words."""
    parts = [f"{m.name} {m.median:.3g} g" + (f", σ_ln {m.sigma_ln:.2f}" if ran.count > 1 else "")
             + f" (NGA-West2 average {m.target_median:.3g} g, σ_ln {m.target_sigma_ln:.2f})" for m in ran.measures]
    return f"Intensity, the median over the {counted(ran.count, 'motion')} as run: " + "; ".join(parts) + "."


def _synthetic_parameters(source: MotionSource) -> tuple[str, dict[Hashable, Any]]:
    """The ensemble's generator parameters as run, with the intensity S0 and σ it implies (one realization is generated), and the
    generated realization's attributes (a scenario ensemble's: its step and window)."""
    table = source.motion
    if table["type"] == "scenario_motions":
        return _scenario_parameters(source)
    parameters = {k: v for k, v in table.items() if k not in ("type", "interpolation")}
    attrs = getattr(synthetic_motions, table["type"])(1, start=source.start, **parameters).attrs
    filtered = "omega_g" in attrs  # white noise has no filter
    title = table["type"].replace("_", "–").title() if filtered else "White noise"
    filters = f"ω_g = {number(attrs['omega_g'])} rad/s, ζ_g = {number(attrs['zeta_g'])}" if filtered else "independent samples"
    if "omega_f" in attrs:
        filters += f", ω_f = {number(attrs['omega_f'])} rad/s, ζ_f = {number(attrs['zeta_f'])}"
    if "pga_target" in attrs:
        intensity = f"expected PGA {number(attrs['pga_target'])} m/s² (peak factor {number(attrs['peak_factor'], 4)}, {attrs['peak_factor_method']})"
    elif "rms_target" in attrs:
        intensity = f"RMS {number(attrs['rms_target'])} m/s²"
    else:
        intensity = "S0 given"
    envelope = json.loads(attrs["envelope"])
    shape = "stationary" if envelope is None else f"{envelope.pop('type')} envelope ({', '.join(f'{k} = {number(v, 4)}' for k, v in envelope.items())})"
    text = (
        f"{title}: {filters}; {intensity}, S0 = {number(attrs['S0'], 4)} m²/s³ "
        f"(two-sided), σ = {number(attrs['sigma'], 4)} m/s²; {shape}" + (f"; {attrs['method']} method" if filtered else "")
        + ("; baseline-corrected (ends at rest)" if attrs.get("baseline_corrected") else "")
        + ("; band-limited" if attrs.get("band_limited") else "")
        + "; linear interpolation between samples"
    )
    return text, attrs


def _analytic_parameters(table: TomlTable) -> str:
    """A harmonic or constant motion's formula and its parameters."""
    motion = MotionTable.of(table)
    if motion.type == "harmonic":
        phase = f" + {number(motion.phase)}" if motion.phase else ""
        return f"harmonic a_g = A sin(Ωt{phase}), A = {number(table.number('amplitude'))} m/s², Ω = {number(table.number('omega'))} rad/s"
    return f"constant a_g = {number(table.number('acceleration'))} m/s²"


def _record_parameters(motion: MotionTable) -> tuple[str, str]:
    """A record's description and its (step, duration) as run."""
    name = str(motion.record)
    if is_suite_member(name):
        record = load_record(name)
        suite, _, member = name.partition("/")
        duration = min(record.duration, motion.duration)
        meta = record.metadata
        return (f"motion {member} of the suite {suite} ({record.description}; {meta['package']}, as recorded; "
                f"sha256 of the samples {meta['sha256'][:12]}…)"
                + (f", scaled by {number(motion.scale)}" if motion.scale != 1.0 else ""),
                f"{number(record.dt)} s, {number(duration)} s")
    entry = registry_entries().get(name)
    if entry is None:
        return f"record file {name} (sha256 {str(motion.file_sha256)[:12]}…)", "the file's"
    record = load_record(name)
    duration = min(record.duration, motion.duration)
    parts = [f"record {name} ({entry.description})"]
    if motion.scale != 1.0:
        parts.append(f"scaled by {number(motion.scale)}")
    parts.append(f"{motion.interpolation} interpolation between samples")
    return ", ".join(parts), f"{number(record.dt)} s, {number(duration)} s"


def motions_table(definitions: Iterable[StoreDefinition]) -> Table:
    """Every ground motion the stores ran: records with their treatment, ensembles with their generator and seed."""
    rows = []
    pool = 0
    simulated_rows: list[int] = []
    spectral = False
    for definition in definitions:
        ran = motions_that_ran(definition.store)
        for motion in definition.definition.motions:
            pool += 1
            if motion.label not in ran:
                continue  # a pool motion a selection did not choose: it never ran
            table, typed = motion.motion, MotionTable.of_source(motion)
            if motion.kind == "synthetic":
                spectral = spectral or table["type"] != "scenario_motions"  # an ensemble of a PSD (Kanai–Tajimi, Clough–Penzien, ...)
                text, attrs = _synthetic_parameters(motion)
                realizations = f"{motion.count} (indices {motion.start}–{motion.start + motion.count - 1}), seed {table['seed']}"
                grid = f"{number(attrs['dt'])} s, {number(attrs['duration'])} s"
            elif typed.is_record:
                text, grid = _record_parameters(typed)
                realizations = "1"
            else:
                text, realizations = _analytic_parameters(TomlTable(table, motion.field)), "1"
                grid = f"{number(float(table['dt']))} s, {number(typed.duration)} s"
            rows.append([definition.name, motion.label, text, grid, realizations])
        simulated = simulated_that_ran(definition.store)
        setting = definition.definition.intensity.selection.simulated if simulated else None
        if setting is not None:
            rows.append([definition.name, f"{simulated[0]} … {simulated[-1]} ({len(simulated)} simulated)",
                         f"{setting.model} site-motion model ({setting.calibration}) of each stripe's scenario, seed {setting.seed}; the "
                         f"{len(simulated)} chosen for some stripe of the {setting.count} simulated per stripe"
                         f"{setting.sampling_words}", f"{number(setting.dt)} s",
                         f"1 each ({len(simulated)})"])
            simulated_rows.append(len(simulated))
    frame = pd.DataFrame(rows, columns=["experiment", "motion", "definition", "step, duration", "realizations"])
    frame.index = pd.RangeIndex(1, len(frame) + 1, name="#")
    return Table(
        key="table-motions",
        caption=motions_caption(len(frame) - len(simulated_rows), pool, simulated_rows),
        frame=frame,
        note="Realization i of an ensemble depends only on (seed, i)." + (" The PSD convention: two-sided in ω, σ² = ∫ S dω." if spectral else ""),
    )


def motions_caption(records: int, pool: int, simulated: Sequence[int] = ()) -> str:
    """The motions table's caption: ``records`` rows of the ``pool`` motions the definitions list (the pool motions a selection
    never chose left out), and one row per experiment of the simulated motions its stripes chose (``simulated``: their numbers)."""
    head = "The ground motions as run: each record with its treatment, each synthetic ensemble with its generator, intensity, envelope, seed and size"
    if records >= pool:
        return head + "."
    rows = "" if not simulated else (f"; and, in {'one row' if len(simulated) == 1 else 'one row per experiment'}, the {sum(simulated)} "
                                     "simulated motions some stripe chose")
    return head + f" ({records} of the {pool} motions the experiments define: a selection's pool motions it never chose are left out{rows})."


def grid_paragraph(definition: StoreDefinition) -> Paragraph:
    """The experiment's axes, studied building and number of cases."""
    axes = []
    for dim in definition.experiment.grid_dims:
        if dim.kind == "variant":
            axes.append(f"{dim.name} ∈ {{{', '.join(map(str, dim.values))}}}")
        elif dim.kind == "gap":
            axes.append(f"{dim.name} ∈ {{{numbers(dim.values)}}} m ({definition.definition.gap_axis(dim.name).targets})")
        elif dim.kind == "intensity":
            setting = definition.definition.intensity
            axes.append(f"intensity ∈ {{{numbers(dim.values)}}} {setting.units} ({setting.description}; {stripe_motions_text(definition.store)})")
        else:
            axes.append(f"μ ∈ {{{numbers(dim.values)}}} for {definition.mu_buildings_text} (∞: fixed base)")
    store = definition.store
    scene = definition.configurations[0].scene
    references = sum(1 for c in definition.experiment.cases if c.kind != CASE)
    defined, ran, simulated = len(definition.definition.motions), motions_that_ran(store), simulated_that_ran(store)
    recorded = len(ran) - len(simulated)
    motions = (_motions_count(definition) if recorded == defined and not simulated else
               f"the {counted(len(ran), 'motion')} that ran ({recorded} of the {defined} the experiment defines"
               + (f", and {len(simulated)} simulated for the stripes' scenarios" if simulated else "") + ")")
    return Paragraph(
        f"Experiment {definition.name}: {', '.join(axes) or 'a single configuration'}, under "
        f"{motions}, listed in the Table of motions; g = {number(scene.g)} m/s². The studied building is "
        f"{definition.experiment.studied}: the response whose moments are reported is its top-floor total displacement, and "
        f"it is also run alone on a fixed base under every motion ({references} reference runs). "
        f"{store.pound.provenance.cases_done} of {store.pound.provenance.cases_total} runs done."
    )


def _motions_count(definition: StoreDefinition) -> str:
    """The experiment's motions in words: "3 motions", "1 synthetic ensemble of 200 realizations", or both."""
    sources = definition.definition.motions
    ensembles = [source.count for source in sources if source.kind == "synthetic"]
    parts = [counted(len(sources) - len(ensembles), "motion")] if len(ensembles) < len(sources) else []
    if ensembles:
        parts.append(f"{counted(len(ensembles), 'synthetic ensemble')} of {counted(sum(ensembles), 'realization')}"
                     + (" in all" if len(ensembles) > 1 else ""))
    return " and ".join(parts)


def model_paragraph(definitions: list[StoreDefinition]) -> Paragraph:
    """The model, saying only what the stores' scenes use."""
    scenes = [c.scene for d in definitions for c in d.configurations]
    buildings = [b for s in scenes for b in s.buildings]
    contacts = [c for s in scenes for c in s.contacts]
    isolated = any(b.base is not None for b in buildings)
    sentences = ["Buildings are shear buildings: lumped floor masses joined by storey springs and dashpots, standing in a row on the same ground."]
    if has_yielding(definitions):
        sentences.append(
            "Storeys given a yield shear F_y are bilinear with kinematic hardening (table of buildings): stiffness k up to F_y, α k "
            "beyond it, elastic unloading from the force reached; each such storey's plastic drift is a state of the solution, "
            "yield and unloading are located as events like contact and slip (docs/model.md), and the drift a storey keeps at rest "
            "after the run is its residual drift. There is no strength loss: no degradation, no collapse."
        )
    if any(b.p_delta for b in buildings):
        sentences.append("With P-Δ a storey's spring is softened by the geometric stiffness −W/h of the weight above it, in its elastic and post-yield branches alike.")
    if isolated:
        friction = sorted({laws.FRICTION_LAWS[b.base.friction_law].title for b in buildings if b.base is not None})
        sentences.append(
            f"A building on a sliding base has one more degree of freedom, its sliding displacement s; {' or '.join(friction)} "
            "opposes the sliding, and the base sticks while the friction force it needs stays below μ_s W (W its weight); "
            "the restoring force, if any, is given in the table of buildings."
        )
    walls = [w for s in scenes for w in s.walls]
    if contacts or walls:
        used = [laws.CONTACT_LAWS[name] for name in dict.fromkeys(e.law for e in (*contacts, *walls))]
        sentences.append(
            "Impact elements act only while their gap is closed: " + "; ".join(f"{law.title}, {law.formula}" for law in used)
            + " (δ the penetration, δ̇ its rate, δ̇₀ its rate at the onset of the impact; parameters in the table of contacts)."
        )
    if walls:
        sentences.append("Walls that move with the ground stand beside some levels, reached through such an impact element (table of contacts).")
    if isolated and contacts:
        sentences.append(
            "The impact forces act on an isolated building as a whole (they enter its base equation), and friction at the onset "
            "of slip opposes the driving force; a slipping base stops only when its velocity reaches zero (docs/model.md)."
        )
    compat = [(d.name, d.study_compat_cases) for d in definitions if d.study_compat_cases]
    if compat:
        sentences.append(
            "The reference study's own equations (study_compat: no impact forces in the base equation, no friction at slip onset) "
            "are run beside them in " + "; ".join(f"{n} cases of {name}" for name, n in compat) + "."
        )
    return Paragraph(" ".join(sentences))


def records_used(definitions: Iterable[StoreDefinition]) -> list[str]:
    """Bundled records run by the stores, sorted."""
    tables = [MotionTable.of_source(m) for d in definitions for m in d.definition.motions]
    used = {table.record for table in tables if table.is_record and table.record is not None}
    return sorted(used & set(registry_entries()))
