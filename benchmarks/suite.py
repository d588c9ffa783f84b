"""The benchmark sections: reference, work–precision, study scheme, targets, ensembles, scaling.

Each section measures and returns plain data; :mod:`benchmarks.report`
turns it into ``docs/benchmarks.md`` and the work–precision figure.
:class:`Config` holds every size and setting, with a full and a quick preset.
"""

from __future__ import annotations

import dataclasses
import subprocess
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import stochpound
from benchmarks.opensees_model import OpenSeesUnavailable, load_opensees, run_opensees
from benchmarks.outcome import Errors, Outcome, compare, outcome_from_dataset
from benchmarks.scenes import MAIN_SCENE, STUDY_SCENES, StudyScene, kanai_tajimi_motions, with_motion
from benchmarks.study_scheme import run_study_scheme
from benchmarks.timing import Timing, best_of, run_subprocess
from stochpound.model.scene import Scene

REFERENCE_RTOL = 1e-12
"""rtol of the ``ivp`` DOP853 run that cross-checks the exact solver (atol = rtol · 1e-2)."""


@dataclass(frozen=True)
class Config:
    """Sizes and settings of one benchmark run (presets: :meth:`full` and :meth:`quick_preset`).

    Attributes
    ----------
    quick : bool
        A smoke run (marked as such in the report).
    scenes : tuple of StudyScene
        Study scenes of the reference and work–precision sections.
    duration : float or None
        Truncate El Centro to this many seconds (None: the study's 49.98 s).
    integrators, rtols : tuple
        ``ivp`` integrators and tolerances (atol = rtol · 1e-2).
    extra_rtols : dict
        More tolerances for some integrators (DOP853 at 1e-11 for the speed-up target).
    scheme_steps, opensees_steps : tuple of float
        Restart intervals of the study scheme and Newmark steps of OpenSees, s.
    repeats, exact_repeats : int
        Timed runs (best of) for the slower solvers and for ``exact``.
    budget : float
        Time allowed to the repeats of one setting, s.
    slow_cap : float
        An integrator whose run takes longer skips its tighter tolerances, s.
    ensemble_runs, ensemble_workers, memory_runs : int
        Realizations of the throughput and memory ensembles, and worker processes.
    lengths, gaps : tuple of float
        Record lengths (s) and gaps (m) of the scaling runs.
    sizes : tuple of (int, int)
        (buildings, floors) of the scene-size runs.
    size_duration, size_gap, size_timeout : float
        Record length (s), gap (m) and timeout (s) of each scene-size run.
    compile_time : bool
        Measure the first-call time with an empty numba cache.
    compile_runs : int
        Fresh processes (each with its own empty cache) of that measurement.
    """

    quick: bool
    scenes: tuple[StudyScene, ...]
    duration: float | None
    integrators: tuple[str, ...]
    rtols: tuple[float, ...]
    extra_rtols: dict[str, tuple[float, ...]]
    scheme_steps: tuple[float, ...]
    opensees_steps: tuple[float, ...]
    repeats: int
    exact_repeats: int
    budget: float
    slow_cap: float
    ensemble_runs: int
    ensemble_workers: int
    memory_runs: int
    lengths: tuple[float, ...]
    gaps: tuple[float, ...]
    sizes: tuple[tuple[int, int], ...]
    size_duration: float
    size_gap: float
    size_timeout: float
    compile_time: bool
    compile_runs: int

    @classmethod
    def full(cls) -> Config:
        """Everything the issue asks for (tens of minutes on the 2-core machine)."""
        return cls(
            quick=False, scenes=STUDY_SCENES, duration=None,
            integrators=("DOP853", "RK45", "LSODA", "Radau"), rtols=(1e-4, 1e-6, 1e-8, 1e-10, 1e-12),
            extra_rtols={"DOP853": (1e-11,)}, scheme_steps=(0.02, 0.01, 0.005), opensees_steps=(0.001, 0.0005),
            repeats=3, exact_repeats=200, budget=20.0, slow_cap=120.0,
            ensemble_runs=1000, ensemble_workers=2, memory_runs=10_000,
            lengths=(10.0, 25.0, 50.0, 100.0, 200.0), gaps=(0.08, 0.04, 0.02, 0.01, 0.005, 0.0025),
            sizes=((2, 2), (2, 6), (2, 10), (6, 2), (10, 2), (4, 4), (6, 6), (10, 10)),
            size_duration=10.0, size_gap=0.05, size_timeout=240.0, compile_time=True, compile_runs=3,
        )

    @classmethod
    def quick_preset(cls) -> Config:
        """A smoke run under a minute: scene (a) on 10 s of El Centro, one setting per solver."""
        return dataclasses.replace(
            cls.full(), quick=True, scenes=(MAIN_SCENE,), duration=10.0, rtols=(1e-6,), scheme_steps=(0.02,),
            opensees_steps=(0.001,), repeats=1, exact_repeats=5, budget=2.0, slow_cap=10.0,
            ensemble_runs=16, memory_runs=32, lengths=(10.0, 20.0), gaps=(0.02, 0.01), sizes=((2, 2), (3, 2)),
            size_timeout=60.0, compile_time=False,
        )


# ------------------------------------------------------------------ reference


@dataclass(frozen=True)
class Reference:
    """The exact solution of one scene, cross-checked against ``ivp`` DOP853 at rtol 1e-12.

    Attributes
    ----------
    exact, check : Outcome
        The exact solver's and the tight ``ivp`` run's outcomes.
    difference : Errors
        ``check`` against ``exact``.
    check_time : float
        Wall time of the ``ivp`` run, s.
    """

    exact: Outcome
    check: Outcome
    difference: Errors
    check_time: float


def reference(scene: Scene) -> Reference:
    """Solve ``scene`` exactly and cross-check it with ``ivp`` DOP853 at rtol 1e-12."""
    exact = outcome_from_dataset(stochpound.simulate(scene, method="exact"))
    timing = best_of(lambda: _ivp_outcome(scene, "DOP853", REFERENCE_RTOL), repeats=0)
    return Reference(exact, timing.result, compare(timing.result, exact), timing.best)


def _ivp_outcome(scene: Scene, integrator: str, rtol: float) -> Outcome:
    run = stochpound.simulate(scene, method="ivp", integrator=integrator, rtol=rtol, atol=rtol * 1e-2)
    return outcome_from_dataset(run)


# -------------------------------------------------------------- work–precision


@dataclass(frozen=True)
class Point:
    """One solver setting of the work–precision study.

    Attributes
    ----------
    family : str
        ``exact``, ``ivp DOP853`` (etc.), ``study scheme`` or ``OpenSees``.
    setting : str
        The tolerance or step, as text.
    time : float or None
        Best wall time, s (None when the setting failed or was skipped).
    runs : int
        Timed runs behind ``time`` (0: the only, cold, run).
    errors : Errors or None
        Against the family's reference.
    outcome : Outcome or None
    note : str
        Why a setting failed or was skipped, or how its error is defined.
    """

    family: str
    setting: str
    time: float | None
    runs: int = 0
    errors: Errors | None = None
    outcome: Outcome | None = None
    note: str = ""


def measure(family: str, setting: str, call: Callable[[], Outcome], against: Outcome, repeats: int, budget: float, note: str = "") -> Point:
    """Time ``call`` (best of ``repeats`` after a warm-up) and compare its outcome with ``against``."""
    try:
        timing: Timing[Outcome] = best_of(call, repeats, budget)
    except Exception as error:  # a failing solver is a result, not a crash of the suite
        return Point(family, setting, None, note=f"failed: {type(error).__name__}: {error}"[:300])
    return Point(family, setting, timing.best, timing.runs, compare(timing.result, against), timing.result, note)


def exact_point(scene: Scene, ref: Reference, config: Config) -> Point:
    """The exact solver; its error is its difference from the tight ``ivp`` run."""
    timing = best_of(lambda: outcome_from_dataset(stochpound.simulate(scene)), config.exact_repeats, config.budget)
    return Point("exact", "", timing.best, timing.runs, ref.difference, timing.result, f"error: difference from ivp DOP853 at rtol {REFERENCE_RTOL:g}")


def ivp_points(scene: Scene, ref: Reference, config: Config) -> list[Point]:
    """``ivp`` at every integrator and tolerance, loosest first.

    Once a tolerance fails or takes longer than ``config.slow_cap``, the
    integrator's tighter tolerances are skipped (with the reason).
    """
    points = []
    for integrator in config.integrators:
        skip = ""
        for rtol in sorted(set(config.rtols + config.extra_rtols.get(integrator, ())), reverse=True):
            family, setting = f"ivp {integrator}", f"rtol {rtol:.0e}"
            if skip:
                points.append(Point(family, setting, None, note=skip))
                continue
            point = measure(family, setting, lambda integrator=integrator, rtol=rtol: _ivp_outcome(scene, integrator, rtol), ref.exact, config.repeats, config.budget)
            if point.time is None:
                skip = f"skipped: rtol {rtol:.0e} failed"
            elif point.time > config.slow_cap:
                skip = f"skipped: rtol {rtol:.0e} took > {config.slow_cap:g} s"
            points.append(point)
    return points


def scheme_points(spline_scene: Scene, spline_ref: Reference, config: Config) -> list[Point]:
    """The study scheme at every restart interval, against the exact solution with the same (spline) input."""
    note = "corrected equations, spline input; error against the exact solution of the same scene"
    return [
        measure("study scheme", f"h {h:g} s", lambda h=h: run_study_scheme(spline_scene, h).outcome(), spline_ref.exact, config.repeats, config.budget, note)
        for h in config.scheme_steps
    ]


def opensees_points(scene: Scene, ref: Reference, config: Config) -> list[Point]:
    """OpenSeesPy at every Newmark step (a single skipped point when it cannot be loaded)."""
    try:
        load_opensees()
    except OpenSeesUnavailable as error:
        return [Point("OpenSees", "", None, note=f"skipped: {error}")]
    return [
        measure("OpenSees", f"dt {dt:g} s", lambda dt=dt: run_opensees(scene, dt), ref.exact, config.repeats, config.budget)
        for dt in config.opensees_steps
    ]


@dataclass(frozen=True)
class SceneBenchmark:
    """Reference and work–precision points of one study scene."""

    spec: StudyScene
    reference: Reference
    spline_reference: Reference
    points: list[Point]
    study_compat: list[Point] = field(default_factory=list)

    def point(self, family: str, setting: str = "") -> Point | None:
        """The point of a family and setting, if measured."""
        return next((p for p in self.points if p.family == family and (not setting or p.setting == setting)), None)


def scene_benchmark(spec: StudyScene, config: Config, log: Callable[[str], None]) -> SceneBenchmark:
    """Every solver of the work–precision study on one study scene."""
    scene = spec.scene(config.duration)
    spline_scene = spec.scene(config.duration, interpolation="spline")
    log(f"scene ({spec.key}): reference")
    ref, spline_ref = reference(scene), reference(spline_scene)
    log(f"scene ({spec.key}): exact, ivp")
    points = [exact_point(scene, ref, config), *ivp_points(scene, ref, config)]
    log(f"scene ({spec.key}): study scheme, OpenSees")
    points += scheme_points(spline_scene, spline_ref, config) + opensees_points(scene, ref, config)
    return SceneBenchmark(spec, ref, spline_ref, points, study_compat_points(spec, spline_ref, config))


def study_compat_points(spec: StudyScene, corrected: Reference, config: Config) -> list[Point]:
    """The study's full method: its scheme on its own equations (``study_compat``), against the corrected model."""
    if spec.mu1 is None and spec.mu2 is None:
        return []  # without a sliding base the two equations are the same
    scene = spec.scene(config.duration, interpolation="spline", study_compat=True)
    note = "study scheme on the study's equations (study_compat), error against the corrected model (spline input)"
    points = [measure("study scheme + study_compat", f"h {h:g} s", lambda h=h: run_study_scheme(scene, h).outcome(), corrected.exact, 1, config.budget, note)
              for h in config.scheme_steps]
    exact_compat = best_of(lambda: outcome_from_dataset(stochpound.simulate(scene)), 1)
    points.append(Point("exact + study_compat", "", exact_compat.best, exact_compat.runs, compare(exact_compat.result, corrected.exact),
                        exact_compat.result, "the study's equations solved exactly, error against the corrected model"))
    return points


# -------------------------------------------------------------- subprocesses

def probe(name: str, *arguments: Any, timeout: float = 3600.0, extra_env: dict[str, str] | None = None, monitor_memory: bool = False) -> dict[str, Any]:
    """Run ``benchmarks.probes.<name>(*arguments)`` in a fresh interpreter; failures become ``{"error": ...}``."""
    code = f"from benchmarks import probes; probes.{name}(*{arguments!r})"
    return guarded(lambda: run_subprocess(code, extra_env=extra_env, timeout=timeout, monitor_memory=monitor_memory))


def guarded(call: Callable[[], dict[str, Any]]) -> dict[str, Any]:
    """Run a subprocess measurement; a failure or timeout becomes ``{"error": ...}``."""
    try:
        return call()
    except subprocess.TimeoutExpired as error:
        return {"error": f"timeout after {error.timeout:g} s"}
    except Exception as error:  # reported in the document, not raised
        return {"error": f"{type(error).__name__}: {error}"[:300]}


def ensemble_available() -> bool:
    """Whether ``stochpound.experiment._ensemble.simulate_ensemble`` exists in this tree."""
    try:
        from stochpound.experiment import simulate_ensemble  # noqa: F401
    except ImportError:
        return False
    return True


def compile_time(config: Config) -> dict[str, Any]:
    """First-call time of the exact solver in fresh processes: ``compile_runs`` with an empty numba cache, then one filled.

    Each empty-cache run is followed by one under numba's default compile
    settings (``NUMBA_OPT=3``, ``cold_default_level``), which the engine's
    own replace (:mod:`stochpound.solvers.compiling`): the pairs show what
    they save and that they cost no speed.
    """
    import os
    import tempfile

    cold, cold_default_level = [], []
    with tempfile.TemporaryDirectory(prefix="stochpound-numba-") as root:
        for run in range(config.compile_runs):
            cache = os.path.join(root, f"run{run}")
            cold.append(probe("first_call", timeout=600, extra_env={"NUMBA_CACHE_DIR": cache}))
            cold_default_level.append(probe("first_call", timeout=600, extra_env={"NUMBA_CACHE_DIR": cache + "-default", "NUMBA_OPT": "3"}))
        cached = probe("first_call", timeout=600, extra_env={"NUMBA_CACHE_DIR": cache})
    return {"cold": cold, "cold_default_level": cold_default_level, "cached": cached}


def ensemble_throughput(config: Config) -> dict[str, Any]:
    """1000 Kanai–Tajimi realizations of 30 s on scene (c), summaries only, on ``ensemble_workers`` processes."""
    return probe("ensemble_throughput", config.ensemble_runs, config.ensemble_workers)


def ensemble_memory(config: Config) -> dict[str, Any]:
    """Peak resident memory of a summaries-only ensemble of ``memory_runs`` realizations (motions made lazily)."""
    return probe("ensemble_memory", config.memory_runs, config.ensemble_workers, timeout=3600, monitor_memory=True)


# ------------------------------------------------------------------ scaling


def length_scaling(config: Config) -> list[dict[str, Any]]:
    """Exact warm time of scene (a) against record length (one stationary Kanai–Tajimi motion, truncated)."""
    dt = 0.02
    values = kanai_tajimi_motions(1, max(config.lengths), dt, envelope=None).values[0]
    base = MAIN_SCENE.scene()
    rows = []
    for length in config.lengths:
        scene = with_motion(base, values[: int(round(length / dt)) + 1], dt, f"stationary Kanai–Tajimi, first {length:g} s")
        rows.append({"length": length, **_exact_run(scene, config)})
    return rows


def impact_scaling(config: Config) -> list[dict[str, Any]]:
    """Exact warm time of scene (b) (fixed–fixed, El Centro) against the number of impacts, varied by the gap."""
    rows = []
    for gap in config.gaps:
        scene = dataclasses.replace(STUDY_SCENES[1], gap=gap).scene(config.duration)
        rows.append({"gap": gap, **_exact_run(scene, config)})
    return rows


def _exact_run(scene: Scene, config: Config) -> dict[str, Any]:
    timing = best_of(lambda: stochpound.simulate(scene), config.exact_repeats, config.budget)
    run = timing.result
    return {"time": timing.best, "impacts": run.sizes.get("impact", 0), "events": run.attrs["events_total"], "modes": run.attrs["modes_visited"]}


def size_scaling(config: Config) -> list[dict[str, Any]]:
    """Exact first-call and warm time of rows of buildings, each in a fresh process with a timeout."""
    rows = []
    for buildings, floors in config.sizes:
        measured = probe("scene_size", buildings, floors, config.size_gap, config.size_duration, timeout=config.size_timeout)
        rows.append({"buildings": buildings, "floors": floors, **measured})
    return rows


# -------------------------------------------------------------------- all


@dataclass
class Results:
    """Everything one benchmark run measured."""

    config: Config
    scenes: list[SceneBenchmark]
    compile: dict[str, Any] | None
    ensemble: dict[str, Any]
    memory: dict[str, Any]
    lengths: list[dict[str, Any]]
    impacts: list[dict[str, Any]]
    sizes: list[dict[str, Any]]


def run_all(config: Config, log: Callable[[str], None] = print) -> Results:
    """Run every section of the suite."""
    scenes = [scene_benchmark(spec, config, log) for spec in config.scenes]
    log("first-call compile time")
    compiled = compile_time(config) if config.compile_time else None
    has_ensemble = ensemble_available()
    missing = {"error": "stochpound.experiment._ensemble.simulate_ensemble is not available in this tree"}
    log("ensemble throughput")
    ensemble = ensemble_throughput(config) if has_ensemble else missing
    log("ensemble memory")
    memory = ensemble_memory(config) if has_ensemble else missing
    log("scaling: record length, impacts, scene size")
    return Results(config, scenes, compiled, ensemble, memory, length_scaling(config), impact_scaling(config), size_scaling(config))
