"""An emulation of the reference study's own solution scheme (Agarwal 2004, its Appendix 4).

The study did not locate events. It restarted MATLAB's ``ode45`` every h
seconds (h = 0.02 s), and only at those restarts decided

* which contacts act: a contact is on for the whole next step when its
  penetration is positive at the restart, and off otherwise;
* which bases slide: a base slides for the whole next step when
  ``|Σ m_i ü_i + (Σ m_i) s̈ + M_tot a_g| ≥ μ W``, evaluated with the
  accelerations of the state reached at the restart (the impact forces are
  not in this sum); otherwise it sticks, and its sliding velocity is set to
  zero at the end of the step.

Inside a step (``ode45`` with MaxStep 0.01 s, InitialStep 0.01 s, AbsTol 1e-3
and the default RelTol 1e-3; here scipy's RK45 with the same settings) a
sliding base feels the friction force −μ W sgn(ṡ) with sgn(0) = 0, so a base
that starts to slide from rest has no friction at the start of its first
step, and a sliding base never stops inside a step. The ground motion is the
scene's own (the study used a cubic spline through the samples).

The equations inside a step are stochpound's mode equations
(:class:`stochpound.model.modes.ModeLibrary`): a sliding base is a free degree of
freedom plus the friction term above, a stuck base keeps s and ṡ. Whether
the impact forces act on the base as a whole follows the scene:
``study_compat = true`` gives the study's equations (they do not), otherwise
the momentum-consistent ones; the sliding test includes them in the second
case, as the required friction force F_req of docs/model.md does.

This module lives in ``benchmarks/``, not in the library: it exists to show
what the study's scheme does, not to be used.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import solve_ivp

from benchmarks.outcome import Outcome
from stochpound.model.friction import FREE, STUCK
from stochpound.model.modes import Mode, ModeDynamics, ModeLibrary
from stochpound.motions.ground import SampledMotion
from stochpound.model.scene import Scene
from stochpound.model.system import System, build_system

STUDY_RK45 = {"max_step": 0.01, "first_step": 0.01, "atol": 1e-3, "rtol": 1e-3}
"""Settings of the RK45 integration inside each step (the study's ode45 options; the
first step is clipped to h)."""


@dataclass
class SchemeRun:
    """Result of one emulated run.

    Attributes
    ----------
    system : System
        The assembled system (DOF layout of ``states``).
    states : np.ndarray
        State x = [q, v] at the motion's samples (n_times × 2N).
    times : np.ndarray
        The motion's sample times, s.
    impacts : int
        Number of contact closures decided at restarts.
    peak_force : float
        Largest contact force over the integrator's steps, N.
    sliding_steps : np.ndarray
        Per sliding base, the number of steps in which it slid.
    """

    system: System = field(repr=False)
    states: np.ndarray
    times: np.ndarray
    impacts: int
    peak_force: float
    sliding_steps: np.ndarray

    def sliding_displacement(self, building: int = 0) -> np.ndarray:
        """Sliding displacement s of a building's base at the sample times, m (0 if fixed)."""
        dofs = [base.dof for base in self.system.bases if base.building == building]
        return self.states[:, dofs[0]] if dofs else np.zeros(len(self.times))

    def total_displacement(self, building: int = 0, floor: int = -1) -> np.ndarray:
        """Total displacement y = s + u of one floor (default: the top) at the sample times, m."""
        dof = self.system.floor_dofs[building][floor]
        return self.states[:, dof] + self.sliding_displacement(building)

    def outcome(self) -> Outcome:
        """The run as a benchmark :class:`~benchmarks.outcome.Outcome`."""
        return Outcome(self.times, self.total_displacement(), self.impacts, self.peak_force, float(self.sliding_displacement()[-1]))


class StudyScheme:
    """The study's fixed-restart scheme applied to one scene.

    Parameters
    ----------
    scene : Scene
        Its motion must be sampled (:class:`~stochpound.motions.ground.SampledMotion`).
    h : float
        Restart interval, s. The motion's sample spacing must be a whole
        multiple of it (the study: h = dt = 0.02 s).
    """

    def __init__(self, scene: Scene, h: float = 0.02) -> None:
        if not isinstance(scene.motion, SampledMotion):
            raise TypeError("the study's scheme needs a sampled ground motion")
        per_sample = scene.motion.dt / h
        if h <= 0 or abs(per_sample - round(per_sample)) > 1e-9:
            raise ValueError(f"h must divide the motion's sample spacing {scene.motion.dt:g} s, got {h:g}")
        self.motion = scene.motion
        self.h = h
        self.steps_per_sample = int(round(per_sample))
        self.system = build_system(scene)
        self.library = ModeLibrary(self.system)
        self._friction_cache: dict[tuple[int, ...], np.ndarray] = {}

    def run(self) -> SchemeRun:
        """Emulate the whole motion; see the module docstring for the rules."""
        system, n_bases = self.system, len(self.system.bases)
        x = system.initial_state.copy()
        states = np.empty((len(self.motion.times), 2 * system.n_dof))
        states[0] = x
        check = np.zeros(n_bases)  # the study starts from zero accelerations
        closed_before = np.zeros(system.n_elements, dtype=bool)
        impacts, peak, sliding_steps = 0, 0.0, np.zeros(n_bases, dtype=int)
        for k in range(len(self.motion.times) - 1):
            edges = np.linspace(self.motion.times[k], self.motion.times[k + 1], self.steps_per_sample + 1)
            for t0, t1 in zip(edges[:-1], edges[1:]):
                mode = self._decide(x, check)
                closed = np.array(mode.closed, dtype=bool)
                impacts += int(np.count_nonzero(closed & ~closed_before))
                closed_before = closed
                sliding_steps += np.array(mode.base) == FREE
                x, step_peak = self._step(k, t0, t1, x, mode)
                peak = max(peak, step_peak)
                check = self._sliding_check(k, t1, x, mode)
            states[k + 1] = x
        return SchemeRun(system, states, self.motion.times.copy(), impacts, peak, sliding_steps)

    def _decide(self, x: np.ndarray, check: np.ndarray) -> Mode:
        """The mode of the next step: contacts penetrated at the restart, bases whose test quantity reaches μ W."""
        system = self.system
        closed = tuple(bool(c) for c in self._penetration(x) > 0.0)
        sliding = [not (base.mu * base.weight > abs(check[b])) for b, base in enumerate(system.bases)]
        return Mode(closed, tuple(FREE if slides else STUCK for slides in sliding))

    def _penetration(self, x: np.ndarray) -> np.ndarray:
        """δ of every contact at state x, m."""
        return self.system.element_geometry @ x[: self.system.n_dof] - self.system.element_gap

    def _friction(self, mode: Mode) -> np.ndarray:
        """Columns: the state rate of each sliding base's friction force −μ W (times sgn ṡ)."""
        cached = self._friction_cache.get(mode.base)
        if cached is not None:
            return cached
        system, n = self.system, self.system.n_dof
        stuck = [base.dof for base, state in zip(system.bases, mode.base) if state == STUCK]
        free = np.setdiff1d(np.arange(n), stuck)
        columns = np.zeros((2 * n, len(system.bases)))
        for b, base in enumerate(system.bases):
            if mode.base[b] == FREE:
                load = np.zeros(len(free))
                load[np.searchsorted(free, base.dof)] = -base.mu * base.weight
                columns[n + free, b] = np.linalg.solve(system.mass[np.ix_(free, free)], load)
        self._friction_cache[mode.base] = columns
        return columns

    def _rate_function(self, k: int, mode: Mode) -> tuple[Callable[[float, np.ndarray], np.ndarray], ModeDynamics]:
        """ẋ(t, x) in ``mode`` inside sample interval k (friction −μ W sgn ṡ on sliding bases), and the mode's dynamics."""
        dynamics = self.library[mode]
        A, B, c = dynamics.A, dynamics.B, dynamics.c
        friction = self._friction(mode)
        velocity_rows = self.system.n_dof + self.system.base_dofs
        acceleration = self.motion.acceleration

        def rate(t: float, x: np.ndarray) -> np.ndarray:
            return A @ x + B * acceleration(t, k) + c + friction @ np.sign(x[velocity_rows])

        return rate, dynamics

    def _step(self, k: int, t0: float, t1: float, x: np.ndarray, mode: Mode) -> tuple[np.ndarray, float]:
        """One restart interval: RK45 from t0 to t1; return the end state and the peak contact force."""
        rate, dynamics = self._rate_function(k, mode)
        options = {**STUDY_RK45, "first_step": min(STUDY_RK45["first_step"], t1 - t0)}
        solution = solve_ivp(rate, (t0, t1), x, method="RK45", **options)
        if not solution.success:
            raise RuntimeError(f"RK45 failed at t = {t0:.4f} s: {solution.message}")
        x_end = solution.y[:, -1].copy()
        for base, state in zip(self.system.bases, mode.base):
            if state == STUCK:
                x_end[self.system.n_dof + base.dof] = 0.0  # the study's "no sliding" reset
        return x_end, _peak_force(dynamics, solution.y)

    def _sliding_check(self, k: int, t: float, x: np.ndarray, mode: Mode) -> np.ndarray:
        """The study's sliding test quantity per sliding base, N, at the end of a step."""
        system, n = self.system, self.system.n_dof
        rate, dynamics = self._rate_function(k, mode)
        acceleration = rate(t, x)[n:]
        forces = dynamics.force_matrix @ x + dynamics.force_constant
        ground = self.motion.acceleration(t, k)
        check = np.zeros(len(system.bases))
        for b, sliding_base in enumerate(system.bases):
            base, floors = sliding_base.dof, system.floor_dofs[sliding_base.building]
            floor_mass = np.diag(system.mass)[floors]
            check[b] = (
                floor_mass @ (acceleration[floors] + acceleration[base])
                + system.influence[base] * ground
                + forces @ system.element_load[:, base]
                + system.stiffness[base, base] * x[base]
            )
        return check


def _peak_force(dynamics: ModeDynamics, states: np.ndarray) -> float:
    """Largest force of the active contacts over the given states (columns), N."""
    if not any(dynamics.mode.closed):
        return 0.0
    forces = dynamics.force_matrix @ states + dynamics.force_constant[:, None]
    return float(forces.max())


def run_study_scheme(scene: Scene, h: float = 0.02) -> SchemeRun:
    """Emulate the study's scheme on ``scene`` with restarts every ``h`` seconds."""
    return StudyScheme(scene, h).run()
