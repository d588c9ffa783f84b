"""The event-driven reference solver on scipy's ``solve_ivp`` integrators.

One mode at a time, the linear equation ẋ = A x + B a_g(t) + c of the mode is
advanced by one of the integrators behind :func:`scipy.integrate.solve_ivp`
(``DOP853`` by default; ``RK45``, ``RK23``, ``Radau``, ``BDF``, ``LSODA``),
step by step. Every step is handed to the event engine
(:mod:`stochpound.solvers.engine`) as the Chebyshev expansion of the
integrator's own dense output, which the engine screens, locates events on,
settles and records exactly as it does the exact solver's flow (the dense
outputs are polynomials of degree at most :data:`SUPPLIED_DEGREE`, so the
expansion reproduces them to round-off). The integration restarts at every
sample of the ground motion, so the forcing is a polynomial (or, for a
harmonic motion, a sine) inside every integration span, and at every event,
in the new mode.
"""

from __future__ import annotations

import numpy as np
from numpy.polynomial import chebyshev
from threadpoolctl import threadpool_limits

from stochpound._errors import StochpoundError
from stochpound.model.modes import Mode, ModeDynamics, ModeLibrary
from stochpound.model.readouts import Readouts
from stochpound.model.scene import Scene
from stochpound.model.system import System, build_system
from stochpound.motions.ground import GroundMotion
from stochpound.results.record import EventCounters, Recorder
from stochpound.solvers import engine
from stochpound.solvers.driver import EngineRun, VisitedModes

INTEGRATORS = ("DOP853", "RK45", "RK23", "Radau", "BDF", "LSODA")
"""The integrators of ``scipy.integrate`` a run can name (imported on first use: scipy.integrate takes a second to load)."""
_IMPLICIT = {"Radau", "BDF", "LSODA"}
SUPPLIED_DEGREE = 12
"""Chebyshev degree of a supplied step: at least the degree of every integrator's dense output (LSODA's Adams order ≤ 12)."""


class IntegrationError(StochpoundError, RuntimeError):
    """The underlying integrator failed (e.g. step size underflow)."""


def run_ivp(scene: Scene, integrator: str = "DOP853", rtol: float = 1e-10, atol: float = 1e-12,
            demands: bool = False) -> tuple[Recorder, EventCounters, VisitedModes]:
    """Simulate ``scene`` with a scipy integrator and the event engine.

    Parameters
    ----------
    scene : Scene
    integrator : str
        One of ``INTEGRATORS``.
    rtol, atol : float
        Relative and absolute tolerances of the integrator (absolute in m and m/s).
    demands : bool
        Also record the demand parameters and locate their peaks (:mod:`stochpound.model.demands`).

    Returns
    -------
    recorder, counters, visited
        The recorded outputs, the event counters and the visited modes.
    """
    if integrator not in INTEGRATORS:
        raise ValueError(f"integrator must be one of {', '.join(INTEGRATORS)}, got {integrator!r}")
    system = build_system(scene, demands)
    stepper = IntegratorSteps(system, scene.motion, integrator, rtol, atol)
    with threadpool_limits(limits=1):
        return EngineRun(system, scene.motion, ModeLibrary(system), stepper=stepper).execute()


class IntegratorSteps:
    """The steps of a scipy integrator, one mode and motion interval at a time (a :class:`~stochpound.solvers.driver.Stepper`).

    The integrator is kept while the engine asks for the next step from where
    the last one ended, in the same mode and interval, and started afresh
    otherwise (after an event, or in a new interval). With nonlinear laws the
    rate function and the supplied steps evaluate their read-outs f
    (:class:`stochpound.model.readouts.Readouts`): ξ = [x, f].
    """

    degree = SUPPLIED_DEGREE

    def __init__(self, system: System, motion: GroundMotion, integrator: str, rtol: float, atol: float) -> None:
        self.readouts = Readouts(system)
        self.size = 2 * system.n_dof
        self.motion = motion
        from scipy import integrate

        self.name, self.integrator, self.implicit = integrator, getattr(integrate, integrator), integrator in _IMPLICIT
        self.rtol, self.atol = rtol, atol
        self.solver = None
        self.span: tuple[Mode, int] | None = None
        self.step_guess: float | None = None

    def step(self, dynamics: ModeDynamics, k: int, t: float, x: np.ndarray, t_end: float, supplied: engine.Supplied, onsets: np.ndarray) -> None:
        """Take one step from (t, ξ = x) in ``dynamics``' mode inside interval k (ending by t_end) into ``supplied``.

        ``onsets``: each element's current impact approach velocity (m/s), for laws that need it.
        """
        if self.solver is None or self.span != (dynamics.mode, k) or self.solver.t != t:
            self.solver, self.span = self._solver(dynamics, k, t, x[: self.size], t_end, onsets), (dynamics.mode, k)
        solver = self.solver
        t_old = solver.t
        solver.step()
        if solver.status == "failed":
            raise IntegrationError(f"{self.name} failed at t = {t_old:.6f} s in mode {dynamics.mode}: {solver.message}")
        self.step_guess = solver.t - t_old
        dense = solver.dense_output()
        half = 0.5 * (solver.t - t_old)

        def xi(s: np.ndarray) -> np.ndarray:
            states = dense(t_old + half * (s + 1.0)).T
            return np.concatenate([states, self.readouts.values(dynamics.mode, states, onsets)], axis=-1)

        supplied.bounds[:] = t_old, solver.t
        supplied.x[:] = xi(np.array([1.0]))[0]
        supplied.x[: self.size] = solver.y
        supplied.coefficients[:] = chebyshev.chebinterpolate(xi, self.degree).ravel()

    def _solver(self, dynamics: ModeDynamics, k: int, t: float, x: np.ndarray, t_end: float, onsets: np.ndarray):
        A, B, c = dynamics.A, dynamics.B, dynamics.c
        if A.shape[1] > self.size:  # read-outs: ẋ = A_x x + E f(x) + B a_g + c
            mode, A, E, readouts = dynamics.mode, A[:, : self.size], A[:, self.size :], self.readouts

            def inputs(state):
                return c + E @ readouts.values(mode, state, onsets)
        else:

            def inputs(state):
                return c

        polynomial = self.motion.polynomial(k)
        if polynomial is None:
            acceleration = self.motion.acceleration

            def rate(time, state):
                return A @ state + B * acceleration(time, k) + inputs(state)

        else:
            c0, c1, c2, c3 = (float(value) for value in polynomial)
            start = float(self.motion.times[k])

            def rate(time, state):
                tau = time - start
                return A @ state + B * (c0 + tau * (c1 + tau * (c2 + tau * c3))) + inputs(state)

        options = {"rtol": self.rtol, "atol": self.atol}
        if self.step_guess is not None:
            options["first_step"] = min(self.step_guess, t_end - t)
        if self.implicit and dynamics.A.shape[1] == self.size:  # with read-outs the integrator estimates the Jacobian
            options["jac"] = lambda time, state: A  # LSODA accepts only a callable
        return self.integrator(rate, t, np.array(x), t_end, **options)
