"""The solver's accuracy, measured while the report is built, on the stores' own buildings and contacts.

Five checks, each against something known exactly or computed independently:

* every studied building on a fixed base under a_g = A sin(Ωt), against the
  closed-form modal solution (:func:`stochpound.modal_solution.harmonic_response`);
  a store's harmonic motions (``[[motions]]`` of type harmonic), when present, are checked on its stored runs;
* every contact element as a single collision of its two floor masses, free,
  against the restitution the Kelvin–Voigt law gives in closed form
  (:func:`free_collision_restitution`);
* one stored case with pounding (and sliding, where a store has it) rerun
  with the exact solver and with scipy's DOP853 at rtol 1e-12;
* per store with yielding storeys, one stored case that yielded, rerun the
  same way and against the store's peak ductility and residual drift;
* the energy balance of every stored case (read from the stores).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import xarray as xr

import stochpound
from stochpound._errors import VerificationError
from stochpound.model import laws
from stochpound.model.modal_solution import harmonic_response, modal_properties
from stochpound.report.sections._description import StoreDefinition, has_yielding, number, numbers
from stochpound.report.render import Paragraph
from stochpound.report.sections._store_reading import select
from stochpound.model.scene import Building, Contact, Scene

#: Closing velocity of the single-collision check, m/s.
COLLISION_VELOCITY = 0.5
#: Ground-acceleration amplitude of the modal check, m/s²; Ω is this fraction of ω1.
HARMONIC_AMPLITUDE, HARMONIC_DETUNING = 1.0, 0.9
#: Tolerances of the DOP853 reference run.
REFERENCE_RTOL, REFERENCE_ATOL = 1e-12, 1e-14
CROSS_CHECK_TOLERANCE = 1e-6
"""Largest difference of the cross-check's two solvers, as a share of the peak displacement, that passes."""


def free_collision_restitution(damping_ratio: float, tensile: bool) -> float:
    """Coefficient of restitution of two free masses colliding through a Kelvin–Voigt element.

    With ζ = c / (2 √(k m_eff)) < 1 the penetration is δ = v0/ω_d e^{−ζωt} sin ω_d t.
    A tensile element separates when δ returns to 0 (ω_d t = π), giving
    r = exp(−ζπ/√(1−ζ²)). A non-tensile one separates when its force
    k δ + c δ̇ returns to 0, at ω_d t = π − atan2(2ζ√(1−ζ²), 1 − 2ζ²),
    giving r = −δ̇(t)/v0 there.
    """
    root = math.sqrt(1.0 - damping_ratio**2)
    if tensile:
        return math.exp(-damping_ratio * math.pi / root)
    phase = math.pi - math.atan2(2.0 * damping_ratio * root, 1.0 - 2.0 * damping_ratio**2)
    return -math.exp(-damping_ratio * phase / root) * (math.cos(phase) - damping_ratio / root * math.sin(phase))


@dataclass(frozen=True)
class CollisionCheck:
    """A contact's single collision: restitution measured on the solver's run and its closed form."""

    masses: tuple[float, float]
    contact: Contact
    expected: float
    measured: float


def collision_check(masses: tuple[float, float], contact: Contact) -> CollisionCheck:
    """Run the two floor masses, free, into each other through ``contact`` (exact solver) and measure the restitution."""
    effective = masses[0] * masses[1] / (masses[0] + masses[1])
    omega = math.sqrt(contact.stiffness / effective)
    zeta = contact.damping / (2.0 * math.sqrt(contact.stiffness * effective))
    duration = 3.0 * math.pi / (omega * math.sqrt(1.0 - zeta**2))

    def body(name: str, mass: float, velocity: float) -> dict:
        return {"name": name, "mass": [mass], "stiffness": [0.0], "damping": [0.0], "initial": {"velocity": [velocity]}}

    scene = {
        "building": [body("A", masses[0], COLLISION_VELOCITY), body("B", masses[1], 0.0)],
        "contact": [{"between": [["A", 1], ["B", 1]], "gap": 0.0, "stiffness": contact.stiffness, "damping": contact.damping, "tensile": contact.tensile}],
        "motion": {"type": "constant", "acceleration": 0.0, "duration": duration, "dt": duration / 300},
    }
    run = stochpound.simulate(stochpound.scene_from_dict(scene), method="exact")
    y, t = run["total_displacement"].sel(floor=1).values, run["time"].values
    velocities = (y[:, -1] - y[:, -2]) / (t[-1] - t[-2])
    measured = float((velocities[1] - velocities[0]) / COLLISION_VELOCITY)
    return CollisionCheck(masses, contact, free_collision_restitution(zeta, contact.tensile), measured)


@dataclass(frozen=True)
class ModalCheck:
    """A building under A sin(Ωt) on a fixed base: the solver against the closed-form modal solution (m)."""

    building: Building
    omega: float
    error: float
    peak: float


def modal_check(building: Building) -> ModalCheck | None:
    """Run ``building`` alone on a fixed base under A sin(0.9 ω1 t) for 20 periods (None if its damping is not classical)."""
    modes = modal_properties(building)
    if not modes.classical:
        return None
    omega = HARMONIC_DETUNING * float(modes.omega[0])
    period = 2.0 * math.pi / float(modes.omega[0])
    alone = Building(building.name, building.mass, building.stiffness, building.damping, building.damping_ratio)
    motion = {"type": "harmonic", "amplitude": HARMONIC_AMPLITUDE, "omega": omega, "duration": 20.0 * period, "dt": period / 40.0}
    scene = stochpound.scene_from_dict({"building": [_building_table(alone)], "motion": motion})
    run = stochpound.simulate(scene, method="exact")
    computed = run["relative_displacement"].sel(building=building.name).values
    exact = harmonic_response(alone, HARMONIC_AMPLITUDE, omega, run["time"].values)
    return ModalCheck(building, omega, float(np.max(np.abs(computed - exact))), float(np.max(np.abs(exact))))


def _building_table(building: Building) -> dict:
    return {"name": building.name, "mass": list(building.mass), "stiffness": list(building.stiffness), "damping": list(building.damping)}


@dataclass(frozen=True)
class HarmonicComparison:
    """A stored harmonic-check run beside the closed-form modal solution.

    Attributes
    ----------
    amplitude, omega : float
        A (m/s²) and Ω (rad/s) of a_g = A sin(Ωt).
    time : numpy.ndarray
        s.
    computed, exact : numpy.ndarray
        Floor displacements relative to the ground, m, (floors, time).
    """

    amplitude: float
    omega: float
    time: np.ndarray
    computed: np.ndarray
    exact: np.ndarray

    @property
    def error(self) -> float:
        """The largest absolute difference between computed and exact, m."""
        return float(np.max(np.abs(self.computed - self.exact)))


def harmonic_comparisons(store: xr.Dataset) -> list[HarmonicComparison]:
    """A store's harmonic motions (``[[motions]]`` of type harmonic) beside the closed-form modal solution."""
    comparisons = []
    for motion in store.pound.definition.motions:
        if motion.motion.get("type") != "harmonic":
            continue
        building = store.pound.scene(record=motion.label).buildings[0]
        run = select(store, record=motion.label)
        computed = run["relative_displacement"].sel(building=building.name).values
        valid = np.isfinite(computed[0])
        time = run["time"].values[valid]
        amplitude, omega = float(motion.motion["amplitude"]), float(motion.motion["omega"])
        comparisons.append(HarmonicComparison(amplitude, omega, time, computed[:, valid], harmonic_response(building, amplitude, omega, time)))
    return comparisons


def cross_check_case(store: xr.Dataset) -> tuple[dict, bool] | None:
    """A stored case with pounding, and with sliding if the store has such a case, and whether it slides.

    Among those, the case with the median impact count (the first in grid
    order); None when no stored case pounds.
    """
    impacts = store["impacts"].load()
    pounding = impacts > 0
    slides = False
    if "peak_sliding_displacement" in store:
        sliding = (store["peak_sliding_displacement"].max("building") > 1e-3).load()
        slides = bool((pounding & sliding).any())
        if slides:
            pounding = pounding & sliding
    counts = impacts.where(pounding).stack(case=impacts.dims).dropna("case")
    if counts.size == 0:
        return None
    median = float(np.sort(counts.values)[(counts.size - 1) // 2])
    chosen = counts.where(counts == median, drop=True).isel(case=0)
    return {dim: chosen[dim].item() for dim in impacts.dims}, slides


def cross_check(definitions: list[StoreDefinition]) -> Paragraph | None:
    """The exact solver against scipy's DOP853 (rtol 1e-12) on one stored case with pounding, with sliding if any store has it.

    The case is re-run exactly as it ran (its scene, motion and intensity
    scale factor). The check can fail: the build stops with a
    :class:`~stochpound._errors.VerificationError` when the re-run does not
    count the impacts the store holds, when the two solvers count different
    impacts, or when they differ by more than :data:`CROSS_CHECK_TOLERANCE`
    of the peak displacement.
    """
    candidates = [(d, found) for d in definitions if "impacts" in d.store for found in [cross_check_case(d.store)] if found is not None]
    if not candidates:
        return None
    definition, (labels, _) = next((c for c in candidates if c[1][1]), candidates[0])
    name, store = definition.name, definition.store
    scene: Scene = store.pound.scene(**labels)
    nonlinear = scene.nonlinear_laws()
    exact, reference, difference, peak = _against_reference(scene)
    held = int(select(store, **labels)["impacts"])
    where = ", ".join(f"{k} = {number(v) if isinstance(v, float) else v}" for k, v in labels.items())
    counts = (exact.sizes["impact"], reference.sizes["impact"])
    _verify(name, where, held, counts, difference, peak)
    sliding = float(exact["sliding_displacement"].max() - exact["sliding_displacement"].min())
    scale = float(select(store, **labels)["scale_factor"]) if "scale_factor" in store else 1.0
    return Paragraph(
        f"Cross-check on a stored case of {name} ({where}"
        + (f", motion scale factor {number(scale, 4)}" if scale != 1.0 else "")
        + f"; {counts[0]} impacts"
        + (f", sliding over {number(sliding * 100, 3)} cm" if sliding > 0 else "")
        + f", {number(float(scene.motion.times[-1]))} s), re-run as it was run: "
        + (f"the ivp solver at its defaults (nonlinear laws: {'; '.join(nonlinear)})" if nonlinear else "the exact solver")
        + " and scipy's DOP853 with event location "
        f"(rtol {REFERENCE_RTOL:g}) differ by at most {difference:.1e} m in any floor's total displacement (peak "
        f"{number(peak * 100, 3)} cm) and both count the {held} impacts the store holds. The report is built only when "
        f"they agree (impact counts equal, displacements within {CROSS_CHECK_TOLERANCE:g} of the peak)."
    )


def _against_reference(scene: Scene) -> tuple[xr.Dataset, xr.Dataset, float, float]:
    """``scene`` run as a store runs it and with scipy's DOP853 at rtol 1e-12: both runs, their largest difference and the peak (m)."""
    exact = stochpound.simulate(scene)  # the solver the store used: exact, or the integrator at its defaults for a nonlinear law
    reference = stochpound.simulate(scene, method="ivp", integrator="DOP853", rtol=REFERENCE_RTOL, atol=REFERENCE_ATOL)
    difference = float(np.nanmax(np.abs(exact["total_displacement"].values - reference["total_displacement"].values)))
    return exact, reference, difference, float(np.nanmax(np.abs(reference["total_displacement"].values)))


#: The store's yielding summaries the yielding check recomputes: name -> the run's per-storey variable (largest absolute value over the storeys).
YIELDING_SUMMARIES = {"peak_ductility": "peak_storey_ductility", "residual_drift": "residual_storey_drift"}
SUMMARY_RTOL = 1e-9
"""Largest relative difference of a re-run's yielding summaries from the store's that passes."""


def yielding_case(store: xr.Dataset) -> dict | None:
    """A stored case whose storeys yielded: the median peak ductility among those > 1 (the first in grid order); None if none yielded."""
    if "peak_ductility" not in store:
        return None
    ductility = store["peak_ductility"].max("building").load()
    yielded = ductility.where(ductility > 1.0).stack(case=ductility.dims).dropna("case")
    if yielded.size == 0:
        return None
    median = float(np.sort(yielded.values)[(yielded.size - 1) // 2])
    chosen = yielded.where(yielded == median, drop=True).isel(case=0)
    return {dim: chosen[dim].item() for dim in ductility.dims}


def yielding_check(definition: StoreDefinition) -> Paragraph | None:
    """A stored case whose storeys yielded, re-run as it ran, against scipy's DOP853 (rtol 1e-12) and against the store (None without one).

    The check can fail: the build stops with a
    :class:`~stochpound._errors.VerificationError` when the re-run's peak
    ductility or residual drift of a building differs from the store's by
    more than :data:`SUMMARY_RTOL`, when its impacts differ from the store's
    or DOP853's, or when the two solvers differ by more than
    :data:`CROSS_CHECK_TOLERANCE` of the peak displacement.
    """
    labels = yielding_case(definition.store)
    if labels is None:
        return None
    name, stored = definition.name, select(definition.store, **labels)
    scene: Scene = definition.store.pound.scene(**labels)
    exact, reference, difference, peak = _against_reference(scene)
    where = ", ".join(f"{k} = {number(v) if isinstance(v, float) else v}" for k, v in labels.items())
    _verify(name, where, int(stored["impacts"]) if "impacts" in stored else exact.sizes["impact"], (exact.sizes["impact"], reference.sizes["impact"]),
            difference, peak)
    rerun = {key: np.abs(exact[source]).max("floor").sel(building=stored["building"]) for key, source in YIELDING_SUMMARIES.items()}
    for key, values in rerun.items():
        if not np.allclose(values.values, stored[key].values, rtol=SUMMARY_RTOL, atol=0.0, equal_nan=True):
            raise VerificationError(f"yielding check: the stored case of {name} ({where}) re-run gives {key} {numbers(values.values, 10)}, "
                                    f"the store holds {numbers(stored[key].values, 10)}")
    building = str(rerun["peak_ductility"].idxmax("building").item())
    scale = float(stored["scale_factor"]) if "scale_factor" in stored else 1.0
    return Paragraph(
        f"Yielding check on a stored case of {name} ({where}"
        + (f", motion scale factor {number(scale, 4)}" if scale != 1.0 else "")
        + f"; {exact.sizes['impact']} impacts, {number(float(scene.motion.times[-1]))} s; its storeys yield: {building}'s peak ductility "
        f"{number(float(rerun['peak_ductility'].sel(building=building)), 4)}, residual drift "
        f"{number(1000.0 * float(rerun['residual_drift'].sel(building=building)), 3)} mm), the median peak ductility of the stored cases "
        "that yield, re-run as it was run with its yielding storeys (yield shears, hardening and P-Δ as stored): the exact solver and "
        f"scipy's DOP853 with event location (rtol {REFERENCE_RTOL:g}) differ by at most {difference:.1e} m in any floor's total "
        f"displacement (peak {number(peak * 100, 3)} cm), and every building's peak ductility and residual drift equal the store's "
        f"within {SUMMARY_RTOL:g}. The report is built only when they agree."
    )


def _verify(name: str, where: str, held: int, counts: tuple[int, int], difference: float, peak: float) -> None:
    """Raise :class:`~stochpound._errors.VerificationError` where the re-run disagrees with the store or the reference."""
    if counts[0] != held:
        raise VerificationError(f"cross-check: the stored case of {name} ({where}) re-run counts {counts[0]} impacts, the store holds {held}")
    if counts[1] != counts[0]:
        raise VerificationError(f"cross-check: on the stored case of {name} ({where}) the solver counts {counts[0]} impacts, "
                                f"scipy's DOP853 {counts[1]}")
    if not difference <= CROSS_CHECK_TOLERANCE * peak:
        raise VerificationError(f"cross-check: on the stored case of {name} ({where}) the solver and scipy's DOP853 differ by "
                                f"{difference:.1e} m, more than {CROSS_CHECK_TOLERANCE:g} of the peak {peak:.3g} m")


def accuracy_paragraphs(definitions: list[StoreDefinition]) -> list[Paragraph]:
    """Every check of the module docstring, run now on the stores."""
    paragraphs = []
    for definition in definitions:
        for check in harmonic_comparisons(definition.store):
            paragraphs.append(Paragraph(
                f"Stored harmonic run of {definition.name} (A = {number(check.amplitude)} m/s², Ω = {number(check.omega)} rad/s, "
                f"{number(float(check.time[-1]))} s) against the closed-form modal solution: largest difference in floor "
                f"displacement {check.error:.1e} m."
            ))
    paragraphs += _modal_paragraphs(definitions)
    paragraphs += _collision_paragraphs(definitions)
    crossed = cross_check(definitions)
    if crossed is not None:
        paragraphs.append(crossed)
    paragraphs += [checked for checked in map(yielding_check, definitions) if checked is not None]
    residuals = {d.name: float(d.store["energy_residual_ratio"].max()) for d in definitions if "energy_residual_ratio" in d.store}
    if residuals:
        worst = max(residuals, key=residuals.get)
        storeys = "storey dashpots, yielding storeys (hysteretic)" if has_yielding(definitions) else "storeys"
        paragraphs.append(Paragraph(
            f"Energy balance (input = kinetic + strain + dissipated in {storeys}, friction and impacts): the largest residual over "
            f"every stored case is {residuals[worst]:.1e} of the energy input (in {worst})."
        ))
    return paragraphs


def _modal_paragraphs(definitions: list[StoreDefinition]) -> list[Paragraph]:
    checked: dict[tuple, ModalCheck | None] = {}
    for definition in definitions:
        for configuration in definition.configurations:
            building = next(b for b in configuration.scene.buildings if b.name == definition.experiment.studied)
            key = (building.mass, building.stiffness, building.damping)
            if key not in checked:
                checked[key] = modal_check(building)
    sentences = []
    for check in checked.values():
        if check is None:
            continue
        sentences.append(
            f"{check.building.name} ({check.building.n_floors} floors, masses {', '.join(number(m) for m in check.building.mass)} kg): "
            f"largest difference {check.error:.1e} m against a peak of {number(check.peak * 100, 3)} cm at Ω = {number(check.omega, 4)} rad/s"
        )
    skipped = sum(1 for c in checked.values() if c is None)
    if not sentences and not skipped:
        return []
    copy = ""
    if any(c is not None and (c.building.yield_force is not None or c.building.p_delta) for c in checked.values()):
        copy = (" (an elastic copy of a yielding building: its yield shears, hardening and P-Δ left out, as the closed form is that of "
                "linear storeys; the yielding check below re-runs a stored yielding case as it ran)")
    text = (
        f"Each studied building alone on a fixed base{copy} under a_g = {number(HARMONIC_AMPLITUDE)} sin(Ωt) m/s², Ω = {HARMONIC_DETUNING:g} ω1, "
        "over 20 periods of its first mode, run now with the exact solver against the closed-form modal solution: " + "; ".join(sentences) + "."
    )
    if skipped:
        text += f" {skipped} building(s) with non-classical damping have no closed-form modal solution and were not checked this way."
    return [Paragraph(text)]


def _collision_paragraphs(definitions: list[StoreDefinition]) -> list[Paragraph]:
    checked: dict[tuple, CollisionCheck] = {}
    for definition in definitions:
        for configuration in definition.configurations:
            scene = configuration.scene
            for contact in (c for c in scene.contacts if laws.contact_law(c.law).piecewise_linear):  # the closed form is the linear element's
                masses = (scene.buildings[contact.left].mass[contact.left_floor - 1], scene.buildings[contact.right].mass[contact.right_floor - 1])
                key = (masses, contact.stiffness, contact.damping, contact.tensile)
                if key not in checked:
                    checked[key] = collision_check(masses, contact)
    if not checked:
        return []
    rows = [
        f"{'tensile' if c.contact.tensile else 'non-tensile'}, masses {number(c.masses[0])} and {number(c.masses[1])} kg, k = {number(c.contact.stiffness)} N/m, "
        f"c = {number(c.contact.damping)} N·s/m"
        + (f" (nominal restitution {number(c.contact.restitution)})" if c.contact.restitution is not None else "")
        + f": measured {c.measured:.6f}, closed form {c.expected:.6f}"
        for c in checked.values()
    ]
    worst = max(abs(c.measured - c.expected) for c in checked.values())
    return [Paragraph(
        f"Every linear (Kelvin–Voigt) contact element between buildings as a single collision of its two floor masses, free, closing at {number(COLLISION_VELOCITY)} m/s, run now "
        "with the exact solver; the coefficient of restitution measured from the velocities after separation against its closed "
        f"form for the element's separation rule (largest difference {worst:.1e}): " + "; ".join(rows) + "."
    )]
