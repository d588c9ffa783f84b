"""The event-driven reference solver on scipy's ``solve_ivp`` integrators.

One mode at a time, the linear equation ẋ = A x + B a_g(t) + c of the mode is
advanced by one of the integrators behind :func:`scipy.integrate.solve_ivp`
(``DOP853`` by default; ``RK45``, ``RK23``, ``Radau``, ``BDF``, ``LSODA``),
driven step by step so that every guard of the mode can be checked on every
step, including for crossings hidden inside a step (see
:mod:`stochpound.events`). The integration restarts at every sample of the
ground motion, so the forcing is a polynomial (or, for a harmonic motion, a
sine) inside every integration span, and at every event, in the new mode.
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import BDF, DOP853, LSODA, RK23, RK45, Radau
from threadpoolctl import threadpool_limits

from stochpound.errors import StochpoundError
from stochpound.events import EventCounters, GuardStates, Step, first_crossing, initial_mode
from stochpound.modes import Mode, ModeDynamics, ModeLibrary
from stochpound.recorder import Recorder, settle_and_record
from stochpound.scene import Scene
from stochpound.system import build_system

INTEGRATORS = {"DOP853": DOP853, "RK45": RK45, "RK23": RK23, "Radau": Radau, "BDF": BDF, "LSODA": LSODA}
_IMPLICIT = {"Radau", "BDF", "LSODA"}


class IntegrationError(StochpoundError, RuntimeError):
    """The underlying integrator failed (e.g. step size underflow)."""


def run_ivp(scene: Scene, integrator: str = "DOP853", rtol: float = 1e-10, atol: float = 1e-12) -> tuple[Recorder, EventCounters, ModeLibrary]:
    """Simulate ``scene`` with a scipy integrator and event location.

    Parameters
    ----------
    scene : Scene
    integrator : str
        One of :data:`INTEGRATORS`.
    rtol, atol : float
        Relative and absolute tolerances of the integrator (absolute in m and m/s).

    Returns
    -------
    recorder, counters, library
        The recorded outputs, the event counters and the visited modes.
    """
    if integrator not in INTEGRATORS:
        raise ValueError(f"integrator must be one of {', '.join(INTEGRATORS)}, got {integrator!r}")
    with threadpool_limits(limits=1):
        return _Run(scene, INTEGRATORS[integrator], integrator in _IMPLICIT, rtol, atol).execute()


class _Run:
    """State of one ivp run (kept in one object so the stepping loop stays short)."""

    def __init__(self, scene: Scene, integrator, implicit: bool, rtol: float, atol: float) -> None:
        self.system = build_system(scene)
        self.library = ModeLibrary(self.system)
        self.motion = scene.motion
        self.recorder = Recorder(self.system, self.motion)
        self.counters = EventCounters()
        self.integrator, self.implicit, self.rtol, self.atol = integrator, implicit, rtol, atol
        self.step_guess: float | None = None

    def execute(self) -> tuple[Recorder, EventCounters, ModeLibrary]:
        times = self.motion.times
        t, x = float(times[0]), self.system.initial_state.copy()
        mode, x, states = settle_and_record(self.library, self.motion, self.recorder, self.counters, 0, t, x, initial_mode(self.system))
        self.recorder.sample(0, x, self.library[mode])
        for k in range(len(times) - 1):
            t_end = float(times[k + 1])
            while t < t_end:
                t, x, mode, states = self._advance(k, t, x, t_end, mode, states)
            self.recorder.sample(k + 1, x, self.library[mode])
        self.recorder.finish(float(times[-1]))
        return self.recorder, self.counters, self.library

    def _advance(self, k: int, t: float, x: np.ndarray, t_end: float, mode: Mode, states: GuardStates):
        """Integrate in ``mode`` from t towards t_end; stop at the first event and settle it."""
        dynamics = self.library[mode]
        if t_end - t <= 2 * np.finfo(float).eps * max(1.0, abs(t_end)):
            return t_end, x, mode, states
        solver = self._solver(dynamics, k, t, x, t_end)
        while solver.status == "running":
            t_old, x_old = solver.t, solver.y.copy()
            solver.step()
            if solver.status == "failed":
                raise IntegrationError(f"{self.integrator.__name__} failed at t = {t_old:.6f} s in mode {mode}")
            self.step_guess = solver.t - t_old
            dense = solver.dense_output()
            crossing = first_crossing(dynamics, self.motion, k, Step(t_old, solver.t, x_old, solver.y, dense), states, self.counters)
            if crossing is None:
                self.recorder.on_step(dynamics, k, t_old, solver.t, dense)
                continue
            t_event, guard = crossing
            self.recorder.on_step(dynamics, k, t_old, t_event, dense)
            mode, x, states = settle_and_record(self.library, self.motion, self.recorder, self.counters, k, t_event, dense(t_event), mode, guard)
            return t_event, x, mode, states
        return t_end, solver.y.copy(), mode, states

    def _solver(self, dynamics: ModeDynamics, k: int, t: float, x: np.ndarray, t_end: float):
        A, B, c = dynamics.A, dynamics.B, dynamics.c
        polynomial = self.motion.polynomial(k)
        if polynomial is None:
            acceleration = self.motion.acceleration

            def rate(time, state):
                return A @ state + B * acceleration(time, k) + c

        else:
            c0, c1, c2, c3 = (float(value) for value in polynomial)
            start = float(self.motion.times[k])

            def rate(time, state):
                tau = time - start
                return A @ state + B * (c0 + tau * (c1 + tau * (c2 + tau * c3))) + c

        options = {"rtol": self.rtol, "atol": self.atol}
        if self.step_guess is not None:
            options["first_step"] = min(self.step_guess, t_end - t)
        if self.implicit:
            options["jac"] = lambda time, state: A  # LSODA accepts only a callable
        return self.integrator(rate, t, x, t_end, **options)
