"""Inelastic demand of simulated and recorded motions at matched elastic spectra: ``python -m benchmarks inelastic_demand``.

The doubt of the fixed-pair risk flagship (experiments/risk/fixed_pair.toml):
at its 2 %/50 yr stripe the simulated motions drove the yielding Building 1
less far than the records chosen to the same conditional spectrum. Measured
here, at the flagship's fitted scenario (M 8.0, R_rup 30 km, Vs30 400 m/s,
reverse faulting) and stripes of PSA(1 s) (10 % and 2 % in 50 years):

1. two sets of :data:`MOTIONS` motions are chosen to each stripe's
   conditional spectrum (:func:`stochpound.motions.select_motions`, the
   flagship's rules: scale factor <= 5, at most 3 motions of an earthquake),
   one from the 100 FEMA P695 components alone, one from :data:`SIMULATED`
   site-based stochastic motions of the scenario alone (the hazard-compatible
   model, seed 1, dt = 0.01 s: the flagship's simulated pool);
2. each motion, scaled, drives Building 1 of the flagship alone (fixed base,
   bilinear storeys, hardening 2 %, P-Delta) and the same building with its
   storeys kept elastic: the peak storey drift (largest over the storeys);
3. each motion drives elastoplastic SDOF oscillators of T = 0.3 s, 5 %
   damping, at constant strength ratios R = 2, 4, 6 (yield force = the
   elastic oscillator's peak force / R): C_R = u_inelastic / u_elastic, scale-free;
   over the selected sets, every record of the pool and the first
   :data:`UNSELECTED` simulated motions; beside the published mean C_R of
   Ruiz-García & Miranda (2003) and ASCE 41's C1 (site class C);
4. per motion, what may cause a difference: the spectral shape beyond T1
   (ln Sa(T)/Sa(0.3 s) at 0.45, 0.6 and 1 s), the significant duration D5-95,
   PGV/PGA, PGD, the scale factor and (records) the pulse flag; a
   regression of ln C_R on the shape and duration with a simulated/recorded
   indicator measures how much of the gap they explain.

Every run is the toolkit's exact solver (:func:`stochpound.simulate`). It rewrites the section
"Inelastic demand of simulated and recorded motions" of ``docs/benchmarks.md``
(``--out`` another file; ``--save`` keeps the per-motion numbers as netCDF, ``--load`` renders from them).
"""

from __future__ import annotations

import argparse
import dataclasses
import time
import tomllib
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from benchmarks import report
from benchmarks.sections import Section
from benchmarks.timing import REPOSITORY

SECTION = Section("<!-- inelastic demand: start -->", "<!-- inelastic demand: end -->")
"""This benchmark's section of docs/benchmarks.md."""
EXPERIMENT = REPOSITORY / "experiments" / "risk" / "fixed_pair.toml"
#: The flagship's fitted scenario, its conditioning period (s) and stripes (g): 10 % and 2 % in 50 years.
SCENARIO = {"magnitude": 8.0, "distance_km": 30.0, "vs30": 400.0, "mechanism": "reverse"}
CONDITIONING_PERIOD = 1.0
STRIPES = {"10 % in 50 yr": 0.7399, "2 % in 50 yr": 1.2031}
#: First-mode periods (s) of Building 1 and its stiff and flexible neighbours: the flagship's selection range, 0.043-1.29 s.
STRUCTURE_PERIODS = (0.2143, 0.3030, 0.4286)
MOTIONS, MAX_SCALE_FACTOR, MAX_PER_EARTHQUAKE, SEED = 40, 5.0, 3, 1
SIMULATED, UNSELECTED, DT = 2000, 400, 0.01
#: The oscillators: period (s), damping ratio, strength ratios R.
SDOF_PERIOD, DAMPING, STRENGTH_RATIOS = 0.3, 0.05, (2.0, 4.0, 6.0)
#: Periods (s) of the spectral-shape measures ln Sa(T)/Sa(SDOF_PERIOD).
SHAPE_PERIODS = (0.45, 0.6, 1.0)
G = 9.81
SUITES = ("fema_p695_far_field", "fema_p695_near_field")


def published_ratios(period: float = SDOF_PERIOD) -> dict[str, list[float]]:
    """Mean C_R at ``period`` (s) for each R of :data:`STRENGTH_RATIOS` from published equations (elastoplastic, 5 %).

    ``Ruiz-García & Miranda 2003``: C_R = 1 + (R − 1) / (79.12 T^1.98), their
    simplified fit to the mean over site classes B–D (216 records, California).
    ``ASCE 41 C1, site class C``: C1 = 1 + (R − 1) / (a T²), a = 90 (the FEMA 440
    form of the same data; the flagship's Vs30 400 m/s is class C); ``D``: a = 60.
    """
    ratios = np.asarray(STRENGTH_RATIOS)
    return {"Ruiz-García & Miranda 2003": list(1.0 + (ratios - 1.0) / (79.12 * period**1.98)),
            "ASCE 41 C1, site class C": list(1.0 + (ratios - 1.0) / (90.0 * period**2)),
            "ASCE 41 C1, site class D": list(1.0 + (ratios - 1.0) / (60.0 * period**2))}


def record_pool() -> list[Any]:
    """The 100 FEMA P695 components (both sets) as records with their metadata."""
    from stochpound.motions.records import load_suite

    return [record for suite in SUITES for record in load_suite(suite)]


def simulated_pool(count: int = SIMULATED, seed: int = SEED) -> tuple[list[Any], xr.Dataset]:
    """``count`` motions of :data:`SCENARIO` (hazard-compatible model, the flagship's seed and dt) as records, and their parameters."""
    from stochpound.motions import site_motions
    from stochpound.motions.records import Record

    motions = site_motions(**SCENARIO, n=count, seed=seed, dt=DT)
    records = [Record(f"simulated {i}", DT, row, "m/s2", metadata={}) for i, row in enumerate(motions["acceleration"].values)]
    return records, motions.drop_vars("acceleration")


def selection_periods() -> np.ndarray:
    """The flagship's selection periods (s): 20 over 0.2 x 0.214-3 x 0.429 s and the conditioning period."""
    from stochpound.motions import selection_periods as periods

    return periods(list(STRUCTURE_PERIODS), [CONDITIONING_PERIOD])


def select(pool: xr.Dataset, periods: np.ndarray, level: float) -> xr.Dataset:
    """:data:`MOTIONS` of ``pool`` (:func:`~stochpound.motions.selection_pool`) chosen and scaled to the scenario's conditional spectrum of PSA(1 s) = ``level`` g."""
    from stochpound.motions import conditional_spectrum, select_motions

    target = conditional_spectrum("psa", CONDITIONING_PERIOD, level=level, periods=periods, **SCENARIO)
    return select_motions(pool, target, MOTIONS, MAX_SCALE_FACTOR, SEED, max_per_earthquake=MAX_PER_EARTHQUAKE)


def frame_scene(yielding: bool = True) -> Any:
    """Building 1 of the flagship alone on a fixed base (bilinear storeys, or elastic ones with ``yielding=False``)."""
    import stochpound

    definition = tomllib.loads(EXPERIMENT.read_text())
    building = {key: value for key, value in definition["scene"]["building"][0].items() if key != "base"}
    if not yielding:
        building = {key: value for key, value in building.items() if key not in ("yield_force", "hardening")}
    return stochpound.scene_from_dict({"g": definition["scene"]["g"], "building": [building], "contact": [],
                                       "motion": {"type": "constant", "acceleration": 0.0, "duration": 1.0, "dt": DT}},
                                      source=f"Building 1 of {EXPERIMENT.name}")


def oscillator(yield_force: float | None) -> Any:
    """The SDOF oscillator (unit mass, :data:`SDOF_PERIOD`, :data:`DAMPING`), elastoplastic at ``yield_force`` (N) or elastic (None)."""
    import stochpound

    storey: dict[str, Any] = {"name": "SDOF", "mass": [1.0], "stiffness": [(2.0 * np.pi / SDOF_PERIOD) ** 2], "damping_ratio": DAMPING}
    if yield_force is not None:
        storey.update(yield_force=[yield_force], hardening=0.0)
    return stochpound.scene_from_dict({"g": G, "building": [storey], "contact": [], "motion": {"type": "constant", "acceleration": 0.0,
                                       "duration": 1.0, "dt": DT}}, source="SDOF oscillator")


def peak_drift(scene: Any, acceleration: np.ndarray, dt: float) -> float:
    """The largest peak storey drift (m) of ``scene`` under ``acceleration`` (m/s²), located on the solution."""
    import stochpound
    from stochpound.motions.ground import SampledMotion

    run = stochpound.simulate(dataclasses.replace(scene, motion=SampledMotion(dt, acceleration, "linear", "motion")), demands=True)
    return float(np.max(np.abs(run["peak_storey_drift"].values)))


def inelastic_ratios(acceleration: np.ndarray, dt: float, peak: Any = None) -> list[float]:
    """C_R = u_inelastic / u_elastic of the oscillator under ``acceleration`` at every R of :data:`STRENGTH_RATIOS` (scale-free).

    ``peak(acceleration, dt, yield_force)``: the oscillator's peak displacement (m; ``yield_force`` None: elastic); default the
    toolkit's exact solver, :func:`newmark_peak` the independent check.
    """
    if peak is None:
        def peak(a: np.ndarray, step: float, force: float | None) -> float:
            return peak_drift(oscillator(force), a, step)
    elastic = peak(acceleration, dt, None)
    stiffness = (2.0 * np.pi / SDOF_PERIOD) ** 2
    return [peak(acceleration, dt, stiffness * elastic / ratio) / elastic for ratio in STRENGTH_RATIOS]


def newmark_peak(acceleration: np.ndarray, dt: float, yield_force: float | None, substeps: int = 20) -> float:
    """Peak displacement (m) of the oscillator by Newmark's average acceleration with Newton iterations, at dt / ``substeps``.

    An independent integrator (elastoplastic return mapping, the ground acceleration linear between samples) to check the
    exact solver's C_R; second-order accurate, so its error at 1 ms substeps is far below the differences measured here.
    """
    omega = 2.0 * np.pi / SDOF_PERIOD
    k, c, h = omega**2, 2.0 * DAMPING * omega, dt / substeps
    ground = np.interp(np.arange((len(acceleration) - 1) * substeps + 1) * h, np.arange(len(acceleration)) * dt, acceleration)
    u = v = plastic = peak = 0.0
    a = -ground[0]
    for load in -ground[1:]:
        new = u + h * v + 0.25 * h * h * a
        for _ in range(30):
            acc = (new - u - h * v - 0.25 * h * h * a) / (0.25 * h * h)
            trial = k * (new - plastic)
            yielded = yield_force is not None and abs(trial) > yield_force
            force = np.sign(trial) * yield_force if yielded else trial
            step = (load - acc - c * (v + 0.5 * h * (a + acc)) - force) / (4.0 / h**2 + 2.0 * c / h + (0.0 if yielded else k))
            new += step
            if abs(step) <= 1e-14 * max(abs(new), 1e-12):
                break
        acc = (new - u - h * v - 0.25 * h * h * a) / (0.25 * h * h)
        if yield_force is not None and abs(k * (new - plastic)) > yield_force:
            plastic = new - np.sign(new - plastic) * yield_force / k
        u, v, a = new, v + 0.5 * h * (a + acc), acc
        peak = max(peak, abs(u))
    return peak


def motion_features(acceleration: np.ndarray, dt: float) -> dict[str, float]:
    """The unscaled motion's PSA(T1) (g), ln Sa(T)/Sa(0.3 s) at :data:`SHAPE_PERIODS`, D5-95 (s), PGV/PGA (s) and PGD/PGV (s)."""
    from stochpound.motions import peak_ground_motion, response_spectrum, significant_duration

    psa = response_spectrum(acceleration, dt, [STRUCTURE_PERIODS[1], SDOF_PERIOD, *SHAPE_PERIODS], DAMPING).psa.values
    pga, pgv, pgd = peak_ground_motion(acceleration, dt)
    features = {f"shape {period:g}": float(np.log(psa[i + 2] / psa[1])) for i, period in enumerate(SHAPE_PERIODS)}
    return {"psa_t1": psa[0] / G, **features, "d5_95": significant_duration(acceleration, dt), "pgv_pga": pgv / pga, "pgd_pgv": pgd / pgv}


def measure_motions(records: list[Any], scales: dict[str, np.ndarray | float]) -> xr.Dataset:
    """Per motion: C_R at every R, the features and Building 1's inelastic and elastic peak drift (m) at each of ``scales``.

    ``scales``: by name, the motions' scale factors, or a PSA(T1) (g) to scale every motion to.
    """
    rows: dict[str, list[float]] = {}
    yielding, elastic = frame_scene(True), frame_scene(False)
    for i, record in enumerate(records):
        a = record.acceleration(G)
        values = {f"C_R {ratio:g}": value for ratio, value in zip(STRENGTH_RATIOS, inelastic_ratios(a, record.dt))}
        values.update(motion_features(a, record.dt))
        for name, scale in scales.items():
            factor = scale[i] if isinstance(scale, np.ndarray) else scale / values["psa_t1"]
            values[f"drift {name}"] = peak_drift(yielding, factor * a, record.dt)
            values[f"elastic_drift {name}"] = peak_drift(elastic, factor * a, record.dt)
        for key, value in values.items():
            rows.setdefault(key, []).append(value)
    return xr.Dataset({key: ("motion", np.array(value)) for key, value in rows.items()}, coords={"motion": [r.name for r in records]})


def _group(result: xr.Dataset, group: str) -> xr.Dataset:
    """``result``'s motions as the dimension ``group``, its variables named ``<name> | <group>``."""
    result = result.rename(motion=group)
    return result.rename({name: f"{name} | {group}" for name in result.data_vars})


def t1_levels(periods: np.ndarray) -> dict[str, float]:
    """PSA(T1) (g) of the stripes' conditional medians at Building 1's period, by stripe."""
    from stochpound.motions import conditional_spectrum

    return {stripe: float(conditional_spectrum("psa", CONDITIONING_PERIOD, level=level, periods=[STRUCTURE_PERIODS[1]], **SCENARIO)["median"][0])
            for stripe, level in STRIPES.items()}


def measure(simulated: int = SIMULATED, unselected: int = UNSELECTED, log: Any = print) -> xr.Dataset:
    """Every measurement of the module docstring, as one dataset (groups of motions as dimensions, variables ``<name> | <group>``)."""
    from stochpound.motions import selection_pool

    start = time.perf_counter()
    recorded = record_pool()
    generated, parameters = simulated_pool(simulated)
    periods = selection_periods()
    spectra = {"records": selection_pool(recorded, periods, "psa", CONDITIONING_PERIOD, DAMPING, G),
               "simulated": selection_pool(generated, periods, "psa", CONDITIONING_PERIOD, DAMPING, G)}
    spectra["mixed"] = xr.concat([spectra["records"], spectra["simulated"]], "motion")
    by_name = {motion.name: motion for motion in recorded + generated}
    log(f"[{time.perf_counter() - start:6.0f} s] pools and their spectra: {len(recorded)} records, {len(generated)} simulated motions")
    parts = []
    for stripe, level in STRIPES.items():
        for kind, pool in spectra.items():
            chosen = select(pool, periods, level)
            group = f"{kind} {stripe}"
            result = measure_motions([by_name[str(name)] for name in chosen["motion"].values], {"stripe": chosen["scale_factor"].values})
            result = result.assign(scale_factor=("motion", chosen["scale_factor"].values), pulse=("motion", pool["pulse"].sel(motion=chosen["motion"].values).values),
                                   earthquake=("motion", chosen["earthquake"].values.astype(str)))
            parts.append(_group(result, group))
            parts.append(xr.Dataset({f"mean_off | {group}": ("period", (chosen["mean_ln"] - np.log(chosen["median"])).values),
                                     f"std_off | {group}": ("period", (chosen["std_ln"] - chosen["sigma_ln"]).values)}))
            log(f"[{time.perf_counter() - start:6.0f} s] {group}: median drift {np.median(result['drift stripe'].values):.4f} m")
    levels = t1_levels(periods)
    parts.append(_group(measure_motions(recorded, levels).assign(pulse=("motion", spectra["records"]["pulse"].values)), "all records"))
    log(f"[{time.perf_counter() - start:6.0f} s] all records")
    others = measure_motions(generated[:unselected], levels).assign(f_corner=("motion", parameters["f_corner"].values[:unselected]))
    parts.append(_group(others, "first simulated"))
    log(f"[{time.perf_counter() - start:6.0f} s] first {unselected} simulated")
    dataset = xr.merge(parts).assign_coords(period=periods)
    dataset.attrs.update(simulated=simulated, unselected=unselected, minutes=(time.perf_counter() - start) / 60.0,
                         **{f"PSA(T1) {stripe}": value for stripe, value in levels.items()})
    return dataset

def _values(dataset: xr.Dataset, name: str, group: str) -> np.ndarray:
    return dataset[f"{name} | {group}"].dropna(group).values


def _ratio_interval(numerator: np.ndarray, denominator: np.ndarray, draws: int = 4000, seed: int = 0) -> tuple[float, float, float]:
    """Ratio of the geometric means of two samples and its 90 % bootstrap interval (each sample resampled on its own)."""
    rng = np.random.default_rng(seed)
    ln_n, ln_d = np.log(numerator), np.log(denominator)
    boot = [np.mean(rng.choice(ln_n, ln_n.size)) - np.mean(rng.choice(ln_d, ln_d.size)) for _ in range(draws)]
    low, high = np.percentile(boot, [5.0, 95.0])
    return float(np.exp(np.mean(ln_n) - np.mean(ln_d))), float(np.exp(low)), float(np.exp(high))


def _regression(outcome: np.ndarray, indicator: np.ndarray, covariates: list[np.ndarray]) -> tuple[float, float, float]:
    """OLS of ``outcome`` on 1, ``indicator`` and ``covariates``: the indicator's coefficient, its standard error, and R²."""
    design = np.column_stack([np.ones_like(outcome), indicator, *covariates])
    coefficients, *_ = np.linalg.lstsq(design, outcome, rcond=None)
    residual = outcome - design @ coefficients
    variance = residual @ residual / (outcome.size - design.shape[1])
    covariance = variance * np.linalg.inv(design.T @ design)
    r2 = 1.0 - residual @ residual / np.sum((outcome - outcome.mean()) ** 2)
    return float(coefficients[1]), float(np.sqrt(covariance[1, 1])), float(r2)


def _gmean(values: np.ndarray) -> float:
    return float(np.exp(np.mean(np.log(values))))


def _pulses(dataset: xr.Dataset, group: str) -> np.ndarray:
    """Whether each motion of ``group`` is a pulse record (simulated motions never are)."""
    name = f"pulse | {group}"
    return dataset[name].values.astype(bool) if name in dataset else np.zeros(dataset.sizes[group], dtype=bool)


def _simulated(dataset: xr.Dataset, group: str) -> np.ndarray:
    return np.char.startswith(dataset[group].values.astype(str), "simulated")


def stripe_table(dataset: xr.Dataset) -> list[str]:
    """The selections and Building 1's drifts at the stripes (Markdown rows)."""
    periods = dataset["period"].values
    t1 = int(np.argmin(np.abs(periods - STRUCTURE_PERIODS[1])))
    lines = ["| stripe | pool | motions (recorded / simulated; pulses) | worst \\|Δ mean ln Sa\\| (at T, s) | worst \\|Δσ\\| | Δ mean ln Sa at "
             f"{periods[t1]:.2f} s | B1 elastic drift, median (m) | B1 drift, median (m) | 84 % (m) | median drift / elastic drift |",
             "|---|---|---|---|---|---|---:|---:|---:|---:|"]
    for stripe in STRIPES:
        for kind in ("records", "simulated", "mixed"):
            group = f"{kind} {stripe}"
            mean_off, std_off = dataset[f"mean_off | {group}"].values, dataset[f"std_off | {group}"].values
            worst = int(np.argmax(np.abs(mean_off)))
            drift, elastic = _values(dataset, "drift stripe", group), _values(dataset, "elastic_drift stripe", group)
            simulated = _simulated(dataset, group)
            lines.append(f"| {_stripe_label(stripe)} | {POOLS[kind]} | {np.sum(~simulated)} / {np.sum(simulated)}; "
                         f"{np.sum(_pulses(dataset, group))} | {abs(mean_off[worst]):.2f} ({periods[worst]:.2g}) | {np.max(np.abs(std_off)):.2f} | "
                         f"{mean_off[t1]:+.2f} | {np.median(elastic):.4f} | {np.median(drift):.4f} | {np.percentile(drift, 84):.4f} | "
                         f"{np.median(drift / elastic):.2f} |")
    return lines


POOLS = {"records": "100 records", "simulated": f"{SIMULATED} simulated", "mixed": "both (the flagship's)"}


def _stripe_label(stripe: str) -> str:
    return stripe.replace(" % in 50 yr", " %/50 yr")


def mixed_lines(dataset: xr.Dataset) -> list[str]:
    """Within the flagship's own selection (the mixed pool): the recorded motions' drifts beside the simulated ones'."""
    lines = []
    for stripe in STRIPES:
        group = f"mixed {stripe}"
        simulated = _simulated(dataset, group)
        drift, psa = _values(dataset, "drift stripe", group), _values(dataset, "psa_t1", group) * _values(dataset, "scale_factor", group)
        lines.append(f"{_stripe_label(stripe)}: {np.sum(~simulated)} records, median drift {np.median(drift[~simulated]):.4f} m at a median scaled "
                     f"PSA(T1) {np.median(psa[~simulated]):.2f} g; {np.sum(simulated)} simulated motions, {np.median(drift[simulated]):.4f} m at "
                     f"{np.median(psa[simulated]):.2f} g")
    return lines


def _spread_interval(sample: np.ndarray, reference: np.ndarray, draws: int = 4000, seed: int = 0) -> tuple[float, float, float]:
    """σ ln ``sample`` − σ ln ``reference`` (sample standard deviations) and its 90 % bootstrap interval."""
    rng = np.random.default_rng(seed)
    ln_s, ln_r = np.log(sample), np.log(reference)
    boot = [np.std(rng.choice(ln_s, ln_s.size), ddof=1) - np.std(rng.choice(ln_r, ln_r.size), ddof=1) for _ in range(draws)]
    low, high = np.percentile(boot, [5.0, 95.0])
    return float(np.std(ln_s, ddof=1) - np.std(ln_r, ddof=1)), float(low), float(high)


def common_table(dataset: xr.Dataset) -> list[str]:
    """Building 1 under every record and the first simulated motions, each scaled to a common PSA(T1) (Markdown rows)."""
    lines = ["| PSA(T1) (g) | motions | B1 drift, median (m) | 84 % (m) | geometric mean (m) | σ ln drift | records / simulated, geometric means "
             "[90 % interval] | σ ln drift, records − simulated [90 % interval] |", "|---|---|---:|---:|---:|---:|---|---|"]
    pulses = _pulses(dataset, "all records")
    for stripe in STRIPES:
        level = dataset.attrs[f"PSA(T1) {stripe}"]
        simulated = _values(dataset, f"drift {stripe}", "first simulated")
        everything = _values(dataset, f"drift {stripe}", "all records")
        for label, drift in ((f"{everything.size} records", everything), (f"{np.sum(~pulses)} records without pulses", everything[~pulses]),
                             (f"{np.sum(pulses)} pulse records", everything[pulses]), (f"{simulated.size} simulated", simulated)):
            ratio = "" if drift is simulated else "{:.2f} [{:.2f}-{:.2f}]".format(*_ratio_interval(drift, simulated))
            spread = "" if drift is simulated else "{:+.2f} [{:+.2f} to {:+.2f}]".format(*_spread_interval(drift, simulated))
            lines.append(f"| {level:.2f} ({_stripe_label(stripe)} median at T1) | {label} | {np.median(drift):.4f} | {np.percentile(drift, 84):.4f} | "
                         f"{_gmean(drift):.4f} | {np.std(np.log(drift), ddof=1):.2f} | {ratio} | {spread} |")
    return lines


def ratio_groups(dataset: xr.Dataset) -> dict[str, np.ndarray]:
    """The groups of motions of the C_R and feature tables: index arrays by label, with their group."""
    pulses = _pulses(dataset, "all records")
    last = list(STRIPES)[-1]
    return {f"all {pulses.size} records": ("all records", slice(None)), f"{np.sum(~pulses)} records without pulses": ("all records", ~pulses),
            f"{np.sum(pulses)} pulse records": ("all records", pulses), f"first {dataset.sizes['first simulated']} simulated": ("first simulated", slice(None)),
            f"40 records selected at {_stripe_label(last)}": (f"records {last}", slice(None)),
            f"40 simulated selected at {_stripe_label(last)}": (f"simulated {last}", slice(None))}


def ratio_table(dataset: xr.Dataset) -> list[str]:
    """C_R by R: mean (median) per group of motions, and the published means (Markdown rows)."""
    lines = ["| motions | " + " | ".join(f"R = {ratio:g}" for ratio in STRENGTH_RATIOS) + " |", "|---|" + "---:|" * len(STRENGTH_RATIOS)]
    for label, (group, rows) in ratio_groups(dataset).items():
        cells = [_values(dataset, f"C_R {ratio:g}", group)[rows] for ratio in STRENGTH_RATIOS]
        lines.append(f"| {label} | " + " | ".join(f"{np.mean(c):.2f} ({np.median(c):.2f}; {_gmean(c):.2f})" for c in cells) + " |")
    for label, values in published_ratios().items():
        lines.append(f"| {label} (mean) | " + " | ".join(f"{value:.2f}" for value in values) + " |")
    return lines


def feature_table(dataset: xr.Dataset) -> list[str]:
    """What differs between the groups: spectral shape beyond T1, duration, low-frequency content (Markdown rows)."""
    shapes = [f"mean ln Sa({period:g} s)/Sa(0.3 s)" for period in SHAPE_PERIODS]
    lines = ["| motions | " + " | ".join(shapes) + " | median D5-95 (s) | median PGV/PGA (s) | median PGD/PGV (s) |", "|---|" + "---:|" * (len(shapes) + 3)]
    for label, (group, rows) in ratio_groups(dataset).items():
        cells = [f"{np.mean(_values(dataset, f'shape {period:g}', group)[rows]):+.2f}" for period in SHAPE_PERIODS]
        cells += [f"{np.median(_values(dataset, name, group)[rows]):.{digits}f}" for name, digits in (("d5_95", 1), ("pgv_pga", 3), ("pgd_pgv", 2))]
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    return lines


def regression_table(dataset: xr.Dataset) -> list[str]:
    """ln B1 drift at the last stripe's common PSA(T1), records and simulated pooled: the simulated motions' factor as covariates enter."""
    stripe = list(STRIPES)[-1]
    groups = ("all records", "first simulated")
    pooled = {name: np.concatenate([_values(dataset, name, group) for group in groups])
              for name in (f"drift {stripe}", "shape 0.6", "shape 1", "d5_95", "pgv_pga")}
    simulated = np.concatenate([np.zeros(dataset.sizes[groups[0]]), np.ones(dataset.sizes[groups[1]])])
    pulse = np.concatenate([_pulses(dataset, groups[0]), np.zeros(dataset.sizes[groups[1]], dtype=bool)]).astype(float)
    models = {"none": [], "+ ln Sa(0.6 s)/Sa(0.3 s), ln Sa(1 s)/Sa(0.3 s)": [pooled["shape 0.6"], pooled["shape 1"]]}
    models["+ ln D5-95"] = [*models[list(models)[-1]], np.log(pooled["d5_95"])]
    models["+ ln PGV/PGA"] = [*models[list(models)[-1]], np.log(pooled["pgv_pga"])]
    models["+ pulse record"] = [*models[list(models)[-1]], pulse]
    lines = ["| covariates | simulated / recorded, at equal covariates | ± 1 s.e. (factor) | R² |", "|---|---:|---:|---:|"]
    for label, covariates in models.items():
        coefficient, error, r2 = _regression(np.log(pooled[f"drift {stripe}"]), simulated, covariates)
        lines.append(f"| {label} | {np.exp(coefficient):.2f} | ×{np.exp(error):.2f} | {r2:.2f} |")
    return lines


def newmark_check(count: int = 2) -> float:
    """Largest |C_R (exact solver) − C_R (:func:`newmark_peak`)| over ``count`` records and ``count`` simulated motions, every R."""
    recorded = record_pool()
    generated, _ = simulated_pool(count)
    motions = [recorded[0], recorded[len(recorded) // 2], *generated]  # a far-field record, the first near-field one, simulated
    return max(float(np.max(np.abs(np.subtract(inelastic_ratios(m.acceleration(G), m.dt), inelastic_ratios(m.acceleration(G), m.dt, newmark_peak)))))
               for m in motions)


def section(dataset: xr.Dataset, check: float) -> str:
    """The section of docs/benchmarks.md (markers included)."""
    scenario = f"M {SCENARIO['magnitude']:g}, R_rup {SCENARIO['distance_km']:g} km, Vs30 {SCENARIO['vs30']:g} m/s, {SCENARIO['mechanism'].replace('_', '-')}"
    text = [SECTION.start, "", "## Inelastic demand of simulated and recorded motions", "",
            f"`python -m benchmarks inelastic_demand` (commit {dataset.attrs['commit']}, {dataset.attrs['date']}, load {dataset.attrs['load']} at start, "
            f"{dataset.attrs['minutes']:.0f} min). The risk flagship's fitted scenario ({scenario}), its stripes of PSA(1 s) and its selection "
            f"rules ({MOTIONS} motions, scale factor ≤ {MAX_SCALE_FACTOR:g}, ≤ {MAX_PER_EARTHQUAKE} of an earthquake, seed {SEED}); pools: the 100 FEMA P695 "
            f"components, {dataset.attrs['simulated']} hazard-compatible simulated motions of the scenario (seed {SEED}, dt = {DT} s), or both "
            "(the flagship's). Building 1 of experiments/risk/fixed_pair.toml alone (fixed base, yield drift 8.8 mm, hardening 2 %, P-Delta) "
            "and the same building kept elastic; peak storey drift, the larger of the two storeys'. The toolkit's exact solver throughout.",
            "", "**At the stripes**, each pool's selection to the same conditional spectrum "
            "(Δ: the set's mean and standard deviation of ln Sa minus the target's over the 21 periods 0.043–1.29 s):", "",
            *stripe_table(dataset), "", "Within the flagship's own selection: " + "; ".join(mixed_lines(dataset)) + ".", "",
            "**At a common PSA(T1)** (T1 = 0.303 s, each motion scaled to the stripe's conditional median at T1, so that the "
            "elastic demand on Building 1 is the same for every motion):", "", *common_table(dataset), "",
            f"**C_R** = u_inelastic / u_elastic of an elastoplastic SDOF oscillator, T = {SDOF_PERIOD} s, {DAMPING:.0%} damping, at constant "
            "strength ratio R (yield force = the elastic peak force / R; scale-free): mean (median; geometric mean), and the published means "
            "(Ruiz-García & Miranda 2003's fit over site classes B–D, C_R = 1 + (R − 1)/(79.12 T^1.98); ASCE 41's C1 = 1 + (R − 1)/(a T²), "
            f"a = 90 for site class C, 60 for D). Checked against an independent Newmark integration (average acceleration, 1/20 of the "
            f"motion's step) on 2 records and 2 simulated motions: largest |ΔC_R| {check:.1e}.", "", *ratio_table(dataset), "",
            "**What differs** between the groups:", "", *feature_table(dataset), "",
            f"**How much of the difference** at the common PSA(T1) of the {_stripe_label(list(STRIPES)[-1])} stripe the measures explain: ln drift of "
            "all records and the first simulated motions pooled, regressed on an indicator of the simulated motions and the covariates "
            "(the indicator's exp(coefficient): the simulated motions' drift over the records' at equal covariates):", "", *regression_table(dataset),
            "", SECTION.end]
    return "\n".join(text) + "\n"


def main(argv: list[str] | None = None) -> int:
    """Measure (or ``--load`` a saved measurement), check the oscillator against Newmark, and rewrite the section."""
    parser = argparse.ArgumentParser(prog="python -m benchmarks inelastic_demand", description=__doc__.splitlines()[0])
    parser.add_argument("--simulated", type=int, default=SIMULATED, help=f"simulated motions of the pool (default {SIMULATED})")
    parser.add_argument("--unselected", type=int, default=UNSELECTED, help=f"simulated motions measured beside every record (default {UNSELECTED})")
    parser.add_argument("--save", type=Path, help="keep the per-motion numbers (netCDF)")
    parser.add_argument("--load", type=Path, help="render from numbers saved by --save instead of measuring")
    parser.add_argument("--out", type=Path, default=REPOSITORY / "docs" / "benchmarks.md")
    arguments = parser.parse_args(argv)
    if arguments.load:
        dataset = xr.load_dataset(arguments.load)
    else:
        info = report.machine()
        dataset = measure(arguments.simulated, arguments.unselected).assign_attrs(
            commit=info["commit"], date=info["date"], load=info["load average (1 min) at start"])
    if arguments.save:
        dataset.to_netcdf(arguments.save)
    SECTION.write(arguments.out, section(dataset, newmark_check()))
    print(f"wrote {arguments.out}")
    return 0
