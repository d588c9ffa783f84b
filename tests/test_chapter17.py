"""ASCE 7-16 chapter 17 for a building on a sliding base (stochpound.codes.chapter17_design) against a hand calculation.

The worked example of docs/separation.md ("An isolated building: ASCE 7-16
chapter 17"): a friction pendulum μ = 0.05, R = 2.24 m, λ_max = 1.8,
λ_min = 0.6 (μ 0.09 and 0.03), W = 5000 kN, W_s = 4000 kN; geometric-mean
SA(0.2 s) = 1.82 g and SA(1 s) = 1.20 g (S_MS = 2.002 g, S_M1 = 1.56 g in
the maximum direction), S_1 = 0.92 g, T_L = 8 s; a 12 m × 18 m plan with the
default e = 0.9 m and y = 9 m; superstructure R = 8 (R_I = 2). The D_M below
are the docs' (5 significant digits): the test checks that they are eq.
17.5-1's fixed point by plain arithmetic, then derives everything else
from them, digit by digit as the docs write it.
"""

from __future__ import annotations

import math

import pytest

from stochpound.risk import IsolatedPlan, MceSpectrum, SlidingBase, chapter17_design, isolated_separation

G = 9.81
W, WS = 5000e3, 4000e3  # N
R = 2.24  # m
SM1 = 1.3 * 1.20  # g, maximum direction
DOCS_DM = {"lower": 1.2955, "upper": 0.8149}  # m, docs/separation.md
AMPLIFICATION = 1.0 + 9.0 * 12.0 * 0.9 / (12.0**2 + 18.0**2)  # eq. 17.5-3 with y = 9 m, e = 0.9 m, b = 12 m, d = 18 m, P_T = 1


def _design():
    base = SlidingBase(mu=0.05, radius=R, weight=W, superstructure_weight=WS)
    spectrum = MceSpectrum.from_geometric_mean(1.82, 1.20, 8.0, s1=0.92)
    return chapter17_design(base, spectrum, IsolatedPlan(12.0, 18.0), 8.0)


def test_the_hand_calculation_of_both_friction_bounds():
    design = _design()
    # (mu, the Table 17.5-1 rows beta_M falls between: (beta_a, B_a), (beta_b, B_b))
    cases = {"lower": (0.05 * 0.6, (0.02, 0.8), (0.05, 1.0)), "upper": (0.05 * 1.8, (0.10, 1.2), (0.20, 1.5))}
    for bound, (mu, (beta_a, b_a), (beta_b, b_b)) in cases.items():
        d_m = DOCS_DM[bound]
        stiffness_per_weight = 1.0 / R + mu / d_m  # 1/m: k_M = W/R + mu W/D
        period = 2.0 * math.pi / math.sqrt(G * stiffness_per_weight)  # eq. 17.5-2
        damping = 2.0 * mu / (math.pi * (mu + d_m / R))  # loop energy 4 mu W D over 2 pi k_M D^2
        assert beta_a <= damping <= beta_b
        coefficient = b_a + (damping - beta_a) / (beta_b - beta_a) * (b_b - b_a)  # Table 17.5-1
        assert G * SM1 * period / (4.0 * math.pi**2 * coefficient) == pytest.approx(d_m, rel=2e-4)  # eq. 17.5-1: the fixed point
        result = getattr(design, bound)
        assert result.mu == pytest.approx(mu, rel=1e-12)
        assert result.displacement == pytest.approx(d_m, rel=1e-4)
        assert result.period == pytest.approx(period, rel=1e-4)
        assert result.damping == pytest.approx(damping, rel=1e-4)
        assert result.damping_coefficient == pytest.approx(coefficient, rel=1e-4)
        assert result.total_displacement == pytest.approx(d_m * AMPLIFICATION, rel=1e-4)  # eq. 17.5-3
        base_shear = W * (d_m / R + mu)  # eq. 17.5-5, k_M D_M
        assert result.base_shear == pytest.approx(base_shear, rel=1e-4)
        unreduced = base_shear * (WS / W) ** (1.0 - 3.5 * damping)  # eq. 17.5-7 (abrupt transition: 3.5)
        assert result.unreduced_shear == pytest.approx(unreduced, rel=1e-4)
        assert result.shear == pytest.approx(unreduced / 2.0, rel=1e-4)  # eq. 17.5-8, R_I = min(2, 3 x 8 / 8)
    # The docs' digits.
    assert design.lower.total_displacement == pytest.approx(1.5646, abs=1e-4)
    assert design.upper.total_displacement == pytest.approx(0.9842, abs=1e-4)
    assert (design.lower.base_shear / 1e3, design.upper.base_shear / 1e3) == pytest.approx((3041.7, 2269.0), abs=0.1)
    assert (design.lower.shear / 1e3, design.upper.shear / 1e3) == pytest.approx((1246.9, 1001.7), abs=0.1)


def test_the_limits_of_section_17_5_4_3_by_hand():
    design = _design()
    upper_period = 2.0 * math.pi / math.sqrt(G * (1.0 / R + 0.09 / DOCS_DM["upper"]))
    sds, sd1 = 2.0 / 3.0 * 1.1 * 1.82, 2.0 / 3.0 * SM1
    # Section 12.8 with R_I = 2, I_e = 1: min(S_DS/2, S_D1/(2 T)) = 0.193, raised to 0.5 S_1 / 2 = 0.23 (eq. 12.8-6, S_1 >= 0.6).
    assert sd1 / (upper_period * 2.0) < 0.23 and 0.044 * sds < 0.23
    assert design.fixed_base_shear == pytest.approx(0.23 * WS, rel=1e-12)
    upper_damping = 2.0 * 0.09 / (math.pi * (0.09 + DOCS_DM["upper"] / R))
    assert design.activation_shear == pytest.approx(0.09 * W * (WS / W) ** (1.0 - 3.5 * upper_damping), rel=1e-4)  # mu_max W > 1.5 mu W
    assert design.activation_shear / 1e3 == pytest.approx(397.3, abs=0.1)  # the docs' digits of item 3
    assert design.wind_shear is None
    assert (design.design_shear, design.governs) == (design.lower.shear, "eq. 17.5-8")
    assert design.total_displacement == design.lower.total_displacement
    assert any("y = d/2" in said for said in design.assumptions) and any("λ_max = 1.8" in said for said in design.assumptions)
    # A wind shear above them all governs.
    base = SlidingBase(mu=0.05, radius=R, weight=W, superstructure_weight=WS)
    windy = chapter17_design(base, MceSpectrum.from_geometric_mean(1.82, 1.20, 8.0, s1=0.92), IsolatedPlan(12.0, 18.0), 8.0, wind_shear=2e6)
    assert (windy.design_shear, windy.governs) == (2e6, "§17.5.4.3 item 2 (wind)")


def test_the_separation_from_a_fixed_neighbour_is_dtm_plus_its_delta_m():
    separation = isolated_separation(_design(), 0.10)
    assert separation.separation == pytest.approx(1.5646 + 0.10, abs=1e-4)
    assert separation.neighbour_displacement == 0.10


def test_given_plan_inputs_replace_the_defaults():
    plan = IsolatedPlan(10.0, 10.0, eccentricity=1.0, distance=2.0)
    assert plan.amplification == pytest.approx(1.0 + 2.0 * 12.0 * 1.0 / 200.0) and plan.assumptions == ()
    assert IsolatedPlan(10.0, 10.0, distance=0.0).amplification == 1.0  # the centre of rigidity itself
    assert IsolatedPlan(10.0, 10.0).amplification == pytest.approx(1.15)  # square plan, defaults: 1 + 5 x 12 x 0.5 / 200


@pytest.mark.parametrize(("build", "message"), [
    (lambda: SlidingBase(mu=0.0, radius=R, weight=W, superstructure_weight=WS), "mu: must be a positive number"),
    (lambda: SlidingBase(mu=0.4, radius=R, weight=W, superstructure_weight=WS), r"mu: must be in \(0, 0.3\]"),
    (lambda: SlidingBase(mu=0.05, radius=R, weight=W, superstructure_weight=1.1 * W), "superstructure_weight: must be in"),
    (lambda: SlidingBase(mu=0.05, radius=R, weight=W, superstructure_weight=WS, lambda_max=0.9), "lambda_max: must be >= 1"),
    (lambda: SlidingBase(mu=0.05, radius=R, weight=W, superstructure_weight=WS, lambda_min=1.2), r"lambda_min: must be in \(0, 1\]"),
    (lambda: SlidingBase(mu=0.05, radius=R, weight=W, superstructure_weight=WS, breakaway=0.04), "breakaway: must be >= mu"),
    (lambda: MceSpectrum.from_geometric_mean(1.8, -1.0, 8.0), "sa_long: must be a positive number"),
    (lambda: MceSpectrum.from_geometric_mean(1.8, 1.2, 8.0, long_factor=0.9), "long_factor: must be >= 1"),
    (lambda: IsolatedPlan(20.0, 10.0), "short_side: must be <= long_side"),
    (lambda: IsolatedPlan(10.0, 20.0, distance=25.0), r"distance: must be in \[0, long_side"),
    (lambda: IsolatedPlan(10.0, 20.0, eccentricity=0.5), "eccentricity: must be >= the accidental 0.05 long_side = 1 m"),
    (lambda: chapter17_design(SlidingBase(0.05, R, W, WS), MceSpectrum(2.0, 1.5, 8.0), IsolatedPlan(10.0, 20.0), 0.0), "r: must be a positive"),
    (lambda: isolated_separation(_design(), float("nan")), "neighbour_displacement: must be >= 0"),
])
def test_bad_inputs_name_the_field_and_range(build, message):
    with pytest.raises(ValueError, match=message) as error:
        build()
    assert "\n" not in str(error.value)


def test_the_isolated_flagships_item_3_limits_by_hand():
    """Issue 45: the isolated flagship's report gives §17.5.4.3 item 3 as 0.101 W_s (μ 0.05) and 0.176 W_s (μ 0.08), not checked
    by hand. Item 3 is V_st of eq. 17.5-7 with V_b the force that fully activates the isolation system at upper-bound friction,
    μ_max W (λ_max = 1.8; it exceeds 1.5 μ W): V_st / W_s = μ_max (W_s/W)^(−3.5 β_M) with β_M at the upper bound, whose D_M is
    found here by plain fixed-point iteration of eq. 17.5-1 (T_M, β_M and B_M of Table 17.5-1 as in the docs' hand calculation).
    The flagship: floor masses 26 268 and 17 512 kg on a 13 134 kg base (W_s/W = 10/13), R = 2.24 m, the site's geometric-mean
    SA(0.2 s) and SA(1 s) at 2 % in 50 yr from its bundled curves, T_L = 8 s."""
    from stochpound.hazard import HazardCurve, rate_from_probability

    rate = float(rate_from_probability(0.02, 50.0))
    sa_short, sa_long = (float(HazardCurve.bundled(f"fox_plaza_los_angeles_{name}").intensity_at(rate)) for name in ("sa0p2s", "sa1p0s"))
    rows = [(0.02, 0.8), (0.05, 1.0), (0.10, 1.2), (0.20, 1.5), (0.30, 1.7), (0.40, 1.9), (0.50, 2.0)]

    def coefficient(beta):  # Table 17.5-1, linear between its rows
        return next(b_a + (beta - beta_a) / (beta_b - beta_a) * (b_b - b_a) for (beta_a, b_a), (beta_b, b_b) in zip(rows, rows[1:])
                    if beta <= beta_b)

    masses, base_mass = 26268.0 + 17512.0, 13134.0
    weight, superstructure = (masses + base_mass) * G, masses * G
    for mu, printed in ((0.05, 0.101), (0.08, 0.176)):
        upper, d_m = 1.8 * mu, 0.5
        for _ in range(200):  # eq. 17.5-1: D = g S_M1 T_M / (4π² B_M), T_M and B_M at D
            period = 2.0 * math.pi / math.sqrt(G * (1.0 / R + upper / d_m))
            damping = 2.0 * upper / (math.pi * (upper + d_m / R))
            d_m = G * 1.3 * sa_long * period / (4.0 * math.pi**2 * coefficient(damping))
        damping = 2.0 * upper / (math.pi * (upper + d_m / R))
        hand = max(upper, 1.5 * mu) * (superstructure / weight) ** (-3.5 * damping)
        design = chapter17_design(SlidingBase(mu=mu, radius=R, weight=weight, superstructure_weight=superstructure),
                                  MceSpectrum.from_geometric_mean(sa_short, sa_long, 8.0), IsolatedPlan(10.0, 10.0), 8.0)
        assert design.upper.displacement == pytest.approx(d_m, rel=1e-3)
        assert design.activation_shear / superstructure == pytest.approx(hand, rel=1e-3)
        assert round(hand, 3) == printed  # the report's digits
