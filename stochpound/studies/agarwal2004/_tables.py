"""The study's Tables 3.2 and 4.1–4.10: its published values beside ours, in its layout.

Each table's rows group a statistic (or a record, or a μ) with its sources:
``study`` (the published value), ``corrected model`` (ours: docs/model.md, the
record interpolated linearly between samples), ``difference`` (corrected −
study) and, where the store has them, the sensitivity rows ``corrected,
spline input`` (the study's cubic-spline interpolation of the record) and
``study's equations`` (``study_compat``: sgn(0) = 0 at slip onset and no
impact forces in the base equation). One convention throughout: every row
but ``corrected, spline input`` runs the record interpolated linearly, so a
``study's equations`` row differs from the ``corrected model`` row by the
equations alone.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd
import xarray as xr

from stochpound.experiment import is_fixed_base
from stochpound.model.modal_solution import modal_properties
from stochpound.motions.records import load_record, record_statistics, registry_entries
from stochpound.report.sections import StoreDefinition, value
from stochpound.report.render import Table
from stochpound.studies.agarwal2004._published import published_tables, study_number
from stochpound.studies.agarwal2004._records import STUDY_G, study_table_3_2

CM = 100.0
STUDY = "study"
CORRECTED = "corrected model"
DIFFERENCE = "difference"
SPLINE = "corrected, spline input"
STUDY_EQUATIONS = "study's equations"

#: (row label, store variable, factor to the study's unit)
STATISTICS = (
    ("mean (cm)", "response_mean", CM),
    ("variance (cm²)", "response_variance", CM * CM),
    ("std (cm)", "response_std", CM),
    ("skewness", "response_skewness", 1.0),
    ("excess", "response_excess", 1.0),
    ("impacts", "impacts", 1.0),
)
#: Stores' record labels of the study's records (``experiments/study/*.toml``).
RECORDS = {"mexico_city": "Mexico City 1985", "el_centro": "El Centro 1940", "loma_prieta": "Loma Prieta 1989", "northridge": "Northridge 1994"}
#: The registry entries behind them (Table 3.2).
RECORD_ENTRIES = {
    "mexico_city": "mexico_city_1985_study",
    "el_centro": "el_centro_1940_study",
    "loma_prieta": "loma_prieta_1989_substitute",
    "northridge": "northridge_1994_substitute",
}
_INTEGER_FORMATS = {"impacts": "{:.0f}", "in-phase impacts": "{:.0f}", "out-of-phase impacts": "{:.0f}"}


def record_label(record: str) -> str:
    """A study record's display name, with "(substitute)" when the bundled record stands in for the study's."""
    entry = registry_entries().get(RECORD_ENTRIES.get(record, ""))
    name = RECORDS.get(record, record)
    return f"{name} (substitute)" if entry is not None and entry.substitute_for else name


def mu_label(mu: float | str) -> str:
    """Column label of a friction coefficient: "μ = ∞" for the fixed base."""
    if mu == "single":
        return "single building"
    return "μ = ∞" if is_fixed_base(mu) else f"μ = {float(mu):g}"


def _variants(store: xr.Dataset | None) -> dict[str, dict[str, str]]:
    """The store labels behind each of our sources (only those the store has)."""
    if store is None:
        return {CORRECTED: {"model": "corrected", "record": "el_centro"}}
    records = list(store["record"].values)
    models = list(store["model"].values) if "model" in store.dims else ["corrected"]
    sources = {CORRECTED: {"model": "corrected", "record": "el_centro"}}
    if "el_centro_spline" in records:
        sources[SPLINE] = {"model": "corrected", "record": "el_centro_spline"}
    if "study_compat" in models:
        sources[STUDY_EQUATIONS] = {"model": "study_compat", "record": "el_centro"}
    return sources


def mu_table(number: str, store: xr.Dataset | None) -> Table:
    """Table 4.1, 4.3, 4.5 or 4.7: Building 1's top-floor total displacement against μ (El Centro, gap 2 cm).

    Parameters
    ----------
    number : str
        ``"4.1"``, ``"4.3"``, ``"4.5"`` or ``"4.7"``.
    store : xarray.Dataset or None
        The ``study_pair_mu`` store (None: only the study's values).
    """
    published = published_tables()
    spec = published["table"][number]
    columns = published["columns"]["mu"]
    sources = _variants(store)
    rows: dict[tuple[str, str], list[float]] = {}
    for label, variable, factor in STATISTICS:
        study = [study_number(v) for v in spec[variable.removeprefix("response_")]]
        rows[(label, STUDY)] = study
        for source, labels in sources.items():
            cells = [_mu_cell(store, variable, factor, column, spec, labels) for column in columns]
            rows[(label, source)] = cells
            if source == CORRECTED:
                rows[(label, DIFFERENCE)] = list(np.subtract(cells, study))
    frame = pd.DataFrame.from_dict(rows, orient="index", columns=[mu_label(c) for c in columns])
    frame.index = pd.MultiIndex.from_tuples(frame.index, names=["statistic", "source"])
    return Table(
        key=f"table-{number}",
        caption=f"Table {number}: {spec['title']}. Building 1's top-floor total displacement, El Centro 1940 (the study's record), gap 2 cm.",
        frame=frame,
        note=_NOTE,
        formats={"impacts": "{:.0f}"},
    )


def _mu_cell(store: xr.Dataset | None, variable: str, factor: float, column: float | str, spec: Mapping[str, str], labels: Mapping[str, str]) -> float:
    record = labels["record"]
    if column == "single":
        if variable == "impacts":
            return float("nan")
        return value(store, f"reference_{variable}", factor, record=record)
    case = {"isolation": spec["configuration"], "neighbour": spec["neighbour"], "model": labels["model"], "gap": 0.02, "mu": float(column), "record": record}
    return value(store, variable, factor, **case)


_NOTE = (
    "study: the published value. corrected model: this project (docs/model.md), the record interpolated linearly "
    "between samples. difference: corrected model − study. corrected, spline input: the same with the study's "
    "cubic-spline interpolation of the record. study's equations: study_compat (sgn(0) = 0 at slip onset, no "
    "impact forces in the base equation), the record interpolated linearly as in the corrected model's row. "
    "Statistics are taken over the whole record on its 0.02 s sample grid (t = 0 included). Excess = kurtosis − 3. "
    "– : not published or not run."
)


def by_record_table(number: str, store: xr.Dataset | None) -> Table:
    """Table 4.2, 4.4, 4.6 or 4.8: by record at μ = 0.2 (gap 2, 2, 4, 8 cm as in the study).

    Parameters
    ----------
    number : str
        ``"4.2"``, ``"4.4"``, ``"4.6"`` or ``"4.8"``.
    store : xarray.Dataset or None
        The ``study_pair_records`` store.
    """
    by_record = published_tables()["by_record"]
    spec = by_record["table"][number]
    variables = (("response_mean", CM), ("response_std", CM), ("response_skewness", 1.0), ("response_excess", 1.0), ("impacts_in_phase", 1.0), ("impacts_out_of_phase", 1.0))
    columns = ["mean (cm)", "std (cm)", "skewness", "excess", "in-phase impacts", "out-of-phase impacts"]
    models = list(store["model"].values) if store is not None and "model" in store.dims else ["corrected"]
    rows: dict[tuple[str, str], list[float]] = {}
    for record, gap in zip(by_record["records"], by_record["gap"]):
        label = f"{record_label(record)}, gap {gap * CM:g} cm"
        study = [study_number(v) for v in spec[record]]
        case = {"isolation": spec["configuration"], "neighbour": spec["neighbour"], "gap": gap, "mu": 0.2, "record": record}
        ours = [value(store, name, factor, model="corrected", **case) for name, factor in variables]
        rows[(label, STUDY)] = study
        rows[(label, CORRECTED)] = ours
        rows[(label, DIFFERENCE)] = list(np.subtract(ours, study))
        if "study_compat" in models:
            rows[(label, STUDY_EQUATIONS)] = [value(store, name, factor, model="study_compat", **case) for name, factor in variables]
    frame = pd.DataFrame.from_dict(rows, orient="index", columns=columns)
    frame.index = pd.MultiIndex.from_tuples(frame.index, names=["record", "source"])
    return Table(
        key=f"table-{number}",
        caption=f"Table {number}: {spec['title']}. Building 1's top-floor total displacement and impacts by record.",
        frame=frame,
        note=_NOTE.replace(" corrected, spline input: the same with the study's cubic-spline interpolation of the record.", "")
        + " In-phase impacts: both floors moving the same way at onset; out-of-phase: moving towards each other. "
        "Loma Prieta and Northridge are substitutes for the study's records (Table 3.2), and their rows are not comparable with the study's.",
        formats=_INTEGER_FORMATS,
    )


def correlation_table(store: xr.Dataset | None) -> Table:
    """Tables 4.9–4.10: correlation of Building 1's response with the same building alone on a fixed base.

    Parameters
    ----------
    store : xarray.Dataset or None
        The ``study_pair_mu`` store.
    """
    published = published_tables()["correlation"]
    configurations = [(n, i) for n in ("stiff", "flexible") for i in ("b1_isolated", "both_isolated")]
    names = {"b1_isolated": "B1 isolated, B2 fixed", "both_isolated": "both isolated"}
    sources = _variants(store)
    rows: dict[tuple[str, str], list[float]] = {}
    for position, mu in enumerate(published["mu"]):
        label = mu_label(mu)
        study = [float(published[f"{n}_{i}"][position]) for n, i in configurations]
        rows[(label, STUDY)] = study
        for source, labels in sources.items():
            cells = [
                value(store, "fixed_base_correlation", isolation=i, neighbour=n, gap=0.02, mu=float(mu), **labels)
                for n, i in configurations
            ]
            rows[(label, source)] = cells
            if source == CORRECTED:
                rows[(label, DIFFERENCE)] = list(np.subtract(cells, study))
    columns = pd.MultiIndex.from_tuples([(f"B2 {n}", names[i]) for n, i in configurations], names=["neighbour", "configuration"])
    frame = pd.DataFrame(list(rows.values()), index=pd.MultiIndex.from_tuples(rows, names=["μ", "source"]), columns=columns)
    return Table(
        key="table-4.9-4.10",
        caption=(
            "Tables 4.9 and 4.10: correlation coefficient of Building 1's top-floor total displacement with that of "
            "the same building alone on a fixed base under the same motion (El Centro 1940, gap 2 cm)."
        ),
        frame=frame,
        note=_NOTE.replace(" Excess = kurtosis − 3.", ""),
        formats={},
    )


def records_table() -> Table:
    """Table 3.2: acceleration statistics of the study's four records beside the bundled ones (m/s²)."""
    columns = ["dt (s)", "points", "peak (g)", "mean (m/s²)", "std (m/s²)", "skewness", "excess"]
    fields = ["dt", "npts", "peak_g", "mean", "std", "skewness", "excess"]
    rows: dict[tuple[str, str], list[float]] = {}
    for record, entry in RECORD_ENTRIES.items():
        study = study_table_3_2(record)
        ours = record_statistics(load_record(entry), g=STUDY_G).as_dict()
        rows[(record_label(record), STUDY)] = [study[f] for f in fields]
        rows[(record_label(record), f"bundled: {entry}")] = [ours[f] for f in fields]
    frame = pd.DataFrame(list(rows.values()), index=pd.MultiIndex.from_tuples(rows, names=["record", "source"]), columns=columns)
    el_centro = frame.loc[record_label("el_centro")]
    differences = ", ".join(
        f"{name.split(' (')[0]} {el_centro.iloc[1][name]:.4g} against {el_centro.iloc[0][name]:.4g}"
        for name in columns[2:]
        if f"{el_centro.iloc[1][name]:.3g}" != f"{el_centro.iloc[0][name]:.3g}"
    )
    return Table(
        key="table-3.2",
        caption="Table 3.2: the four records' ground accelerations, the study's statistics beside those of the records this project runs (g = 9.814 m/s²).",
        frame=frame,
        note=(
            "Excess = kurtosis − 3. The study's El Centro is reconstructed as the first 2500 samples divided by 1.0197; it "
            f"matches the published values to three significant digits except: {differences or 'none'}. The study's Mexico City "
            "had about 17 s more quiet coda; Loma Prieta and Northridge are substitutes (the study's files were not found): see "
            "the records' provenance in the methods section."
        ),
        formats={"points": "{:.0f}"},
    )


def building_2_table(store: xr.Dataset) -> Table:
    """Table 3.3: Building 2 stiff and flexible (modes) and the impact elements of each pair, the study's values beside the store's.

    Parameters
    ----------
    store : xarray.Dataset
        A store with the ``neighbour`` variants (``study_gap``).
    """
    published = published_tables()["table"]["3.3"]
    configurations = {c.labels["neighbour"]: c.scene for c in StoreDefinition("study_gap", store).configurations}
    rows: dict[str, list[float]] = {}
    for neighbour in ("stiff", "flexible"):
        scene = configurations[neighbour]
        modes = modal_properties(scene.buildings[1])
        ours = {
            "mass factor": scene.buildings[1].mass[0] / scene.buildings[0].mass[0],
            "T1 (s)": modes.periods[0], "T2 (s)": modes.periods[1], "ω1 (rad/s)": modes.omega[0], "ω2 (rad/s)": modes.omega[1],
            "ζ1 (%)": modes.damping_ratio[0] * 100,
            **{f"k_imp, floor {c.left_floor} (N/m)": c.stiffness for c in scene.contacts},
            **{f"c_imp, floor {c.left_floor} (N·s/m)": c.damping for c in scene.contacts},
        }
        study = published[neighbour]
        study_values = [
            study["mass_factor"], study["T1"], study["T2"], study["omega1"], study["omega2"], study["zeta1"] * 100,
            *study.get("k_imp", [np.nan] * 2), *study.get("c_imp", [np.nan] * 2),
        ]
        for label, computed, theirs in zip(ours, ours.values(), study_values):
            rows.setdefault(label, []).extend([theirs, computed])
    columns = pd.MultiIndex.from_product([["B2 stiff", "B2 flexible"], [STUDY, CORRECTED]], names=["neighbour", "source"])
    frame = pd.DataFrame.from_dict(rows, orient="index", columns=columns)
    frame.index.name = "property"
    return Table(
        key="table-3.3",
        caption="Table 3.3: Building 2, stiff or flexible, on a fixed base, and the impact elements between it and Building 1 at each floor.",
        frame=frame,
        note=(
            "Building 2 has Building 1's storey stiffnesses and its masses times the factor. "
            "k_imp keeps √(k_imp/m_eff) of the equal-mass pair, so it grows with m_eff = m1 m2/(m1 + m2): the flexible pair's "
            "elements are stiffer. c_imp = 2ξ√(k_imp m_eff) with ξ from the restitution. The study gives k_imp and c_imp only "
            "for the flexible pair (in its program listing)."
        ),
        formats={},
    )
