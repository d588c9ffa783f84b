"""The read-outs f of a system's nonlinear laws: their values along a flow and their value and rate at an instant.

A nonlinear law's force cannot be folded into a mode's linear matrices, so it
enters them as an input (:mod:`stochpound.model.modes`: ẋ = A x + E f + B a_g + c)
and is evaluated here, by the law's own module, wherever it is needed:

* the integrator's rate function and the steps it supplies to the event
  engine (:mod:`stochpound.solvers.ivp`) need f at states x(t);
* settling an event needs f and ḟ at the event's state, in each mode the
  settling meets (:class:`stochpound.solvers.driver.EngineRun`).

The read-outs are, in order, the forces of the impact elements with a
nonlinear contact law (0 while open) and the foundation's force on the
sliding bases with a nonlinear friction law (0 unless slipping), each
evaluated by its law's object (:mod:`stochpound.model.laws`).
"""

from __future__ import annotations

import numpy as np

from stochpound.model import friction, laws
from stochpound.model.laws.contract import ElementParameters
from stochpound.model.modes import Mode, ModeDynamics
from stochpound.model.system import System


class Readouts:
    """The read-outs of ``system``'s modes.

    Parameters
    ----------
    system : System
    """

    def __init__(self, system: System) -> None:
        self.system = system
        self.elements = system.readout_elements
        self.bases = [system.bases[b] for b in system.readout_bases]
        self.element_laws = [laws.contact_law(system.element_law[p]) for p in self.elements]
        self.parameters = [ElementParameters(system.element_stiffness[p], system.element_damping[p], system.element_restitution[p],
                                             system.element_tensile[p], system.element_mass[p]) for p in self.elements]
        self.base_laws = [laws.friction_law(base.friction_law) for base in self.bases]

    def values(self, mode: Mode, x: np.ndarray, onsets: np.ndarray) -> np.ndarray:
        """f (N) at states ``x`` (… × 2N) in ``mode``; ``onsets``: each element's impact approach velocity δ̇₀ (m/s)."""
        x = np.asarray(x, float)
        f = np.zeros(x.shape[:-1] + (self.system.n_readouts,))
        for j, p in enumerate(self.elements):
            if mode.closed[p]:
                delta, rate = self._penetration(p, x)
                f[..., j] = self.element_laws[j].force(self.parameters[j], delta, rate, onsets[p])
        for j, (b, base, law) in enumerate(zip(self.system.readout_bases, self.bases, self.base_laws), start=len(self.elements)):
            state = mode.base[b]
            if friction.slipping(state):
                f[..., j] = law.force(base, state, np.abs(x[..., self.system.n_dof + base.dof]))
        return f

    def at_instant(self, dynamics: ModeDynamics, x: np.ndarray, ground: np.ndarray, onsets: np.ndarray) -> np.ndarray:
        """f and ḟ (2 × n_f) at state x (2N) in the mode of ``dynamics``, with ``ground`` = [a_g, ȧ_g]."""
        n = self.system.n_dof
        f = self.values(dynamics.mode, x, onsets)
        acceleration = (dynamics.A[:, : 2 * n] @ x + dynamics.A[:, 2 * n :] @ f + dynamics.B * ground[0] + dynamics.c)[n:]
        rates = np.zeros_like(f)
        for j, p in enumerate(self.elements):
            if dynamics.mode.closed[p]:
                delta, rate = self._penetration(p, x)
                along, across = self.element_laws[j].partials(self.parameters[j], delta, rate, onsets[p])
                rates[j] = along * rate + across * (self.system.element_geometry[p] @ acceleration)
        for j, (b, base, law) in enumerate(zip(self.system.readout_bases, self.bases, self.base_laws), start=len(self.elements)):
            if friction.slipping(dynamics.mode.base[b]):
                rates[j] = law.partial(base, abs(x[n + base.dof])) * acceleration[base.dof]
        return np.vstack([f, rates])

    def _penetration(self, p: int, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """δ (m) and δ̇ (m/s) of element p at states x."""
        geometry, n = self.system.element_geometry[p], self.system.n_dof
        return x[..., :n] @ geometry - self.system.element_gap[p], x[..., n : 2 * n] @ geometry
