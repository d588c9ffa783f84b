"""Yielding storeys: ``python -m benchmarks yielding``.

The study's fixed-base pair (Building 2 flexible) with bilinear storeys
(kinematic hardening α = 0.05; yield shears of about a fifth of the elastic
demand: Building 1 1.0e5 and 0.7e5 N, Building 2 twice that), under El
Centro:

* **OpenSees** (Steel01 with the same yield force, stiffness and hardening,
  :mod:`benchmarks.opensees_model`) at Newmark steps halving from 2 ms, on
  the first 10 s: without contacts (the law alone), and pounding at a 2 cm
  gap. Each step's error against the exact solution is set beside OpenSees'
  own step error, estimated by Richardson from its run at half the step
  (|y_dt − y_dt/2| · 4/3 for a second-order scheme).
* **Speed**: the pounding pair under the whole record (49.98 s): the exact
  solver (best of warm runs) against scipy's DOP853 at rtol 1e-11 in the
  same session; both errors against DOP853 at rtol 1e-12 (the reference).

It rewrites the section "Yielding storeys" of ``docs/benchmarks.md`` and
draws ``docs/figures/yielding_benchmark.png``.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import Any

import stochpound
from benchmarks import report
from benchmarks.opensees_model import YIELDING_TOLERANCE, opensees_version, run_opensees
from benchmarks.outcome import compare, outcome_from_dataset
from benchmarks.scenes import STUDY_RECORD
from benchmarks.sections import Section
from benchmarks.timing import REPOSITORY, best_of
from stochpound.model.scene import Scene
from stochpound.studies.agarwal2004 import study_scene

START = "<!-- yielding storeys: start -->"
END = "<!-- yielding storeys: end -->"
SECTION = Section(START, END)
"""This benchmark's section of docs/benchmarks.md."""
FIGURE_NAME = "yielding_benchmark.png"
YIELD_FORCES = ((1.0e5, 0.7e5), (2.0e5, 1.4e5))
"""Storey yield shears of Building 1 and Building 2, N."""
HARDENING = 0.05
STEPS = (0.002, 0.001, 0.0005, 0.00025)
"""OpenSees' Newmark steps, s."""
CROSS_CHECK_DURATION = 10.0
"""Seconds of El Centro of the OpenSees cross-check."""
SPEED_RTOL, REFERENCE_RTOL = 1e-11, 1e-12


def yielding_pair(gap: float, duration: float | None) -> Scene:
    """The study's fixed-base pair with yielding storeys at ``gap`` (m; inf: no contacts) under El Centro (its first ``duration`` s)."""
    motion: dict[str, Any] = {"record": STUDY_RECORD}
    if duration is not None:
        motion["duration"] = duration
    data = study_scene(None, None, 2.0, gap=0.02 if math.isinf(gap) else gap, motion=motion)
    for building, forces in zip(data["building"], YIELD_FORCES):
        building.update(yield_force=list(forces), hardening=HARDENING)
    if math.isinf(gap):
        data["contact"] = []
    return stochpound.scene_from_dict(data, source=f"yielding benchmark, gap {gap:g} m")


def cross_check(gap: float) -> dict[str, Any]:
    """OpenSees at every step against the exact solution, with its own step error (Richardson, from the next step)."""
    scene = yielding_pair(gap, CROSS_CHECK_DURATION)
    run = stochpound.simulate(scene)
    exact = outcome_from_dataset(run)
    rows = []
    for dt in STEPS:
        try:
            outcome = run_opensees(scene, dt)
        except Exception as error:  # a step at which OpenSees does not converge is a result
            rows.append({"dt": dt, "error": None, "note": f"{type(error).__name__}: {error}"[:200]})
            continue
        rows.append({"dt": dt, "outcome": outcome, "error": compare(outcome, exact).displacement, "impacts": outcome.impacts})
    for row, finer in zip(rows, rows[1:]):
        if row.get("outcome") is not None and finer.get("outcome") is not None:
            row["step_error"] = compare(row["outcome"], finer["outcome"]).displacement * 4.0 / 3.0
    for row in rows:
        row.pop("outcome", None)
    return {"gap": gap, "impacts": int(run.sizes["impact"]), "ductility": float(run["peak_storey_ductility"].max()), "rows": rows}


def speed(repeats: int) -> dict[str, Any]:
    """The pounding pair under the whole record: exact (best of warm runs) against DOP853 at rtol 1e-11, errors against rtol 1e-12."""
    scene = yielding_pair(0.02, None)
    reference = outcome_from_dataset(stochpound.simulate(scene, method="ivp", integrator="DOP853", rtol=REFERENCE_RTOL, atol=REFERENCE_RTOL * 1e-2))
    exact = best_of(lambda: stochpound.simulate(scene), repeats)
    dop = best_of(lambda: stochpound.simulate(scene, method="ivp", integrator="DOP853", rtol=SPEED_RTOL, atol=SPEED_RTOL * 1e-2), 1)
    return {
        "duration": float(scene.motion.times[-1]),
        "impacts": int(exact.result.sizes["impact"]), "events": int(exact.result.attrs["events_total"]),
        "ductility": float(exact.result["peak_storey_ductility"].max()),
        "exact_time": exact.best, "exact_runs": exact.runs, "dop_time": dop.best,
        "exact_error": compare(outcome_from_dataset(exact.result), reference).displacement,
        "dop_error": compare(outcome_from_dataset(dop.result), reference).displacement,
        "exact_impacts": int(exact.result.sizes["impact"]), "dop_impacts": int(dop.result.sizes["impact"]), "reference_impacts": reference.impacts,
    }


def figure(checks: list[dict[str, Any]], path: Path) -> Path:
    """OpenSees' error against the exact solution and its own step error, against the step (log–log)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.0, 4.2))
    for check, colour in zip(checks, ("C0", "C3")):
        label = "no contact" if math.isinf(check["gap"]) else f"gap {check['gap'] * 100:g} cm ({check['impacts']} impacts)"
        done = [r for r in check["rows"] if r["error"] is not None]
        ax.loglog([r["dt"] for r in done], [r["error"] for r in done], "o-", color=colour, label=f"against exact, {label}")
        estimated = [r for r in done if r.get("step_error") is not None]
        ax.loglog([r["dt"] for r in estimated], [r["step_error"] for r in estimated], "x--", color=colour, label=f"own step error, {label}")
    dt = [STEPS[0], STEPS[-1]]
    first = next(r["error"] for r in checks[0]["rows"] if r["error"] is not None)
    ax.loglog(dt, [first, first * (dt[1] / dt[0]) ** 2], "k:", lw=0.8, label="∝ dt²")
    ax.set_xlabel("OpenSees Newmark step dt (s)")
    ax.set_ylabel("largest |Δy| of B1's top floor (m)")
    ax.set_title(f"Yielding pair, first {CROSS_CHECK_DURATION:g} s of El Centro: Steel01 vs exact")
    ax.legend(fontsize=7)
    return report.save_figure(fig, path)


def _e(value: float | None) -> str:
    return "–" if value is None else f"{value:.2e}"


def section(checks: list[dict[str, Any]], fast: dict[str, Any], info: dict[str, str]) -> str:
    """The Markdown section, markers included."""
    ratio = fast["dop_time"] / fast["exact_time"]
    lines = [
        START,
        "## Yielding storeys",
        "",
        f"The study's fixed-base pair (Building 2 flexible) with bilinear storeys: yield shears {YIELD_FORCES[0][0]:.3g} and "
        f"{YIELD_FORCES[0][1]:.3g} N (Building 1), {YIELD_FORCES[1][0]:.3g} and {YIELD_FORCES[1][1]:.3g} N (Building 2), hardening "
        f"α = {HARDENING:g}; El Centro. OpenSeesPy {opensees_version()} models each storey as Steel01 (the same F_y, k and α) beside "
        f"its dashpot, Newmark average acceleration, Newton with a line search to {YIELDING_TOLERANCE:g} m. "
        f"Commit {info['commit']}, {info['date']}, load {info['load average (1 min) at start']}. "
        "`python -m benchmarks yielding` rewrites this section.",
        "",
        f"**Against OpenSees** (first {CROSS_CHECK_DURATION:g} s): the largest difference of Building 1's top-floor displacement "
        "from the exact solution at each step, beside OpenSees' own step error (Richardson: 4/3 of the difference from its run "
        "at half the step).",
        "",
        "| scene | dt (s) | against exact (m) | own step error (m) | impacts |",
        "|---|---:|---:|---:|---:|",
    ]
    for check in checks:
        name = "no contact" if math.isinf(check["gap"]) else f"gap {check['gap'] * 100:g} cm (exact: {check['impacts']} impacts)"
        name += f", peak ductility {check['ductility']:.2f}"
        for row in check["rows"]:
            impacts = row.get("impacts", "–") if row["error"] is not None else f"failed: {row['note']}"
            lines.append(f"| {name} | {row['dt']:g} | {_e(row['error'])} | {_e(row.get('step_error'))} | {impacts} |")
    lines += ["", _cross_check_reading(checks)]
    lines += [
        "",
        f"![OpenSees against exact](figures/{FIGURE_NAME})",
        "",
        f"**Speed** (the pounding pair at a 2 cm gap under the whole record, {fast['duration']:g} s: {fast['exact_impacts']} impacts, "
        f"{fast['events']} events, peak ductility {fast['ductility']:.2f}), in one session; errors are the largest difference of "
        f"Building 1's top-floor displacement from DOP853 at rtol {REFERENCE_RTOL:g} ({fast['reference_impacts']} impacts). "
        f"Target: ≥ 100× over DOP853 at rtol {SPEED_RTOL:g}.",
        "",
        "| solver | time (ms) | error (m) | impacts |",
        "|---|---:|---:|---:|",
        f"| exact (best of {fast['exact_runs']} warm runs) | {1e3 * fast['exact_time']:.1f} | {_e(fast['exact_error'])} | {fast['exact_impacts']} |",
        f"| ivp DOP853, rtol {SPEED_RTOL:g} | {1e3 * fast['dop_time']:.0f} | {_e(fast['dop_error'])} | {fast['dop_impacts']} |",
        "",
        f"Speed-up: {ratio:.0f}× ({report._verdict(ratio >= 100)}).",
        END,
    ]
    return "\n".join(lines) + "\n"


def _cross_check_reading(checks: list[dict[str, Any]]) -> str:
    """What the cross-check shows, from its numbers: the convergence order without contact, and the errors against OpenSees' step errors."""
    texts = []
    for check in checks:
        rows = [r for r in check["rows"] if r["error"] is not None]
        orders = [math.log2(a["error"] / b["error"]) for a, b in zip(rows, rows[1:]) if a["dt"] == 2 * b["dt"]]
        within = [r["error"] <= r["step_error"] * 1.05 for r in rows if r.get("step_error") is not None]
        name = "Without contact" if math.isinf(check["gap"]) else f"With pounding at {check['gap'] * 100:g} cm"
        order = f"the observed order of OpenSees' error is {', '.join(f'{o:.2f}' for o in orders)} as the step halves" if orders else "no order"
        texts.append(f"{name}, {order}; its difference from the exact solution is within its own step error (to 5 %) at "
                     f"{sum(within)} of the {len(within)} steps where that is estimated.")
    return " ".join(texts) + (" With pounding, OpenSees detects contact at its steps (ViscoelasticGap) and a yielding building keeps what an "
                              "impact's timing error does to it, so its error need not fall with the step; the exact solution locates each "
                              "impact and each yield event on the solution.")


def parse_arguments(argv: list[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="python -m benchmarks yielding", description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=20, help="timed warm runs of the exact solver (best of)")
    parser.add_argument("--out", type=Path, default=REPOSITORY / "docs" / "benchmarks.md", help="the document whose section is rewritten")
    return parser.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    """Run the measurements and rewrite the section of ``--out``."""
    arguments = parse_arguments(argv)
    info = report.machine()
    checks = [cross_check(math.inf), cross_check(0.02)]
    fast = speed(arguments.repeats)
    figure(checks, arguments.out.parent / "figures" / FIGURE_NAME)
    SECTION.write(arguments.out, section(checks, fast, info))
    print(f"wrote the section 'Yielding storeys' of {arguments.out}")
    return 0
