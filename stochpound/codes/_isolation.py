"""ASCE 7-16 chapter 17 for a building on a sliding base: displacements and design forces at both friction bounds.

A friction pendulum (or a flat slider with a restoring stiffness W/R) of
friction coefficient μ and radius R carries the building's weight W. Its
force at displacement D is (D/R + μ) W, so at D (§17.5.3):

- effective stiffness k_M = W/R + μ W/D (the secant of the loop);
- effective period T_M = 2π √(W / (k_M g)) (eq. 17.5-2);
- effective damping β_M = E_loop / (2π k_M D²) with the loop's energy
  E_loop = 4 μ W D: β_M = 2μ / (π (μ + D/R));
- D_M = g S_M1 T_M / (4π² B_M) (eq. 17.5-1), B_M of Table 17.5-1 at β_M;
  D_M is the fixed point of these (found by root bracketing).

Then D_TM = D_M (1 + y / P_T² · 12 e / (b² + d²)) (eq. 17.5-3, torsion),
V_b = k_M D_M (eq. 17.5-5), V_st = V_b (W_s/W)^(1 − c β_M) (eq. 17.5-7;
c = 2.5, or 3.5 under §17.5.4.2's exception for a hysteresis with an abrupt
pre-slip to post-slip transition, as a slider's) and V_s = V_st / R_I
(eq. 17.5-8), R_I = 3/8 R within [1, 2] (§17.5.4.2). V_s is not taken less
than the limits of §17.5.4.3: (1) the §12.8 base shear of a fixed-base
structure of weight W_s at the upper-bound T_M, (2) the factored design
wind base shear, (3) V_st with V_b the force that fully activates the
isolation system: the larger of the upper-bound friction force μ_max W
(item 3d, the force at zero displacement after a cycle), 1.5 times the
nominal yield μ W (item 3a) and the upper-bound breakaway force (item 3c).

Everything is computed at lower- and upper-bound friction μ λ_min and
μ λ_max (§17.2.8.4): the lower bound gives the larger displacements, the
upper bound the larger forces.

The ``asce7-16`` package gives the §12.8 seismic response coefficient
(``seismic_response_coeff``, used for limit 1 with I_e = 1, §17.2.1); it
has none of chapter 17 (Table 17.5-1, eqs. 17.5-1 to 17.5-8, §17.5.4.3),
so those are written out here with their clauses.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from stochpound.motions import DEFAULT_G

DAMPING_TABLE = ((0.02, 0.8), (0.05, 1.0), (0.10, 1.2), (0.20, 1.5), (0.30, 1.7), (0.40, 1.9), (0.50, 2.0))
"""ASCE 7-16 Table 17.5-1: damping coefficient B_M against effective damping β_M (interpolated linearly, the ends held)."""
MAXIMUM_DIRECTION = (1.1, 1.3)
"""Factors from the geometric-mean to the maximum-direction spectral acceleration at 0.2 s and at 1 s (ASCE 7-16 §21.2)."""
PROPERTY_MODIFICATION = (1.8, 0.6)
"""Default λ_max, λ_min on a slider's friction: the wide default bounds taken under ASCE 7-16 §17.2.8.4 where no
manufacturer's qualification data are at hand; give the manufacturer's factors where known."""
ACCIDENTAL_ECCENTRICITY = 0.05
"""Accidental eccentricity as a fraction of the longest plan dimension (ASCE 7-16 §17.5.3.3)."""


def damping_coefficient(damping: float) -> float:
    """B_M (1) of ASCE 7-16 Table 17.5-1 at effective damping β_M (1) (linear interpolation; the table's ends outside it)."""
    ratios, coefficients = zip(*DAMPING_TABLE, strict=True)
    return float(np.interp(damping, ratios, coefficients))


def _positive(name: str, value: float | None) -> None:
    if value is not None and not (math.isfinite(value) and value > 0.0):
        raise ValueError(f"{name}: must be a positive number, got {value!r}")


def _at_least(name: str, value: float, low: float) -> None:
    if not (math.isfinite(value) and value >= low):
        raise ValueError(f"{name}: must be >= {low:g}, got {value!r}")


@dataclass(frozen=True)
class SlidingBase:
    """A sliding isolation system: friction pendulum, or flat slider with restoring stiffness W/R.

    Attributes
    ----------
    mu : float
        Nominal friction coefficient (1), in (0, 0.3].
    radius : float
        Radius of curvature R (m): restoring stiffness W/R.
    weight : float
        W, effective seismic weight above the isolation interface, base level included (N).
    superstructure_weight : float
        W_s, the same without the base level (N), in (0, W].
    lambda_max, lambda_min : float
        Property-modification factors on μ (§17.2.8.4): λ_max >= 1, 0 < λ_min <= 1.
        Defaults 1.8 and 0.6 (``PROPERTY_MODIFICATION``).
    breakaway : float, optional
        Nominal breakaway (static) friction coefficient (1), >= ``mu``, for
        §17.5.4.3 item 3c (times λ_max); None: taken as ``mu``.
    """

    mu: float
    radius: float
    weight: float
    superstructure_weight: float
    lambda_max: float = PROPERTY_MODIFICATION[0]
    lambda_min: float = PROPERTY_MODIFICATION[1]
    breakaway: float | None = None

    def __post_init__(self) -> None:
        for name in ("mu", "radius", "weight", "superstructure_weight", "lambda_min", "breakaway"):
            _positive(name, getattr(self, name))
        if self.mu > 0.3:
            raise ValueError(f"mu: must be in (0, 0.3] (a slider's friction coefficient), got {self.mu!r}")
        if self.superstructure_weight > self.weight:
            raise ValueError(f"superstructure_weight: must be in (0, weight = {self.weight:g}] N, got {self.superstructure_weight!r}")
        _at_least("lambda_max", self.lambda_max, 1.0)
        if self.lambda_min > 1.0:
            raise ValueError(f"lambda_min: must be in (0, 1], got {self.lambda_min!r}")
        if self.breakaway is not None and self.breakaway < self.mu:
            raise ValueError(f"breakaway: must be >= mu = {self.mu:g}, got {self.breakaway!r}")


@dataclass(frozen=True)
class MceSpectrum:
    """The MCE_R spectral values chapter 17 reads, in the maximum direction.

    Attributes
    ----------
    sms, sm1 : float
        S_MS and S_M1 (g), maximum direction (eq. 17.5-1 reads S_M1).
    long_period : float
        T_L (s), §11.4.6.
    s1 : float, optional
        Mapped S_1 (g) for eq. 12.8-6 in §17.5.4.3 item 1; None: S_M1 stands for it
        (the larger where F_v >= 1, site classes C to E).
    """

    sms: float
    sm1: float
    long_period: float
    s1: float | None = None

    def __post_init__(self) -> None:
        for name in ("sms", "sm1", "long_period", "s1"):
            _positive(name, getattr(self, name))

    @classmethod
    def from_geometric_mean(cls, sa_short: float, sa_long: float, long_period: float, *, short_factor: float = MAXIMUM_DIRECTION[0],
                            long_factor: float = MAXIMUM_DIRECTION[1], s1: float | None = None) -> MceSpectrum:
        """S_MS = ``short_factor`` SA(0.2 s), S_M1 = ``long_factor`` SA(1 s) from a site's geometric-mean MCE_R values (g).

        The factors (default 1.1 and 1.3, ASCE 7-16 §21.2) turn the geometric
        mean of a hazard model into the maximum direction; pass 1.0 for values
        already in the maximum direction.
        """
        for name, value in (("sa_short", sa_short), ("sa_long", sa_long)):
            _positive(name, value)
        for name, value in (("short_factor", short_factor), ("long_factor", long_factor)):
            _at_least(name, value, 1.0)
        return cls(sms=short_factor * sa_short, sm1=long_factor * sa_long, long_period=long_period, s1=s1)


@dataclass(frozen=True)
class IsolatedPlan:
    """The plan of an isolated building for eq. 17.5-3's torsion.

    Attributes
    ----------
    short_side, long_side : float
        b and d, the shortest and longest plan dimensions (m), 0 < b <= d.
    eccentricity : float, optional
        e (m), actual plus accidental eccentricity, >= 0.05 d; None: accidental only,
        0.05 d (a slider's stiffness follows the weight it carries, so its
        centre of rigidity sits under the centre of mass).
    distance : float, optional
        y (m), from the centre of rigidity to the element of interest,
        perpendicular to the loading, in [0, d]; None: d/2, the far corner.
    torsion_ratio : float
        P_T, translational over torsional period of the isolation system
        (eq. 17.5-4); 1 (the default) for isolators spread evenly over a
        rectangular plan, and the largest D_TM §17.5.3.3 asks for.
    """

    short_side: float
    long_side: float
    eccentricity: float | None = None
    distance: float | None = None
    torsion_ratio: float = 1.0

    def __post_init__(self) -> None:
        for name in ("short_side", "long_side", "torsion_ratio"):
            _positive(name, getattr(self, name))
        if self.short_side > self.long_side:
            raise ValueError(f"short_side: must be <= long_side = {self.long_side:g} m, got {self.short_side!r}")
        if self.eccentricity is not None and not (math.isfinite(self.eccentricity)
                                                  and self.eccentricity >= ACCIDENTAL_ECCENTRICITY * self.long_side):
            raise ValueError(f"eccentricity: must be >= the accidental 0.05 long_side = {ACCIDENTAL_ECCENTRICITY * self.long_side:g} m "
                             f"(actual plus accidental), got {self.eccentricity!r}")
        if self.distance is not None and not (math.isfinite(self.distance) and 0.0 <= self.distance <= self.long_side):
            raise ValueError(f"distance: must be in [0, long_side = {self.long_side:g}] m, got {self.distance!r}")

    @property
    def amplification(self) -> float:
        """D_TM / D_M (1) of eq. 17.5-3, 1 + y / P_T² · 12 e / (b² + d²)."""
        e = ACCIDENTAL_ECCENTRICITY * self.long_side if self.eccentricity is None else self.eccentricity
        y = self.long_side / 2.0 if self.distance is None else self.distance
        return 1.0 + y / self.torsion_ratio**2 * 12.0 * e / (self.short_side**2 + self.long_side**2)

    @property
    def assumptions(self) -> tuple[str, ...]:
        """The defaults taken, one sentence each (empty when every input was given)."""
        said = []
        if self.eccentricity is None:
            said.append(f"e = 0.05 d = {ACCIDENTAL_ECCENTRICITY * self.long_side:.3g} m assumed (accidental only)")
        if self.distance is None:
            said.append(f"y = d/2 = {self.long_side / 2.0:.3g} m assumed (the far corner)")
        return tuple(said)


@dataclass(frozen=True)
class IsolationBound:
    """Chapter 17's displacements and forces at one friction bound.

    Attributes
    ----------
    bound : str
        ``"lower"`` or ``"upper"``.
    mu : float
        Friction coefficient at this bound (1).
    stiffness : float
        k_M, effective stiffness at D_M (N/m).
    period : float
        T_M, effective period at D_M (s), eq. 17.5-2.
    damping : float
        β_M, effective damping at D_M (1), from the friction loop.
    damping_coefficient : float
        B_M (1), Table 17.5-1.
    displacement : float
        D_M (m), eq. 17.5-1.
    total_displacement : float
        D_TM (m), eq. 17.5-3.
    base_shear : float
        V_b = k_M D_M (N), eq. 17.5-5.
    unreduced_shear : float
        V_st (N), eq. 17.5-7.
    shear : float
        V_s = V_st / R_I (N), eq. 17.5-8, before the limits of §17.5.4.3.
    """

    bound: str
    mu: float
    stiffness: float
    period: float
    damping: float
    damping_coefficient: float
    displacement: float
    total_displacement: float
    base_shear: float
    unreduced_shear: float
    shear: float


@dataclass(frozen=True)
class Chapter17Design:
    """An isolated building designed by ASCE 7-16 §17.5 (equivalent lateral force procedure).

    Attributes
    ----------
    lower, upper : IsolationBound
        The results at lower- and upper-bound friction.
    r_i : float
        R_I (1), §17.5.4.2.
    fixed_base_shear : float
        §17.5.4.3 item 1 (N): the §12.8 base shear of a fixed-base structure of weight W_s at the upper-bound T_M.
    wind_shear : float or None
        §17.5.4.3 item 2 (N), the factored design wind base shear given; None: not checked.
    activation_shear : float
        §17.5.4.3 item 3 (N): V_st with V_b the force that fully activates the isolation system.
    design_shear : float
        V_s the superstructure is designed for (N): the larger bound's V_s, not less than the limits.
    governs : str
        What sets ``design_shear``: ``"eq. 17.5-8"`` or the limit's item.
    total_displacement : float
        The larger bound's D_TM (m): the isolation system's displacement capacity and a moat's clearance (§17.2.5.2).
    assumptions : tuple of str
        Every default taken, one sentence each.
    """

    lower: IsolationBound
    upper: IsolationBound
    r_i: float
    fixed_base_shear: float
    wind_shear: float | None
    activation_shear: float
    design_shear: float
    governs: str
    total_displacement: float
    assumptions: tuple[str, ...]


@dataclass(frozen=True)
class IsolatedSeparation:
    """The separation of an isolated building from a fixed-base neighbour: D_TM + the neighbour's δ_M.

    Attributes
    ----------
    total_displacement : float
        D_TM of the isolated building at the contact (m), eq. 17.5-3.
    neighbour_displacement : float
        δ_M of the fixed-base neighbour at the contact (m), eq. 12.12-1.
    separation : float
        Their sum (m): §17.2.5.2's clearance to a fixed obstruction plus the obstruction's own motion.
    """

    total_displacement: float
    neighbour_displacement: float
    separation: float


def isolator_displacement(mu: float, radius: float, sm1: float, g: float = DEFAULT_G, tolerance: float = 1e-13) -> tuple[float, float, float]:
    """D_M (m), T_M (s), β_M (1) of a friction slider of friction ``mu`` and radius ``radius`` (m) at S_M1 = ``sm1`` (g).

    The fixed point of eq. 17.5-1 with eq. 17.5-2, k_M = W/R + μW/D and
    β_M = 2μ / (π (μ + D/R)) (the weight cancels), bracketed between a
    displacement too small (where eq. 17.5-1 gives more) and the frictionless
    pendulum's (T_M = 2π √(R/g), B_M = 0.8), to ``tolerance`` (m); ``g`` in m/s².
    """
    from scipy.optimize import brentq

    for name, value in (("mu", mu), ("radius", radius), ("sm1", sm1), ("g", g)):
        _positive(name, value)

    def period(displacement: float) -> float:
        return 2.0 * math.pi / math.sqrt(g / radius + mu * g / displacement)

    def damping(displacement: float) -> float:
        return 2.0 * mu / (math.pi * (mu + displacement / radius))

    def excess(displacement: float) -> float:
        return g * sm1 * period(displacement) / (4.0 * math.pi**2 * damping_coefficient(damping(displacement))) - displacement

    largest = g * sm1 * 2.0 * math.pi * math.sqrt(radius / g) / (4.0 * math.pi**2 * DAMPING_TABLE[0][1])
    displacement = float(brentq(excess, 1e-12 * largest, 1.0001 * largest, xtol=tolerance, rtol=1e-14))
    return displacement, period(displacement), damping(displacement)


def chapter17_design(base: SlidingBase, spectrum: MceSpectrum, plan: IsolatedPlan, r: float, *, wind_shear: float | None = None,
                     abrupt: bool = True, g: float = DEFAULT_G) -> Chapter17Design:
    """Design an isolated building on a sliding base by ASCE 7-16 §17.5 at both friction bounds.

    Parameters
    ----------
    base : SlidingBase
        The isolation system, its weights and property-modification factors.
    spectrum : MceSpectrum
        S_MS, S_M1 (maximum direction), T_L.
    plan : IsolatedPlan
        Plan dimensions, eccentricity and the element's distance for eq. 17.5-3.
    r : float
        R of the superstructure's seismic force-resisting system (Table 12.2-1), > 0: R_I = 3R/8 within [1, 2].
    wind_shear : float, optional
        Factored design wind base shear (N), §17.5.4.3 item 2; None: not checked (said in the assumptions).
    abrupt : bool
        Exponent 1 − 3.5 β_M in eq. 17.5-7 (§17.5.4.2's exception for an abrupt
        pre-slip to post-slip transition, a slider's); False: 1 − 2.5 β_M.
    g : float
        Standard gravity (m/s²).

    Returns
    -------
    Chapter17Design
    """
    from asce7_16.seismic import seismic_response_coeff

    _positive("r", r)
    _positive("wind_shear", wind_shear)
    r_i = min(2.0, max(1.0, 3.0 * r / 8.0))
    exponent = 3.5 if abrupt else 2.5
    bounds = [_bound(name, base.mu * factor, base, spectrum, plan, r_i, exponent, g)
              for name, factor in (("lower", base.lambda_min), ("upper", base.lambda_max))]
    lower, upper = bounds
    coefficient = seismic_response_coeff(r_i, 1.0, 2.0 / 3.0 * spectrum.sms, 2.0 / 3.0 * spectrum.sm1,
                                         spectrum.sm1 if spectrum.s1 is None else spectrum.s1, upper.period, spectrum.long_period)
    activation = max(upper.mu, 1.5 * base.mu, base.lambda_max * (base.breakaway or base.mu)) * base.weight
    limits = {"eq. 17.5-8": max(lower.shear, upper.shear),
              "§17.5.4.3 item 1 (fixed base at T_M)": coefficient * base.superstructure_weight,
              "§17.5.4.3 item 2 (wind)": wind_shear or 0.0,
              "§17.5.4.3 item 3 (activation)": activation * (base.superstructure_weight / base.weight) ** (1.0 - exponent * upper.damping)}
    governs = max(limits, key=limits.__getitem__)
    return Chapter17Design(lower=lower, upper=upper, r_i=r_i, fixed_base_shear=limits["§17.5.4.3 item 1 (fixed base at T_M)"],
                           wind_shear=wind_shear, activation_shear=limits["§17.5.4.3 item 3 (activation)"], design_shear=limits[governs],
                           governs=governs, total_displacement=max(lower.total_displacement, upper.total_displacement),
                           assumptions=_assumptions(base, spectrum, plan, wind_shear, abrupt))


def isolated_separation(design: Chapter17Design, neighbour_displacement: float) -> IsolatedSeparation:
    """D_TM + δ_M: the separation of an isolated building from a fixed-base neighbour whose δ_M (m, eq. 12.12-1) is given."""
    _at_least("neighbour_displacement", neighbour_displacement, 0.0)
    return IsolatedSeparation(design.total_displacement, neighbour_displacement, design.total_displacement + neighbour_displacement)


def _bound(name: str, mu: float, base: SlidingBase, spectrum: MceSpectrum, plan: IsolatedPlan, r_i: float, exponent: float,
           g: float) -> IsolationBound:
    displacement, period, damping = isolator_displacement(mu, base.radius, spectrum.sm1, g)
    stiffness = base.weight / base.radius + mu * base.weight / displacement
    base_shear = stiffness * displacement
    unreduced = base_shear * (base.superstructure_weight / base.weight) ** (1.0 - exponent * damping)
    return IsolationBound(bound=name, mu=mu, stiffness=stiffness, period=period, damping=damping,
                          damping_coefficient=damping_coefficient(damping), displacement=displacement,
                          total_displacement=displacement * plan.amplification, base_shear=base_shear,
                          unreduced_shear=unreduced, shear=unreduced / r_i)


def _assumptions(base: SlidingBase, spectrum: MceSpectrum, plan: IsolatedPlan, wind_shear: float | None, abrupt: bool) -> tuple[str, ...]:
    said = list(plan.assumptions)
    if (base.lambda_max, base.lambda_min) == PROPERTY_MODIFICATION:
        said.append("λ_max = 1.8, λ_min = 0.6 assumed on μ (no manufacturer's qualification data)")
    if base.breakaway is None:
        said.append("breakaway friction taken as μ")
    if spectrum.s1 is None:
        said.append("S_1 of eq. 12.8-6 taken as S_M1")
    if wind_shear is None:
        said.append("wind base shear not checked (§17.5.4.3 item 2)")
    said.append(f"eq. 17.5-7 exponent 1 − {3.5 if abrupt else 2.5} β_M")
    return tuple(said)
