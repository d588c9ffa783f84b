"""Timings of the exact solver, for the benchmark suite (``python -m stochpound.solvers.exact_timing``).

* :func:`time_single_run`: warm single run of the study scene (B1 isolated
  μ = 0.2 next to the flexible fixed B2, gap 2 cm, El Centro 50 s).
* :func:`time_compile`: first call in a fresh process with an empty numba
  cache (compilation of every kernel).
* :func:`time_ensemble`: 1000 Kanai–Tajimi realizations of 30 s at dt = 0.01 s
  on the study pair (both isolated μ = 0.1, stiff B2, gap 1 cm), summaries only.

Wall times are the best of ``repeat`` runs; CPU times are of this process
(the ensemble's worker processes are not included in its CPU time).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from typing import Any

from stochpound.scene import Scene

STUDY_SCENE = """
g = 9.814
[[building]]
name = "B1"
mass = [26268.0, 17512.0]
stiffness = [24516800.0, 17512000.0]
damping = [23634.2, 16881.57]
[building.base]
mass = 13134.0
mu = {mu1}
[[building]]
name = "B2"
mass = [{m21}, {m22}]
stiffness = [24516800.0, 17512000.0]
damping_ratio = 0.01
{base2}
[[contact]]
between = [["B1", 1], ["B2", 1]]
gap = {gap}
stiffness = {k1}
restitution = 0.5
[[contact]]
between = [["B1", 2], ["B2", 2]]
gap = {gap}
stiffness = {k2}
restitution = 0.5
[motion]
record = "el_centro_1940_study"
"""


def study_scene(mu1: float = 0.2, mu2: float | None = None, factor: float = 2.0, gap: float = 0.02) -> Scene:
    """The reference study's pair (tests/conftest.py ``study_scene``) as a :class:`Scene`."""
    import tomllib

    from stochpound.scene_file import scene_from_dict

    masses = (26268.0, 17512.0)
    stiffness = [57.05**2 * m * m * factor / (m + m * factor) for m in masses]
    base2 = f"[building.base]\nmass = {0.5 * masses[0] * factor}\nmu = {mu2}" if mu2 is not None else ""
    text = STUDY_SCENE.format(mu1=mu1, m21=masses[0] * factor, m22=masses[1] * factor, base2=base2, gap=gap, k1=stiffness[0], k2=stiffness[1])
    return scene_from_dict(tomllib.loads(text), source="exact_timing")


def time_single_run(repeat: int = 20, method: str = "exact") -> dict[str, float]:
    """Warm single run of the study scene: solver alone and ``simulate`` (dataset included), s."""
    from stochpound.simulate import simulate
    from stochpound.solvers.exact import run_exact

    scene = study_scene()
    simulate(scene, method=method)  # warm: compiled kernels loaded, propagators cached
    solver = [_timed(lambda: run_exact(scene)) for _ in range(repeat)] if method == "exact" else [(float("nan"),) * 2]
    full = [_timed(lambda: simulate(scene, method=method)) for _ in range(repeat)]
    return {
        "solver_wall_s": min(w for w, _ in solver),
        "solver_cpu_s": min(c for _, c in solver),
        "simulate_wall_s": min(w for w, _ in full),
        "simulate_cpu_s": min(c for _, c in full),
    }


def time_compile() -> dict[str, float]:
    """First exact run in a fresh process with an empty numba cache, s (wall and CPU of that process)."""
    code = (
        "import time, json; w = time.perf_counter(); c = time.process_time()\n"
        "from stochpound.solvers.exact_timing import study_scene\n"
        "from stochpound.solvers.exact import run_exact\n"
        "i = time.perf_counter(); run_exact(study_scene())\n"
        "print(json.dumps({'first_run_wall_s': time.perf_counter() - i, 'process_cpu_s': time.process_time() - c,"
        " 'import_wall_s': i - w}))"
    )
    with tempfile.TemporaryDirectory() as cache:
        environment = {**os.environ, "NUMBA_CACHE_DIR": cache}
        output = subprocess.run([sys.executable, "-c", code], env=environment, check=True, capture_output=True, text=True).stdout
    return json.loads(output.strip().splitlines()[-1])


def time_ensemble(n_realizations: int = 1000, workers: int = 2, duration: float = 30.0, dt: float = 0.01, seed: int = 1) -> dict[str, Any]:
    """Summaries-only ensemble of Kanai–Tajimi realizations on the study pair (both isolated, μ = 0.1, stiff B2, gap 1 cm)."""
    from stochpound import motions
    from stochpound.ensemble import simulate_ensemble

    scene = study_scene(mu1=0.1, mu2=0.1, factor=0.5, gap=0.01)
    ground = motions.kanai_tajimi(n_realizations, duration, dt, omega_g=15.0, zeta_g=0.6, pga=3.4, envelope="jennings", seed=seed)
    simulate_ensemble(scene, ground.isel(realization=slice(0, 2)))  # warm
    wall, cpu = _timed(lambda: simulate_ensemble(scene, ground, workers=workers))
    result = simulate_ensemble(scene, ground.isel(realization=slice(0, 1)))
    return {
        "realizations": n_realizations,
        "workers": workers,
        "wall_s": wall,
        "parent_cpu_s": cpu,
        "realizations_per_s": n_realizations / wall,
        "events_first_realization": int(result.events_total[0]),
    }


def _timed(function) -> tuple[float, float]:
    wall, cpu = time.perf_counter(), time.process_time()
    function()
    return time.perf_counter() - wall, time.process_time() - cpu


def main() -> None:
    """Print every timing as JSON."""
    print(json.dumps({"single_run": time_single_run(), "compile": time_compile(), "ensemble": time_ensemble()}, indent=2))


if __name__ == "__main__":
    main()
