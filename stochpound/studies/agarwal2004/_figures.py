"""The study's figures (3.2–3.4, 3.6–3.9, 4.1–4.20) from the study's experiment stores.

Each function takes the store it needs (see ``experiments/study/``) and
returns :class:`FigureItem` objects; the record is named in every caption and
substitutes are labelled as such.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from stochpound.experiment import FIXED_BASE, is_fixed_base
from stochpound.store import isolated_mus
from stochpound.motions.records import load_record
from stochpound.report.render import figures
from stochpound.report.render import FigureItem
from stochpound.report.sections import harmonic_comparisons, select
from stochpound.studies.agarwal2004._tables import RECORD_ENTRIES, record_label

CM = 100.0
NEIGHBOURS = {"stiff": "B2 stiff", "flexible": "B2 flexible"}
CONFIGURATIONS = {"b1_isolated": "Building 1 isolated, Building 2 fixed", "both_isolated": "both isolated, same μ"}
#: Our runs of the study's cases: corrected model, the record interpolated linearly.
CORRECTED = {"model": "corrected", "record": "el_centro"}


def harmonic_check(store: xr.Dataset) -> list[FigureItem]:
    """Figures 3.2–3.3: the solver against the closed-form modal solution, fixed-base building, a_g = A sin(Ωt)."""
    items = []
    for number, check in zip(("3.2", "3.3"), harmonic_comparisons(store)):
        panels = {
            f"floor {floor} (cm)": {"closed-form modal solution": check.exact[floor - 1] * CM, "stochpound (exact solver)": check.computed[floor - 1] * CM}
            for floor in (1, 2)
        }
        title = f"Harmonic check: A = {check.amplitude:g} m/s², Ω = {check.omega:g} rad/s; largest difference {check.error:.1e} m"
        caption = (
            f"Figure {number}: the fixed-base reference building under a_g = A sin(Ωt), A = {check.amplitude:g} m/s², "
            f"Ω = {check.omega:g} rad/s: floor displacements relative to the ground, closed-form modal solution and "
            f"the solver (largest difference {check.error:.1e} m over {check.time[-1]:g} s)."
        )
        items.append(FigureItem(f"figure-{number}", caption, figures.traces(check.time, panels, title)))
    return items


def accelerograms() -> FigureItem:
    """Figure 3.4: the four records as this project runs them (substitutes labelled)."""
    panels, longest = {}, 0.0
    series = {}
    for record, entry in RECORD_ENTRIES.items():
        loaded = load_record(entry)
        series[record] = (loaded.time, loaded.acceleration(g=9.814))
        longest = max(longest, loaded.duration)
    time = np.arange(0.0, longest + 0.005, 0.005)
    for record, (t, a) in series.items():
        panels[record_label(record)] = {record_label(record): np.interp(time, t, a, left=np.nan, right=np.nan)}
    caption = (
        "Figure 3.4: ground accelerations of the four records (the study's El Centro and Mexico City; substitutes "
        "for Loma Prieta and Northridge, whose study files were not found)."
    )
    return FigureItem("figure-3.4", caption, figures.traces(time, panels, "The four records", height=1.7, y_label="a_g (m/s²)"))


def gap_time_history(store: xr.Dataset, gap: float = 0.02, neighbour: str = "flexible") -> FigureItem:
    """Figure 3.6: Building 1's top floor with impact onsets, and each contact's force with its impacts' located peaks (both fixed)."""
    case = {"neighbour": neighbour, "gap": gap, "mu": FIXED_BASE, "record": "el_centro"}
    run = select(store, **case)
    top = run["total_displacement"].sel(building="B1").isel(floor=-1).values
    impacts = store.pound.impacts(**case, realization=0)
    forces = {}
    for contact in run["contact"].values:
        mine = impacts.isel(impact=np.flatnonzero(impacts["impact_contact"].values == contact))
        forces[f"contact at floor {contact + 1}"] = (run["impact_force"].sel(contact=contact).values, mine["impact_peak_time"].values, mine["impact_peak_force"].values)
    title = f"Both fixed, {NEIGHBOURS[neighbour]}, gap {gap * CM:g} cm, El Centro 1940"
    figure = figures.time_history_with_impacts(run["time"].values, top, impacts["impact_start"].values, forces, "Building 1, floor 2", title)
    step = float(run["time"].values[1] - run["time"].values[0])
    largest = int(np.argmax(impacts["impact_peak_force"].values))
    sampled = float(run["impact_force"].max())
    caption = (
        f"Figure 3.6: Building 1's top-floor total displacement with impact onsets, and the force of each contact: sampled every "
        f"{step:g} s (grey) and the peak of every impact located on the solution (dots); both buildings fixed, Building 2 "
        f"{neighbour}, gap {gap * CM:g} cm, El Centro 1940 (the study's record). Largest located peak "
        f"{float(impacts['impact_peak_force'][largest]) / 1e3:.0f} kN (contact at floor {int(impacts['impact_contact'][largest]) + 1}, "
        f"t = {float(impacts['impact_peak_time'][largest]):.2f} s); the largest sampled value is {sampled / 1e3:.0f} kN, because the "
        f"peaks fall between samples."
    )
    return FigureItem("figure-3.6", caption, figure)


def against_gap(store: xr.Dataset) -> list[FigureItem]:
    """Figures 3.7–3.9: impacts, peak displacements and peak impact force against the gap (both fixed)."""
    gaps = store["gap"].values * CM
    data = {n: select(store, neighbour=n, mu=FIXED_BASE, record="el_centro").load() for n in NEIGHBOURS}
    spline = {n: select(store, neighbour=n, mu=FIXED_BASE, record="el_centro_spline").load() for n in NEIGHBOURS} if "el_centro_spline" in store["record"].values else {}
    impacts = {
        "impacts": {f"{NEIGHBOURS[n]}": data[n]["impacts"].values for n in NEIGHBOURS}
        | {f"{NEIGHBOURS[n]}, spline input": spline[n]["impacts"].values for n in spline},
        "in-phase impacts": {NEIGHBOURS[n]: data[n]["impacts_in_phase"].values for n in NEIGHBOURS},
        "out-of-phase impacts": {NEIGHBOURS[n]: data[n]["impacts_out_of_phase"].values for n in NEIGHBOURS},
    }
    peaks = {
        f"{building} peak total displacement (cm)": {NEIGHBOURS[n]: data[n]["peak_total_displacement"].sel(building=building).values * CM for n in NEIGHBOURS}
        for building in ("B1", "B2")
    }
    force = {"peak impact force (kN)": {NEIGHBOURS[n]: _where_impacts(data[n], "peak_impact_force") / 1e3 for n in NEIGHBOURS}}
    where = "both buildings fixed, El Centro 1940 (the study's record)"
    specs = (
        ("3.7", impacts, f"Figure 3.7: number of impacts (total, in-phase, out-of-phase) against the gap; {where}; total also with the study's spline input."),
        ("3.8", peaks, f"Figure 3.8: peak total displacement of each building against the gap; {where}."),
        ("3.9", force, f"Figure 3.9: peak impact force against the gap (not drawn at gaps without impacts); {where}."),
    )
    return [FigureItem(f"figure-{number}", caption, figures.against(gaps, panels, caption.split(":")[0], "gap (cm)")) for number, panels, caption in specs]


def single_against_mu(store: xr.Dataset) -> list[FigureItem]:
    """Figures 4.1–4.5: the single isolated building against μ, four records.

    A frictionless base (μ = 0) drifts with the ground's displacement: its
    sliding and total displacements (Figures 4.4–4.5) are an order of
    magnitude beyond the others, so they are given in the caption instead.
    """
    finite = np.array(isolated_mus(store["mu"].values))
    records = list(store["record"].values)
    specs = (
        ("4.1", "skewness", "response_skewness", 1.0, None, False),
        ("4.2", "excess", "response_excess", 1.0, None, False),
        ("4.3", "peak relative displacement (cm)", "peak_relative_displacement", CM, "B1", False),
        ("4.4", "peak sliding displacement (cm)", "peak_sliding_displacement", CM, "B1", True),
        ("4.5", "peak total displacement (cm)", "peak_total_displacement", CM, "B1", True),
    )
    items = []
    for number, label, variable, factor, building, without_frictionless in specs:
        mus = finite[finite > 0] if without_frictionless else finite
        lines, frictionless = {}, []
        for record in records:
            data = select(store[[variable]], record=record, mu=finite)[variable]
            values = (data.sel(building=building) if building else data) * factor
            lines[record_label(record)] = values.sel(mu=mus).values
            if without_frictionless and 0.0 in finite:
                frictionless.append(f"{record_label(record)} {float(values.sel(mu=0.0)):.0f} cm")
        caption = f"Figure {number}: {label} of the single isolated building's top floor against μ, four records (substitutes labelled)."
        if frictionless:
            caption = caption[:-1] + (
                f", μ > 0. A frictionless base (μ = 0) has no friction to hold it and drifts with the ground's displacement: "
                f"{'; '.join(frictionless)} at μ = 0, left out of the plot."
            )
        items.append(FigureItem(f"figure-{number}", caption, figures.against(mus, {label: lines}, caption.split(":")[0], "friction coefficient μ")))
    return items


def single_histograms(store: xr.Dataset, mus: tuple[float, ...] = (FIXED_BASE, 0.2, 0.1, 0.05)) -> FigureItem:
    """Figure 4.6: histograms of the single building's top-floor total displacement with fitted normals, El Centro."""
    samples = {}
    for mu in mus:
        run = select(store, record="el_centro", mu=mu)
        label = "fixed base" if is_fixed_base(mu) else f"isolated, μ = {mu:g}"
        samples[label] = run["total_displacement"].sel(building="B1").isel(floor=-1)
    caption = "Figure 4.6: histograms of the single building's top-floor total displacement with the fitted normal density, El Centro 1940."
    return FigureItem("figure-4.6", caption, figures.histograms_with_normal(samples, "Single building, El Centro 1940"))


def pair_against_mu(store: xr.Dataset) -> list[FigureItem]:
    """Figures 4.8–4.17: impacts, peak force, longest impact, peak total and relative displacement against μ."""
    quantities = {
        "impacts": ("impacts", 1.0, None),
        "peak impact force (kN)": ("peak_impact_force", 1e-3, None),
        "longest impact (ms)": ("longest_impact", 1e3, None),
        "peak total displacement (cm)": ("peak_total_displacement", CM, "B1"),
    }
    finite = np.array(isolated_mus(store["mu"].values))
    common = "gap 2 cm, El Centro 1940 interpolated linearly; corrected model and the study's equations (study_compat)"
    items = []
    for isolation, description in CONFIGURATIONS.items():
        panels = {label: _lines_against_mu(store, isolation, *spec) for label, spec in quantities.items()}
        caption = (
            f"Figures 4.8–4.15 ({description}): impacts, peak impact force, longest impact (logarithmic axis) and Building 1's "
            f"peak total displacement against μ, Building 2 stiff and flexible; {common}. Force and duration are not drawn "
            "where a case has no impact."
        )
        figure = figures.against(finite, panels, f"Figures 4.8–4.15: {description}", "friction coefficient μ", log_panels=["longest impact (ms)"])
        items.append(FigureItem(f"figure-4.8-4.15-{isolation}", caption, figure))
    panels = {f"{description}: peak relative displacement (cm)": _lines_against_mu(store, isolation, "peak_relative_displacement", CM, "B1") for isolation, description in CONFIGURATIONS.items()}
    caption = f"Figures 4.16–4.17: Building 1's peak relative displacement against μ, Building 1 isolated and both isolated; {common}."
    items.append(FigureItem("figure-4.16-4.17", caption, figures.against(finite, panels, "Figures 4.16–4.17", "friction coefficient μ")))
    return items


def _lines_against_mu(store: xr.Dataset, isolation: str, variable: str, factor: float, building: str | None) -> dict[str, np.ndarray]:
    """One line per neighbour and model: ``variable`` (× ``factor``) against the finite μ of the store."""
    finite = np.array(isolated_mus(store["mu"].values))
    models = list(store["model"].values) if "model" in store.dims else ["corrected"]
    lines = {}
    read = store[[name for name in (variable, "impacts") if name in store]]  # not every variable: select slices each
    for neighbour in NEIGHBOURS:
        for model in models:
            case = select(read, isolation=isolation, neighbour=neighbour, gap=0.02, mu=finite, model=model, record="el_centro")
            name = NEIGHBOURS[neighbour] + ("" if model == "corrected" else ", study's equations")
            if variable in ("peak_impact_force", "longest_impact"):
                lines[name] = _where_impacts(case, variable) * factor
            else:
                lines[name] = (case[variable].sel(building=building) if building else case[variable]).values * factor
    return lines


def _where_impacts(case: xr.Dataset, variable: str) -> np.ndarray:
    """An impact extreme where the case has impacts, NaN where it has none (the store holds 0 there)."""
    return np.where(case["impacts"].values > 0, case[variable].values, np.nan)


def by_record_histograms(store: xr.Dataset) -> list[FigureItem]:
    """Figures 4.18–4.19: histograms by record at μ = 0.2, Building 2 flexible (B1 isolated; both isolated)."""
    gaps = {"mexico_city": 0.02, "el_centro": 0.02, "loma_prieta": 0.04, "northridge": 0.08}
    items = []
    for number, isolation in zip(("4.18", "4.19"), CONFIGURATIONS):
        samples = {}
        for record in store["record"].values:
            run = select(store, isolation=isolation, neighbour="flexible", model="corrected", gap=gaps.get(str(record), 0.02), mu=0.2, record=record)
            samples[f"{record_label(str(record))}, gap {gaps.get(str(record), 0.02) * CM:g} cm"] = run["total_displacement"].sel(building="B1").isel(floor=-1)
        caption = (
            f"Figure {number}: histograms of Building 1's top-floor total displacement with the fitted normal density by record, "
            f"{CONFIGURATIONS[isolation]}, Building 2 flexible, μ = 0.2 (substitutes labelled)."
        )
        items.append(FigureItem(f"figure-{number}", caption, figures.histograms_with_normal(samples, f"Figure {number}: {CONFIGURATIONS[isolation]}, B2 flexible, μ = 0.2")))
    return items


def configurations_time_history(store: xr.Dataset, neighbour: str = "flexible", mu: float = 0.2) -> FigureItem:
    """Figure 4.20: Building 1's top-floor total displacement alone on a fixed base, isolated next to a fixed B2, both isolated."""
    reference = select(store, record="el_centro")["reference_total_displacement"].isel(floor=-1)
    lines = {"alone, fixed base": reference.values * CM}
    for isolation, description in CONFIGURATIONS.items():
        run = select(store, isolation=isolation, neighbour=neighbour, model="corrected", gap=0.02, mu=mu, record="el_centro")
        lines[description] = run["total_displacement"].sel(building="B1").isel(floor=-1).values * CM
    title = f"Building 1, floor 2: El Centro 1940, B2 {neighbour}, μ = {mu:g}, gap 2 cm"
    caption = (
        f"Figure 4.20: Building 1's top-floor total displacement alone on a fixed base, isolated next to a fixed Building 2, "
        f"and both isolated (μ = {mu:g}, Building 2 {neighbour}, gap 2 cm, El Centro 1940)."
    )
    return FigureItem("figure-4.20", caption, figures.traces(store["time"].values, {"total displacement (cm)": lines}, title, height=3.2))
