"""The solver's accuracy, measured on a store's own buildings, contacts and cases, against what is known exactly.

Each check is a record that knows how to run itself (:meth:`CollisionCheck.run`,
:meth:`ModalCheck.run`, :meth:`HarmonicComparison.of_store`, :meth:`ReferenceRun.of`):
a single collision of two free floor masses against the Kelvin–Voigt
restitution in closed form (:func:`free_collision_restitution`), a building on
a fixed base under a_g = A sin(Ωt) against the closed-form modal solution
(:func:`stochpound.model.modal_solution.harmonic_response`), and a stored case
re-run with the solver the store used and with scipy's DOP853 at rtol 1e-12
(:class:`ReferenceRun`, of the case :meth:`ReferenceRun.pounding_case` or
:meth:`ReferenceRun.yielding_case` chooses). :meth:`ReferenceRun.verify` raises
:class:`~stochpound._errors.VerificationError` where a re-run disagrees.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import xarray as xr

from stochpound.analysis._cells import CellLabels
from stochpound._errors import VerificationError
from stochpound.model.modal_solution import harmonic_response, modal_properties
from stochpound.model.scene import Building, Contact, Scene
from stochpound.model.scene_file import scene_from_dict
from stochpound.model.scene_tables import BuildingEntry
from stochpound.solvers.simulate import simulate
from stochpound.store import Label, select_case

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

    @classmethod
    def run(cls, masses: tuple[float, float], contact: Contact) -> CollisionCheck:
        """Run the two floor masses, free, into each other through ``contact`` (exact solver) and measure the restitution."""
        effective = masses[0] * masses[1] / (masses[0] + masses[1])
        omega = math.sqrt(contact.stiffness / effective)
        zeta = contact.damping / (2.0 * math.sqrt(contact.stiffness * effective))
        duration = 3.0 * math.pi / (omega * math.sqrt(1.0 - zeta**2))

        def body(name: str, mass: float, velocity: float) -> BuildingEntry:
            return {"name": name, "mass": [mass], "stiffness": [0.0], "damping": [0.0], "initial": {"velocity": [velocity]}}

        scene = {
            "building": [body("A", masses[0], COLLISION_VELOCITY), body("B", masses[1], 0.0)],
            "contact": [{"between": [["A", 1], ["B", 1]], "gap": 0.0, "stiffness": contact.stiffness, "damping": contact.damping, "tensile": contact.tensile}],
            "motion": {"type": "constant", "acceleration": 0.0, "duration": duration, "dt": duration / 300},
        }
        run = simulate(scene_from_dict(scene), method="exact")
        y, t = run["total_displacement"].sel(floor=1).values, run["time"].values
        velocities = (y[:, -1] - y[:, -2]) / (t[-1] - t[-2])
        measured = float((velocities[1] - velocities[0]) / COLLISION_VELOCITY)
        return cls(masses, contact, free_collision_restitution(zeta, contact.tensile), measured)


@dataclass(frozen=True)
class ModalCheck:
    """A building under A sin(Ωt) on a fixed base: the solver against the closed-form modal solution (m)."""

    building: Building
    omega: float
    error: float
    peak: float

    @classmethod
    def run(cls, building: Building) -> ModalCheck | None:
        """Run ``building`` alone on a fixed base under A sin(0.9 ω1 t) for 20 periods (None if its damping is not classical)."""
        modes = modal_properties(building)
        if not modes.classical:
            return None
        omega = HARMONIC_DETUNING * float(modes.omega[0])
        period = 2.0 * math.pi / float(modes.omega[0])
        alone = Building(building.name, building.mass, building.stiffness, building.damping, building.damping_ratio)
        motion = {"type": "harmonic", "amplitude": HARMONIC_AMPLITUDE, "omega": omega, "duration": 20.0 * period, "dt": period / 40.0}
        scene = scene_from_dict({"building": [_building_table(alone)], "motion": motion})
        run = simulate(scene, method="exact")
        computed = run["relative_displacement"].sel(building=building.name).values
        exact = harmonic_response(alone, HARMONIC_AMPLITUDE, omega, run["time"].values)
        return cls(building, omega, float(np.max(np.abs(computed - exact))), float(np.max(np.abs(exact))))



def _building_table(building: Building) -> BuildingEntry:
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

    @classmethod
    def of_store(cls, store: xr.Dataset) -> list[HarmonicComparison]:
        """A store's harmonic motions (``[[motions]]`` of type harmonic) beside the closed-form modal solution."""
        comparisons = []
        for motion in store.pound.definition.motions:
            if motion.type != "harmonic":
                continue
            building = store.pound.scene(record=motion.label).buildings[0]
            run = select_case(store, record=motion.label)
            computed = run["relative_displacement"].sel(building=building.name).values
            valid = np.isfinite(computed[0])
            time = run["time"].values[valid]
            amplitude, omega = float(motion.motion["amplitude"]), float(motion.motion["omega"])
            comparisons.append(cls(amplitude, omega, time, computed[:, valid], harmonic_response(building, amplitude, omega, time)))
        return comparisons



#: The store's yielding summaries the yielding check recomputes: name -> the run's per-storey variable (largest absolute value over the storeys).
YIELDING_SUMMARIES = {"peak_ductility": "peak_storey_ductility", "residual_drift": "residual_storey_drift"}
SUMMARY_RTOL = 1e-9
"""Largest relative difference of a re-run's yielding summaries from the store's that passes."""


@dataclass(frozen=True)
class ReferenceRun:
    """A stored case's scene run as the store ran it (the exact solver, or the integrator at its defaults for a nonlinear law)
    and with scipy's DOP853 at rtol :data:`REFERENCE_RTOL`: both runs, their largest difference in any floor's total
    displacement and the reference's peak (m)."""

    scene: Scene
    exact: xr.Dataset
    reference: xr.Dataset
    difference: float
    peak: float

    @classmethod
    def of(cls, scene: Scene) -> ReferenceRun:
        """Run ``scene`` both ways."""
        exact = simulate(scene)  # the solver the store used: exact, or the integrator at its defaults for a nonlinear law
        reference = simulate(scene, method="ivp", integrator="DOP853", rtol=REFERENCE_RTOL, atol=REFERENCE_ATOL)
        difference = float(np.nanmax(np.abs(exact["total_displacement"].values - reference["total_displacement"].values)))
        return cls(scene, exact, reference, difference, float(np.nanmax(np.abs(reference["total_displacement"].values))))

    @property
    def impacts(self) -> tuple[int, int]:
        """The impacts the two runs count."""
        return self.exact.sizes["impact"], self.reference.sizes["impact"]

    @property
    def sliding(self) -> float:
        """The peak |sliding displacement| over the run and its bases (m): the largest excursion, not the range between the extremes."""
        return float(np.abs(self.exact["sliding_displacement"]).max())

    def yielding_summaries(self, buildings: xr.DataArray) -> dict[str, xr.DataArray]:
        """The run's summaries of :data:`YIELDING_SUMMARIES` per building of ``buildings`` (the largest absolute value over its storeys)."""
        return {key: np.abs(self.exact[source]).max("floor").sel(building=buildings) for key, source in YIELDING_SUMMARIES.items()}

    @staticmethod
    def mismatched_summaries(summaries: dict[str, xr.DataArray], stored: xr.Dataset) -> list[str]:
        """The summaries of :meth:`yielding_summaries` that differ from the ``stored`` case's by more than :data:`SUMMARY_RTOL`."""
        return [key for key, values in summaries.items()
                if not np.allclose(values.values, stored[key].values, rtol=SUMMARY_RTOL, atol=0.0, equal_nan=True)]

    @staticmethod
    def most_ductile(summaries: dict[str, xr.DataArray]) -> str:
        """The building with the largest peak ductility of :meth:`yielding_summaries`."""
        return str(summaries["peak_ductility"].idxmax("building").item())

    def verify(self, name: str, where: str, held: int) -> None:
        """Raise :class:`~stochpound._errors.VerificationError` where the re-run of the case of ``name`` at ``where`` disagrees with
        the ``held`` impacts of the store or with the reference (more than :data:`CROSS_CHECK_TOLERANCE` of the peak)."""
        counts, difference, peak = self.impacts, self.difference, self.peak
        if counts[0] != held:
            raise VerificationError(f"cross-check: the stored case of {name} ({where}) re-run counts {counts[0]} impacts, the store holds {held}")
        if counts[1] != counts[0]:
            raise VerificationError(f"cross-check: on the stored case of {name} ({where}) the solver counts {counts[0]} impacts, "
                                    f"scipy's DOP853 {counts[1]}")
        if not difference <= CROSS_CHECK_TOLERANCE * peak:
            raise VerificationError(f"cross-check: on the stored case of {name} ({where}) the solver and scipy's DOP853 differ by "
                                    f"{difference:.1e} m, more than {CROSS_CHECK_TOLERANCE:g} of the peak {peak:.3g} m")

    @staticmethod
    def pounding_case(store: xr.Dataset) -> tuple[dict[str, Label], bool] | None:
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

    @staticmethod
    def yielding_case(store: xr.Dataset) -> CellLabels | None:
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
