"""The methods section: model and its corrections, solver and its verified accuracy, records, experiments, software.

The accuracy figures are measured while the report is built (the solver
against the closed-form modal solution, the exact solver against scipy's
DOP853 on a stored case, the energy balance of every stored case), not
quoted.
"""

from __future__ import annotations

import importlib.metadata
import json
import platform
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import pandas as pd
import xarray as xr

import stochpound
from stochpound.model.modal_solution import harmonic_response
from stochpound.motions.records import registry_entries
from stochpound.report.document import Paragraph, Section, Table
from stochpound.report.stores import case_scene, select

#: Packages whose versions the report lists.
PACKAGES = ("numpy", "scipy", "xarray", "numba", "dask", "pandas", "matplotlib", "h5netcdf", "jinja2")
#: The stored case the exact solver is cross-checked on (Table 4.3's μ = 0.2 column: sliding and pounding).
CROSS_CHECK_CASE = {"isolation": "b1_isolated", "neighbour": "flexible", "model": "corrected", "gap": 0.02, "mu": 0.2, "record": "el_centro"}

MODEL_TEXT = (
    "Buildings are shear buildings with lumped floor masses, storey springs and dashpots (C = a1·K, 1 % in mode 1); a "
    "building on a flat friction slider has one more degree of freedom, its sliding displacement, with Coulomb friction "
    "μW that sticks while the force it needs stays below μW. Adjacent floors at the same level are joined by a linear "
    "Kelvin–Voigt impact element that acts only while the gap is closed (impact frequency 57.05 rad/s, restitution 0.5), "
    "tensile until the penetration returns to zero as in the study. The model (docs/model.md) corrects the study's "
    "equations in two places: the impact forces act on the isolated building as a whole (the study's sliding equation "
    "left them out, so an impact could not change a sliding building's momentum), and friction at the onset of slip "
    "opposes the driving force (the study used sgn(0) = 0) with a slipping base stopping only when its velocity reaches "
    "zero. The study's equations remain available as study_compat, and are run beside the corrected model in every "
    "isolated case here."
)
SOLVER_TEXT = (
    "Every case is solved with the exact event-driven solver (docs/solvers.md): between events each contact/stick–slip "
    "mode is linear and the ground acceleration is piecewise linear (or a natural cubic spline, the study's choice) "
    "between samples, so the state is advanced by matrix exponentials without truncation error, and contact, separation, "
    "slip and stop are located on that exact flow to 1e-10 s, including crossings hidden inside a sample interval."
)


def methods_section(stores: Mapping[str, xr.Dataset]) -> Section:
    """The methods section for the given stores (keyed by experiment name)."""
    section = Section("Methods", key="methods")
    section.add(Paragraph(MODEL_TEXT))
    section.add(Paragraph(SOLVER_TEXT))
    for paragraph in accuracy(stores):
        section.add(paragraph)
    section.add(records_provenance(stores))
    for name, store in stores.items():
        section.add(Paragraph(experiment_provenance(name, store)))
    section.add(Paragraph(software()))
    return section


def accuracy(stores: Mapping[str, xr.Dataset]) -> list[Paragraph]:
    """The solver's accuracy, measured now on the stores."""
    paragraphs = []
    harmonic = stores.get("study_harmonic")
    if harmonic is not None:
        errors = [f"{c.error:.1e} m at Ω = {c.omega:g} rad/s" for c in harmonic_comparisons(harmonic)]
        paragraphs.append(Paragraph(
            "Against the closed-form modal solution of the fixed-base building under A sin(Ωt) (Figures 3.2–3.3) the "
            f"largest difference in floor displacement over 15 s is {' and '.join(errors)}."
        ))
    pair = stores.get("study_pair_mu")
    if pair is not None:
        paragraphs.append(Paragraph(cross_check(pair)))
    residuals = [float(store["energy_residual_ratio"].max()) for store in stores.values() if "energy_residual_ratio" in store]
    if residuals:
        paragraphs.append(Paragraph(
            "Energy balance (input = kinetic + strain + dissipated in storeys, friction and impacts): the largest residual "
            f"over every stored case is {max(residuals):.1e} of the energy input."
        ))
    return paragraphs


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
        """Largest |computed − exact|, m."""
        return float(np.max(np.abs(self.computed - self.exact)))


def harmonic_comparisons(store: xr.Dataset) -> list[HarmonicComparison]:
    """The stored harmonic-check runs (``study_harmonic``) beside the closed-form modal solution."""
    definition = json.loads(store.attrs["definition"])
    building = case_scene(store, record=str(store["record"].values[0])).buildings[0]
    comparisons = []
    for motion in definition["motions"]:
        run = select(store, record=motion["label"])
        computed = run["relative_displacement"].sel(building=building.name).values
        valid = np.isfinite(computed[0])
        time = run["time"].values[valid]
        amplitude, omega = float(motion["motion"]["amplitude"]), float(motion["motion"]["omega"])
        exact = harmonic_response(building, amplitude, omega, time)
        comparisons.append(HarmonicComparison(amplitude, omega, time, computed[:, valid], exact))
    return comparisons


def cross_check(store: xr.Dataset) -> str:
    """The exact solver against scipy's DOP853 (rtol 1e-12) on a stored case with sliding and pounding."""
    scene = case_scene(store, **CROSS_CHECK_CASE)
    exact = stochpound.simulate(scene, method="exact")
    reference = stochpound.simulate(scene, method="ivp", integrator="DOP853", rtol=1e-12, atol=1e-14)
    difference = float(np.nanmax(np.abs(exact["total_displacement"].values - reference["total_displacement"].values)))
    stored = select(store, **CROSS_CHECK_CASE)
    return (
        "Cross-check on a stored case with sliding and pounding (Building 1 isolated, μ = 0.2, flexible fixed Building 2, "
        f"gap 2 cm, El Centro, 50 s): the exact solver and scipy's DOP853 with event location (rtol 1e-12) differ by at most "
        f"{difference:.1e} m in any floor's total displacement, and count {exact.sizes['impact']} and "
        f"{reference.sizes['impact']} impacts (the store holds {float(stored['impacts']):.0f})."
    )


def records_provenance(stores: Mapping[str, xr.Dataset]) -> Table:
    """Where each record run by the stores comes from (data/records/SOURCES.md has the full provenance)."""
    entries = registry_entries()
    rows = {}
    for name in sorted(_records_used(stores)):
        entry = entries[name]
        base = entries.get(str(entry.fields.get("base", "")))
        source = entry.fields.get("source") or (base.fields.get("source") if base is not None else "")
        rows[name] = [entry.description, source, entry.fields.get("study_relation", "")]
    frame = pd.DataFrame.from_dict(rows, orient="index", columns=["record", "source", "relation to the study"])
    frame.index.name = "name"
    return Table(
        key="table-records",
        caption="The records run by these experiments, with their provenance.",
        frame=frame,
        note="Full provenance, checksums and the checks made on each file: data/records/SOURCES.md and data/records/registry.toml.",
    )


def _records_used(stores: Mapping[str, xr.Dataset]) -> set[str]:
    used = set()
    for store in stores.values():
        for motion in json.loads(store.attrs["definition"])["motions"]:
            if motion["motion"].get("type") == "record":
                used.add(str(motion["motion"]["record"]))
    return used & set(registry_entries())


def experiment_provenance(name: str, store: xr.Dataset) -> str:
    """One store: what it ran, how far, with what, and its identity."""
    attrs = store.attrs
    return (
        f"Experiment {name} ({attrs.get('experiment_file', '')}): {attrs.get('experiment_description', '')}. "
        f"{int(attrs.get('cases_done', 0))} of {int(attrs.get('cases_total', 0))} cases done, solver "
        f"{attrs.get('solver', '')}, stochpound {attrs.get('stochpound_version', '')} (commit {attrs.get('git_commit', 'unknown')}), "
        f"definition sha256 {str(attrs.get('definition_sha256', ''))[:16]}…"
    )


def software() -> str:
    """Versions of Python, stochpound and its main dependencies."""
    versions = [f"{package} {_version(package)}" for package in PACKAGES]
    return f"Software: Python {platform.python_version()}, stochpound {stochpound.__version__}, " + ", ".join(versions) + "."


def _version(package: str) -> str:
    try:
        return importlib.metadata.version(package)
    except importlib.metadata.PackageNotFoundError:
        return "not installed"
