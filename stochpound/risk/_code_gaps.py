"""Building separations as the codes compute them: from the design analysis, at the code's design level.

The codes do not take a gap from the mean peak of a suite of response
histories. They take it from the displacements of the design analysis, a
linear analysis under the design spectrum with forces reduced for
ductility, amplified back to the expected inelastic displacement:

- **ASCE 7-16 §12.12.3.** δ_M = C_d δ_max / I_e (eq. 12.12-1), δ_max the
  design analysis's displacement at the critical location under the
  design forces (the elastic demand of the design spectrum divided by
  R / I_e). A structure is set back from the property line by δ_M;
  adjacent structures on the same property are separated by
  δ_MT = √(δ_M1² + δ_M2²) (eq. 12.12-2). The design spectrum is the design
  earthquake's (S_DS, S_D1: two thirds of MCE_R), §11.4.6.
- **Eurocode 8 (EN 1998-1) §4.4.2.7.** d_s = q d_e (eq. 4.23), d_e the
  displacement of the linear analysis under the design spectrum S_d(T)
  (§3.2.2.5, reduced by the behaviour factor q). A unit is kept from the
  property line by d_s; units of the same property are separated by the
  SRSS of their d_s (§4.4.2.7(2)); where the floor levels of the two units
  coincide, the distance may be reduced by the factor 0.7 (§4.4.2.7(3)).
- **ASCE 7-16 §17.5.3, isolation.** D_M = g S_M1 T_M / (4 π² B_M)
  (eq. 17.5-1), T_M = 2π √(W / (k_M g)) (eq. 17.5-2) the effective period
  at D_M and B_M the damping coefficient of Table 17.5-1 at the effective
  damping β_M. For a flat-sliding or pendulum bearing of friction μ and
  radius R (restoring stiffness W/R), at displacement D: k_M = W/R + μW/D
  and β_M = 2μ / (π (μ + D/R)); D_M is their fixed point. A planar model
  has no torsion, so D_TM = D_M (§17.5.3.3's amplification is 1).

The displacements of the design analysis come from a modal response
spectrum analysis of the fixed-base shear building (ASCE 7 §12.9.1,
EN 1998-1 §4.3.3.3): each mode's peak floor displacements
Γ_n φ_n S(T_n) / ω_n² combined by SRSS over all modes. The codes' further
adjustments (ASCE 7 §12.9.1.4's scaling to the equivalent lateral force
base shear, accidental torsion, P-Δ amplification) are not applied: say
so where a gap is reported.

No maintained Python package computes these (the ``asce7-16`` package has
the ASCE 7 design spectrum, used here, but neither the §12.12 separations,
chapter 17's displacement nor Eurocode 8's spectra), so the formulas are
written out here with their clauses; chapter 17's are in
:mod:`stochpound.codes` (the isolated building's design, forces and
displacements at both friction bounds).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.linalg import eigh

from stochpound.codes import isolator_displacement
from stochpound.motions import DEFAULT_G
from stochpound.model.building import Building, storey_matrix

#: EN 1998-1 Table 3.2 (Type 1 spectrum): S, T_B, T_C, T_D (s) of each ground type.
EC8_TYPE1_GROUND = {
    "A": (1.0, 0.15, 0.4, 2.0),
    "B": (1.2, 0.15, 0.5, 2.0),
    "C": (1.15, 0.20, 0.6, 2.0),
    "D": (1.35, 0.20, 0.8, 2.0),
    "E": (1.4, 0.15, 0.5, 2.0),
}


@dataclass(frozen=True)
class Asce7Design:
    """The ASCE 7-16 design of one building: its design spectrum and seismic force-resisting system.

    Attributes
    ----------
    sds, sd1 : float
        Design spectral accelerations at short periods and at 1 s (g), §11.4.5.
    tl : float
        Long-period transition period T_L (s), §11.4.6.
    r : float
        Response modification coefficient R (Table 12.2-1).
    cd : float
        Deflection amplification factor C_d (Table 12.2-1).
    ie : float
        Importance factor I_e (Table 1.5-2).
    """

    sds: float
    sd1: float
    tl: float
    r: float
    cd: float
    ie: float = 1.0

    def __post_init__(self) -> None:
        for name in ("sds", "sd1", "tl", "r", "cd", "ie"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0.0):
                raise ValueError(f"design.{name}: must be a positive number, got {value!r}")

    def spectrum(self, period: np.ndarray) -> np.ndarray:
        """The design response spectrum S_a(T) (g) of §11.4.6, from the ``asce7-16`` package."""
        from asce7_16.seismic import design_response_spectrum

        curve = design_response_spectrum(self.sds, self.sd1, self.tl)
        return np.array([float(curve(float(t))) for t in np.atleast_1d(period)])


@dataclass(frozen=True)
class Ec8Design:
    """The Eurocode 8 design of one building: its Type 1 design spectrum and behaviour factor.

    Attributes
    ----------
    ag : float
        Design ground acceleration on type A ground a_g = γ_I a_gR (g).
    ground : str
        Ground type, ``"A"`` to ``"E"`` (Table 3.2).
    q : float
        Behaviour factor (≥ 1).
    beta : float
        Lower bound factor of the design spectrum (eq. 3.16; 0.2 recommended).
    """

    ag: float
    ground: str
    q: float
    beta: float = 0.2

    def __post_init__(self) -> None:
        if self.ground not in EC8_TYPE1_GROUND:
            raise ValueError(f"design.ground: must be one of {', '.join(EC8_TYPE1_GROUND)}, got {self.ground!r}")
        if not (math.isfinite(self.ag) and self.ag > 0.0):
            raise ValueError(f"design.ag: must be a positive acceleration (g), got {self.ag!r}")
        if not (math.isfinite(self.q) and self.q >= 1.0):
            raise ValueError(f"design.q: must be >= 1, got {self.q!r}")

    def spectrum(self, period: np.ndarray) -> np.ndarray:
        """The design spectrum S_d(T) (g) of EN 1998-1 §3.2.2.5, eqs. 3.13–3.16."""
        s, tb, tc, td = EC8_TYPE1_GROUND[self.ground]
        t = np.atleast_1d(np.asarray(period, dtype=float))
        ag, q = self.ag, self.q
        rising = ag * s * (2.0 / 3.0 + t / tb * (2.5 / q - 2.0 / 3.0))
        plateau = np.full_like(t, ag * s * 2.5 / q)
        with np.errstate(divide="ignore"):
            falling = np.maximum(ag * s * 2.5 / q * tc / t, self.beta * ag)
            tail = np.maximum(ag * s * 2.5 / q * tc * td / t**2, self.beta * ag)
        return np.select([t <= tb, t <= tc, t <= td], [rising, plateau, falling], tail)


def modal_floor_displacements(building: Building, spectrum_g: np.ndarray | None = None, *, design: Asce7Design | Ec8Design | None = None,
                              g: float = DEFAULT_G) -> np.ndarray:
    """Peak floor displacements (m) of a fixed-base shear building under a design spectrum: modal analysis, SRSS of modes.

    Parameters
    ----------
    building : Building
        The building (its base, if any, is held fixed: the design analysis of the superstructure).
    spectrum_g : numpy.ndarray, optional
        Spectral accelerations S(T_n) (g) of the building's modes, lowest first.
    design : Asce7Design or Ec8Design, optional
        Where ``spectrum_g`` is not given: the design whose spectrum is read at the modes' periods.
    g : float
        Standard gravity (m/s²).

    Returns
    -------
    numpy.ndarray
        One displacement per floor relative to the ground (m), floor 1 upwards.
    """
    mass = np.asarray(building.mass, dtype=float)
    eigenvalues, shapes = eigh(storey_matrix(np.asarray(building.stiffness, dtype=float)), np.diag(mass))
    omega = np.sqrt(eigenvalues)
    if spectrum_g is None:
        if design is None:
            raise ValueError("design: give the design or the spectral accelerations of the modes")
        spectrum_g = design.spectrum(2.0 * np.pi / omega)
    participation = shapes.T @ mass / np.einsum("in,i,in->n", shapes, mass, shapes)
    modal = shapes * participation[None, :] * np.asarray(spectrum_g, dtype=float)[None, :] * g / eigenvalues[None, :]
    return np.sqrt(np.sum(modal**2, axis=1))


def asce7_inelastic_displacement(elastic_design: np.ndarray, design: Asce7Design) -> np.ndarray:
    """δ_M = C_d δ_max / I_e (ASCE 7-16 eq. 12.12-1), δ_max = the design spectrum's elastic displacement / (R / I_e) (m)."""
    delta_max = np.asarray(elastic_design, dtype=float) / (design.r / design.ie)
    return design.cd * delta_max / design.ie


def ec8_design_displacement(design_analysis: np.ndarray, design: Ec8Design) -> np.ndarray:
    """d_s = q d_e (EN 1998-1 eq. 4.23), d_e from the analysis under the design spectrum S_d (m)."""
    return design.q * np.asarray(design_analysis, dtype=float)


def srss_separation(left: float, right: float) -> float:
    """√(δ_1² + δ_2²): ASCE 7-16 eq. 12.12-2 (δ_MT) and EN 1998-1 §4.4.2.7(2b), for units on the same property (m)."""
    return float(math.hypot(left, right))


def asce7_isolator_displacement(weight: float, mu: float, radius: float, sm1: float, g: float = DEFAULT_G,
                                tolerance: float = 1e-10) -> tuple[float, float, float]:
    """ASCE 7-16 §17.5.3's displacement D_M of a friction pendulum (or flat slider with restoring stiffness W/R).

    ``stochpound.codes.isolator_displacement`` (eqs. 17.5-1, 17.5-2, Table 17.5-1; the weight cancels).

    Parameters
    ----------
    weight : float
        Seismic weight W on the isolators (N); it cancels, kept for clarity.
    mu : float
        Friction coefficient at the design displacement (> 0).
    radius : float
        Radius of curvature R (m) (W/R the restoring stiffness).
    sm1 : float
        MCE_R spectral acceleration at 1 s, S_M1 (g).
    g : float
        Standard gravity (m/s²).
    tolerance : float
        Tolerance on D (m).

    Returns
    -------
    displacement, period, damping : float
        D_M (m), T_M (s), β_M (1).
    """
    if not (math.isfinite(weight) and weight > 0.0):
        raise ValueError(f"weight: must be a positive number, got {weight!r}")
    return isolator_displacement(mu, radius, sm1, g, tolerance)
