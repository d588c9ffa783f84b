"""The solver's accuracy, measured while the report is built, on the stores' own buildings and contacts.

Five checks, each against something known exactly or computed independently:

* every studied building on a fixed base under a_g = A sin(Ωt), against the
  closed-form modal solution (:func:`stochpound.modal_solution.harmonic_response`);
  a store's harmonic motions (``[[motions]]`` of type harmonic), when present, are checked on its stored runs;
* every contact element as a single collision of its two floor masses, free,
  against the restitution the Kelvin–Voigt law gives in closed form
  (:func:`stochpound.analysis.free_collision_restitution`);
* one stored case with pounding (and sliding, where a store has it) rerun
  with the exact solver and with scipy's DOP853 at rtol 1e-12;
* per store with yielding storeys, one stored case that yielded, rerun the
  same way and against the store's peak ductility and residual drift;
* the energy balance of every stored case (read from the stores).
"""

from __future__ import annotations

from stochpound._errors import VerificationError
from stochpound.analysis import (COLLISION_VELOCITY, CROSS_CHECK_TOLERANCE, HARMONIC_AMPLITUDE, HARMONIC_DETUNING, REFERENCE_RTOL,
                                 SUMMARY_RTOL, CollisionCheck, HarmonicComparison, ModalCheck, ReferenceRun)
from stochpound.model import laws
from stochpound.model.scene import Scene
from stochpound.report.render import Paragraph
from stochpound.report.sections._description import StoreDefinition, has_yielding, number, numbers
from stochpound.report.sections._store_reading import select

harmonic_comparisons = HarmonicComparison.of_store
"""A store's harmonic motions beside the closed-form modal solution (:meth:`stochpound.analysis.HarmonicComparison.of_store`)."""


def cross_check(definitions: list[StoreDefinition]) -> Paragraph | None:
    """The exact solver against scipy's DOP853 (rtol 1e-12) on one stored case with pounding, with sliding if any store has it.

    The case is re-run exactly as it ran (its scene, motion and intensity
    scale factor). The check can fail: the build stops with a
    :class:`~stochpound._errors.VerificationError` when the re-run does not
    count the impacts the store holds, when the two solvers count different
    impacts, or when they differ by more than :data:`CROSS_CHECK_TOLERANCE`
    of the peak displacement.
    """
    candidates = [(d, found) for d in definitions if "impacts" in d.store for found in [ReferenceRun.pounding_case(d.store)] if found is not None]
    if not candidates:
        return None
    definition, (labels, _) = next((c for c in candidates if c[1][1]), candidates[0])
    name, store = definition.name, definition.store
    scene: Scene = store.pound.scene(**labels)
    nonlinear = scene.nonlinear_laws()
    run = ReferenceRun.of(scene)
    difference, peak = run.difference, run.peak
    held = int(select(store, **labels)["impacts"])
    where = ", ".join(f"{k} = {number(v) if isinstance(v, float) else v}" for k, v in labels.items())
    counts = run.impacts
    run.verify(name, where, held)
    sliding = run.sliding
    scale = float(select(store, **labels)["scale_factor"]) if "scale_factor" in store else 1.0
    return Paragraph(
        f"Cross-check on a stored case of {name} ({where}"
        + (f", motion scale factor {number(scale, 4)}" if scale != 1.0 else "")
        + f"; {counts[0]} impacts"
        + (f", peak base sliding {number(sliding * 100, 3)} cm" if sliding > 0 else "")
        + f", {number(float(scene.motion.times[-1]))} s), re-run as it was run: "
        + (f"the ivp solver at its defaults (nonlinear laws: {'; '.join(nonlinear)})" if nonlinear else "the exact solver")
        + " and scipy's DOP853 with event location "
        f"(rtol {REFERENCE_RTOL:g}) differ by at most {difference:.1e} m in any floor's total displacement (peak "
        f"{number(peak * 100, 3)} cm) and both count the {held} impacts the store holds. The report is built only when "
        f"they agree (impact counts equal, displacements within {CROSS_CHECK_TOLERANCE:g} of the peak)."
    )


def yielding_check(definition: StoreDefinition) -> Paragraph | None:
    """A stored case whose storeys yielded, re-run as it ran, against scipy's DOP853 (rtol 1e-12) and against the store (None without one).

    The check can fail: the build stops with a
    :class:`~stochpound._errors.VerificationError` when the re-run's peak
    ductility or residual drift of a building differs from the store's by
    more than :data:`SUMMARY_RTOL`, when its impacts differ from the store's
    or DOP853's, or when the two solvers differ by more than
    :data:`CROSS_CHECK_TOLERANCE` of the peak displacement.
    """
    labels = ReferenceRun.yielding_case(definition.store)
    if labels is None:
        return None
    name, stored = definition.name, select(definition.store, **labels)
    scene: Scene = definition.store.pound.scene(**labels)
    run = ReferenceRun.of(scene)
    exact, difference, peak = run.exact, run.difference, run.peak
    where = ", ".join(f"{k} = {number(v) if isinstance(v, float) else v}" for k, v in labels.items())
    run.verify(name, where, int(stored["impacts"]) if "impacts" in stored else exact.sizes["impact"])
    rerun = run.yielding_summaries(stored["building"])
    for key in run.mismatched_summaries(rerun, stored):
        raise VerificationError(f"yielding check: the stored case of {name} ({where}) re-run gives {key} {numbers(rerun[key].values, 10)}, "
                                f"the store holds {numbers(stored[key].values, 10)}")
    building = run.most_ductile(rerun)
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


def accuracy_paragraphs(definitions: list[StoreDefinition]) -> list[Paragraph]:
    """Every check of the module docstring, run now on the stores."""
    paragraphs = []
    for definition in definitions:
        for check in HarmonicComparison.of_store(definition.store):
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
    residuals = {d.name: d.energy_residual for d in definitions if d.energy_residual is not None}
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
                checked[key] = ModalCheck.run(building)
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
            for contact in (c for c in scene.contacts if laws.CONTACT_LAWS[c.law].piecewise_linear):  # the closed form is the linear element's
                masses = (scene.buildings[contact.left].mass[contact.left_floor - 1], scene.buildings[contact.right].mass[contact.right_floor - 1])
                key = (masses, contact.stiffness, contact.damping, contact.tensile)
                if key not in checked:
                    checked[key] = CollisionCheck.run(masses, contact)
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
